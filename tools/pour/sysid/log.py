# SPDX-License-Identifier: MIT
"""A candump -L log of the identify experiment, as the controller's node and the rig's sensors put it on
the bus (pour-bench identify records it; host_sim --experiment writes the same), turned into one row per
control tick. Everything that makes it unfit for a fit is a LogError that says what is wrong."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import can
import numpy as np

from pour.bench import node as bn

PHASES = bn.EXPERIMENT_PHASES
PHASE_DONE = 8
PHASE_OUT_OF_RANGE = 9
MODE_RUN = 1
MODE_FAULT = 2  # pour_mode_t, the DBC's Mode "FAULT"


class LogError(ValueError):
    """A log that cannot be fitted, and why."""


class LogUnreadable(LogError):
    """The log's file cannot be opened or read (missing, a folder, no permission)."""


@dataclass
class Run:
    """One tick per row, from the first tick of the experiment (RUN) to the last logged."""
    node_id: int
    kind: int               # ExperimentStart.Kind (1 identify, 2 tilt)
    tau_max: float          # [N m] of Torque 100 %, from Identity
    t: np.ndarray           # [s] the Sensors frames' time stamps
    encoder: np.ndarray     # raw counts
    scale_rotating: np.ndarray  # [g]
    scale_target: np.ndarray    # [g]
    torque: np.ndarray      # the command answering each sample [N m]
    action: np.ndarray      # Torque.Action: the phase
    mode: np.ndarray        # Torque.Mode

    def theta(self, encoder_bits: int) -> np.ndarray:
        """θ [rad] of the counts, as the firmware's estimator reads them (above half a turn: below upright)."""
        n = 1 << encoder_bits
        if int(self.encoder.max()) >= n:
            raise LogError(f"encoder counts reach {int(self.encoder.max())}: not a {encoder_bits}-bit encoder "
                           "(the rig file's encoder_bits)")
        c = self.encoder.astype(np.int64)
        c = np.where(c > n // 2, c - n, c)
        return c * (2.0 * np.pi / n)


def read(path: Path, node_id: int) -> Run:
    """The run of node_id in the log at path; LogError for a log that is not one, truncated, of another
    node, with gaps, or of a start the controller refused."""
    try:
        msgs = list(can.CanutilsLogReader(str(path)))
    except OSError as e:
        raise LogUnreadable(f"{path}: cannot read ({e.strerror})") from None
    except (ValueError, IndexError) as e:
        raise LogError(f"{path}: not a candump -L log ({e}); truncated mid-line?") from e
    if not msgs:
        raise LogError(f"{path}: no frames")
    db = bn.load_dbc()
    decoder = bn.Decoder(db)
    start_cmd = db.get_message_by_name("ExperimentStart").frame_id  # as ParamAck.Request names it
    seen: set[int] = set()
    kind, tau_max, answer = None, None, None
    samples: list[tuple[float, dict]] = []
    rows: list[tuple[float, dict, dict]] = []
    for m in msgs:
        d = decoder.decode(m)
        if d is None:
            continue
        nid, name, s = d
        seen.add(nid)
        if nid != node_id:
            continue
        if name == "ExperimentStart":
            # What came before the (last) start is another run; its answer may follow the first tick.
            kind, answer, samples, rows = int(s["Kind"]), None, [], []
        elif name == "ParamAck" and s["Request"] == start_cmd:
            answer = int(s["Result"])
        elif name == "Identity":
            tau_max = s["TauMax"] * 0.01
        elif name == "Sensors":
            samples.append((m.timestamp, s))
        elif name == "Torque" and samples:
            rows.append((samples[-1][0], samples[-1][1], s))
    if node_id not in seen:
        others = ", ".join(str(n) for n in sorted(seen)) or "none"
        raise LogError(f"{path}: no frames of node {node_id} (nodes in the log: {others}); --node names the "
                       "controller")
    if kind is None:
        raise LogError(f"{path}: no ExperimentStart for node {node_id}: not a log of pour-bench identify")
    if answer is None:
        raise LogError(f"{path}: node {node_id}'s answer to the ExperimentStart (a ParamAck) is not in the log")
    if answer != 0:
        result = db.get_message_by_name("ParamAck").get_signal_by_name("Result").choices.get(answer, answer)
        raise LogError(f"{path}: the controller refused the experiment ({result}): nothing ran")
    if not rows:
        raise LogError(f"{path}: truncated: no Sensors and Torque frames of node {node_id} after its start")
    if tau_max is None:
        raise LogError(f"{path}: no Identity frame of node {node_id}: the torque's scale (TauMax) is unknown")
    mode = np.array([r[2]["Mode"] for r in rows])
    running = np.flatnonzero(mode == MODE_RUN)
    if running.size == 0:
        if PHASE_OUT_OF_RANGE in {r[2]["Action"] for r in rows}:
            raise LogError(f"{path}: the experiment left its angle range at its first tick: the bucket was outside "
                           "it when it started (start it upright, at rest)")
        raise LogError(f"{path}: node {node_id} never ran the experiment (no Torque frame in RUN)")
    rows = rows[running[0]:]
    seq = np.array([r[1]["Seq"] for r in rows])
    t = np.array([r[0] for r in rows])
    # A sample lost or answered twice breaks the tick grid the fit stands on: one Sensors frame, one Torque
    # frame, seq + 1 every tick.
    step = (np.diff(seq) % 256)
    bad = np.flatnonzero(step != 1)
    if bad.size:
        k = int(bad[0])
        raise LogError(f"{path}: gaps: {bad.size} break(s) in the samples' sequence, the first at t = "
                       f"{t[k + 1] - t[0]:.3f} s (seq {seq[k]} -> {seq[k + 1]}): samples or answers were lost")
    action = np.array([r[2]["Action"] for r in rows])
    mode = mode[running[0]:]
    end = int(action[-1])
    if mode[-1] == MODE_FAULT:
        k = int(np.flatnonzero(mode == MODE_FAULT)[0])
        raise LogError(f"{path}: a fault ended the experiment at t = {t[k] - t[0]:.3f} s in phase "
                       f"'{PHASES.get(int(action[k - 1]), int(action[k - 1]))}' (pour-bench faults names it; a "
                       "bucket that does not move under torque latches Encoder): nothing fitted")
    if mode[-1] == MODE_RUN or end not in (PHASE_DONE, PHASE_OUT_OF_RANGE):
        raise LogError(f"{path}: truncated: it ends at t = {t[-1] - t[0]:.3f} s in phase "
                       f"'{PHASES.get(end, end)}', before the experiment ended")
    if end == PHASE_OUT_OF_RANGE:
        raise LogError(f"{path}: the experiment left its angle range and was ended (bucket held) at t = "
                       f"{t[np.flatnonzero(mode != MODE_RUN)[0]] - t[0]:.3f} s: lower the step and chirp "
                       "amplitudes or widen the range")
    return Run(node_id=node_id, kind=kind, tau_max=float(tau_max), t=t,
               encoder=np.array([r[1]["Encoder"] for r in rows], dtype=np.int64),
               scale_rotating=np.array([r[1]["ScaleRotating"] for r in rows], dtype=float),
               scale_target=np.array([r[1]["ScaleTarget"] for r in rows], dtype=float),
               torque=np.array([r[2]["Torque"] for r in rows], dtype=float) / 32768.0 * tau_max,
               action=action, mode=mode)
