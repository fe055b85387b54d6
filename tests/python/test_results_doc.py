# SPDX-License-Identifier: MIT
"""docs/results.md is what pour-results-doc makes of results/*.json: regenerated here and compared byte for
byte, so a results file re-measured without the page (or a page edited by hand) fails. Bad input: one line,
exit 2, nothing written."""
import json
import shutil
import subprocess
import sys

from conftest import SOURCE_DIR

from pour.eval import results_doc


def run(*args, cwd=SOURCE_DIR):
    return subprocess.run([sys.executable, "-m", "pour.eval.results_doc", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def test_the_page_is_what_the_results_give():
    page = (SOURCE_DIR / "docs" / "results.md").read_text(encoding="utf-8")
    assert page == results_doc.render(SOURCE_DIR / "results"), "docs/results.md is stale: run pour-results-doc"


def test_check_disagrees_with_a_changed_figure(tmp_path):
    res = tmp_path / "results"
    shutil.copytree(SOURCE_DIR / "results", res, ignore=shutil.ignore_patterns("*.png", "*.csv", "logs"))
    out = tmp_path / "results.md"
    assert run("--results", res, "--out", out).returncode == 0
    assert run("--results", res, "--out", out, "--check").returncode == 0
    doc = json.loads((res / "robustness" / "robustness.json").read_text())
    doc["rows"][0]["spilled_pct"] += 0.01
    (res / "robustness" / "robustness.json").write_text(json.dumps(doc))
    r = run("--results", res, "--out", out, "--check")
    assert r.returncode == 1 and "stale" in r.stderr, r.stderr


def test_bad_input_is_one_line_and_exit_2(tmp_path):
    out = tmp_path / "results.md"
    r = run("--results", tmp_path / "none", "--out", out)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "missing" in r.stderr and not out.exists()
    assert len(r.stderr.strip().splitlines()) == 1
    res = tmp_path / "results"
    shutil.copytree(SOURCE_DIR / "results", res, ignore=shutil.ignore_patterns("*.png", "*.csv", "logs"))
    (res / "figures.json").write_text("{not json")
    r = run("--results", res, "--out", out)
    assert r.returncode == 2 and "not readable JSON" in r.stderr and not out.exists(), r.stderr
    (res / "figures.json").write_text(json.dumps({"figures": [{"what": "x"}]}))
    r = run("--results", res, "--out", out)
    assert r.returncode == 2 and "lacks a field" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not out.exists()
