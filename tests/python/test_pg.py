# SPDX-License-Identifier: MIT
"""Policy-gradient maths: gradients against finite differences, estimators, optimiser, NaN guard."""
import numpy as np
import pytest

from pour.policy import linear
from pour.sim import envs
from pour.train import config as cfgmod
from pour.train import pg, reinforce, rundir


def _problem(seed=0, t=7, f=6, a=5):
    rng = np.random.default_rng(seed)
    w = rng.normal(0, 0.7, (f, a))
    x = rng.uniform(0, 1, (t, f))
    x[:, -1] = 1.0
    acts = rng.integers(0, a, t)
    weights = rng.normal(0, 1, t)
    return w, x, acts, weights


@pytest.mark.parametrize("entropy_coef", [0.0, 0.3])
def test_grad_surrogate_matches_finite_differences(entropy_coef):
    w, x, acts, weights = _problem()
    g = reinforce.grad_surrogate(w, x, acts, weights, entropy_coef)
    num = np.zeros_like(w)
    h = 1e-6
    for i in np.ndindex(w.shape):
        wp, wm = w.copy(), w.copy()
        wp[i] += h
        wm[i] -= h
        num[i] = (reinforce.surrogate(wp, x, acts, weights, entropy_coef)
                  - reinforce.surrogate(wm, x, acts, weights, entropy_coef)) / (2 * h)
    np.testing.assert_allclose(g, num, rtol=1e-6, atol=1e-8)


def test_batch_gradient_matches_finite_differences_of_mean_surrogate():
    rng = np.random.default_rng(3)
    n, t, f, a = 4, 6, 6, 3
    w = rng.normal(0, 0.5, (f, a))
    b = reinforce.Batch(rng.uniform(0, 1, (n, t, f)), rng.integers(0, a, (n, t)), rng.normal(0, 1, (n, t)))
    adv = reinforce.advantages(b, 0.9, True, "loo", True)
    coef = 0.05

    def obj(wv):
        # Mean over episodes of the advantage term; the entropy bonus is coef x (decisions per
        # episode) x (mean entropy over all decisions), spread over the n episodes of the mean.
        pg = np.mean([reinforce.surrogate(wv, b.x[i], b.actions[i], adv[i]) for i in range(n)])
        return pg + coef * t * np.mean(reinforce.entropy(linear.probs(wv, b.x.reshape(n * t, f)))) / n

    g = reinforce.batch_gradient(w, b, adv, coef)
    num = np.zeros_like(w)
    h = 1e-6
    for i in np.ndindex(w.shape):
        wp, wm = w.copy(), w.copy()
        wp[i] += h
        wm[i] -= h
        num[i] = (obj(wp) - obj(wm)) / (2 * h)
    np.testing.assert_allclose(g, num, rtol=1e-5, atol=1e-8)


def test_vanilla_weights_every_step_by_the_full_discounted_return():
    r = np.array([[1.0, 2.0, 3.0]])
    b = reinforce.Batch(np.ones((1, 3, 6)), np.zeros((1, 3), dtype=int), r)
    adv = reinforce.advantages(b, 0.5, reward_to_go=False, baseline="none", normalize=False)
    np.testing.assert_allclose(adv, [[2.75, 2.75, 2.75]])  # 1 + 0.5*2 + 0.25*3


def test_rewards_to_go():
    np.testing.assert_allclose(reinforce.rewards_to_go(np.array([1.0, 2.0, 3.0]), 0.5), [2.75, 3.5, 3.0])


def test_leave_one_out_baseline_subtracts_mean_of_the_others():
    r = np.array([[1.0, 0.0], [3.0, 0.0], [8.0, 0.0]])
    b = reinforce.Batch(np.ones((3, 2, 6)), np.zeros((3, 2), dtype=int), r)
    adv = reinforce.advantages(b, 1.0, reward_to_go=True, baseline="loo", normalize=False)
    np.testing.assert_allclose(adv[:, 0], [1 - 5.5, 3 - 4.5, 8 - 2.0])
    with pytest.raises(ValueError, match="at least 2"):
        reinforce.advantages(reinforce.Batch(b.x[:1], b.actions[:1], r[:1]), 1.0, True, "loo", False)


def test_normalised_advantages_have_zero_mean_unit_std():
    rng = np.random.default_rng(1)
    b = reinforce.Batch(np.ones((5, 9, 6)), np.zeros((5, 9), dtype=int), rng.normal(3, 10, (5, 9)))
    adv = reinforce.advantages(b, 0.99, True, "loo", True)
    assert abs(adv.mean()) < 1e-12 and abs(adv.std() - 1) < 1e-12


def test_softmax_survives_huge_logits():
    p = linear.softmax(np.array([[1e300, 0.0, -1e300], [1000.0, 1000.0, 0.0]]))
    assert np.all(np.isfinite(p))
    np.testing.assert_allclose(p[0], [1, 0, 0])
    np.testing.assert_allclose(p[1], [0.5, 0.5, 0])


def test_adam_first_step_is_lr_times_sign_and_state_round_trips():
    opt = reinforce.Adam((2, 2), lr=0.1)
    g = np.array([[3.0, -0.001], [0.0, 5.0]])
    step = opt.step(g)
    np.testing.assert_allclose(step, 0.1 * np.sign(g), atol=1e-6)
    st = opt.state_dict()
    opt2 = reinforce.Adam((2, 2), lr=0.1)
    opt2.load_state_dict(st)
    np.testing.assert_array_equal(opt.step(g), opt2.step(g))


def test_clip_norm():
    g, n = reinforce.clip_norm(np.array([3.0, 4.0]), 1.0)
    assert n == 5.0
    np.testing.assert_allclose(g, [0.6, 0.8])
    g, _ = reinforce.clip_norm(np.array([3.0, 4.0]), 0.0)
    np.testing.assert_allclose(g, [3.0, 4.0])


def test_nan_reward_gives_a_clear_gradient_error():
    cfg = cfgmod.from_dict({"env": {"kind": "toy"}, "algo": {"batch_episodes": 2}})
    ep = envs.Episode(np.ones((4, 6)), np.zeros(4, dtype=int), np.array([1.0, np.nan, 0.0, 0.0]),
                      {"v_target": 0, "v_spill": 0, "finish_s": 0})
    with pytest.raises(reinforce.GradientError, match=r"iteration 7: gradient has .* non-finite.*lower algo.lr"):
        pg.update(cfg, np.zeros((6, 11)), [ep, ep], reinforce.Adam((6, 11), 0.1), 7)


def test_overflowing_weights_give_a_clear_gradient_error():
    cfg = cfgmod.from_dict({"env": {"kind": "toy"}, "algo": {"kind": "vanilla", "batch_episodes": 1,
                                                              "optimizer": "sgd", "baseline": "none",
                                                              "normalize_advantages": False, "lr": 10.0,
                                                              "reward_to_go": False, "entropy_coef": 0.0}})
    ep = envs.Episode(np.ones((4, 6)), np.array([0, 1, 2, 3]), np.full(4, 1e307),
                      {"v_target": 0, "v_spill": 0, "finish_s": 0})
    with pytest.raises(reinforce.GradientError, match="non-finite"):
        pg.update(cfg, np.zeros((6, 11)), [ep], None, 0)


def test_feedback_parameterisation_gradient_matches_finite_differences():
    rng = np.random.default_rng(11)
    n_act, c = 7, 3.0
    beta = rng.normal(0, 0.5, 6)
    x = rng.uniform(0, 1, (9, 6))
    x[:, -1] = 1.0
    acts = rng.integers(0, n_act, 9)
    wts = rng.normal(0, 1, 9)

    def obj(b):
        return reinforce.surrogate(reinforce.w_from_params("feedback", b, n_act, c), x, acts, wts, 0.2)

    g_w = reinforce.grad_surrogate(reinforce.w_from_params("feedback", beta, n_act, c), x, acts, wts, 0.2)
    g = reinforce.grad_params("feedback", g_w, n_act, c)
    num = np.array([(obj(beta + h) - obj(beta - h)) / 2e-6 for h in np.eye(6) * 1e-6])
    np.testing.assert_allclose(g, num, rtol=1e-6, atol=1e-8)


def test_feedback_policy_peaks_at_the_level_nearest_u():
    beta = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.33])  # u(x) = 0.33 everywhere
    w = reinforce.w_from_params("feedback", beta, 11, 4.0)
    x = np.array([[0.3, 0.5, 1.0, 0.0, 0.0, 1.0]])
    assert int(np.argmax(x @ w)) == 7  # levels are -1, -0.8, ..., 0.4 at index 7 is nearest 0.33
    assert reinforce.w_from_params("full", np.arange(12.0), 2, 1.0).shape == (6, 2)


def test_mean_kl_is_zero_for_the_same_policy_and_matches_the_definition():
    w, x, _, _ = _problem(seed=5)
    w2 = w + np.random.default_rng(6).normal(0, 0.3, w.shape)
    assert reinforce.mean_kl(w, w, x) == pytest.approx(0.0, abs=1e-15)
    p, q = linear.probs(w, x), linear.probs(w2, x)
    want = np.mean(np.sum(p * np.log(p / q), axis=1))
    assert reinforce.mean_kl(w, w2, x) == pytest.approx(want, rel=1e-12)
    assert reinforce.mean_kl(w, w2, x) > 0


def test_trust_region_halves_the_step_until_the_kl_fits():
    w, x, _, _ = _problem(seed=7)
    step = np.random.default_rng(8).normal(0, 2.0, w.shape)

    def kl_of(s):
        return reinforce.mean_kl(w, w + s, x)

    full = kl_of(step)
    out, kl, scale = reinforce.trust_region(step, kl_of, full / 10)
    assert scale in (0.5, 0.25, 0.125, 0.0625)
    np.testing.assert_array_equal(out, step * scale)
    assert kl == kl_of(out) <= full / 10 < kl_of(out * 2)
    # A step inside the region is taken whole.
    out, kl, scale = reinforce.trust_region(step, kl_of, full)
    assert scale == 1.0 and kl == full
    np.testing.assert_array_equal(out, step)
    # No halving fits: the step is dropped rather than taken outside the region.
    out, kl, scale = reinforce.trust_region(step, lambda s: 1.0 + float(np.sum(s * s)), 0.5, max_halvings=3)
    assert scale == 0.0 and kl == 0.0 and not np.any(out)


def test_update_keeps_the_feedback_policy_inside_the_trust_region():
    cfg = cfgmod.from_dict({"iterations": 4, "policy": {"n_actions": 11, "param": "feedback", "sharpness": 10.0,
                                                        "init": "beta", "init_beta": [-4, -4, 0, 0, 0, 4]},
                            "algo": {"batch_episodes": 4, "lr": 0.25, "max_kl": 0.02}, "env": {"kind": "toy"}})
    env = envs.make_env("toy", 11, 10, 1.0, {})
    p0 = np.array(cfg.policy.init_beta, dtype=np.float64)
    w0 = rundir.weights(cfg, p0)
    eps = [env.rollout(w0, s, False) for s in range(4)]
    p1, st = pg.update(cfg, p0, eps, reinforce.Adam(p0.shape, cfg.algo.lr), 0)
    x = np.concatenate([e.x for e in eps])
    kl = reinforce.mean_kl(w0, rundir.weights(cfg, p1), x)
    assert 0 < kl <= 0.02 and st["kl"] == pytest.approx(kl, rel=1e-12)
    assert st["step_scale"] < 1.0 and st["lr"] == 0.25
    # Adam's first step is lr x sign(g) before the trust region scales it down.
    np.testing.assert_allclose(np.abs(p1 - p0), 0.25 * st["step_scale"], rtol=1e-5)


@pytest.mark.parametrize("param", ["feedback", "full"])
def test_fisher_gives_the_second_order_kl_of_a_step(param):
    rng = np.random.default_rng(11)
    x = rng.uniform(0, 1, (300, 6))
    x[:, 5] = 1.0
    p = np.array([-4.0, -4.0, 0.0, 0.0, 0.0, 4.0]) if param == "feedback" else rng.normal(0, 0.5, (6, 11))
    w = reinforce.w_from_params(param, p, 11, 10.0)
    fim = reinforce.fisher(param, w, x, 10.0)
    assert fim.shape == (p.size, p.size)
    np.testing.assert_allclose(fim, fim.T, atol=1e-12)
    d = rng.normal(0, 1, p.shape)
    d *= 1e-3 / np.linalg.norm(d)
    kl = reinforce.mean_kl(w, reinforce.w_from_params(param, p + d, 11, 10.0), x)
    dv = d.reshape(-1)
    assert kl == pytest.approx(0.5 * dv @ fim @ dv, rel=1e-2)


def test_natural_step_has_the_requested_kl_and_ascends():
    rng = np.random.default_rng(12)
    x = rng.uniform(0, 1, (300, 6))
    x[:, 5] = 1.0
    p = np.array([-4.0, -4.0, 0.5, 0.0, 0.0, 4.0])
    w = reinforce.w_from_params("feedback", p, 11, 10.0)
    g = rng.normal(0, 1, 6)
    d = reinforce.natural_step(g, reinforce.fisher("feedback", w, x, 10.0), 1e-3)
    assert g @ d > 0
    kl = reinforce.mean_kl(w, reinforce.w_from_params("feedback", p + d, 11, 10.0), x)
    assert kl == pytest.approx(1e-3, rel=5e-2)
    assert not np.any(reinforce.natural_step(np.zeros(6), reinforce.fisher("feedback", w, x, 10.0), 1e-3))
