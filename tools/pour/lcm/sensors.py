# SPDX-License-Identifier: MIT
"""The raw sensor sample of POUR_SENSORS (pour.sensor_sample_t, the CAN Sensors frame) in physical units, for the
bench tools: what a rig's encoder count and load-cell grams mean. The firmware does its own conversion in
fixed point (pour_estimator_update); this is the tools' reading of the same definitions, used where no
ground truth exists (a rig's log has no POUR_TRUTH), and to script samples in tests.
"""
from __future__ import annotations

import math

ENCODER_BITS = 17
"""The firmware's default encoder resolution (pour_sensors_config_t.encoder_bits) and the simulator's."""


def encoder_count(theta_rad: float, bits: int = ENCODER_BITS) -> int:
    """The single-turn count an absolute encoder reads at tilt theta: round(θ·2^bits/2π) mod 2^bits, so
    upright is 0 and a tilt below upright wraps to just under 2^bits (as libpoursim's obs.encoder)."""
    if not math.isfinite(theta_rad):
        raise ValueError(f"tilt {theta_rad!r} is not finite")
    return round(theta_rad * (1 << bits) / (2 * math.pi)) % (1 << bits)


def encoder_angle(count: int, bits: int = ENCODER_BITS) -> float:
    """Tilt [rad] of a count, in [-π, π): counts from 2^(bits-1) on are below upright."""
    if not 0 <= count < (1 << bits):
        raise ValueError(f"encoder count {count} outside 0 .. 2^{bits} - 1")
    signed = count - (1 << bits) if count >= 1 << (bits - 1) else count
    return signed * 2 * math.pi / (1 << bits)


def volumes(scale_rotating_g: float, scale_target_g: float, m0_g: float) -> tuple[float, float, float]:
    """Liquid fractions (rotating, target, unaccounted) from the two tared scales, as the firmware's estimator
    defines them: V = m / m0 with m0 the liquid weighed at the start (rotating + target of the first sample);
    what neither scale carries is spilled or in flight, 1 - V_rot - V_tgt, clamped to 0 .. 1."""
    if not m0_g > 0:
        raise ValueError(f"initial liquid mass {m0_g!r} g must be positive")
    v_rot, v_tgt = scale_rotating_g / m0_g, scale_target_g / m0_g
    return v_rot, v_tgt, min(1.0, max(0.0, 1.0 - v_rot - v_tgt))
