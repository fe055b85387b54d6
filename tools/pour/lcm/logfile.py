# SPDX-License-Identifier: MIT
"""pour-lcmlog: an LCM log of a pour (lcm-logger) → the summary and plots of a simulated pour.

    pour-lcmlog pour.lcmlog --out DIR [--render pour.gif] [--json] [--encoder-bits 17]

Prints one line per episode and a summary in host_sim's words (poured, spilled, left, finish, return),
the round-trip latency POUR_SENSORS → POUR_TORQUE as the logger saw it (median, p99, max), answers that
never came, and messages on our channels that did not decode or were refused. Writes DIR/traces.png (θ,
torque and volumes over time), DIR/latency.png (histogram) and DIR/summary.json. With --render, the
logged POUR_PARTICLES frames become the same animation and snapshot as host_sim --render.

θ and the volumes come from POUR_TRUTH when the log has it (host_sim publishes the simulated plant's
ground truth there); a rig's log has none, and then they are read from the raw sensor samples of
POUR_SENSORS (encoder count → θ with --encoder-bits; the two scales → volumes, as the firmware's estimator
defines them). Each episode's summary names its source.
"""
from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pour import atomic, cli  # noqa: E402
from pour.lcm import channels, messages, sensors  # noqa: E402


class LogError(RuntimeError):
    """The log cannot be read or holds no pour."""


@dataclass
class Episode:
    index: int
    seq: list[int] = field(default_factory=list)             # sensor samples, in the order they were logged
    sample_ts: dict[int, int] = field(default_factory=dict)   # seq → logger time of its first sample [µs]
    raw: dict[int, tuple[int, int, int]] = field(default_factory=dict)  # seq → (encoder, rotating g, target g)
    truth: dict[int, tuple[float, ...]] = field(default_factory=dict)   # seq → (θ, θ̇, v_rot, v_tgt, v_spill)
    torque: dict[int, tuple[float, int, int, int]] = field(default_factory=dict)  # seq → (N·m, action, mode, faults)
    torque_ts: dict[int, int] = field(default_factory=dict)  # seq → logger time of its first answer [µs]
    frames: list = field(default_factory=list)               # decoded particles_t
    # The plant over time, sorted by seq (finish() fills them): from POUR_TRUTH, else from the sensors.
    source: str = ""
    series_seq: list[int] = field(default_factory=list)
    t: list[float] = field(default_factory=list)             # simulated time of each sample [s]
    theta: list[float] = field(default_factory=list)
    omega: list[float] = field(default_factory=list)
    v: list[tuple[float, float, float]] = field(default_factory=list)

    def finish(self, encoder_bits: int) -> None:
        if self.truth:
            self.source = channels.TRUTH
            self.series_seq = sorted(self.truth)
            rows = [self.truth[k] for k in self.series_seq]
            self.theta = [r[0] for r in rows]
            self.omega = [r[1] for r in rows]
            self.v = [tuple(r[2:5]) for r in rows]
        else:
            self.source = f"{channels.SENSORS} (encoder {encoder_bits} bits, scales)"
            self.series_seq = sorted(self.raw)
            rows = [self.raw[k] for k in self.series_seq]
            self.theta = [sensors.encoder_angle(r[0], encoder_bits) for r in rows]
            m0 = rows[0][1] + rows[0][2] if rows else 0
            if m0 <= 0:
                raise LogError(f"episode {self.index}: the scales' first sample weighs {m0} g of liquid: "
                               "no volumes without POUR_TRUTH")
            self.v = [sensors.volumes(r[1], r[2], m0) for r in rows]
            th = np.asarray(self.theta)
            self.omega = list(np.gradient(th, np.asarray(self.series_seq) * 1e-3)) if len(th) > 1 else [0.0] * len(th)
        self.t = [k * 1e-3 for k in self.series_seq]


@dataclass
class Log:
    episodes: list[Episode]
    status: list = field(default_factory=list)
    undecodable: dict[str, int] = field(default_factory=dict)
    refused: dict[str, int] = field(default_factory=dict)  # decoded, but values no sensor or plant can have
    events: int = 0


def _plausible_sample(msg, encoder_bits: int) -> bool:
    return 0 <= msg.encoder < (1 << encoder_bits)


def _plausible_truth(msg) -> bool:
    return all(math.isfinite(x) for x in (msg.theta, msg.omega, msg.v_rotating, msg.v_target, msg.v_spill))


def read_log(path: Path, encoder_bits: int = sensors.ENCODER_BITS) -> Log:
    """Decodes our channels of an LCM log; undecodable messages are counted, never fatal. Sensor samples with
    an encoder count outside 0 .. 2^encoder_bits - 1 and truth with a non-finite value are counted as
    refused and left out of the plant's series (a sample still counts for the latency it was answered in)."""
    import lcm

    m = messages.load()
    try:
        ev_log = lcm.EventLog(str(path), "r")
    except (OSError, ValueError) as e:
        raise LogError(f"cannot open LCM log {path}: {e}") from e
    eps: dict[int, Episode] = {}
    out = Log(episodes=[])
    decoders = {channels.SENSORS: m.sensor_sample_t, channels.TRUTH: m.plant_truth_t, channels.TORQUE: m.torque_t,
                channels.STATUS: m.controller_status_t, channels.PARTICLES: m.particles_t,
                channels.COMMAND: m.command_t}

    def refuse(channel: str) -> None:
        out.refused[channel] = out.refused.get(channel, 0) + 1

    try:
        for ev in ev_log:
            out.events += 1
            dec = decoders.get(ev.channel)
            if dec is None:
                continue
            try:
                msg = dec.decode(ev.data)
            except Exception:  # wrong fingerprint (ValueError) or truncated (struct.error)
                out.undecodable[ev.channel] = out.undecodable.get(ev.channel, 0) + 1
                continue
            if ev.channel == channels.SENSORS:
                ep = eps.setdefault(msg.episode, Episode(msg.episode))
                if msg.seq in ep.sample_ts:
                    continue  # a resend
                ep.sample_ts[msg.seq] = ev.timestamp
                ep.seq.append(msg.seq)
                if _plausible_sample(msg, encoder_bits):
                    ep.raw[msg.seq] = (msg.encoder, msg.scale_rotating_g, msg.scale_target_g)
                else:
                    refuse(ev.channel)
            elif ev.channel == channels.TRUTH:
                ep = eps.setdefault(msg.episode, Episode(msg.episode))
                if msg.seq in ep.truth:
                    continue
                if _plausible_truth(msg):
                    ep.truth[msg.seq] = (msg.theta, msg.omega, msg.v_rotating, msg.v_target, msg.v_spill)
                else:
                    refuse(ev.channel)
            elif ev.channel == channels.TORQUE:
                ep = eps.setdefault(msg.episode, Episode(msg.episode))
                if msg.seq not in ep.torque_ts:
                    ep.torque_ts[msg.seq] = ev.timestamp
                    ep.torque[msg.seq] = (msg.torque, msg.action, msg.mode, msg.faults)
            elif ev.channel == channels.PARTICLES:
                if eps:
                    eps[max(eps)].frames.append(msg)
            elif ev.channel == channels.STATUS:
                out.status.append(msg)
    except (OSError, ValueError) as e:
        raise LogError(f"{path} is not a readable LCM log ({e})") from e
    out.episodes = [eps[k] for k in sorted(eps) if eps[k].seq and (eps[k].raw or eps[k].truth)]
    if not out.episodes:
        raise LogError(f"{path} holds no usable {channels.SENSORS} messages: nothing to analyse")
    for ep in out.episodes:
        ep.finish(encoder_bits)
    return out


def reward_params(k_target: float | None, k_spill: float | None, gamma: float | None):
    """libpoursim's default reward (host_sim's) where not given; None if neither given nor available."""
    if None not in (k_target, k_spill, gamma):
        return k_target, k_spill, gamma
    try:
        from pour.sim import poursim

        d = poursim.default_reward()
    except Exception:
        return None
    return (d.k_target if k_target is None else k_target, d.k_spill if k_spill is None else k_spill,
            d.gamma if gamma is None else gamma)


def episode_summary(ep: Episode, reward) -> dict:
    """Same definitions as host_sim: values of the last sample; finish = first time V_target + V_spill
    reaches 99 % of its final value (None if under 1 % moved); return = Σ γ^t r(s_{t+1})."""
    seq = np.asarray(ep.series_seq)
    v = np.asarray(ep.v)
    moved = v[:, 1] + v[:, 2]
    final = moved[-1]
    finish = None
    if final >= 0.01:
        k = int(np.argmax(moved >= 0.99 * final))
        finish = float(seq[k]) * 1e-3
    samples = np.sort(np.asarray(ep.seq))
    out = {"episode": ep.index, "source": ep.source, "samples": int(len(samples)), "first_seq": int(samples[0]),
           "last_seq": int(samples[-1]), "gaps": int(samples[-1] - samples[0] + 1 - len(samples)),
           "poured_pct": 100 * float(v[-1, 1]), "spilled_pct": 100 * float(v[-1, 2]),
           "left_pct": 100 * float(v[-1, 0]), "finish_s": finish, "max_theta_deg": float(np.degrees(np.max(ep.theta)))}
    if reward is not None:
        kt, ks, g = reward
        r = kt * v[1:, 1] - ks * v[1:, 2]
        out["return"] = float(np.sum(r * g ** np.arange(len(r))))
    return out


def latencies_us(log: Log) -> np.ndarray:
    """Logger time of each answer minus that of the sample it answers [µs]."""
    lat = [ep.torque_ts[s] - ep.sample_ts[s] for ep in log.episodes for s in ep.torque_ts if s in ep.sample_ts]
    return np.asarray(lat, dtype=float)


def plot_pour(log: Log, out: Path) -> None:
    """θ, torque and volumes over time, one colour per episode (volumes: first episode)."""
    fig, (a_th, a_tq, a_v) = plt.subplots(3, 1, figsize=(8, 7), dpi=100, sharex=True)
    for ep in log.episodes:
        a_th.plot(ep.t, np.degrees(ep.theta), lw=1, label=f"episode {ep.index}")
        ts = sorted(ep.torque)
        a_tq.step(np.asarray(ts) * 1e-3, [ep.torque[s][0] for s in ts], where="post", lw=0.8)
    ep = log.episodes[0]
    t, v = np.asarray(ep.t), np.asarray(ep.v)
    a_v.plot(t, v[:, 0], label="in bucket", color="0.4")
    a_v.plot(t, v[:, 1], label="in target", color="tab:green")
    a_v.plot(t, v[:, 2], label="spilled", color="tab:red")
    a_th.set_ylabel("θ [deg]")
    a_tq.set_ylabel("torque [N·m]")
    a_v.set_ylabel("fraction of liquid")
    a_v.set_ylim(-0.02, 1.02)
    a_v.set_xlabel("t [s]")
    for a in (a_th, a_tq, a_v):
        a.grid(alpha=0.3)
    a_th.legend(fontsize=8)
    a_v.legend(fontsize=8, loc="center right")
    fig.suptitle(f"Pour from an LCM log (plant from {log.episodes[0].source})")
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)


def plot_latency(lat: np.ndarray, out: Path) -> None:
    fig, ax = plt.subplots(figsize=(7, 3.6), dpi=100)
    if len(lat):
        hi = max(np.percentile(lat, 99.9), 1.0)
        ax.hist(np.clip(lat, 0, hi), bins=100, color="tab:blue")
        med, p99 = np.median(lat), np.percentile(lat, 99)
        ax.axvline(med, color="k", lw=1, label=f"median {med:.0f} µs")
        ax.axvline(p99, color="tab:red", lw=1, label=f"p99 {p99:.0f} µs")
        ax.legend()
    ax.set_xlabel(f"round trip {channels.SENSORS} → {channels.TORQUE} at the logger [µs]")
    ax.set_ylabel("answers")
    ax.set_yscale("log")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)


def render_json(log: Log, summary: dict) -> dict:
    """The first episode in host_sim's --render trajectory format (tools/pour/eval/render.py)."""
    ep = log.episodes[0]
    if not ep.frames:
        raise LogError(f"the log has no {channels.PARTICLES} messages to render")
    f0 = ep.frames[0]
    v = np.asarray(ep.v)
    pick = slice(None, None, 10)
    tq = [ep.torque.get(s, (0.0,))[0] for s in ep.series_seq]
    # host_sim renders 12.5 frames/s; keep about that many of the logged snapshots.
    frames, next_t = [], 0.0
    for fr in ep.frames:
        if fr.n == f0.n and fr.seq * 1e-3 >= next_t - 1e-9:
            frames.append({"t": fr.seq * 1e-3, "theta": fr.theta, "xy": np.column_stack([fr.x, fr.y]).ravel().tolist()})
            next_t = fr.seq * 1e-3 + 0.08
    dt = np.diff([fr["t"] for fr in frames])
    return {"title": f"LCM log, episode {ep.index}", "poured": summary["poured_pct"] / 100,
            "spilled": summary["spilled_pct"] / 100,
            "finish_s": -1 if summary["finish_s"] is None else summary["finish_s"],
            "fps": float(1.0 / np.median(dt)) if len(dt) else 12.5,
            "scene": {"inner_width": f0.bucket_inner_width, "height": f0.bucket_height, "wall": f0.bucket_wall,
                      "pivot_x": f0.pivot_x, "pivot_y": f0.pivot_y, "target_x": f0.target_x,
                      "theta_max": f0.theta_max},
            "radius": list(f0.r),
            "series": {"t": np.asarray(ep.t)[pick].tolist(), "theta": np.asarray(ep.theta)[pick].tolist(),
                       "v_rotating": v[pick, 0].tolist(), "v_target": v[pick, 1].tolist(),
                       "v_spill": v[pick, 2].tolist(), "torque": tq[::10]},
            "frames": frames}


def fmt_episode(s: dict) -> str:
    fin = "  -   " if s["finish_s"] is None else f"{s['finish_s']:.3f} s"
    ret = f"  return {s['return']:.1f}" if "return" in s else ""
    return (f"episode {s['episode'] + 1}: poured {s['poured_pct']:5.1f} %  spilled {s['spilled_pct']:4.1f} %  "
            f"left {s['left_pct']:4.1f} %  finish {fin}{ret}")


def analyse(path: Path, out_dir: Path | None, reward=None, encoder_bits: int = sensors.ENCODER_BITS) -> dict:
    log = read_log(path, encoder_bits)
    eps = [episode_summary(ep, reward) for ep in log.episodes]
    lat = latencies_us(log)
    answered = sum(len(set(ep.torque_ts) & set(ep.sample_ts)) for ep in log.episodes)
    samples = sum(len(ep.seq) for ep in log.episodes)
    summary = {
        "log": str(path), "events": log.events, "episodes": eps,
        "latency_us": {"n": int(len(lat)),
                       "median": float(np.median(lat)) if len(lat) else None,
                       "p99": float(np.percentile(lat, 99)) if len(lat) else None,
                       "max": float(np.max(lat)) if len(lat) else None},
        "samples": samples, "unanswered": samples - answered, "undecodable": log.undecodable, "refused": log.refused,
        "particle_frames": sum(len(ep.frames) for ep in log.episodes),
    }
    if log.status:
        st = log.status[-1]
        summary["controller"] = {"mode": st.mode, "faults": st.faults, "overruns": st.overruns,
                                 "messages_dropped": st.messages_dropped, "stale_ticks": st.stale_ticks,
                                 "step_time_max_ns": max(s.step_time_max_ns for s in log.status),
                                 "weights_hash": f"0x{st.weights_hash & 0xffffffff:08x}"}
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        plot_pour(log, out_dir / "traces.png")
        plot_latency(lat, out_dir / "latency.png")
        (out_dir / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    summary["_log"] = log
    return summary


def _fault_text(faults: int) -> str:
    """The core's fault word by name (pour_fault_name), with its hex; the hex alone without libpoursim."""
    if not faults:
        return "none"
    try:
        from pour import functions
        return f"{', '.join(functions.fault_names(faults))} (0x{faults:04x})"
    except functions.SimError:
        return f"0x{faults:04x} (names: libpoursim not found)"


def main(argv: Sequence[str] | None = None) -> int:
    ap = cli.ArgumentParser(prog="pour-lcmlog", description=__doc__.split("\n\n")[0])
    ap.add_argument("log", type=Path, help="LCM log file (lcm-logger)")
    ap.add_argument("-o", "--out", type=Path, help="folder for traces.png, latency.png, summary.json")
    ap.add_argument("--render", type=Path, help="also animate the first episode: FILE.gif (+ FILE.png)")
    ap.add_argument("--json", action="store_true", help="print the summary as JSON")
    ap.add_argument("--k-target", type=float)
    ap.add_argument("--k-spill", type=float)
    ap.add_argument("--gamma", type=float)
    ap.add_argument("--encoder-bits", type=int, default=sensors.ENCODER_BITS,
                    help="resolution of the rig's encoder, for a log without POUR_TRUTH (default %(default)s)")
    a = ap.parse_args(argv)
    if not 8 <= a.encoder_bits <= 24:
        print(f"pour-lcmlog: error: --encoder-bits must be 8 .. 24 (the CAN Sensors frame's count field), "
              f"got {a.encoder_bits}", file=sys.stderr)
        return 2
    if not a.log.is_file():
        print(f"pour-lcmlog: error: no such log file: {a.log}", file=sys.stderr)
        return 2
    if a.render is not None and a.render.suffix.lower() not in (".gif", ".mp4"):
        print(f"pour-lcmlog: error: --render wants a .gif or .mp4 file name, got {a.render}", file=sys.stderr)
        return 2
    try:
        s = analyse(a.log, a.out, reward_params(a.k_target, a.k_spill, a.gamma), a.encoder_bits)
        log = s.pop("_log")
        if a.render is not None:
            from pour.eval import render

            traj = a.render.with_suffix(".json")
            atomic.write_atomic(traj, json.dumps(render_json(log, s["episodes"][0])))
            render.render(traj, a.render)
    except LogError as e:
        print(f"pour-lcmlog: error: {e}", file=sys.stderr)
        return 1
    for e in s["episodes"]:
        if e["gaps"]:
            print(f"pour-lcmlog: warning: episode {e['episode'] + 1}: {e['gaps']} of the samples "
                  f"{e['first_seq']}..{e['last_seq']} are not in the log (lost by the logger or the link)",
                  file=sys.stderr)
    if a.json:
        print(json.dumps(s))
        return 0
    for e in s["episodes"]:
        print(fmt_episode(e))
    eps = s["episodes"]
    fins = [e["finish_s"] for e in eps if e["finish_s"] is not None]
    ret = f"  return {np.mean([e['return'] for e in eps]):.1f}" if "return" in eps[0] else ""
    print(f"summary ({len(eps)} episode{'s' if len(eps) > 1 else ''}): poured {np.mean([e['poured_pct'] for e in eps]):.1f} %"
          f"  spilled {np.mean([e['spilled_pct'] for e in eps]):.1f} %"
          f"  finish {f'{np.mean(fins):.3f} s' if fins else '-'}{ret}")
    L = s["latency_us"]
    if L["n"]:
        print(f"latency {channels.SENSORS} -> {channels.TORQUE}: median {L['median']:.0f} us  p99 {L['p99']:.0f} us"
              f"  max {L['max']:.0f} us over {L['n']} answers")
    print(f"samples {s['samples']}  unanswered {s['unanswered']}  undecodable {sum(s['undecodable'].values())}"
          f"  refused {sum(s['refused'].values())}  particle frames {s['particle_frames']}")
    print(f"plant from {eps[0]['source']}")
    if "controller" in s:
        c = s["controller"]
        print(f"controller: mode {c['mode']}  faults {_fault_text(c['faults'])}  overruns {c['overruns']}"
              f"  dropped {c['messages_dropped']}  step max {c['step_time_max_ns']} ns  weights {c['weights_hash']}")
    if a.out:
        print(f"plots: {a.out / 'traces.png'}, {a.out / 'latency.png'}; summary: {a.out / 'summary.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
