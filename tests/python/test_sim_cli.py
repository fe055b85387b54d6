# SPDX-License-Identifier: MIT
"""host_sim CLI: runs, baselines, outputs, and clear errors on bad input."""
import csv
import json
import re
import signal
import subprocess

import pytest

SHORT = ["--set", "episode_s=1.5"]


@pytest.fixture
def host_sim(build_dir):
    exe = build_dir / "bin" / "host_sim"
    assert exe.is_file(), f"{exe} not built"

    def run(*args, timeout=300, cwd=None):
        return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=timeout, cwd=cwd)
    return run


@pytest.fixture
def example(source_dir):
    return (source_dir / "policy" / "example_weights.h").read_text()


def test_help_explains_the_modes(host_sim):
    r = host_sim("--help")
    assert r.returncode == 0
    for flag in ("--policy", "--baseline", "--episodes", "--seed", "--config", "--json", "--csv", "--render"):
        assert flag in r.stdout


@pytest.mark.parametrize("args, message", [
    ((), "choose exactly one of"),
    (("--bogus",), "unknown option '--bogus'"),
    (("--baseline", "wobble"), "unknown baseline 'wobble'"),
    (("--baseline", "rate", "--episodes", "zero"), "--episodes wants an integer"),
    (("--baseline", "rate", "--seed"), "--seed needs a value"),
    (("--baseline", "rate", "--render", "out.png"), "--render wants a .gif or .mp4"),
    (("--baseline", "rate", "--set", "tau_max"), "--set wants KEY=VALUE"),
    (("--baseline", "rate", "--set", "gamma=2"), "reward gamma = 2 is out of range [0, 1]"),
    (("--baseline", "rate", "--set", "k_spill=lots"), "reward k_spill: 'lots' is not a number"),
    (("--baseline", "rate", "--set", "wobble=1"), "unknown key 'wobble'"),
])
def test_bad_arguments_exit_2_with_a_message(host_sim, args, message):
    r = host_sim(*args)
    assert r.returncode == 2 and message in r.stderr


def test_missing_policy_file(host_sim, tmp_path):
    r = host_sim("--policy", tmp_path / "none.h")
    assert r.returncode == 2 and "cannot read weights file" in r.stderr


def _edit(text, pattern, repl):
    """text with the first match of pattern replaced (the match must exist)."""
    new, n = re.subn(pattern, repl, text, count=1, flags=re.S)
    assert n == 1, pattern
    return new


@pytest.mark.parametrize("pattern, repl, field", [
    (r"(#define POUR_WEIGHTS_N_ACTIONS )(\d+)", lambda m: m[1] + str(int(m[2]) - 2), "pour_weights_w"),
    (r"(#define POUR_WEIGHTS_W_FRAC_BITS )(\d+)", r"\g<1>19", "POUR_WEIGHTS_W_FRAC_BITS"),
    (r"(pour_weights_w_float\[[^=]*=\s*\{\s*\{)[^,]*", r"\g<1>NAN", "pour_weights_w_float[0][0]"),
    (r"#define POUR_WEIGHTS_CONTENT_HASH", "#define POUR_WEIGHTS_CONTENT_HASH_GONE", "POUR_WEIGHTS_CONTENT_HASH"),
    (r"(pour_weights_w\[[^=]*=\s*\{\s*\{)(-?\d+)", lambda m: m[1] + str(int(m[2]) ^ 1), "POUR_WEIGHTS_CONTENT_HASH"),
])
def test_bad_policy_is_refused_naming_the_field(host_sim, tmp_path, example, pattern, repl, field):
    bad = tmp_path / "bad.h"
    bad.write_text(_edit(example, pattern, repl))
    r = host_sim("--policy", bad, *SHORT)
    assert r.returncode == 2 and "bad policy" in r.stderr and field in r.stderr, r.stderr


def test_truncated_policy_is_refused(host_sim, tmp_path, example):
    bad = tmp_path / "cut.h"
    bad.write_text(example[: example.index("pour_weights_action_levels_q15[") + 60])
    r = host_sim("--policy", bad)
    assert r.returncode == 2 and "pour_weights_action_levels_q15" in r.stderr and "truncated" in r.stderr


@pytest.mark.parametrize("text, message", [
    (None, "cannot read config file"),
    ("substeps = two\n", "'two' is not a number"),
    ("friction = 5\n", "friction = 5 is out of range"),
    ("wobble = 1\n", "unknown config key 'wobble'"),
    ("tau_max 20\n", "expected 'key = value'"),
    ("friction = 0.1\nseed = 7\0JUNK\n", "sim.cfg:2: contains a NUL byte"),
    ("seed = 7\nseed = 8\n", "sim.cfg:2: seed is set twice (first on line 1)"),
])
def test_bad_config_is_refused(host_sim, tmp_path, text, message):
    path = tmp_path / "sim.cfg"
    if text is not None:
        path.write_text(text)
    r = host_sim("--baseline", "rate", "--config", path)
    assert r.returncode == 2 and "bad config" in r.stderr and message in r.stderr, r.stderr


def test_endless_config_is_refused_at_the_size_cap(host_sim):
    r = host_sim("--baseline", "rate", "--config", "/dev/zero", timeout=60)
    assert r.returncode == 2 and "/dev/zero: larger than 1048576 bytes" in r.stderr, r.stderr


def _files(folder):
    return {p.name: p.read_bytes() if p.is_file() else "dir" for p in folder.iterdir()}


@pytest.fixture
def inputs(tmp_path, source_dir):
    """A policy, a config, a hard link to the policy and an existing CSV in tmp_path."""
    (tmp_path / "p.h").write_bytes((source_dir / "policy" / "weights.h").read_bytes())
    (tmp_path / "c.cfg").write_text("seed = 1\n")
    (tmp_path / "link.csv").hardlink_to(tmp_path / "p.h")
    (tmp_path / "old.csv").write_text("a good old CSV\n")
    return tmp_path


# An output that names an input or another output of the same run: refused before any work, nothing touched.
@pytest.mark.parametrize("args, message", [
    (("--policy", "p.h", "--csv", "p.h"), "--csv 'p.h' is the input --policy 'p.h'"),
    (("--policy", "p.h", "--csv", "./sub/../p.h"), "is the input --policy"),
    (("--policy", "p.h", "--csv", "link.csv"), "--csv 'link.csv' is the input --policy 'p.h'"),
    (("--baseline", "full", "--config", "c.cfg", "--csv", "c.cfg"), "--csv 'c.cfg' is the input --config"),
    (("--baseline", "full", "--csv", "out.json", "--render", "out.gif"),
     "--render (its .json trajectory) 'out.json' is also --csv 'out.json'"),
    (("--baseline", "full", "--config", "c.cfg", "--render", "c.gif", "--csv", "c.png"),
     "--render (its .png snapshot) 'c.png' is also --csv 'c.png'"),
    (("--baseline", "full", "--csv", ""), "--csv: the file name is empty"),
    (("--baseline", "full", "--render", ""), "--render: the file name is empty"),
    (("--baseline", "full", "--render", "sub/.gif"), "--render wants a file name before its .gif"),
])
def test_outputs_never_overwrite_inputs_or_each_other(host_sim, inputs, args, message):
    (inputs / "sub").mkdir()
    before = _files(inputs)
    r = host_sim(*args, "--set", "episode_s=0.05", cwd=inputs, timeout=30)
    assert r.returncode == 2 and message in r.stderr and "(run host_sim --help" in r.stderr, r.stderr
    assert "episode 1" not in r.stdout
    assert _files(inputs) == before


def test_a_failed_output_check_leaves_no_file_behind(host_sim, inputs):
    """The old write probe created the CSV, then the render's folder was found missing: an empty CSV stayed."""
    (inputs / "sub").mkdir()
    before = _files(inputs)
    r = host_sim("--baseline", "full", "--csv", "new.csv", "--render", "nodir/x.gif", cwd=inputs, timeout=30)
    assert r.returncode == 2 and "cannot write --render 'nodir/x.gif'" in r.stderr, r.stderr
    r = host_sim("--baseline", "full", "--csv", "sub", "--render", "x.gif", cwd=inputs, timeout=30)
    assert r.returncode == 2 and "is a directory" in r.stderr, r.stderr
    assert _files(inputs) == before


@pytest.mark.parametrize("sig", ["TERM", "INT", "KILL"])
def test_a_killed_run_leaves_the_existing_csv_whole(build_dir, inputs, sig):
    """The CSV is written to a temporary beside it and renamed at the end: killed half-way, the old CSV is
    still there, byte for byte. On SIGTERM/SIGINT the temporary is removed too; SIGKILL cannot be caught,
    so a hidden .old.csv.XXXXXX may stay (never the CSV itself)."""
    proc = subprocess.Popen([str(build_dir / "bin" / "host_sim"), "--baseline", "full", "--episodes", "100",
                             "--csv", "old.csv"], cwd=inputs, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    assert proc.stdout.readline().startswith("host_sim:")   # the run has started ...
    assert proc.stdout.readline().startswith("episode 1")   # ... and written a first episode
    proc.send_signal(getattr(signal, "SIG" + sig))
    proc.communicate(timeout=60)
    assert proc.returncode < 0
    assert (inputs / "old.csv").read_text() == "a good old CSV\n"
    left = {p.name for p in inputs.iterdir()} - {"p.h", "c.cfg", "link.csv", "old.csv"}
    if sig == "KILL":
        assert all(name.startswith(".old.csv.") for name in left), left
    else:
        assert not left, left


def test_a_complete_run_replaces_the_csv(host_sim, inputs):
    r = host_sim("--baseline", "full", "--csv", "old.csv", "--set", "episode_s=0.05", cwd=inputs, timeout=60)
    assert r.returncode == 0, r.stderr
    assert (inputs / "old.csv").read_text().startswith("episode,seed,step")
    assert {p.name for p in inputs.iterdir()} == {"p.h", "c.cfg", "link.csv", "old.csv"}


@pytest.mark.parametrize("flag, name", [("--csv", "run.csv"), ("--render", "pour.gif")])
def test_unwritable_output_is_refused_before_running(host_sim, tmp_path, flag, name):
    r = host_sim("--baseline", "rate", flag, tmp_path / "no_such_dir" / name, timeout=30)
    assert r.returncode == 2 and "cannot write" in r.stderr and "No such file or directory" in r.stderr
    assert "episode 1" not in r.stdout


def test_out_of_range_set_is_refused(host_sim):
    r = host_sim("--baseline", "rate", "--set", "n_particles=5000")
    assert r.returncode == 2 and "n_particles" in r.stderr


def test_reward_keys_set_the_return_not_the_world(host_sim):
    """k_spill weighs the spilled share in the return; the pour itself is the same."""
    args = ("--baseline", "full", "--json", "--quiet", "--set", "episode_s=1.5")
    a, b = host_sim(*args), host_sim(*args, "--set", "k_spill=10")
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    ja, jb = json.loads(a.stdout), json.loads(b.stdout)
    assert ja["spilled_pct"] == jb["spilled_pct"] > 0 and ja["poured_pct"] == jb["poured_pct"]
    assert jb["return"] < ja["return"]


def test_config_tau_max_must_match_the_policy(host_sim, tmp_path, source_dir):
    cfg = tmp_path / "sim.cfg"
    cfg.write_text("tau_max = 12\n")
    r = host_sim("--policy", source_dir / "policy" / "weights.h", "--config", cfg)
    assert r.returncode == 2 and "mismatch" in r.stderr and "tau_max" in r.stderr


def test_shipped_config_file_loads(host_sim, source_dir):
    r = host_sim("--baseline", "full", "--config", source_dir / "configs" / "sim" / "default.cfg", *SHORT, "--json")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["episodes"] == 1


def test_policy_run_prints_json_summary(host_sim, source_dir):
    r = host_sim("--policy", source_dir / "policy" / "weights.h", "--episodes", 2, "--seed", 5, "--json", *SHORT)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["episodes"] == 2 and s["seed"] == 5 and len(s["per_episode"]) == 2
    assert s["controller"].startswith("firmware")
    for key in ("poured_pct", "spilled_pct", "finish_s", "return"):
        assert key in s
    assert [e["seed"] for e in s["per_episode"]] == [5, 6]
    assert "episode 1 seed 5" in r.stderr  # per-episode lines go to stderr with --json


def summary(host_sim, *args):
    r = host_sim(*args, "--json", "--quiet")
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_scene_allows_a_good_pour_and_the_rate_baseline_is_beatable(host_sim):
    """The hand-written pour reaches what the trainer must reach; tilting at a constant rate onto the
    stop spills clearly more (as the paper's best binary policy did)."""
    hand = summary(host_sim, "--baseline", "hand", "--episodes", 3)
    rate = summary(host_sim, "--baseline", "rate", "--episodes", 3)
    full = summary(host_sim, "--baseline", "full", "--episodes", 3)
    assert hand["poured_pct"] >= 95.0 and hand["spilled_pct"] <= 3.0 and 0 < hand["finish_s"] <= 8.0
    assert rate["spilled_pct"] >= hand["spilled_pct"] + 3.0
    assert full["spilled_pct"] >= rate["spilled_pct"]


def test_csv_has_every_step(host_sim, tmp_path):
    out = tmp_path / "run.csv"
    r = host_sim("--baseline", "rate", "--episodes", 2, "--csv", out, *SHORT)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 2 * 1500
    assert rows[0]["episode"] == "1" and rows[-1]["episode"] == "2" and rows[-1]["step"] == "1500"
    for row in rows[::97]:
        v = [float(row[k]) for k in ("v_rotating", "v_target", "v_spill", "v_flight")]
        assert sum(v) == pytest.approx(1.0, abs=1e-5)  # printed with 6 decimals


def test_render_writes_gif_and_png(host_sim, tmp_path):
    from PIL import Image
    gif = tmp_path / "pour.gif"
    r = host_sim("--baseline", "hand", "--render", gif, "--set", "episode_s=1.2", timeout=600)
    assert r.returncode == 0, r.stderr
    png = tmp_path / "pour.png"
    with Image.open(gif) as im:
        assert im.n_frames >= 10
    with Image.open(png) as im:
        assert im.size[0] >= 600 and im.size[1] >= 300


@pytest.mark.parametrize("content, out, message", [
    (None, "x.gif", "cannot read trajectory"),
    ("{not json", "x.gif", "cannot read trajectory"),
    ('{"scene": {}, "radius": [], "series": {}}', "x.gif", "has no 'frames'"),
    ('{"scene": {}, "radius": [], "series": {}, "frames": []}', "x.gif", "has no frames"),
    ('{"scene": {}, "radius": [], "series": {}, "frames": [{}]}', "x.png", "must end in .gif or .mp4"),
])
def test_renderer_refuses_bad_input(tmp_path, content, out, message):
    import sys
    traj = tmp_path / "t.json"
    if content is not None:
        traj.write_text(content)
    r = subprocess.run([sys.executable, "-m", "pour.eval.render", str(traj), str(tmp_path / out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and message in r.stderr, r.stderr


def test_firmware_pour_is_bit_identical_across_runs(host_sim, tmp_path, source_dir):
    outs = []
    for k in range(2):
        out = tmp_path / f"run{k}.csv"
        r = host_sim("--policy", source_dir / "policy" / "weights.h", "--sampled", "--seed", 3, "--csv", out, *SHORT)
        assert r.returncode == 0, r.stderr
        outs.append(out.read_bytes())
    assert outs[0] == outs[1] and len(outs[0]) > 100_000


def test_drive_json_carries_the_peak_current_the_bus_range_and_the_faults_by_name(host_sim, source_dir):
    """--set drive=1 --json: the summary's "drive" is the worst of the episodes' own "drive" objects, and the
    text line (on stderr with --json) says the same figures."""
    args = ("--policy", source_dir / "policy" / "weights.h", "--set", "drive=1", "--set", "episode_s=2",
            "--episodes", 2)
    r = host_sim(*args, "--json", "--quiet")
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    per = [e["drive"] for e in s["per_episode"]]
    assert len(per) == 2 and all(set(d) == {"peak_current_a", "peak_vbus_v", "min_vbus_v", "faults"} for d in per)
    assert s["drive"]["peak_current_a"] == max(d["peak_current_a"] for d in per) > 1.0
    assert s["drive"]["peak_vbus_v"] == max(d["peak_vbus_v"] for d in per)
    assert s["drive"]["min_vbus_v"] == min(d["min_vbus_v"] for d in per)
    assert 20.0 < s["drive"]["min_vbus_v"] <= s["drive"]["peak_vbus_v"] < 26.0  # the 24 V supply
    assert s["drive"]["faults"] == [] and all(e["fault_names"] == [] for e in s["per_episode"])
    line = r.stderr.strip().splitlines()[-1]
    # The text rounds the full double, the JSON carries it to fewer digits: the same figures within a last digit.
    m = re.fullmatch(r"drive \(field-oriented, docs/motor.md\): peak phase current ([0-9.]+) A, "
                     r"peak bus ([0-9.]+) V \(lowest ([0-9.]+) V\), faults none", line)
    assert m, line
    assert abs(float(m[1]) - s["drive"]["peak_current_a"]) <= 0.051
    assert abs(float(m[2]) - s["drive"]["peak_vbus_v"]) <= 0.0051
    assert abs(float(m[3]) - s["drive"]["min_vbus_v"]) <= 0.0051


def test_drive_json_names_an_injected_drive_fault(host_sim, source_dir):
    s = summary(host_sim, "--policy", source_dir / "policy" / "weights.h", "--set", "drive=1", "--set",
                "drive_fault=3", "--set", "episode_s=2")  # the encoder wired backwards
    (e,) = s["per_episode"]
    assert e["drive"]["faults"] == ["ENCODER_DIRECTION"] == s["drive"]["faults"]
    assert e["fault_names"] == ["DRIVE"] and e["faults"] == 1 << 11 and s["faulted"] == 1


def test_json_without_the_full_drive_has_no_drive_object(host_sim):
    s = summary(host_sim, "--baseline", "hand", "--set", "episode_s=1")
    assert "drive" not in s and "drive" not in s["per_episode"][0]
