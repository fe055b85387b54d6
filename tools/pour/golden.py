# SPDX-License-Identifier: MIT
"""Hand-made policies and golden vectors for the firmware's unit tests.

    python -m pour.golden            # rewrites tests/golden/golden_vectors.h and the hand-made policies
    python -m pour.golden --check    # exits 1 if any committed file differs from a fresh generation
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from pour import fixedpoint as fp
from pour import weights_h

SOURCE_DIR = Path(__file__).resolve().parents[2]
NORM = fp.ObsNorm(0, 2356194, 4000000)  # 0..135 deg, ±4 rad/s


def hand_made_weights(n_actions: int, sharpness: float = 4.0) -> np.ndarray:
    """W [6][n] whose softmax peaks at the level nearest u*(x) = 1.2 V_rot - 0.9 θn - (ωn - 1/2) - 0.2.

    logit_a = -c (L_a - u*)^2 + const = 2c L_a u* - c L_a^2: tilt forward while liquid remains, ease off
    as θ grows, damp θ̇, back off once the rotating bucket is nearly empty.
    """
    levels = weights_h.even_levels(n_actions)
    beta = np.array([-0.9, -1.0, 1.2, 0.0, 0.0, 0.5 - 0.2])  # θn, ωn, V_rot, V_tgt, V_spill, bias
    w = 2.0 * sharpness * np.outer(beta, levels)
    w[5] -= sharpness * levels**2
    return w


def write_policies(source_dir: Path = SOURCE_DIR) -> list[Path]:
    """The hand-made policies: shipped (weights.h), tests (example_weights.h), benchmarks (2 actions)."""
    out = []
    for rel, n, what in (("policy/example_weights.h", 11, "pour.golden.hand_made_weights(11), kept for tests"),
                         ("policy/weights.h", 11, "pour.golden.hand_made_weights(11), until a trained export"),
                         ("tests/golden/example_weights_2.h", 2, "pour.golden.hand_made_weights(2), benchmarks")):
        path = source_dir / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        weights_h.write_weights_h(path, hand_made_weights(n), decision_period_ms=10, norm=NORM, tau_max_mnm=40000,
                                  banner_inputs=what)
        out.append(path)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare instead of writing")
    ap.add_argument("--source-dir", type=Path, default=SOURCE_DIR)
    args = ap.parse_args(argv)
    write_policies(args.source_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main())
