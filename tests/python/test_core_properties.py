# SPDX-License-Identifier: MIT
"""Property tests (Hypothesis) of the firmware core itself, driven through ctypes (pour.core on libpoursim):
after every tick the rules of docs/safety.md hold — clamp, slew, angle limits, the speed band, e-stop,
latched faults, the input timeout, refused samples — for generated configs and input scripts.

There is no Python model of the state machine to compare with: the properties are the specification.
The runs are bounded and reproducible (derandomized, a fixed number of examples, no example database).
"""
import ctypes
import os
import shutil
import subprocess

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pour import core
from pour.policy import weights_h
from pour.sim import poursim

PROFILE = settings(max_examples=300, derandomize=True, database=None, deadline=None,
                   suppress_health_check=[HealthCheck.too_slow])
INT32_MIN, INT32_MAX = -(2**31), 2**31 - 1
Q15_MAX = 32767
CC = os.environ.get("CC") or shutil.which("cc") or "gcc"


# --- the ctypes structures are the C headers' ----------------------------------------------------------

def test_the_records_that_cross_the_c_api_have_c_sizes():
    """Each plain record pour.core and pour.sim.poursim build from the library's table (a sample, a state, a
    tick's inputs and outputs, the simulator's observations, policies, buffers, episodes and checks) has the
    size the library was built with; the core's own state and configs are handles and opaque blocks, never mirrored."""
    lib = core.load()
    for module in (core, poursim):
        for py_name, cname in module.RECORDS.items():
            assert lib.poursim_sizeof(cname.encode()) == ctypes.sizeof(getattr(module, py_name)), cname
    assert lib.poursim_sizeof(b"pour_control_t") == 0  # not exported: Python never holds it


def test_the_core_config_is_read_and_set_by_name():
    cfg = core.control_config()
    assert "safety.tau_limit" in cfg.fields() and "stop.timeout_ms" in cfg.fields()
    assert "restart_jump_max_urad" in cfg.fields() and "experiment.tilt_kd_per_rad_s" in cfg.fields()
    cfg.experiment.prbs_bit_ms = 255  # a uint8_t field: its whole range, and no more
    assert cfg.get("experiment.prbs_bit_ms") == 255
    with pytest.raises(core.CoreError):
        cfg.set("experiment.prbs_bit_ms", 256)
    cfg.safety.tau_limit = 12345
    assert cfg.get("safety.tau_limit") == cfg.safety.tau_limit == 12345
    cfg.safety.theta_min_urad = -87266
    assert cfg.safety.theta_min_urad == -87266  # signed fields come back signed
    with pytest.raises(core.CoreError, match="unknown field"):
        cfg.set("safety.no_such_field", 1)
    with pytest.raises(core.CoreError, match="out of its type's range"):
        cfg.safety.tau_limit = 40000  # a q15_t
    with pytest.raises(core.CoreError, match="out of its type's range"):
        cfg.sensors.encoder_bits = -1  # a uint8_t


def test_fault_and_mode_names_come_from_the_core():
    assert core.FAULT_STALE_INPUT == 0x0001 and core.FAULT_LINK == 0x0100 and core.FAULT_SCALE == 0x0400
    assert [core.mode_name(m) for m in range(4)] == ["IDLE", "RUN", "FAULT", "ESTOP"]
    assert core.MODE_ESTOP == 3 and core.mode_name(4) is None
    assert core.fault_names(0x0101) == ["STALE_INPUT", "LINK"]
    assert core.fault_name(0x0003) is None
    with pytest.raises(AttributeError):
        core.FAULT_NO_SUCH


# --- the envelope (pour_safety_apply) ---------------------------------------------------------------------

@st.composite
def safety_configs(draw):
    theta_min = draw(st.integers(-3_000_000, 2_000_000))
    return core.safety_config(
        tau_limit=draw(st.integers(1, Q15_MAX)), slew_per_tick=draw(st.integers(1, Q15_MAX)),
        theta_min_urad=theta_min, theta_max_urad=draw(st.integers(theta_min + 1, 3_200_000)),
        omega_max_urad_s=draw(st.integers(1, core.SPEED_BAND_MAX_URAD_S)),
        alpha_max_urad_s2=draw(st.integers(1000, 2_000_000_000)),
        omega_slack_urad_s=draw(st.integers(1, core.SPEED_BAND_MAX_URAD_S)),
        governor_gain=draw(st.integers(1, Q15_MAX)))


@st.composite
def envelope_ticks(draw, cfg):
    """(requested, θ, θ̇) per tick: full-scale and random requests, θ at and around the limits, θ̇ that
    walks, jumps, sits at ±ω_max and at the int32 extremes."""
    n = draw(st.integers(1, 60))
    ticks, omega = [], 0
    for _ in range(n):
        req = draw(st.one_of(st.sampled_from([-32768, Q15_MAX, 0]), st.integers(-32768, Q15_MAX)))
        theta = draw(st.one_of(st.sampled_from([cfg.theta_min_urad, cfg.theta_max_urad, cfg.theta_min_urad - 1,
                                                cfg.theta_max_urad + 1]),
                               st.integers(cfg.theta_min_urad - 200_000, cfg.theta_max_urad + 200_000)))
        omega = draw(st.one_of(st.integers(omega - 300_000, omega + 300_000).map(
                                   lambda w: max(INT32_MIN, min(INT32_MAX, w))),
                               st.sampled_from([cfg.omega_max_urad_s, -cfg.omega_max_urad_s, cfg.omega_max_urad_s + 1,
                                                INT32_MAX, INT32_MIN, 0]),
                               st.integers(INT32_MIN, INT32_MAX)))
        ticks.append((req, theta, omega))
    return ticks


@st.composite
def envelope_cases(draw):
    cfg = draw(safety_configs())
    return cfg, draw(envelope_ticks(cfg))


def _on_the_way(x: int, frm: int, safe: int) -> bool:
    """x lies between frm and the safe torque, or between frm and zero (the safe torque cut at an angle limit)."""
    return any(min(frm, t) <= x <= max(frm, t) for t in (safe, 0))


def _between_zero_and(x: int, ref: int) -> bool:
    return min(0, ref) <= x <= max(0, ref)


@PROFILE
@given(envelope_cases())
def test_envelope_holds_every_rule_after_every_tick(case):
    cfg, ticks = case
    env = core.Envelope(cfg)
    k_per_urad = cfg.governor_gain / 1e6  # Q15 torque per µrad/s of speed margin
    alpha_step = (cfg.alpha_max_urad_s2 + 500) // 1000
    prev, ceiling, floor = 0, cfg.omega_slack_urad_s, -cfg.omega_slack_urad_s
    for req, theta, omega in ticks:
        cmd = env.apply(req, theta, omega)
        act = env.active
        w = max(-core.SPEED_BAND_MAX_URAD_S, min(core.SPEED_BAND_MAX_URAD_S, omega))
        # clamp
        assert -cfg.tau_limit <= cmd <= cfg.tau_limit
        # slew: at most slew_per_tick a tick, except a cut toward zero, which never waits
        assert abs(cmd - prev) <= cfg.slew_per_tick or _between_zero_and(cmd, prev), (prev, cmd)
        # angle limits: nothing that tilts further at or past a limit
        if theta >= cfg.theta_max_urad:
            assert cmd <= 0
        if theta <= cfg.theta_min_urad:
            assert cmd >= 0
        # the speed band: widens at most one alpha step a tick, never beyond ω_max nor slack past the speed
        f, c = env.band
        assert c <= min(cfg.omega_max_urad_s, ceiling + alpha_step, max(w, 0) + cfg.omega_slack_urad_s)
        assert f >= max(-cfg.omega_max_urad_s, floor - alpha_step, min(w, 0) - cfg.omega_slack_urad_s)
        ceiling, floor = c, f
        # ... and no torque that speeds θ̇ beyond it (1 LSB of rounding); beyond ω_max the envelope brakes
        assert cmd <= max(k_per_urad * (c - w), 0) + 1
        assert cmd >= min(k_per_urad * (f - w), 0) - 1
        if omega > cfg.omega_max_urad_s:
            assert cmd <= 0
        if omega < -cfg.omega_max_urad_s:
            assert cmd >= 0
        # the limit bits say which rule shaped the command, and only rules that could have
        if act == 0:
            assert cmd == req
        angle_refused = (req > 0 and theta >= cfg.theta_max_urad) or (req < 0 and theta <= cfg.theta_min_urad)
        assert bool(act & core.LIMIT_CLAMP) == (abs(req) > cfg.tau_limit and not angle_refused)
        if act & core.LIMIT_ANGLE_MAX:
            assert theta >= cfg.theta_max_urad
        if act & core.LIMIT_ANGLE_MIN:
            assert theta <= cfg.theta_min_urad
        assert env.torque == cmd
        prev = cmd


@settings(PROFILE, max_examples=100)
@given(envelope_cases(), st.integers(-32768, Q15_MAX))
def test_envelope_force_sets_the_torque_at_once_and_slews_from_it(case, forced):
    cfg, ticks = case
    env = core.Envelope(cfg)
    req, theta, omega = ticks[0]
    env.apply(req, theta, omega)
    env.force(forced)
    assert env.torque == forced
    cmd = env.apply(forced, theta, omega)  # from the forced torque: through the slew, or a cut toward zero
    assert abs(cmd - forced) <= cfg.slew_per_tick or _between_zero_and(cmd, forced)


def test_envelope_refuses_a_bad_config():
    for bad in ({"tau_limit": 0}, {"slew_per_tick": 0}, {"theta_min_urad": 5, "theta_max_urad": 5},
                {"omega_max_urad_s": 0}, {"alpha_max_urad_s2": 999}, {"omega_slack_urad_s": 0},
                {"governor_gain": 0}, {"omega_max_urad_s": core.SPEED_BAND_MAX_URAD_S + 1}):
        with pytest.raises(core.CoreError, match="EINVAL"):
            core.Envelope(core.safety_config(**bad))


# --- the estimator (pour_estimator_update) ------------------------------------------------------------------

def _count(theta_urad: float, bits: int) -> int:
    return int(np.floor(theta_urad * 1e-6 / (2 * np.pi) * (1 << bits) + 0.5)) % (1 << bits)


@st.composite
def sample_scripts(draw, bits):
    """Samples of a bucket turning through upright and back, with gaps, repeats, counts beyond the encoder's
    bits, jumps, scales beyond their range and a liquid too light to divide by."""
    n = draw(st.integers(1, 80))
    seq, theta, omega, m_rot, m_tgt = draw(st.integers(0, 2**32 - 1)), draw(st.integers(-500_000, 2_500_000)), 0, \
        draw(st.integers(500, 12000)), draw(st.integers(-50, 2000))
    out = []
    for _ in range(n):
        seq = (seq + draw(st.sampled_from([1, 1, 1, 2, 5, 0, 40]))) & 0xFFFFFFFF
        omega = max(-4_000_000, min(4_000_000, omega + draw(st.integers(-200_000, 200_000))))
        theta += omega // 1000
        moved = draw(st.integers(0, 80))
        m_rot, m_tgt = m_rot - moved, m_tgt + moved
        smp = [seq, _count(theta, bits), m_rot, m_tgt]
        kind = draw(st.integers(0, 12))
        if kind == 0:
            smp[1] = (1 << bits) + draw(st.integers(0, 1000))
        elif kind == 1:
            smp[2] = draw(st.sampled_from([-40000, 40000, -2001, 30001]))
        elif kind == 2:
            smp[1] = _count(theta + draw(st.sampled_from([-1, 1])) * draw(st.integers(20_000, 3_000_000)), bits)
        out.append(tuple(smp))
    return out


@PROFILE
@given(st.integers(8, 24).flatmap(lambda b: st.tuples(st.just(b), sample_scripts(b))))
def test_estimator_never_uses_a_refused_sample(case):
    """A refused sample changes nothing: an estimator that never saw it says the same thereafter. Counts
    beyond the encoder's bits and scales beyond their limits are always refused; an accepted sample's
    volumes are Q15 fractions within [0, 32767]."""
    bits, samples = case
    cfg = core.sensors_config(encoder_bits=bits)
    seen, clean = core.Estimator(cfg), core.Estimator(cfg)
    for smp in samples:
        got = seen.update(*smp)
        if smp[1] >= (1 << bits) or not all(cfg.scale_min_g <= m <= cfg.scale_max_g for m in smp[2:]):
            assert got is None
        if got is None:
            continue
        assert clean.update(*smp) == got
        _, theta, omega, v_rot, v_tgt, v_spill = got
        assert all(0 <= v <= Q15_MAX for v in (v_rot, v_tgt, v_spill))
        assert theta == core.theta_urad(smp[1], bits)


@PROFILE
@given(st.integers(8, 24).flatmap(lambda b: st.tuples(st.just(b), st.integers(1, (1 << (b - 1)) - 1))))
def test_encoder_angle_is_sign_symmetric_and_rounded(case):
    bits, c = case
    theta = core.theta_urad(c, bits)
    assert theta == -core.theta_urad((1 << bits) - c, bits)
    assert abs(theta - c * 2 * np.pi * 1e6 / (1 << bits)) <= 0.5 + 1e-3


def test_estimator_tracks_a_constant_speed():
    est = core.Estimator(encoder_bits=17)
    state = None
    for k in range(400):  # 1 rad/s
        state = est.update(k, round(k * 1e-3 / (2 * np.pi) * (1 << 17)), 7500, 2500)
    assert abs(state[2] - 1000000) < 30000  # the 17-bit counts' noise: docs/safety.md
    assert state[3:] == (24576, 8192, 0)


# --- the control step (pour_control_step) -----------------------------------------------------------------

@pytest.fixture(scope="module")
def example_weights():
    from conftest import SOURCE_DIR
    return weights_h.parse_weights_h(SOURCE_DIR / "policy" / "example_weights.h")


@st.composite
def control_cases(draw):
    """A config and a script of ticks: samples of a moving bucket (some implausible), gaps long enough to
    time out, e-stops held and released, clears, link faults, stops and resets."""
    cfg = core.control_config()
    s = cfg.safety
    s.tau_limit = draw(st.integers(1000, Q15_MAX))
    s.slew_per_tick = draw(st.integers(1, Q15_MAX))
    s.theta_min_urad = draw(st.integers(-300_000, 0))
    s.theta_max_urad = draw(st.integers(500_000, 2_400_000))
    cfg.input_timeout_ms = draw(st.integers(1, 30))
    cfg.safe_torque = draw(st.integers(-s.tau_limit, s.tau_limit))
    cfg.policy_mode = draw(st.integers(0, 1))
    cfg.seed = draw(st.integers(1, 2**32 - 1))
    cfg.supervisor.checks = draw(st.sampled_from([0, 0x7F]))
    bits = cfg.sensors.encoder_bits
    n = draw(st.integers(1, 150))
    ticks, theta, m_rot, m_tgt = [], draw(st.integers(-100_000, 2_000_000)), 10000, 0
    gap = 0
    for t in range(n):
        if gap > 0:
            gap -= 1
            fresh = False
        else:
            fresh = draw(st.integers(0, 19)) != 0
            if draw(st.integers(0, 40)) == 0:
                gap = draw(st.integers(1, 40))  # a silence, maybe past the timeout
        theta += draw(st.integers(-3000, 3000))
        moved = draw(st.integers(0, 40)) if theta > 1_000_000 else 0
        m_rot, m_tgt = m_rot - moved, m_tgt + moved
        sample = [t, _count(theta, bits), m_rot, m_tgt]  # seq = tick: always advances
        if draw(st.integers(0, 60)) == 0:
            sample[1] = (1 << bits) + 3  # a count no encoder of these bits gives
        flags = draw(st.lists(st.integers(0, 99), min_size=5, max_size=5))
        ticks.append(dict(sample=tuple(sample) if fresh else None, estop=flags[0] < 3, clear=flags[1] < 10,
                          link_fault=flags[2] < 1, stop=flags[3] < 2, reset=flags[4] < 2))
    return cfg, ticks


@PROFILE
@given(control_cases())
def test_control_step_holds_the_safety_rules_after_every_tick(example_weights, case):
    cfg, ticks = case
    ctl = core.Controller(example_weights, cfg)
    tau, slew, safe = cfg.safety.tau_limit, cfg.safety.slew_per_tick, cfg.safe_torque
    prev = core.Output(0, 0, [], core.MODE_IDLE, 0, 0, 0, 0, True, False)  # power-on: no torque on the wire yet
    since_fresh = 0  # ticks since a sample was offered (the core's own count is since one was accepted: >=)
    outs = []
    for t, tk in enumerate(ticks):
        o = ctl.step(tk["sample"], estop=tk["estop"], clear_faults=tk["clear"], link_fault=tk["link_fault"],
                     stop=tk["stop"], reset=tk["reset"])
        outs.append(o)
        since_fresh = 0 if tk["sample"] is not None else since_fresh + 1
        assert o.tick == t + 1
        assert -tau <= o.torque <= tau
        # e-stop: zero torque in the same tick, brake, power cut, latched; nothing else counts
        if tk["estop"]:
            assert (o.torque, o.mode, o.brake, o.power) == (0, core.MODE_ESTOP, True, False)
            assert o.faults & core.FAULT_ESTOP
        # released: FAULT, the e-stop fault still latched, until a clear
        if prev.mode == core.MODE_ESTOP and not tk["estop"] and not tk["clear"]:
            assert o.mode == core.MODE_FAULT and o.faults & core.FAULT_ESTOP
        # faults are latched: only a clear, with the e-stop released, in FAULT, drops one
        if prev.faults & ~o.faults:
            assert tk["clear"] and not tk["estop"] and prev.mode in (core.MODE_FAULT, core.MODE_ESTOP)
        if o.mode in (core.MODE_FAULT, core.MODE_ESTOP):
            assert o.faults != 0
        if o.mode == core.MODE_RUN:
            assert o.faults == 0 and o.power and not o.brake
            assert since_fresh <= cfg.input_timeout_ms  # the input timeout, armed in RUN
        # braked (IDLE, FAULT after the stop): on the way from the last command to the safe torque (or to zero
        # at an angle limit), never beyond it
        if o.mode == core.MODE_IDLE:
            assert o.brake and not o.power and _on_the_way(o.torque, prev.torque, safe)
        if o.mode == core.MODE_FAULT:
            assert o.brake != o.power
            if o.brake:
                assert _on_the_way(o.torque, prev.torque, safe)
        if prev.mode == core.MODE_RUN and not (tk["estop"] or tk["stop"] or tk["link_fault"]) \
                and since_fresh > cfg.input_timeout_ms:
            assert o.faults & core.FAULT_STALE_INPUT
        # the transport's link fault goes through the core: FAULT, latched (a clear in the same tick clears it)
        if tk["link_fault"] and not tk["estop"] and not tk["clear"]:
            assert o.faults & core.FAULT_LINK and o.mode == core.MODE_FAULT
        smp = tk["sample"]
        if smp is not None and smp[1] >= (1 << cfg.sensors.encoder_bits) and not tk["estop"]:
            assert o.faults & core.FAULT_BAD_INPUT and o.mode == core.MODE_FAULT
        # continuity across every transition (power-on, stop, reset, clear, the stop's end, the e-stop): the
        # command moves by at most the slew limit a tick, or toward zero
        assert abs(o.torque - prev.torque) <= slew or _between_zero_and(o.torque, prev.torque), (prev, o)
        prev = o
    # the step is a pure function of the config and the inputs
    again = core.Controller(example_weights, cfg)
    assert [again.step(tk["sample"], tk["estop"], tk["clear"], tk["link_fault"], tk["stop"], tk["reset"])
            for tk in ticks] == outs


def test_the_core_handle_refuses_what_the_core_refuses(example_weights):
    with pytest.raises(core.CoreError, match="decision_period_ms 1..65535"):
        core.Controller(None, decision_period_ms=0)
    bad = core.control_config(input_timeout_ms=0)
    with pytest.raises(core.CoreError, match="pour_control_init_external refused the config: .*EINVAL"):
        core.Controller(None, bad, decision_period_ms=10)
    with pytest.raises(core.CoreError, match="pour_control_init refused the config: .*EINVAL"):
        core.Controller(example_weights, bad)
    with pytest.raises(core.CoreError, match="pour_estimator_init refused the config"):
        core.Estimator(encoder_bits=40)


def test_an_outside_request_runs_the_same_pipeline_as_the_policy(example_weights):
    """The handle's stages with the policy's own choices give pour_control_step's outputs tick for tick."""
    own = core.Controller(example_weights)
    ext = core.Controller(None, decision_period_ms=example_weights.decision_period_ms)
    levels = list(example_weights.levels_q15)
    for t in range(120):
        sample = (t, _count(2000 * t, 17), 10000 - 5 * t, 5 * t)
        want = own.step(sample)
        if ext.update(sample):
            ext.request(want.action, levels[want.action])
        got = ext.shape()
        assert (got.torque, got.action, got.mode, got.faults, got.limits, got.brake) == \
               (want.torque, want.action, want.mode, want.faults, want.limits, want.brake)


@pytest.mark.parametrize("fill_depth", [0.10, 0.16, 0.2387, 0.2653])
def test_fill_schedule_knee_is_the_hydrostatic_onset_less_3_degrees(fill_depth):
    """A rig file that asks for the fill schedule gives the core the angle at which a level liquid of its fill
    reaches the lip, less 3°: checked against the simulator's own hydrostatics (poursim_ideal_retained, the
    level liquid's share kept), which keeps all of it just before that angle and loses some just after. The
    fills cover both shapes of the liquid at the onset (a triangle below half the depth, a trapezoid above).
    A fill at or below fill_schedule_l gets no schedule."""
    lib = poursim.load_library()
    rig = poursim.make_config({"fill_depth": fill_depth, "fill_schedule_l": 1.0})
    depth = rig["bucket_height"] - rig["bucket_wall"]
    onset = core.control_config(rig).safety.knee_theta_urad * 1e-6 + np.radians(3.0)
    kept = lambda theta: lib.poursim_ideal_retained(rig["bucket_inner_width"], depth, fill_depth, theta)  # noqa: E731
    assert kept(onset - 2e-3) == 1.0 and kept(onset + 2e-3) < 1.0
    litres = 1000 * np.pi * (rig["bucket_inner_width"] / 2) ** 2 * fill_depth
    off = poursim.make_config({"fill_depth": fill_depth, "fill_schedule_l": round(litres + 0.01, 2)})
    assert core.control_config(off).safety.knee_theta_urad == 0


def test_a_greedy_decisions_probabilities_reach_python(example_weights):
    # The step computes no softmax for a greedy policy (pour_control_step); the binding asks for the latest
    # decision's probabilities (pour_control_probs), as the Linux port's POUR_TORQUE does: they sum to one in
    # Q15 and their argmax is the action taken.
    ctl = core.Controller(example_weights, core.control_config())
    before = ctl.step(None)
    assert not any(before.probs)  # no decision yet
    o = ctl.step((1, 1 << 10, 9000, 0))
    assert o.mode == core.MODE_RUN, o
    n = len(example_weights.levels_q15)
    assert abs(sum(o.probs[:n]) - 32768) <= n and not any(o.probs[n:]), o.probs
    assert max(range(n), key=lambda a: (o.probs[a], -a)) == o.action, o
