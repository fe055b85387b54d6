# SPDX-License-Identifier: MIT
"""Policy-gradient maths for the softmax-linear policy pi(a|x) = softmax(x.W) (pour.policy.linear).

x is the feature row [theta_n, omega_n, V_rot, V_tgt, V_spill, 1.0]; W is [6][n_actions].
Two updates are provided:
  * vanilla  -- the paper's eq. 19: every grad log pi(a_t|x_t) of an episode is multiplied by the
                episode's full discounted return R(tau); plain gradient ascent.
  * pg       -- reward-to-go, a leave-one-out time-indexed baseline over a batch of episodes,
                normalised advantages, an entropy bonus, Adam, optional gradient-norm clipping and an
                optional trust region on the mean KL divergence between the old and the new policy.
Everything here is pure numpy and deterministic.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pour.policy.linear import action_levels, probs


class GradientError(FloatingPointError):
    """A gradient or weight that is not finite: training stops instead of corrupting the run."""


def discounted_return(rewards: np.ndarray, gamma: float) -> float:
    """R(tau) = sum_t gamma^t r_t."""
    r = np.asarray(rewards, dtype=np.float64)
    return float(np.sum(r * gamma ** np.arange(r.size)))


def rewards_to_go(rewards: np.ndarray, gamma: float) -> np.ndarray:
    """G_t = sum_{k>=t} gamma^(k-t) r_k, for every t."""
    r = np.asarray(rewards, dtype=np.float64)
    out = np.empty_like(r)
    acc = 0.0
    for t in range(r.size - 1, -1, -1):
        acc = r[t] + gamma * acc
        out[t] = acc
    return out


def entropy(p: np.ndarray) -> np.ndarray:
    """Entropy of each row of probabilities [nats]."""
    return -np.sum(p * np.log(np.clip(p, 1e-300, None)), axis=-1)


def surrogate(w: np.ndarray, x: np.ndarray, actions: np.ndarray, weights: np.ndarray,
              entropy_coef: float = 0.0) -> float:
    """sum_t weights_t log pi(a_t|x_t) + entropy_coef * mean_t H(pi(.|x_t)).

    Its gradient in w is the policy-gradient estimate; grad_surrogate computes it in closed form and
    the tests check it against finite differences of this function.
    """
    logits = x @ w
    z = logits - np.max(logits, axis=1, keepdims=True)
    logp = z - np.log(np.sum(np.exp(z), axis=1, keepdims=True))
    lp_a = logp[np.arange(x.shape[0]), actions]
    p = np.exp(logp)
    h = -np.sum(p * logp, axis=1)
    return float(np.sum(weights * lp_a) + entropy_coef * np.mean(h))


def grad_surrogate(w: np.ndarray, x: np.ndarray, actions: np.ndarray, weights: np.ndarray,
                   entropy_coef: float = 0.0) -> np.ndarray:
    """Closed-form gradient of surrogate() in w, shape [F][A].

    d log pi(a|x)/dW = x (e_a - pi)^T;  dH/dlogits_j = -pi_j (log pi_j + H).
    """
    t, a = x.shape[0], w.shape[1]
    p = probs(w, x)
    onehot = np.zeros((t, a))
    onehot[np.arange(t), actions] = 1.0
    g_logits = weights[:, None] * (onehot - p)
    if entropy_coef:
        logp = np.log(np.clip(p, 1e-300, None))
        h = -np.sum(p * logp, axis=1, keepdims=True)
        g_logits = g_logits + (entropy_coef / t) * (-p * (logp + h))
    return x.T @ g_logits


@dataclass
class Batch:
    """Decisions of a batch of equally long episodes: x [N][T][F], actions [N][T], rewards [N][T]."""
    x: np.ndarray
    actions: np.ndarray
    rewards: np.ndarray


def advantages(batch: Batch, gamma_decision: float, reward_to_go: bool, baseline: str,
               normalize: bool) -> np.ndarray:
    """Per-decision weights of grad log pi, [N][T], for the chosen estimator.

    baseline 'loo' subtracts, at each decision index t, the mean over the *other* episodes of the
    batch (leave-one-out keeps the estimate unbiased; episodes all have the same length).
    """
    r = batch.rewards
    n, t = r.shape
    if reward_to_go:
        g = np.stack([rewards_to_go(r[i], gamma_decision) for i in range(n)])
    else:
        g = np.repeat(np.array([discounted_return(r[i], gamma_decision) for i in range(n)])[:, None], t, 1)
    if baseline == "loo":
        if n < 2:
            raise ValueError("baseline 'loo' needs at least 2 episodes per batch")
        g = g - (np.sum(g, axis=0, keepdims=True) - g) / (n - 1)
    elif baseline != "none":
        raise ValueError(f"unknown baseline {baseline!r}")
    if normalize:
        sd = float(np.std(g))
        g = (g - float(np.mean(g))) / (sd if sd > 1e-12 else 1.0)
    return g


def batch_gradient(w: np.ndarray, batch: Batch, adv: np.ndarray, entropy_coef: float) -> np.ndarray:
    """Mean over episodes of the per-episode surrogate gradient (sum over decisions)."""
    n, t, f = batch.x.shape
    x = batch.x.reshape(n * t, f)
    acts = batch.actions.reshape(n * t)
    # Entropy term: the mean over all decisions, times the number of decisions per episode, so its
    # scale matches the per-episode sum of the advantage term.
    g = grad_surrogate(w, x, acts, adv.reshape(n * t), entropy_coef * t)
    return g / n


def check_finite(name: str, arr: np.ndarray, iteration: int) -> None:
    """Raises GradientError if arr holds NaN or infinity."""
    if not np.all(np.isfinite(arr)):
        bad = int(np.size(arr) - np.count_nonzero(np.isfinite(arr)))
        raise GradientError(
            f"iteration {iteration}: {name} has {bad} non-finite value(s) (NaN or inf); "
            "lower algo.lr or algo.reward_scale, or enable algo.grad_clip / normalize_advantages")


class Adam:
    """Adam for gradient *ascent* on one array; its state round-trips through state_dict()."""

    def __init__(self, shape: tuple, lr: float, b1: float = 0.9, b2: float = 0.999, eps: float = 1e-8):
        self.lr, self.b1, self.b2, self.eps = lr, b1, b2, eps
        self.m = np.zeros(shape)
        self.v = np.zeros(shape)
        self.t = 0

    def step(self, grad: np.ndarray) -> np.ndarray:
        """The increment to add to the parameters."""
        self.t += 1
        self.m = self.b1 * self.m + (1 - self.b1) * grad
        self.v = self.b2 * self.v + (1 - self.b2) * grad * grad
        mh = self.m / (1 - self.b1 ** self.t)
        vh = self.v / (1 - self.b2 ** self.t)
        return self.lr * mh / (np.sqrt(vh) + self.eps)

    def state_dict(self) -> dict:
        return {"adam_m": self.m.copy(), "adam_v": self.v.copy(), "adam_t": np.array(self.t)}

    def load_state_dict(self, d: dict) -> None:
        self.m = np.array(d["adam_m"], dtype=np.float64)
        self.v = np.array(d["adam_v"], dtype=np.float64)
        self.t = int(d["adam_t"])


def mean_kl(w_old: np.ndarray, w_new: np.ndarray, x: np.ndarray) -> float:
    """Mean over the rows of x [T][F] of KL(pi_old(.|x) || pi_new(.|x)) [nats]."""
    def logp(w: np.ndarray) -> np.ndarray:
        z = x @ w
        z = z - np.max(z, axis=1, keepdims=True)
        return z - np.log(np.sum(np.exp(z), axis=1, keepdims=True))
    lo, ln = logp(w_old), logp(w_new)
    return float(np.mean(np.sum(np.exp(lo) * (lo - ln), axis=1)))


def trust_region(step: np.ndarray, kl_of, max_kl: float, max_halvings: int = 12
                 ) -> tuple[np.ndarray, float, float]:
    """Backtracking on the step's length: halves it until kl_of(step) <= max_kl.

    kl_of maps a parameter increment to the mean KL(old || new) over the batch's states. Returns
    (step, its KL, the scale applied: 1, 1/2, 1/4, ...); after max_halvings the step is dropped
    (scale 0, KL 0) rather than taken outside the region.
    """
    scale = 1.0
    for _ in range(max_halvings + 1):
        kl = kl_of(step * scale)
        if kl <= max_kl:
            return step * scale, kl, scale
        scale *= 0.5
    return np.zeros_like(step), 0.0, 0.0


def fisher(param: str, w: np.ndarray, x: np.ndarray, sharpness: float) -> np.ndarray:
    """The policy's Fisher information in its parameters, averaged over the rows of x [T][F].

    F = mean_x E_a[s s^T], s = grad log pi(a|x) in the parameters; the second-order term of the mean
    KL(old || new) is 1/2 d^T F d for a parameter step d. "full": d logit_a / d W[f][b] = x_f [a = b],
    so F[(f,a),(g,b)] = mean x_f x_g (diag(pi) - pi pi^T)[a][b]. "feedback": d logit_a / d beta =
    2c L_a x, so F = 4c^2 mean Var_pi(L) x x^T.
    """
    p = probs(w, x)
    n, f = x.shape
    a = p.shape[1]
    if param == "feedback":
        lv = action_levels(a)
        var = p @ (lv * lv) - (p @ lv) ** 2
        return 4.0 * sharpness ** 2 * (x * var[:, None]).T @ x / n
    if param == "full":
        cov = -p[:, :, None] * p[:, None, :]
        cov[:, np.arange(a), np.arange(a)] += p
        xx = (x[:, :, None] * x[:, None, :]).reshape(n, f * f)
        m = (xx.T @ cov.reshape(n, a * a) / n).reshape(f, f, a, a)
        return m.transpose(0, 2, 1, 3).reshape(f * a, f * a)
    raise ValueError(f"unknown parameterisation {param!r}")


def natural_step(g: np.ndarray, fim: np.ndarray, kl: float, damping: float = 1e-4) -> np.ndarray:
    """The natural-gradient step whose quadratic KL estimate 1/2 d^T F d equals kl [nats].

    d = sqrt(2 kl / g^T F^-1 g) F^-1 g, with F damped by damping x its mean diagonal so that
    directions the batch never explores (a feature always 0) stay finite.
    """
    shape = g.shape
    gv = g.reshape(-1)
    lam = damping * float(np.mean(np.diag(fim))) + 1e-12
    d = np.linalg.solve(fim + lam * np.eye(gv.size), gv)
    gd = float(gv @ d)
    if not gd > 0.0:
        return np.zeros(shape)
    return (np.sqrt(2.0 * kl / gd) * d).reshape(shape)


def clip_norm(g: np.ndarray, max_norm: float) -> tuple[np.ndarray, float]:
    """Scales g down to L2 norm max_norm if larger (max_norm 0 = off); returns (g, original norm)."""
    norm = float(np.linalg.norm(g))
    if max_norm > 0 and norm > max_norm:
        g = g * (max_norm / norm)
    return g, norm


# --- parameterisations of W ---------------------------------------------------------------------------
# "full": W itself (6 x n_actions), the paper's policy.
# "feedback": W = c (2 beta (x) L - e_bias (x) L^2), so logit_a = -c (L_a - u(x))^2 + const with
#   u(x) = beta . x: the softmax peaks at the torque level nearest a linear state feedback u(x), and c
#   (the sharpness) sets how widely it explores around it. Still a softmax-linear policy over the same
#   features (W has rank 2), exported and run by the firmware unchanged; REINFORCE's gradient reaches
#   beta through the chain rule. Exploring around a feedback law rather than with white-noise torque
#   is what lets the gradient find pours that do not spill.

def params_shape(param: str, n_actions: int) -> tuple:
    return (6, n_actions) if param == "full" else (6,)


def w_from_params(param: str, p: np.ndarray, n_actions: int, sharpness: float) -> np.ndarray:
    """The policy's W [6][n_actions] for a parameter vector."""
    if param == "full":
        return np.asarray(p, dtype=np.float64).reshape(6, n_actions)
    if param == "feedback":
        lv = action_levels(n_actions)
        w = 2.0 * sharpness * np.outer(p, lv)
        w[5] -= sharpness * lv ** 2
        return w
    raise ValueError(f"unknown parameterisation {param!r}")


def grad_params(param: str, g_w: np.ndarray, n_actions: int, sharpness: float) -> np.ndarray:
    """Chain rule: the gradient in the parameters from the gradient in W."""
    if param == "full":
        return np.asarray(g_w)
    if param == "feedback":
        return 2.0 * sharpness * (np.asarray(g_w) @ action_levels(n_actions))
    raise ValueError(f"unknown parameterisation {param!r}")
