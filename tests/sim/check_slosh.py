# SPDX-License-Identifier: MIT
"""bench_slosh (argv[1]) and the sweep it wrote into results/slosh (argv[2]); standard library only.

1. The measured fact the sweep rests on: the pair viscosity's fluctuation (the agitation, √(2σ·dt)·v_T) is
   what keeps the slosh from being damped by the jammed particles. Switched off (fluid_viscosity = 0, which
   removes the kick with the friction) the damping ratio triples; the default's is the documented ~0.10 at
   the tank's first mode within 15 %.
2. Bad input: a one-line error and exit 2 for each bad argument; an unwritable JSON: one line, exit 1.
3. The committed sweep: its schema, at least 12 points, the default among them with the figure above.
"""
import json
import os
import subprocess
import sys
import tempfile

BIN, SWEEP = sys.argv[1], sys.argv[2]
KEYS = {"label", "set", "damping", "damping_halves", "freq_hz", "freq_theory_hz", "amplitude_m", "noise_m",
        "hydro_rms", "weir_rms", "x_real_time", "x_real_time_wall", "meets_bars"}


def run(*args):
    return subprocess.run([BIN, *args], capture_output=True, text=True, timeout=50)


def check_schema(d, n_min):
    assert d["schema"] == "pour.slosh_sweep/1", d["schema"]
    assert d["bars"] == {"damping": 0.03, "weir_rms": 0.03, "hydro_rms": 0.04}, d["bars"]
    assert len(d["points"]) >= n_min, len(d["points"])
    for p in d["points"]:
        assert set(p) == KEYS, sorted(set(p) ^ KEYS)
        assert isinstance(p["set"], dict) and isinstance(p["meets_bars"], bool), p
        assert p["label"] == "default" or p["label"] == ",".join(f"{k}={v}" for k, v in p["set"].items()), p
        assert 0.0 <= p["damping"] < 1.0 and p["freq_hz"] > 0 and p["x_real_time"] > 0, p
    return {p["label"]: p for p in d["points"]}


# 1. The effect, measured now (16 seeds, as docs/simulator.md; ~15 s).
with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "s.json")
    r = run("--point", "default", "--point", "fluid_viscosity=0", "--retention-seeds", "0", "--json", out)
    assert r.returncode == 0, r.stderr
    assert not os.path.exists(out + ".tmp")
    with open(out, encoding="utf-8") as f:
        pts = check_schema(json.load(f), 2)
    d0, dz = pts["default"], pts["fluid_viscosity=0"]
    print(f"damping: default {d0['damping']:.3f}, fluid_viscosity=0 {dz['damping']:.3f}")
    assert 0.07 <= d0["damping"] <= 0.14, d0
    assert abs(d0["freq_hz"] / d0["freq_theory_hz"] - 1) <= 0.15, d0
    assert dz["damping"] >= 2.0 * d0["damping"], (d0["damping"], dz["damping"])
    assert d0["hydro_rms"] is None and d0["weir_rms"] is None and d0["meets_bars"] is False, d0

    # 2. Bad input.
    for args, word in [(["--bogus"], "unknown argument"), (["--point", "foo=1"], "foo"),
                       (["--point", "fluid_viscosity=abc"], "fluid_viscosity"),
                       (["--point", "fluid_viscosity=-1"], "out of range"), (["--point", "fluid_viscosity"], "key=value"),
                       (["--point", "fluid_viscosity=1,"], "key=value"), (["--slosh-seeds", "0"], "--slosh-seeds"),
                       (["--retention-seeds", "11"], "--retention-seeds"), (["--json"], "needs a value"),
                       (["--json", ""], "needs a path")]:
        r = run(*args)
        assert r.returncode == 2 and r.stdout == "", (args, r.returncode, r.stdout)
        assert r.stderr.count("\n") == 1 and r.stderr.startswith("bench_slosh: ") and word in r.stderr, (args, r.stderr)
    r = run("--point", "default", "--slosh-seeds", "1", "--retention-seeds", "0", "--json",
            os.path.join(tmp, "no", "such", "dir", "s.json"))
    assert r.returncode == 1 and r.stderr.count("\n") == 1 and "cannot write" in r.stderr, r.stderr

# 3. The committed sweep.
with open(SWEEP, encoding="utf-8") as f:
    sweep = json.load(f)
pts = check_schema(sweep, 12)
assert abs(pts["default"]["damping"] - d0["damping"]) < 1e-4, "results/slosh is stale: re-run the sweep"
assert all(p["hydro_rms"] is not None and p["weir_rms"] is not None for p in pts.values())
print(f"bench_slosh ok; committed sweep: {len(pts)} points")
