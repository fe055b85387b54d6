# SPDX-License-Identifier: MIT
"""pour-eval robust: the scenes, the bars, the table, and the command on the real simulator."""
import json
import subprocess
import sys

from pour.eval import robustness


def episode(poured=99.5, spilled=0.3, finish=2.0, peak=1.9, alpha=60.0, reversals=5):
    return {"poured_pct": poured, "spilled_pct": spilled, "finish_s": finish, "peak_omega_rad_s": peak,
            "peak_alpha_rad_s2": alpha, "reversals": reversals}


def summary(per):
    n = len(per)
    return {"per_episode": per, "poured_pct": sum(e["poured_pct"] for e in per) / n,
            "spilled_pct": sum(e["spilled_pct"] for e in per) / n, "poured_l": 9.9, "spilled_l": 0.03,
            "finish_s": sum(e["finish_s"] for e in per) / n}


def scene(name):
    return next(s for s in robustness.scenes() if s.name == name)


def test_the_scenes_are_the_issues_edges():
    nominal = {"fill_depth": 0.2, "target_dx": 0.3, "pivot_height": 0.5, "motor_peak_torque": 25.0,
               "scale_delay_s": 0.05, "command_latency_ticks": 1}
    args = {s.name: robustness.scene_args(s, nominal) for s in robustness.scenes()}
    assert len(args) == 9 and args["nominal"] == []
    assert args["fill +20 %"] == ["--set", "fill_depth=0.24"]
    assert args["target -2 cm"] == ["--set", "target_dx=0.28"]
    assert args["motor torque -15 %"] == ["--set", "motor_peak_torque=21.25"]
    assert args["sensor lag x2"] == ["--set", "scale_delay_s=0.1", "--set", "command_latency_ticks=2"]


def test_nominal_needs_ninety_of_a_hundred_within_all_three():
    good = [episode() for _ in range(90)]
    bad = [episode(spilled=1.3) for _ in range(10)]  # over 1 % each, the mean still well under
    assert robustness.judge(scene("nominal"), summary(good + bad))["bar_met"]
    worse = good[:89] + bad + [episode(spilled=1.3)]
    row = robustness.judge(scene("nominal"), summary(worse))
    assert row["meet_all_three"] == 89 and not row["bar_met"]


def test_an_unfinished_pour_or_a_slow_one_fails_the_nominal_bar():
    per = [episode() for _ in range(99)]
    assert not robustness.judge(scene("nominal"), summary(per + [episode(finish=6.5)]))["bar_met"]
    assert not robustness.judge(scene("nominal"), summary(per + [episode(finish=-1.0)]))["bar_met"]


def test_edges_judge_the_means_and_every_episode_judges_the_motion():
    per = [episode(spilled=2.9, poured=95.5) for _ in range(30)]
    assert robustness.judge(scene("fill +20 %"), summary(per))["bar_met"]
    assert not robustness.judge(scene("fill +20 %"), summary(per[:29] + [episode(reversals=31)]))["bar_met"]
    assert not robustness.judge(scene("fill +20 %"), summary(per[:29] + [episode(peak=2.6)]))["bar_met"]
    assert not robustness.judge(scene("fill +20 %"), summary([episode(spilled=3.2)] * 30))["bar_met"]


def test_a_missing_header_is_named_with_exit_2(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pour.eval.evaluate", "robust", "--header", str(tmp_path / "no.h"),
                        "--out", str(tmp_path / "r")], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "no.h" in r.stderr and "Traceback" not in r.stderr


def test_a_short_run_on_the_simulator_writes_the_table(tmp_path, source_dir, build_dir):
    out = tmp_path / "rob"
    r = subprocess.run([sys.executable, "-m", "pour.eval.evaluate", "robust", "--header",
                        str(source_dir / "policy" / "weights.h"), "--out", str(out), "--nominal-episodes", "1",
                        "--edge-episodes", "1", "--build-dir", str(build_dir)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode in (0, 1), r.stderr  # 1: a bar missed, which one episode a scene may do
    doc = json.loads((out / "robustness.json").read_text())
    assert [row["scene"] for row in doc["rows"]] == [s.name for s in robustness.scenes()]
    assert all(row["episodes"] == 1 for row in doc["rows"])
    # +20 % fill pours more litres than -20 % fill: the override reached the simulator.
    litres = {row["scene"]: row["poured_l"] for row in doc["rows"]}
    assert litres["fill +20 %"] > 1.3 * litres["fill -20 %"]
    assert (out / "robustness.png").stat().st_size > 10_000
    assert (out / "robustness.md").read_text().count("\n| ") == 10  # header row + 9 scenes


def test_episode_metrics_count_reversals_and_litres():
    """libpoursim's episode figures (host_sim/physics/metrics.cpp), through the trainer's C rollout."""
    import math

    import numpy as np

    from pour.sim import poursim
    cfg = poursim.make_config({"episode_s": 2.0})
    levels = np.array([-1.0, 1.0])

    def run(w):
        pol = poursim.Policy(np.asarray(w, dtype=float), levels, 10, 0.0, 2.356194, 4.0, True)
        with poursim.World(cfg) as world:
            return world.rollout(pol, 5).metrics

    forward = run([[0, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 1]])  # always +tau_max
    assert forward["reversals"] == 0
    # The motion envelope holds the speed near 2 rad/s whatever the policy asks.
    assert 1.5 < forward["peak_omega"] < 2.3
    litres = 1000 * math.pi * (cfg.bucket_inner_width / 2) ** 2 * cfg.fill_depth
    assert abs(forward["liquid_l"] - litres) < 1e-9
    # Bang-bang about theta_n = 0.2 (27 deg): +tau_max below it, -tau_max above: reverses again and again.
    bang = run([[8, -8], [0, 0], [0, 0], [0, 0], [0, 0], [-1.6, 1.6]])
    assert bang["reversals"] >= 10 and bang["peak_alpha"] > 0


def test_a_bad_reversal_cost_is_refused_by_the_c_rollout():
    import numpy as np
    import pytest

    from pour.sim import poursim
    cfg = poursim.make_config({"episode_s": 0.1})
    for bad in (float("nan"), -1.0):
        pol = poursim.Policy(np.zeros((6, 2)), np.array([-1.0, 1.0]), 10, 0.0, 2.356194, 4.0, True, bad)
        with pytest.raises(poursim.SimError, match="k_reversal"):
            poursim.World(cfg).rollout(pol, 1)


def test_a_rig_file_that_weighs_the_fill_narrows_the_fill_edges_to_its_range(tmp_path, source_dir, build_dir):
    # 11.7 L weighed to ±0.1 mm: ±20 % would ask for 14 L, more than the bucket holds; the edges are the range
    # pour-train --rig trains over, ±√3 σ.
    rig = tmp_path / "rig.toml"
    rig.write_text("fill_depth = 0.2595\n[sigma]\nfill_depth = 0.0001\n")
    out = tmp_path / "rob"
    r = subprocess.run([sys.executable, "-m", "pour.eval.evaluate", "robust", "--header",
                        str(source_dir / "policy" / "weights.h"), "--out", str(out), "--nominal-episodes", "1",
                        "--edge-episodes", "1", "--build-dir", str(build_dir), "--rig", str(rig)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode in (0, 1), r.stderr
    rows = {row["scene"]: row for row in json.loads((out / "robustness.json").read_text())["rows"]}
    w = 3 ** 0.5 * 0.0001 / 0.2595
    assert rows[f"fill +{w * 100:.2g} %"]["sets"] == [f"fill_depth={0.2595 * (1 + w):.6g}"]
    assert rows[f"fill -{w * 100:.2g} %"]["sets"] == [f"fill_depth={0.2595 * (1 - w):.6g}"]
    assert rows["nominal"]["poured_l"] > 11.0   # the rig's fill, not the default 10 L


def test_repeats_step_the_fill_by_one_millilitre_centred_on_the_nominal():
    from pour.eval import robust_scale
    assert robust_scale.fill_factors(1) == [1.0]
    f = robust_scale.fill_factors(4)
    assert f == sorted(f) and abs(sum(f) / 4 - 1.0) < 1e-12
    assert all(abs((b - a) - 1e-4) < 1e-12 for a, b in zip(f, f[1:]))


def test_a_rig_is_judged_by_the_mean_of_its_repeats_and_the_worst_of_its_peaks():
    """Two repeats of one rig become one record: the spill that one episode of 4.0 % and one of 1.0 % give is
    2.5 %, not the 4.0 % that would fail the 3 % bar; the peaks are the worse one; an unfinished repeat makes
    the rig unfinished."""
    from pour.eval import robust_scale

    def rep(seed, spilled, peak, finish, reversals):
        return dict(episode(poured=100 - spilled, spilled=spilled, finish=finish, peak=peak, reversals=reversals),
                    seed=seed, liquid_l=11.0 + spilled / 1000)
    per = [rep(7, 4.0, 2.1, 2.0, 3), rep(5, 0.0, 1.0, 2.2, 0), rep(7, 1.0, 2.4, -1.0, 0), rep(5, 0.0, 1.1, 2.4, 1)]
    rigs = robust_scale.per_rig(per)
    assert [r["seed"] for r in rigs] == [5, 7] and [r["repeats"] for r in rigs] == [2, 2]
    five, seven = rigs
    assert seven["spilled_pct"] == 2.5 and seven["spilled_pct_worst"] == 4.0 and seven["poured_pct"] == 97.5
    assert seven["peak_omega_rad_s"] == 2.4 and seven["reversals"] == 1.5 and seven["finish_s"] == -1.0
    assert five["finish_s"] == 2.3 and five["reversals"] == 0.5 and five["peak_omega_rad_s"] == 1.1
    rows = robust_scale.reduce(rigs, [])
    assert rows[0]["episodes"] == 2 and rows[0]["spilled_pct_max"] == 2.5 and rows[0]["reversals_max"] == 1.5
