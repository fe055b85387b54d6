# SPDX-License-Identifier: MIT
"""The trajectory test_outputs wrote (argv[1]) loads in Python's json module, its escaped title round-trips."""
import json
import sys

with open(sys.argv[1], encoding="utf-8") as f:
    d = json.load(f)
assert d["title"] == 'policy "a\\b"\nsampled', d["title"]
assert d["fps"] == 12.5 and d["poured"] == 0.5 and d["finish_s"] == 0.002, d
assert d["radius"] == [0.01, 0.0125], d["radius"]
assert d["series"] == {"t": [0.001], "theta": [0.5], "v_rotating": [0.75], "v_target": [0.25], "v_spill": [0.05],
                       "torque": [10]}, d["series"]
assert [fr["t"] for fr in d["frames"]] == [0.0, 0.002]
assert d["frames"][1]["xy"] == [0.0, 0.25, 0.5, 0.125]
assert set(d["scene"]) == {"inner_width", "height", "wall", "pivot_x", "pivot_y", "target_x", "theta_max"}
print("render JSON ok:", sys.argv[1])
