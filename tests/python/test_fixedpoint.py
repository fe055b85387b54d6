# SPDX-License-Identifier: MIT
"""pour.fixedpoint: the Python mirror of the firmware's fixed-point maths."""
import re

import numpy as np
import pytest

from pour import fixedpoint as fp
from pour import golden, weights_h


def test_exp2_table_matches_the_c_source(source_dir):
    text = (source_dir / "firmware/src/policy.c").read_text()
    body = re.search(r"exp2_neg_q24\[65\] = \{(.*?)\};", text, re.S).group(1)
    c_table = [int(v.strip().rstrip("u")) for v in body.split(",") if v.strip()]
    assert c_table == fp.EXP2_TABLE_Q24
    assert fp.EXP2_TABLE_Q24[0] == 1 << 24 and fp.EXP2_TABLE_Q24[64] == 1 << 23


def test_log2e_constant_is_rounded_log2e():
    assert fp.LOG2E_Q16 == int(np.floor(np.log2(np.e) * 65536 + 0.5))


def test_exp_cutoff_and_the_c_32_bit_form_match_the_definition():
    d = np.arange(0, fp.EXP_D_CUTOFF + 64, dtype=np.int64)
    y = (d * fp.LOG2E_Q16 + 32768) >> 16
    assert np.array_equal(y[: fp.EXP_D_CUTOFF], (d + ((d * 7253 + 8192) >> 14))[: fp.EXP_D_CUTOFF])
    assert int((y >> 15)[fp.EXP_D_CUTOFF - 1]) == 16 and np.all((y >> 15)[fp.EXP_D_CUTOFF:] > 16)
    assert fp.EXP_D_CUTOFF * 7253 < 2**32
    assert fp.exp_neg_q16(0) == 65536 and fp.exp_neg_q16(fp.EXP_D_CUTOFF) == 0


def test_committed_golden_files_equal_a_fresh_generation(source_dir):
    assert golden.main(["--check", "--source-dir", str(source_dir)]) == 0


def test_golden_check_reports_a_stale_file(tmp_path, source_dir, capsys):
    for rel in ("policy/example_weights.h", "policy/weights.h", "tests/golden/example_weights_2.h",
                golden.GOLDEN_REL):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text((source_dir / rel).read_text())
    golden_path = tmp_path / golden.GOLDEN_REL
    golden_path.write_text(golden_path.read_text().replace("{0, 16384, 0, 0, 0}", "{0, 16385, 0, 0, 0}", 1))
    assert golden.main(["--check", "--source-dir", str(tmp_path)]) == 1
    assert golden.GOLDEN_REL in capsys.readouterr().err


@pytest.mark.parametrize("value, expected", [
    (1.0, 32767), (-1.0, -32768), (0.0, 0), (0.5 / 32768, 1), (-0.5 / 32768, 0), (1.5 / 32768, 2),
    (-1.5 / 32768, -1), (0.49 / 32768, 0), (2.0, 32767), (-2.0, -32768), (32767.5 / 32768, 32767)])
def test_float_to_q15_rounds_half_up_then_saturates(value, expected):
    assert fp.float_to_q15(value) == expected


def test_round_half_up_shift_matches_floor_semantics():
    assert fp.round_half_up_shift(1, 1) == 1      # 0.5 -> 1
    assert fp.round_half_up_shift(-1, 1) == 0     # -0.5 -> 0
    assert fp.round_half_up_shift(-3, 1) == -1    # -1.5 -> -1
    assert fp.round_half_up_shift(5, 0) == 5


def test_quantize_obs_is_within_half_an_lsb_of_the_float_normalisation():
    rng = np.random.default_rng(7)
    norm = fp.ObsNorm(-87266, 2356194, 4000000)
    for _ in range(2000):
        theta = int(rng.integers(-500000, 2600000))
        omega = int(rng.integers(-5000000, 5000000))
        vols = [int(v) for v in rng.integers(0, 32768, size=3)]
        q = fp.quantize_obs(norm, theta, omega, *vols)
        x = fp.obs_float(norm, theta * 1e-6, omega * 1e-6, *(v / 32768 for v in vols))
        exact = np.minimum(x * 32768, 32767)
        assert np.all(np.abs(np.array(q[:2]) - exact[:2]) <= 0.5 + 1e-6)
        assert q[2:] == vols


def test_quantize_obs_saturates_extremes():
    norm = fp.ObsNorm(0, 2356194, 4000000)
    assert fp.quantize_obs(norm, fp.INT32_MIN, fp.INT32_MIN, -32768, -1, -5) == [0, 0, 0, 0, 0]
    assert fp.quantize_obs(norm, fp.INT32_MAX, fp.INT32_MAX, 32767, 32767, 32767) == [32767] * 5


def test_obs_norm_validate_names_the_bad_field():
    with pytest.raises(ValueError, match="theta_max_urad"):
        fp.ObsNorm(5, 5, 1).validate()
    with pytest.raises(ValueError, match="omega_max_urad_s"):
        fp.ObsNorm(0, 5, 0).validate()
    with pytest.raises(ValueError, match="int32"):
        fp.ObsNorm(0, 2**31, 1).validate()


def test_logits_saturate_at_the_accumulator_extremes():
    w = np.full((6, 2), -32768)
    assert fp.logits_q15(w, 0, [32767] * 5) == [fp.INT32_MIN] * 2
    assert fp.logits_q15(w, 15, [32767] * 5) == [-(5 * 32767 + 32768)] * 2
    assert fp.logits_q15(np.full((6, 2), 32767), 0, [32767] * 5) == [fp.INT32_MAX] * 2


def test_logits_refuse_a_bad_shape():
    with pytest.raises(ValueError, match="shape"):
        fp.logits_q15(np.zeros((5, 3)), 0, [0] * 5)


def test_softmax_sum_bound_and_float_agreement():
    """|sum p - 32768| <= n/2 LSB; each p within 3 LSB of the float softmax of the same logits."""
    rng = np.random.default_rng(11)
    worst = 0.0
    for _ in range(3000):
        n = int(rng.integers(2, 17))
        logits = [int(v) for v in rng.integers(-(1 << 19), 1 << 19, size=n)]
        p = fp.softmax_q15(logits)
        assert abs(sum(p) - 32768) * 2 <= n
        z = np.array(logits, dtype=np.float64) / 32768.0
        ref = np.exp(z - z.max())
        ref = np.minimum(ref / ref.sum() * 32768.0, 32767)
        worst = max(worst, float(np.max(np.abs(np.array(p) - ref))))
    print(f"softmax: worst |p_fixed - p_float| = {worst:.2f} LSB over 3000 cases")
    assert worst <= 3.0


def test_argmax_ties_go_to_the_lowest_index():
    assert fp.argmax([5, 5, 5]) == 0
    assert fp.argmax([9, 1, 9]) == 0
    assert fp.argmax([1, 7, 3, 7]) == 1
    assert fp.argmax([0, 0, 1]) == 2


def test_xorshift32_reference_sequence():
    assert fp.xorshift32(1) == 0x00042021
    assert fp.xorshift32(0x00042021) == 0x04080601
    assert fp.xorshift32(2463534242) == 723471715


def test_sample_never_picks_zero_probability_and_follows_the_distribution():
    rng = 99
    counts = [0, 0, 0, 0]
    for _ in range(20000):
        a, rng = fp.sample([0, 20000, 0, 12768], rng)
        counts[a] += 1
    assert counts[0] == 0 and counts[2] == 0
    assert abs(counts[1] / 20000 - 20000 / 32768) < 0.015


def test_fixed_policy_agrees_with_the_float_policy(source_dir):
    """Example policy: float (trainer) vs fixed (firmware) on random states. Stated tolerance: each
    probability within 0.001 (33 LSB); greedy actions agree in >= 99.5 % of states."""
    ex = weights_h.parse_weights_h(source_dir / "policy/example_weights.h")
    pol = fp.FixedPolicy(ex.w_q, ex.w_frac_bits)
    rng = np.random.default_rng(3)
    agree, worst, n = 0, 0.0, 3000
    for _ in range(n):
        theta = int(rng.integers(0, 2356194))
        omega = int(rng.integers(-4000000, 4000000))
        vols = [int(v) for v in rng.integers(0, 32768, size=3)]
        q = fp.quantize_obs(ex.norm, theta, omega, *vols)
        e = pol.eval(q)
        x = fp.obs_float(ex.norm, theta * 1e-6, omega * 1e-6, *(v / 32768 for v in vols))
        pf = fp.float_policy_probs(ex.w_float, x)
        worst = max(worst, float(np.max(np.abs(np.array(e.probs) / 32768 - pf))))
        agree += int(e.action == int(np.argmax(pf)))
    print(f"float vs fixed: greedy agreement {agree / n:.4f}, worst |dp| = {worst:.5f}")
    assert worst <= 0.001
    assert agree / n >= 0.995


def test_safety_envelope_mirrors_the_c_rules():
    env = fp.SafetyEnvelope()
    env.force(-32768)
    ticks = 0
    while env.torque != 32767:
        env.apply(32767, 1000000)
        ticks += 1
    assert ticks == 20
    assert env.apply(32767, 2356194) == 0 and env.active & fp.LIMIT_ANGLE_MAX
    assert env.apply(-32768, -87266) == 0 and env.active & fp.LIMIT_ANGLE_MIN
    clamp = fp.SafetyEnvelope(fp.SafetyConfig(tau_limit=1000, slew_per_tick=32767))
    assert clamp.apply(20000, 0) == 1000 and clamp.active & fp.LIMIT_CLAMP


def test_python_safety_defaults_match_the_c_defaults(source_dir):
    text = (source_dir / "firmware/src/safety.c").read_text()
    c = {m.group(1): int(m.group(2)) for m in re.finditer(r"#define DEFAULT_(\w+) \(?(-?\d+)\)?", text)}
    py = fp.SafetyConfig()
    assert (py.slew_per_tick, py.theta_min_urad, py.theta_max_urad) == \
        (c["SLEW_PER_TICK"], c["THETA_MIN_URAD"], c["THETA_MAX_URAD"])
    assert py.tau_limit == fp.Q15_MAX
