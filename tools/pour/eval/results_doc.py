# SPDX-License-Identifier: MIT
"""pour-results-doc: docs/results.md, written from the measurements in results/ (their JSON files), never by hand.

    pour-results-doc                       # reads results/, writes docs/results.md
    pour-results-doc --check               # exit 1 if docs/results.md is not what results/ gives

Each table comes from one JSON file that a command wrote (pour-eval robust, pour-robust-scale, pour-results),
and the command stands above it; results/figures.json holds the figures that benchmarks and test programs
print (scripts/bench.sh and the others), each with its command. tests/python/test_results_doc.py fails when
docs/results.md is stale.
"""
from __future__ import annotations

import hashlib
import json
import re
import sys
from pathlib import Path
from typing import Any, Sequence

from pour import atomic, cli
from pour.eval import results, robustness

# The JSON files the page is made from, relative to the results folder, in the page's order.
ROBUSTNESS = "robustness/robustness.json"
SCALE = ("robustness_scale/robust_scale.json", "robustness_scale_repeats8/robust_scale.json",
         "robustness_scale_fill_schedule/robust_scale.json")
HELD_OUT_100 = "heldout100/results.json"
COMPARISON = "results.json"
ZERO = "zero/results.json"
FIGURES = "figures.json"
INPUTS = (ROBUSTNESS, *SCALE, HELD_OUT_100, COMPARISON, ZERO, FIGURES)

SPILL_BAR_PCT = 3.0  # the 400 rigs' bar: no rig over 3 % spilled


class ResultsError(Exception):
    """A results file missing, unreadable or without the fields the page needs."""


def _load(folder: Path, name: str) -> dict[str, Any]:
    path = folder / name
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ResultsError(f"{path}: missing (the command that writes it is in docs/results.md)") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ResultsError(f"{path}: not readable JSON ({exc})") from None
    if not isinstance(doc, dict):
        raise ResultsError(f"{path}: expected a JSON object")
    return doc


def _from_root(text: str) -> str:
    """Links written relative to the repository's root, made relative to docs/."""
    return re.sub(r"\]\((?!https?:|#)([^)]+)\)",
                  lambda m: "](" + (m[1][5:] if m[1].startswith("docs/") else "../" + m[1]) + ")", text)


def _robustness(doc: dict[str, Any]) -> list[str]:
    rows = doc["rows"]
    alpha = [r["peak_alpha_max_rad_s2"] for r in rows]
    return [
        "## The shipped policy: nominal and each edge of the rig",
        "",
        "`policy/weights.h`, the firmware core in the loop, seeds never used in training; the fill edges are the "
        "training distribution's (10 L ± 20 %). Measured by:",
        "",
        "```sh",
        f".venv/bin/pour-eval robust --header policy/weights.h --out results/robustness   # {ROBUSTNESS}",
        "```",
        "",
        robustness.table(rows, doc["header"], doc["seed"]).rstrip("\n"),
        "",
        "\"Meet all three\" counts episodes with ≥ 98 % poured, ≤ 1 % spilled and finished within 6 s; one "
        "particle is 0.67 % of the liquid, so a single episode's spill moves in steps of 0.67 %. The peak angular "
        f"acceleration is {min(alpha):.0f}–{max(alpha):.0f} rad/s²: the motion envelope's ramp holds only above "
        "its slack ([safety.md](safety.md#the-motion-envelope-firmwaresrcsafetyc)), so the first 0.1 s of a "
        "swing from rest is faster than the ramp. "
        f"All bars: {'met' if doc['all_bars_met'] else 'NOT met'}.",
        "",
        "![robustness](../results/robustness/robustness.png)",
        "",
    ]


def _over(doc: dict[str, Any]) -> tuple[list[dict[str, Any]], str]:
    """The rigs over the spill bar and the key of their spill: each rig's mean over its repeats when it has
    repeats, else its one episode."""
    if doc.get("repeats", 1) > 1:
        rigs, key = doc["per_rig"], "spilled_pct"
    else:
        rigs, key = doc["per_episode"], "spilled_pct"
    return [r for r in rigs if r[key] > SPILL_BAR_PCT], key


def _scale(doc: dict[str, Any], name: str) -> list[str]:
    repeats = int(doc.get("repeats", 1))
    sets = [f"--{k.replace('_', '-')} {v:g}" for k, v in (("fill_schedule", doc.get("fill_schedule_l", 0.0)),) if v]
    cmd = (".venv/bin/pour-robust-scale --header policy/weights.h --rigs {rigs}{rep}{sets} --num-cpus 2 "
           "--out {out}").format(rigs=doc["rigs"], rep=f" --repeats {repeats}" if repeats > 1 else "",
                                 sets="".join(" " + s for s in sets), out=str(Path("results") / Path(name).parent))
    over, key = _over(doc)
    fill = [r["liquid_l"] for r in over]
    what = "rigs (each rig's mean over its repeats)" if repeats > 1 else "rigs (one episode each)"
    verdict = (f"{len(over)} of {doc['rigs']} {what} spill more than {SPILL_BAR_PCT:g} %"
               + (f", the worst {max(r[key] for r in over):.2f} %, all holding {min(fill):.2f}–{max(fill):.2f} L"
                  if over else "") + ": the bar of no rig over 3 % is " + ("not met." if over else "met."))
    lines = ["```sh", f"{cmd}   # {name}", "```", ""]
    if doc.get("fill_schedule_l"):
        lines += ["With the envelope's fill schedule configured from each rig's drawn fill, as a rig file sets it "
                  "([safety.md](safety.md#fill-schedule-a-rig-files-setting-off-by-default)): the controller is told "
                  "the fill; it does not weigh it itself.", ""]
    elif repeats > 1:
        lines += [f"Each rig {repeats} times, its fill stepped by a millilitre between repeats (one episode is a "
                  "noisy reading of a rig: a millilitre more moves a rig's spill by several particles).", ""]
    return lines + [robustness.table(doc["rows"], Path(doc["header"]).name, doc["first_seed"],
                                     "episodes" if repeats == 1 else "rigs").rstrip("\n"), "", verdict, ""]


def _scales(docs: Sequence[tuple[str, dict[str, Any]]]) -> list[str]:
    rand = ", ".join(f"{k.removeprefix('rand_')} ±{v:g}" for k, v in docs[0][1]["rand"].items())
    lines = ["## 400 randomised rigs", "",
             f"Every parameter drawn at once from the training distribution ({rand}; fill, bucket mass, motor and "
             "liquid as fractions, target and pivot in metres, the scales' lag and noise as fractions), seeds "
             f"{docs[0][1]['first_seed']}.. never used in training, on Ray. Bars: ≤ 30 reversals per 10 s on "
             "average and ≤ 60 on the worst rig; no rig over 3 % spilled.", ""]
    for name, doc in docs:
        lines += _scale(doc, name)
    return lines + ["![400 rigs](../results/robustness_scale/robust_scale.png)", ""]


def _row_table(rows: Sequence[dict[str, Any]]) -> list[str]:
    out = ["| policy | episodes | poured % (mean / min) | spilled % (mean / max) | finish s (mean / max) | "
           "reversals per 10 s (mean / max) | return | episodes meeting all targets |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        fin = "never (nothing poured)" if r["finish_s_max"] < 0 else f"{r['finish_s']:.2f} / {r['finish_s_max']:.2f}"
        out.append(f"| {r['name']} | {r['episodes']} | {r['poured_pct']:.1f} / {r['poured_pct_min']:.1f} | "
                   f"{r['spilled_pct']:.2f} / {r['spilled_pct_max']:.1f} | {fin} | "
                   f"{r['reversals']:.2f} / {r['reversals_max']:.0f} | {r['return']:.0f} | "
                   f"{r['episodes_meeting_all_targets']}/{r['episodes']} |")
    return out


def _held_out(doc: dict[str, Any]) -> list[str]:
    return ["## The binary policy and the baselines, 100 held-out seeds", "",
            "Seeds 1000001–1000100, 10 s, nominal rig, every controller through the firmware's whole pipeline "
            "(the baselines too: the constant-rate and full-torque ones drive the bucket onto its hard stop, where "
            "the supervisor stops it after the liquid has left). Targets: poured ≥ 95 %, spilled ≤ 3 %, finished "
            "within 8 s. The 11-level shipped policy's row on the same seeds is the nominal row above.", "",
            "```sh",
            f".venv/bin/pour-results --header policy/weights_binary.h --episodes 100 --out results/heldout100"
            f"   # {HELD_OUT_100}",
            "```", "", *_row_table(doc["rows"]), ""]


def _comparison(doc: dict[str, Any], zero: dict[str, Any]) -> list[str]:
    n = zero["rows"][0]["episodes"]
    return ["## Training methods side by side", "",
            "The seed paper's update against ours and the peers ([training.md](training.md#the-method) says "
            "what each is), 20 held-out seeds, nominal rig, greedy. The commands that train every row are in "
            "[notes/training-2026-12.md](notes/training-2026-12.md#commands-behind-the-results); "
            f"`pour-results` writes `results/{COMPARISON}` ({doc['header_hash']} is the shipped header's hash).",
            "", results.markdown(doc["rows"], doc["rows"][0]["episodes"]).rstrip("\n"), "",
            "| return during training (mean and spread over 3 seeds) | the shipped policy's angle over time |",
            "|---|---|",
            "| ![reward curve](../results/compare_reward_curve.png) | ![angle](../results/shipped_angle.png) |", "",
            "### Learning from zero", "",
            "The same randomised rig, the same held-out seeds, the same budget of training episodes per run, in one "
            f"`pour-results --reach` run (`results/{ZERO}`; its commands are in the "
            "[notes](notes/training-2026-12.md#side-by-side-in-one-pour-results---reach-run-issue-22s-peers)).",
            results.reach_markdown(zero["reach"], {r["name"]: r for r in zero["rows"]}, n).rstrip("\n"), "",
            "![curves](../results/zero/reach_curves.png)", ""]


def _figures(doc: dict[str, Any]) -> list[str]:
    lines = ["## Figures measured by benchmarks and test programs", "",
             "Measured on this project's 2-core build machine and recorded in `results/figures.json` by hand: these "
             "programs print their figures and write no JSON yet. The command that measures each is beside it.", "",
             "| what | figure | bar | command |", "|---|---|---|---|"]
    for f in doc["figures"]:
        lines.append("| " + " | ".join(_from_root(f[k]) for k in ("what", "figure", "bar", "command")) + " |")
    return lines + [""]


def render(folder: Path) -> str:
    """docs/results.md from the JSON files under folder (INPUTS); ResultsError when one is missing or lacks a
    field."""
    docs = {name: _load(folder, name) for name in INPUTS}
    digest = hashlib.sha256()
    for name in INPUTS:
        digest.update(name.encode() + b"\0" + (folder / name).read_bytes())
    try:
        body = [
            f"<!-- Generated by pour-results-doc from results/ ({', '.join(INPUTS)}; sha256 "
            f"{digest.hexdigest()[:16]}). Do not edit: run .venv/bin/pour-results-doc. -->",
            "",
            "# Results",
            "",
            "Every figure of the pour, the policies and the machine, each with the command that measured it. All "
            "of it is measured in simulation (the Box2D rig, the firmware's own code; the README's \"Operating "
            "limits and status\" says what that leaves out). The dated notes behind these runs are in "
            "[notes/training-2026-12.md](notes/training-2026-12.md).",
            "",
            *_robustness(docs[ROBUSTNESS]),
            *_scales([(name, docs[name]) for name in SCALE]),
            *_held_out(docs[HELD_OUT_100]),
            *_comparison(docs[COMPARISON], docs[ZERO]),
            *_figures(docs[FIGURES]),
        ]
    except (KeyError, TypeError, IndexError, ValueError, AttributeError) as exc:
        raise ResultsError(f"{folder}: a results file lacks a field the page needs ({exc!r})") from None
    return "\n".join(body).rstrip("\n") + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-results-doc", description=__doc__.split("\n")[0])
    ap.add_argument("--results", type=Path, default=Path("results"), help="the results folder (default results)")
    ap.add_argument("-o", "--out", type=Path, default=Path("docs/results.md"),
                    help="the page to write (default docs/results.md)")
    ap.add_argument("--check", action="store_true",
                    help="write nothing; exit 1 if the page differs from what the results give")
    args = ap.parse_args(argv)
    try:
        text = render(args.results)
    except ResultsError as exc:
        print(f"pour-results-doc: error: {exc}", file=sys.stderr)
        return 2
    if args.check:
        try:
            current = args.out.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            print(f"pour-results-doc: error: {args.out}: {exc}", file=sys.stderr)
            return 2
        if current != text:
            print(f"pour-results-doc: {args.out} is stale: run pour-results-doc", file=sys.stderr)
            return 1
        return 0
    try:
        atomic.write_atomic(args.out, text)
    except OSError as exc:
        print(f"pour-results-doc: error: {args.out}: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
