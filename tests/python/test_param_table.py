# SPDX-License-Identifier: MIT
"""The parameter declaration (POUR_PARAMS) against what repeats it: the tables of docs/can.md and docs/safety.md
and the DBC's ParamId value lists are what scripts/param_table.py writes, the compiled defaults (the modules'
default configs, pour-bench's table) are the declared ones, and each row's C member follows the naming rule
params.h states; a declaration with two rows on one CAN id, two rows of one name, a default outside its range,
a bound that is no number, a member off the rule or a row that does not parse fails naming the rows involved,
in scripts/param_table.py and (where C can say it) in the compiler."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts/param_table.py"
HEADER = ROOT / "firmware/include/pour/params.h"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("args", [("check",), ("docs", "--check"), ("dbc", "--check")])
def test_the_tree_agrees_with_the_declaration(args):
    r = run(*args)
    assert r.returncode == 0 and r.stderr == "", r.stderr


def _module():
    """scripts/param_table.py as a module."""
    sys.path.insert(0, str(SCRIPT.parent))
    try:
        import param_table
    finally:
        sys.path.pop(0)
    return param_table


def _declaration() -> list[dict]:
    return _module().declaration()


def test_the_envelope_ranges_are_the_safety_cases():
    rows = {r["name"]: r for r in _declaration()}
    for name in ("omega_max", "omega_slack", "slow_omega", "stop_return_speed", "stop_rest_omega"):
        assert rows[name]["max"] == 2_000_000, name  # docs/safety.md: 2 rad/s, the hot-liquid limit
    assert rows["alpha_max"]["max"] == 3_400_000 and rows["governor_gain"]["max"] == 16384
    # the supervisor's and the estimator's limits: the safety case's values are the loosest the bus takes
    assert rows["supervisor_theta_margin"]["max"] == rows["supervisor_theta_margin"]["default"] == 87266  # 5 deg
    assert rows["supervisor_omega_max"]["max"] == rows["supervisor_omega_max"]["default"] == 4_000_000  # 4 rad/s
    assert rows["jump_max"]["max"] == rows["jump_max"]["default"] == 10_000  # 10 mrad


def _bad(tmp_path: Path, old: str, new: str) -> Path:
    text = HEADER.read_text()
    assert text.count(old) == 1, old
    bad = tmp_path / "params.h"
    bad.write_text(text.replace(old, new))
    return bad


BAD = [
    ("X(5, alpha_max,", "X(4, alpha_max,", "omega_max and alpha_max have the same CAN parameter id 4"),
    ('X(27, slow_ki, "1/s", 5, 0, UINT16_MAX, uint16_t, safety, slow_ki_per_s,',
     'X(27, slow_omega, "urad/s", 5, 0, UINT16_MAX, uint16_t, safety, slow_omega_urad_s,',
     "ids 24 and 27 have the same name slow_omega"),
    ('X(17, encoder_zero, "counts", 0, 0, 16777215,', 'X(17, encoder_zero, "counts", 0, 16777215, 0,',
     "encoder_zero: min 16777215 is above max 0"),
    ('X(6, omega_slack, "urad/s", 800000,', 'X(6, omega_slack, "urad/s", 3000000,',
     "omega_slack: default 3000000 is outside its range 1 .. 2000000"),
    ('X(0, tau_limit, "Q15", POUR_Q15_MAX, 1,', 'X(0, tau_limit, "Q15", 0, 1,',
     "tau_limit: default 0 is outside its range 1 .. 32767"),
    ('X(15, node_id, "", 0, 0, 63,', 'X(15, node_id, "", 0, 0, NODE_MAX,',
     "node_id: bound NODE_MAX is not a number or a #define of the headers"),
    ("q15_t, safety, slow_torque_ff,", "q15_t, safety, slow_ff,",
     "slow_torque_ff: its member is slow_ff, the naming rule gives slow_torque_ff (name less '', plus the unit's "
     "suffix '')"),
    ('X(13, stop_rest_omega, "urad/s",', 'X(13, stop_rest_omega, "mrad/s",',
     "stop_rest_omega: unit 'mrad/s' has no member suffix in the naming rule"),
    ("X(14, stop_timeout,", "X(14, timeout,", "timeout: a row of group stop is named stop_..."),
    ('"uncalibrated: no tare")', '"")',
     "scale_target_tare: its doc must say in one line, without '|', why its default is what it is"),
]


@pytest.mark.parametrize("old,new,message", BAD, ids=["same id", "same name", "min > max", "default above max",
                                                     "default below min", "unknown bound", "member off the rule",
                                                     "unit off the rule", "group prefix missing", "no doc"])
def test_a_bad_declaration_is_refused_naming_its_rows(tmp_path, old, new, message):
    r = run("check", "--header", str(_bad(tmp_path, old, new)))
    assert r.returncode == 1 and r.stdout == "", (r.stdout, r.stderr)
    assert r.stderr.strip().splitlines() == [f"params.h: {message}"], r.stderr
    assert "Traceback" not in r.stderr


def test_a_missing_header_is_one_line(tmp_path):
    r = run("check", "--header", str(tmp_path / "none.h"))
    assert r.returncode == 1 and r.stderr.startswith("error: ") and len(r.stderr.splitlines()) == 1, r.stderr


def test_the_bridge_lists_every_field_of_the_cores_config():
    r = run("fields")
    assert r.returncode == 0 and r.stderr == "", r.stderr


def _bridge() -> Path:
    for f in sorted((ROOT / "host_sim").rglob("*.cpp")):
        if "POURSIM_FW_FIELD(safety." in f.read_text():
            return f
    raise AssertionError("no bridge source")


@pytest.mark.parametrize("old,new,message", [
    ("POURSIM_FW_FIELD(supervisor.window_ms), ", "",
     "pour_control_config_t.supervisor.window_ms has no POURSIM_FW_FIELD"),
    ("POURSIM_FW_FIELD(seed),", "POURSIM_FW_FIELD(seed), POURSIM_FW_FIELD(safety.omega_max),",
     "POURSIM_FW_FIELD(safety.omega_max) is no field of pour_control_config_t"),
], ids=["a field left out", "a path that is no field"])
def test_a_bridge_that_drifts_is_named(tmp_path, old, new, message):
    text = _bridge().read_text()
    assert text.count(old) == 1, old
    bad = tmp_path / "core_api.cpp"
    bad.write_text(text.replace(old, new))
    r = run("fields", "--bridge", str(bad))
    assert r.returncode == 1 and r.stderr.strip().splitlines() == [f"{bad}: {message}"], r.stderr


@pytest.mark.parametrize("old,new,message", [
    ("X(5, alpha_max,", "X(4, alpha_max,", "duplicate case value"),
    ("X(27, slow_ki,", "X(27, slow_omega,", "POUR_PARAM_ID_slow_omega"),
    BAD[2][:2] + ("pour_param_range_not_empty_encoder_zero",),
    BAD[3][:2] + ("pour_param_default_in_range_omega_slack",),
    BAD[4][:2] + ("pour_param_default_in_range_tau_limit",),
], ids=["same id", "same name", "min > max", "default above max", "default below min"])
def test_the_compiler_refuses_a_bad_declaration_too(tmp_path, old, new, message):
    include = tmp_path / "include"
    shutil.copytree(HEADER.parent.parent, include)
    (include / "pour/params.h").write_text(HEADER.read_text().replace(old, new))
    def compile_with(inc: Path) -> subprocess.CompletedProcess:
        return subprocess.run([shutil.which("cc") or "cc", "-std=c99", "-fsyntax-only", "-I", str(inc),
                               str(ROOT / "firmware/src/params.c")], capture_output=True, text=True, timeout=60)
    good = compile_with(HEADER.parent.parent)
    assert good.returncode == 0, good.stderr  # the same command takes the real declaration
    r = compile_with(include)
    assert r.returncode != 0 and message in r.stderr, r.stderr


def test_the_modules_default_configs_are_the_declared_defaults(build_dir, monkeypatch):
    """pour_control_default_config (through libpoursim's field table, by C path) holds each declared row's
    default: a module that kept its own value, or set a row to another member, differs here."""
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))
    from pour import core
    cfg = core.control_config()
    rows = [r for r in _declaration() if r["field"].startswith("control.")]
    assert {r["group"] for r in rows} == {"safety", "stop", "sensors", "supervisor"}  # every module's default config
    got = {r["name"]: cfg.get(r["field"][len("control."):]) for r in rows}
    assert got == {r["name"]: r["default"] for r in rows}


def test_the_bench_table_is_the_declaration(build_dir, monkeypatch):
    """pour-bench's table (libpoursim's pour_param_info) has every row of the declaration, with its id, unit,
    range and default, and no other."""
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))
    from pour.bench import params
    got = [(p.id, p.name, p.unit, p.min, p.max, p.default) for p in params.table().values()]
    assert got == [(r["id"], r["name"], r["unit"], r["min"], r["max"], r["default"]) for r in _declaration()]


SAFETY_MD = ROOT / "docs/safety.md"


@pytest.mark.parametrize("old,new,message", [
    ("| `omega_slack` (6) | `safety.omega_slack_urad_s` | 800000 urad/s |",
     "| `omega_slack` (6) | `safety.omega_slack_urad_s` | 900000 urad/s |",
     "a parameter table differs from POUR_PARAMS; run scripts/param_table.py docs --write"),
    ("| `governor_gain` | the stiffest governor", "| `torque_per_rad_s` | the stiffest governor",
     "`torque_per_rad_s` in a parameter table is no row of POUR_PARAMS"),
    ("<!-- params:begin ids=28-30 ", "<!-- params:begin ids=28-32 ", "ids=28-32: no row has id 31, 32"),
], ids=["a generated value edited by hand", "a hand table naming no parameter", "a block of ids that are none"])
def test_safety_md_drifting_from_the_declaration_is_named(tmp_path, old, new, message):
    text = SAFETY_MD.read_text()
    assert text.count(old) == 1, old
    bad = tmp_path / "safety.md"
    bad.write_text(text.replace(old, new))
    r = run("docs", "--check", "--doc", str(bad))
    assert r.returncode == 1 and r.stderr.strip().splitlines() == [f"{bad}: {message}"], r.stderr
    assert run("docs", "--check", "--doc", str(SAFETY_MD)).returncode == 0


def test_docs_write_puts_the_declaration_back(tmp_path):
    bad = tmp_path / "safety.md"
    bad.write_text(SAFETY_MD.read_text().replace("| 800000 urad/s |", "| 900000 urad/s |"))
    assert run("docs", "--write", "--doc", str(bad)).returncode == 0
    assert bad.read_text() == SAFETY_MD.read_text() and not list(tmp_path.glob("*.tmp"))


def test_a_row_that_does_not_parse_is_named_not_dropped(tmp_path):
    """A row the parser cannot read (here one column too many) is reported, not silently left out."""
    old = 'X(22, scale_target_tare, "g", 0, -32767, 32767, int32_t, port, scale_target_tare_g,'
    r = run("check", "--header", str(_bad(tmp_path, old, old.replace("port,", "port, 7,"))))
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 1 and lines[0] == (
        "params.h: a row does not read as X(id, name, unit, default, min, max, type, group, member, doc): "
        'X(22, scale_target_tare, "g", 0, -32767, 32767, int32_t, por ...'), r.stderr


DBC = ROOT / "can/pour.dbc"


def test_a_dbc_list_that_drifts_is_named_and_written_back(tmp_path):
    bad = tmp_path / "pour.dbc"
    text = DBC.read_text()
    head = 'VAL_ 9 ParamId 0 "tau_limit" 1 '
    bad.write_text(text.replace(head + '"slew_per_tick"', head + '"slew"'))
    r = run("dbc", "--check", "--dbc", str(bad))
    assert r.returncode == 1 and r.stderr.strip().splitlines() == [
        f"{bad}: VAL_ 9 ParamId differs from POUR_PARAMS at [(1, 'slew'), (1, 'slew_per_tick')]; "
        "run scripts/param_table.py dbc --write"], r.stderr
    assert run("dbc", "--write", "--dbc", str(bad)).returncode == 0
    assert bad.read_text() == text  # the shipped DBC is what the declaration writes, byte for byte


def test_every_declared_unit_has_an_si_reading():
    """pour-bench shows each parameter in SI units; a row whose unit it does not know would show raw."""
    from pour.bench import params
    assert {r["unit"] for r in _declaration()} <= set(params.SI)


def test_the_naming_rule_params_h_states_is_the_one_checked():
    """Each unit suffix and group prefix param_table.py holds a row to is named in params.h's rule, and the rule
    names no suffix the checker does not know."""
    param_table = _module()
    text = HEADER.read_text()
    rule = text[text.index("/* One name per parameter."):]
    rule = " ".join(rule[:rule.index("*/")].replace("\n *", " ").split())
    stated = set(re.findall(r"(?<![\w.])_[a-z0-9_]+\b", rule)) - {"_"}
    assert stated == {s for s in param_table.UNIT_SUFFIX.values() if s}, stated
    for group, prefix in param_table.GROUP_PREFIX.items():
        assert f"({prefix} for the" in rule or f", {prefix} for the" in rule, (group, prefix)


def _hand_defaults(text: str) -> list[tuple[str, str]]:
    """(field, default cell) of docs/safety.md's hand-written '| field | default | reason |' tables (the core's
    fields that are no bus parameter): the rows naming one field whose default is a raw integer, maybe with a
    reading in parentheses ('11469 (0.35 τ_max = 7 N·m)', '1,000'); readings in other units are not compared."""
    out, inside = [], False
    for line in text.splitlines():
        if line.startswith("| field | default | reason |"):
            inside = True
            continue
        if not line.startswith("|"):
            inside = False
        if not inside or line.startswith("|---"):
            continue
        cells = [c.strip() for c in line.strip("|").split(" | ")]
        m = re.fullmatch(r"`([\w.]+)`", cells[0])
        v = re.fullmatch(r"([−-]?\d[\d,]*)(?: \(.*\))?", cells[1])
        if m and v:
            out.append((m.group(1), v.group(1).replace(",", "").replace("−", "-")))
    return out


def test_the_hand_written_defaults_in_safety_md_are_the_compiled_ones(build_dir, monkeypatch):
    """The core's fields that are no parameter keep their defaults in their modules; where docs/safety.md's
    tables give one as a raw integer, it is what pour_control_default_config holds (by its C path, or the one
    field whose path ends so)."""
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))
    from pour import core
    cfg = core.control_config()
    rows = _hand_defaults(SAFETY_MD.read_text())
    assert len(rows) >= 8, rows
    for name, want in rows:
        paths = [f for f in cfg.fields() if f == name or f.endswith("." + name)]
        assert len(paths) == 1, (name, paths)
        assert cfg.get(paths[0]) == int(want), (name, want)
