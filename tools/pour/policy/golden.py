# SPDX-License-Identifier: MIT
"""Hand-made policies and golden vectors for the firmware's unit tests.

The fixed-point kernels' vectors (quantisation, softmax and argmax, the policy's logits, probabilities and
sampled actions) come from the independent Python reference, pour.policy.fixedpoint. The stateful parts (the
safety envelope, the estimator, whole control-step trajectories) are recorded from the C core itself
through pour.core (libpoursim): regression pins, not a second implementation. Their correctness against
docs/safety.md is what tests/python/test_core_properties.py checks, with Hypothesis.

    python -m pour.policy.golden            # rewrites tests/golden/golden_vectors.h and the hand-made policies
    python -m pour.policy.golden --check    # exits 1 if any committed file differs from a fresh generation
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from pour import paths
from pour import core
from pour.policy import weights_h
from pour.policy import fixedpoint as fp

SOURCE_DIR = paths.SOURCE_DIR
NORM = fp.ObsNorm(0, 2356194, 4000000)  # 0..135 deg, ±4 rad/s


def hand_made_weights(n_actions: int, sharpness: float = 4.0) -> np.ndarray:
    """W [6][n] of a hand-made pouring policy: a rate controller written as a softmax-linear policy.

    Target tilt rate ω* = 2.0 − 2.0 θn + 1.5 V_rot − 1.0 V_tgt [rad/s] (fast while the bucket is full and
    upright, easing off as θ grows, turning back once the target holds the liquid), preferred torque
    u* = 0.5 (ω* − ω) + 0.1 (fraction of τ_max; ω = 8 ωn − 4 for ω_max = 4 rad/s). The logits
    −c (L_a − u*)² + const = 2c L_a u* − c L_a² put the greedy action on the level nearest u*.
    In host_sim (τ_max 20 N·m, 8 seeds) it pours 100 % with no spill in 1.4 s.
    """
    levels = weights_h.even_levels(n_actions)
    gain, bias = 0.5, 0.1
    # u* as a linear function of the features θn, ωn, V_rot, V_tgt, V_spill, 1
    beta = np.array([gain * -2.0, gain * -8.0, gain * 1.5, gain * -1.0, 0.0, gain * (2.0 + 4.0) + bias])
    w = 2.0 * sharpness * np.outer(beta, levels)
    w[5] -= sharpness * levels**2
    return w


HAND_MADE = (("policy/example_weights.h", 11, "pour.policy.golden.hand_made_weights(11), kept for tests"),
             ("tests/golden/example_weights_2.h", 2, "pour.policy.golden.hand_made_weights(2), benchmarks"),
             ("policy/weights.h", 11, "pour.policy.golden.hand_made_weights(11), until a trained export"))


def _is_hand_made(path: Path) -> bool:
    try:
        first = path.read_text(encoding="utf-8").split("\n", 1)[0]
    except OSError:
        return True  # absent: ours to write
    return "Hand-made" in first


def write_policies(source_dir: Path = SOURCE_DIR) -> list[Path]:
    """The hand-made policies: tests (example_weights.h), benchmarks (2 actions) and the shipped
    policy/weights.h — the last only while it is hand-made (a trained export is never overwritten)."""
    out = []
    for rel, n, what in HAND_MADE:
        path = source_dir / rel
        if rel == "policy/weights.h" and not _is_hand_made(path):
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        weights_h.write_weights_h(path, hand_made_weights(n), decision_period_ms=10, norm=NORM, tau_max_mnm=20000,
                                  banner_inputs=what)
        out.append(path)
    return out


GOLDEN_REL = "tests/golden/golden_vectors.h"
EXAMPLE_REL = "policy/example_weights.h"
N_SOFTMAX = 120
N_POLICY = 120
N_SAMPLED = 4
SAMPLED_LEN = 32
SAFETY_LEN = 100


def _c_array(values) -> str:
    return "{" + ", ".join(str(int(v)) for v in values) + "}"


def _quant_cases(rng: np.random.Generator) -> list[tuple]:
    """(norm, state, expected obs) cases: edges, half LSBs, extremes, then random."""
    i32min, i32max = fp.INT32_MIN, fp.INT32_MAX
    norms = [NORM, fp.ObsNorm(-87266, 2356194, 4000000), fp.ObsNorm(0, 65536, 1), fp.ObsNorm(i32min, i32max, i32max),
             fp.ObsNorm(-5, 3 * 32768 - 5, 3),
             # either side of obs.c's switch from two 32-bit divides to one 64-bit divide (span 2^24)
             fp.ObsNorm(0, (1 << 24) - 1, (1 << 23) - 1), fp.ObsNorm(0, 1 << 24, 1 << 23)]
    states = [(0, 0, 0, 0, 0), (2356194, 4000000, 32767, 32767, 32767), (i32min, i32min, -32768, -1, -32768),
              (i32max, i32max, 32767, 0, 1), (1, 1, 1, 1, 1), (3, -3, 2, 3, 4), (1178097, -2000000, 16384, 8192, 100),
              (65535, 2, 0, 0, 0), (-1, -1, -1, -1, -1), ((1 << 24) - 2, (1 << 23) - 2, 5, 5, 5),
              (8388607, -8388607, 0, 0, 0), (16777215, 0, 0, 0, 0), (12345678, 7654321, 0, 0, 0)]
    cases = [(n, s) for n in norms for s in states]
    for _ in range(60):
        n = norms[int(rng.integers(len(norms)))]
        s = (int(rng.integers(i32min, i32max, endpoint=True)) if rng.random() < 0.2 else int(rng.integers(-300000, 2600000)),
             int(rng.integers(-5000000, 5000000)), int(rng.integers(-40000, 32768)) if rng.random() < 0.1 else
             int(rng.integers(0, 32768)), int(rng.integers(0, 32768)), int(rng.integers(0, 32768)))
        cases.append((n, (s[0], s[1], max(min(s[2], 32767), -32768), s[3], s[4])))
    return [(n, s, fp.quantize_obs(n, *s)) for n, s in cases]


def _softmax_cases(rng: np.random.Generator) -> list[tuple[list[int], list[int], int]]:
    i32min, i32max = fp.INT32_MIN, fp.INT32_MAX
    fixed = [[0, 0], [i32max, i32min], [i32min, i32max, i32min], [0, -22713], [5, 5, 5, 4],
             [i32min] * 16, [i32max] * 3 + [i32min] * 13, list(range(0, 16 * 40000, 40000)),
             [100000, 50000, 50001, -7], [-12, 0, -12], [0] * 11,
             [0, -(fp.EXP_D_CUTOFF - 1), -fp.EXP_D_CUTOFF, -(fp.EXP_D_CUTOFF + 1)]]
    out = [list(v) for v in fixed]
    while len(out) < N_SOFTMAX:
        n = int(rng.integers(2, 17))
        spread = [1 << 10, 1 << 15, 1 << 17, 1 << 19, 1 << 31][int(rng.integers(5))]
        out.append([int(np.clip(rng.integers(-spread, spread), i32min, i32max)) for _ in range(n)])
    return [(lg, fp.softmax_q15(lg), fp.argmax(lg)) for lg in out]


def _encoder_count(theta_urad: int, bits: int = 17) -> int:
    """The raw count a single-turn encoder reads at θ (0 = upright, below upright wraps)."""
    return int(np.floor(theta_urad * 1e-6 / (2 * np.pi) * (1 << bits) + 0.5)) % (1 << bits)


def _control_script(rng: np.random.Generator) -> list[tuple[bool, tuple, bool, bool]]:
    """Ticks of (fresh, sample, estop, clear), sample = (seq, encoder, scale_rotating_g, scale_target_g): idle,
    a pour with short gaps and scales that hold for 12 ticks, a timeout, clear, e-stop, clear, an implausible
    sample, clear, run."""
    ticks: list[tuple[bool, tuple, bool, bool]] = []
    theta, omega, m_rot, m_tgt, seq = 0, 0, 10300, 0, 0
    held = (m_rot, m_tgt)

    def sample() -> tuple:
        return (seq, _encoder_count(theta), held[0], held[1])

    def run(n: int, gaps: bool = True) -> None:
        nonlocal theta, omega, m_rot, m_tgt, seq, held
        for _ in range(n):
            seq += 1
            omega = int(np.clip(omega + rng.integers(-60000, 90000), -3000000, 3000000))
            theta = int(np.clip(theta + omega // 1000, -50000, 2300000))
            moved = min(int(rng.integers(0, 60)) if theta > 1200000 else 0, m_rot)
            m_rot, m_tgt = m_rot - moved, m_tgt + moved - int(rng.integers(0, 2))
            if seq % 12 == 0:  # an 80 Hz load cell
                held = (m_rot + int(rng.integers(-5, 6)), m_tgt + int(rng.integers(-5, 6)))
            fresh = not (gaps and rng.random() < 0.1)
            ticks.append((fresh, sample(), False, False))

    ticks += [(False, sample(), False, False)] * 15
    run(160)
    ticks += [(False, sample(), False, False)] * 25         # stale input: fault
    run(20, gaps=False)                                     # latched: still FAULT
    seq += 1
    ticks.append((True, sample(), False, True))             # clear, and this sample restarts RUN
    run(60)
    ticks += [(True, sample(), True, False)] * 4            # e-stop held
    ticks.append((True, sample(), True, True))              # clear ignored while held
    seq += 1
    ticks.append((True, sample(), False, False))            # released: FAULT
    seq += 1
    ticks.append((True, sample(), False, True))             # clear
    run(40)
    seq += 1
    ticks.append((True, (seq, 1 << 17, held[0], held[1]), False, False))  # implausible: count out of range
    run(5, gaps=False)
    ticks.append((False, sample(), False, True))
    run(60)
    return ticks


# Per control config: tau_limit, slew_per_tick, theta_min, theta_max, input_timeout_ms, safe_torque, sampled,
# seed, omega_max, alpha_max, omega_slack, governor_gain, encoder_bits, bandwidth (test_golden.c's order).
CONTROL_CONFIGS = (
    ("greedy, default config",
     (32767, 3277, -87266, 2356194, 20, 0, 0, 1, 2000000, 3400000, 800000, 16384, 17, 300)),
    ("sampled (seed 7), tighter envelope and motion limits, 10 ms timeout, a slow tracking loop (80 rad/s)",
     (24000, 2000, -20000, 1900000, 10, -1000, 1, 7, 1500000, 10000000, 400000, 30000, 17, 80)),
)


def control_config(row: tuple) -> core.ControlConfig:
    """The C config of a CONTROL_CONFIGS row, set as test_golden.c sets it (the supervisor disarmed)."""
    c = core.control_config()
    s = c.safety
    (s.tau_limit, s.slew_per_tick, s.theta_min_urad, s.theta_max_urad, c.input_timeout_ms, c.safe_torque, sampled,
     c.seed, s.omega_max_urad_s, s.alpha_max_urad_s2, s.omega_slack_urad_s, s.governor_gain,
     c.sensors.encoder_bits, c.sensors.bandwidth_rad_s) = row
    c.policy_mode = 1 if sampled else 0
    c.supervisor.checks = 0  # the vectors are scripted, not physical, states
    return c


def _control_lines(ex: weights_h.WeightsH, rng: np.random.Generator) -> list[str]:
    lines = ["/* pour_control_step on example_weights.h: per tick the inputs (flags: 1 fresh, 2 e-stop, 4 clear;",
             " * sample seq, encoder, scale_rotating_g, scale_target_g) and the outputs (torque, action, mode,",
             " * faults, limits). */",
             "typedef struct { uint8_t flags; uint32_t sample[4]; int16_t torque; uint8_t action; uint8_t mode; "
             "uint16_t faults; uint8_t limits; } pour_golden_tick_t;"]
    script = _control_script(rng)
    for i, (what, row) in enumerate(CONTROL_CONFIGS):
        ctl = core.Controller(ex, control_config(row))
        lines += [f"/* {what} */",
                  f"static const int32_t pour_golden_control_config_{i}[14] = {_c_array(row)};",
                  f"static const pour_golden_tick_t pour_golden_control_{i}[] = {{"]
        for fresh, smp, estop, clear in script:
            o = ctl.step(smp if fresh else None, estop=estop, clear_faults=clear)
            flags = int(fresh) | 2 * int(estop) | 4 * int(clear)
            lines.append(f"    {{{flags}, {{{smp[0]}u, {smp[1]}u, {smp[2] & 0xFFFFFFFF}u, {smp[3] & 0xFFFFFFFF}u}}, "
                         f"{o.torque}, {o.action}, {o.mode}, {o.faults}, {o.limits}}},")
        lines.append("};")
    lines += [f"#define POUR_GOLDEN_CONTROL_LEN {len(script)}", ""]
    return lines


ESTIMATOR_LEN = 200


def _estimator_lines(rng: np.random.Generator) -> list[str]:
    """pour_estimator_update over a scripted motion per config: rest, a swing through upright (the wrap),
    seq gaps, repeats, held scales, and implausible samples (count, scales, m0) in between."""
    configs = [core.sensors_config(encoder_bits=17, bandwidth_rad_s=300, scale_min_g=-2000, scale_max_g=30000,
                                   mass_min_g=1000, jump_max_urad=10000),
               core.sensors_config(encoder_bits=12, bandwidth_rad_s=40, scale_min_g=-100, scale_max_g=20000,
                                   mass_min_g=2000, jump_max_urad=3000),
               core.sensors_config(encoder_bits=24, bandwidth_rad_s=1000, scale_min_g=-32767, scale_max_g=32767,
                                   mass_min_g=1, jump_max_urad=1000000)]
    lines = ["/* pour_estimator_update: config (encoder_bits, bandwidth, scale_min, scale_max, mass_min, jump_max), per",
             " * sample (seq, encoder, scale_rotating_g, scale_target_g) -> ok and the state (θ, θ̇, V_rot, V_tgt,",
             " * V_spill; the last good one where not ok) */",
             f"typedef struct {{ int32_t config[6]; uint32_t sample[{ESTIMATOR_LEN}][4]; uint8_t ok[{ESTIMATOR_LEN}]; "
             f"int32_t state[{ESTIMATOR_LEN}][5]; }} pour_golden_estimator_t;",
             "static const pour_golden_estimator_t pour_golden_estimator[] = {"]
    for cfg in configs:
        est = core.Estimator(cfg)
        bits = cfg.encoder_bits
        theta, omega, seq, m_rot, m_tgt = 300000, 0.0, 7, 9000, 1000
        samples, oks, states, last = [], [], [], (0, 0, 0, 0, 0)
        for t in range(ESTIMATOR_LEN):
            seq = (seq + [1, 1, 1, 3, 0, 40][int(rng.integers(6))]) & 0xFFFFFFFF
            omega = -3.0 * np.sin(t / 25.0) + float(rng.normal(0, 0.05))
            theta = int(theta + omega * 1000)
            if t % 12 == 0:
                moved = int(rng.integers(0, 300))
                m_rot, m_tgt = m_rot - moved, m_tgt + moved - int(rng.integers(0, 20))
            smp = [seq, _encoder_count(theta, bits), m_rot, m_tgt]
            kind = int(rng.integers(20))
            if t == 0:
                smp[2] = cfg.mass_min_g - 1 - smp[3]  # m0 too small: the first good sample comes after
            elif kind == 0:
                smp[1] = (1 << bits) + int(rng.integers(0, 5))
            elif kind == 1:
                smp[2] = cfg.scale_max_g + 1
            elif kind == 2:
                smp[3] = cfg.scale_min_g - 1
            elif kind == 3:
                smp[2] = cfg.scale_max_g  # at the limit: plausible
            elif kind == 4:
                smp[1] = _encoder_count(theta + int(rng.choice([-1, 1])) * int(rng.integers(2000, 60000)), bits)
            r = est.update(*smp)
            oks.append(0 if r is None else 1)
            if r is not None:
                last = r[1:]
            samples.append(smp)
            states.append(last)
        lines.append(f"    {{{_c_array([cfg.encoder_bits, cfg.bandwidth_rad_s, cfg.scale_min_g, cfg.scale_max_g, cfg.mass_min_g, cfg.jump_max_urad])}, "
                     "{" + ", ".join("{" + ", ".join(f"{v & 0xFFFFFFFF}u" for v in sm) + "}" for sm in samples) + "}, "
                     f"{_c_array(oks)}, " + "{" + ", ".join(_c_array(st) for st in states) + "}},")
    lines += ["};", f"#define POUR_GOLDEN_N_ESTIMATOR {len(configs)}", f"#define POUR_GOLDEN_ESTIMATOR_LEN {ESTIMATOR_LEN}",
              ""]
    return lines


def golden_vectors_text(source_dir: Path = SOURCE_DIR, seed: int = 20261123) -> str:
    """The text of tests/golden/golden_vectors.h, from the Python reference and example_weights.h."""
    rng = np.random.default_rng(seed)
    ex = weights_h.parse_weights_h(source_dir / EXAMPLE_REL)
    n = ex.n_actions
    # The banner keeps the binding's former name (pour.policy.core, now pour.core) so that the shipped header
    # stays byte for byte what it was.
    lines = [
        f"/* golden_vectors.h — expected outputs of the fixed-point core, generated by tools/pour/policy/golden.py "
        f"(seed {seed}; kernels from pour.policy.fixedpoint, envelope, estimator and control step recorded from the C "
        f"core through pour.policy.core) from {EXAMPLE_REL} (content hash 0x{ex.content_hash:08x}). DO NOT EDIT. */",
        "#ifndef POUR_GOLDEN_VECTORS_H",
        "#define POUR_GOLDEN_VECTORS_H",
        "#include <stdint.h>",
        "",
        f"#define POUR_GOLDEN_EXAMPLE_HASH 0x{ex.content_hash:08x}u",
        f"#define POUR_GOLDEN_EXAMPLE_N_ACTIONS {n}",
        "",
        "/* pour_obs_quantize: norm (theta_min, theta_max, omega_max), state (theta, omega, v_rot, v_tgt, v_spill)"
        " -> obs */",
        "typedef struct { int32_t norm[3]; int32_t state[5]; int16_t obs[5]; } pour_golden_quant_t;",
        "static const pour_golden_quant_t pour_golden_quant[] = {",
    ]
    quant = _quant_cases(rng)
    for nm, st, ob in quant:
        lines.append(f"    {{{_c_array([nm.theta_min_urad, nm.theta_max_urad, nm.omega_max_urad_s])}, "
                     f"{_c_array(st)}, {_c_array(ob)}}},")
    lines += ["};", f"#define POUR_GOLDEN_N_QUANT {len(quant)}", "",
              "/* pour_policy_softmax_q15 and pour_policy_argmax: n logits (Q16.15) -> probs (Q15), argmax */",
              "typedef struct { uint8_t n; int32_t logits[16]; int16_t probs[16]; uint8_t argmax; } pour_golden_softmax_t;",
              "static const pour_golden_softmax_t pour_golden_softmax[] = {"]
    soft = _softmax_cases(rng)
    for lg, pr, am in soft:
        lines.append(f"    {{{len(lg)}, {_c_array(lg)}, {_c_array(pr)}, {am}}},")
    lines += ["};", f"#define POUR_GOLDEN_N_SOFTMAX {len(soft)}", "",
              "/* pour_policy_eval, greedy, example_weights.h: obs -> logits, probs, action */",
              f"typedef struct {{ int16_t obs[5]; int32_t logits[{n}]; int16_t probs[{n}]; uint8_t action; }} "
              "pour_golden_policy_t;",
              "static const pour_golden_policy_t pour_golden_policy[] = {"]
    pol = fp.FixedPolicy(ex.w_q, ex.w_frac_bits)
    obs_cases = [[0] * 5, [32767] * 5, [0, 16384, 32767, 0, 0], [19000, 16384, 1000, 30000, 0]]
    while len(obs_cases) < N_POLICY:
        obs_cases.append([int(v) for v in rng.integers(0, 32768, size=5)])
    for ob in obs_cases:
        e = pol.eval(ob)
        lines.append(f"    {{{_c_array(ob)}, {_c_array(e.logits)}, {_c_array(e.probs)}, {e.action}}},")
    lines += ["};", f"#define POUR_GOLDEN_N_POLICY {len(obs_cases)}", "",
              "/* pour_policy_eval, sampled, example_weights.h: seed and obs -> the first actions drawn */",
              f"typedef struct {{ uint32_t seed; int16_t obs[5]; uint8_t actions[{SAMPLED_LEN}]; }} pour_golden_sampled_t;",
              "static const pour_golden_sampled_t pour_golden_sampled[] = {"]
    for i in range(N_SAMPLED):
        seed_i = [0, 1, 42, 0xDEADBEEF][i]
        ob = [int(v) for v in rng.integers(0, 32768, size=5)]
        sp = fp.FixedPolicy(ex.w_q, ex.w_frac_bits, sampled=True, seed=seed_i)
        acts = [sp.eval(ob).action for _ in range(SAMPLED_LEN)]
        lines.append(f"    {{{seed_i}u, {_c_array(ob)}, {_c_array(acts)}}},")
    lines += ["};", f"#define POUR_GOLDEN_N_SAMPLED {N_SAMPLED}", f"#define POUR_GOLDEN_SAMPLED_LEN {SAMPLED_LEN}", ""]
    configs = [core.safety_config(tau_limit=32767, slew_per_tick=3277, theta_min_urad=-87266, theta_max_urad=2356194,
                                  omega_max_urad_s=2000000, alpha_max_urad_s2=3400000, omega_slack_urad_s=800000,
                                  governor_gain=16384),
               core.safety_config(tau_limit=20000, slew_per_tick=3000, theta_min_urad=-1000, theta_max_urad=2000000,
                                  omega_max_urad_s=3000000, alpha_max_urad_s2=50000000, omega_slack_urad_s=200000,
                                  governor_gain=32767)]
    lines += ["/* pour_safety_apply: config (tau_limit, slew_per_tick, theta_min, theta_max, omega_max, alpha_max,",
              " * omega_slack, torque_per_rad_s), then per tick requested torque, θ and θ̇ -> command and active limits */",
              f"typedef struct {{ int32_t config[8]; int32_t requested[{SAFETY_LEN}]; int32_t theta[{SAFETY_LEN}]; "
              f"int32_t omega[{SAFETY_LEN}]; int16_t torque[{SAFETY_LEN}]; uint8_t active[{SAFETY_LEN}]; }} "
              "pour_golden_safety_t;",
              "static const pour_golden_safety_t pour_golden_safety[] = {"]
    for cfg in configs:
        env = core.Envelope(cfg)
        req, th, om, tq, act = [], [], [], [], []
        omega = 0
        for t in range(SAFETY_LEN):
            r = int(rng.choice([-32768, 32767, 0, int(rng.integers(-32768, 32768))]))
            theta = int(rng.choice([cfg.theta_min_urad, cfg.theta_max_urad, int(rng.integers(-200000, 2500000))]))
            omega = int(rng.choice([omega + int(rng.integers(-300000, 300000)), -cfg.omega_max_urad_s,
                                    cfg.omega_max_urad_s + 1, int(rng.integers(-8000000, 8000000)),
                                    fp.INT32_MAX, fp.INT32_MIN], p=[0.7, 0.05, 0.05, 0.1, 0.05, 0.05]))
            req.append(r)
            th.append(theta)
            om.append(omega)
            tq.append(env.apply(r, theta, omega))
            act.append(env.active)
            omega = int(np.clip(omega, -4000000, 4000000))
        lines.append(f"    {{{_c_array([cfg.tau_limit, cfg.slew_per_tick, cfg.theta_min_urad, cfg.theta_max_urad, cfg.omega_max_urad_s, cfg.alpha_max_urad_s2, cfg.omega_slack_urad_s, cfg.governor_gain])}, "
                     f"{_c_array(req)}, {_c_array(th)}, {_c_array(om)}, {_c_array(tq)}, {_c_array(act)}}},")
    lines += ["};", f"#define POUR_GOLDEN_N_SAFETY {len(configs)}", f"#define POUR_GOLDEN_SAFETY_LEN {SAFETY_LEN}", ""]
    lines += _estimator_lines(rng)
    lines += _control_lines(ex, rng) + ["#endif", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare instead of writing")
    ap.add_argument("--source-dir", type=Path, default=SOURCE_DIR)
    args = ap.parse_args(argv)
    if args.check:
        import tempfile
        stale = []
        with tempfile.TemporaryDirectory() as tmp:
            fresh = Path(tmp)
            write_policies(fresh)
            for rel, _, _ in HAND_MADE:
                if rel == "policy/weights.h" and not _is_hand_made(args.source_dir / rel):
                    continue  # a trained export: not ours to compare
                if (fresh / rel).read_text() != _read(args.source_dir / rel):
                    stale.append(rel)
        if golden_vectors_text(args.source_dir) != _read(args.source_dir / GOLDEN_REL):
            stale.append(GOLDEN_REL)
        for rel in stale:
            print(f"error: {rel} differs from a fresh generation (run: python -m pour.policy.golden)", file=sys.stderr)
        return 1 if stale else 0
    write_policies(args.source_dir)
    (args.source_dir / GOLDEN_REL).write_text(golden_vectors_text(args.source_dir), encoding="utf-8")
    return 0


def _read(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except OSError:
        return ""


if __name__ == "__main__":
    sys.exit(main())
