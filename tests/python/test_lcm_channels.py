# SPDX-License-Identifier: MIT
"""Channel names live in one C header and one Python module: they must agree. The generated types
round-trip and refuse foreign or truncated data."""
import re

import pytest

from pour import paths
from pour.lcm import channels, messages


def header_macros(source_dir) -> dict:
    text = (source_dir / "lcmtypes" / "include" / "pour_lcm" / "channels.h").read_text()
    out = {}
    for name, value in re.findall(r"#define\s+POUR_LCM_(\w+)\s+(\"[^\"]*\"|\d+)", text):
        out[name] = value.strip('"') if value.startswith('"') else int(value)
    return out


def test_channels_header_and_module_agree(source_dir):
    h = header_macros(source_dir)
    py = {"CHANNEL_SENSORS": channels.SENSORS, "CHANNEL_TRUTH": channels.TRUTH, "CHANNEL_TORQUE": channels.TORQUE,
          "CHANNEL_STATUS": channels.STATUS, "CHANNEL_PARTICLES": channels.PARTICLES,
          "CHANNEL_COMMAND": channels.COMMAND, "DEFAULT_URL": channels.DEFAULT_URL,
          "STATUS_PERIOD_MS": channels.STATUS_PERIOD_MS, "PARTICLES_PERIOD_MS": channels.PARTICLES_PERIOD_MS}
    assert h == py
    assert len(set(channels.ALL)) == len(channels.ALL) == 6


def test_every_message_starts_with_utime_and_comments_each_field(source_dir):
    for f in sorted((source_dir / "lcmtypes" / "pour").glob("*.lcm")):
        lines = [x.strip() for x in f.read_text().splitlines()]
        body = lines[lines.index("{") + 1: lines.index("}")]
        fields = [i for i, x in enumerate(body) if x and not x.startswith("//")]
        assert body[fields[0]] == "int64_t utime;", f.name
        for i in fields:
            # a comment above each field, or above the group of fields it shares
            j = i - 1
            while j >= 0 and body[j] and not body[j].startswith("//"):
                j -= 1
            assert j >= 0 and body[j].startswith("//"), f"{f.name}: {body[i]} has no comment"


def test_generated_types_round_trip(build_dir, monkeypatch):
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))
    m = messages.load()
    s = m.sensor_sample_t()
    s.utime, s.seq, s.encoder, s.scale_rotating_g, s.scale_target_g = 1000, 1, 131071, -5, 12345
    d = m.sensor_sample_t.decode(s.encode())
    assert (d.utime, d.seq, d.encoder, d.scale_rotating_g, d.scale_target_g) == (1000, 1, 131071, -5, 12345)
    g = m.plant_truth_t()
    g.utime, g.seq, g.theta, g.motor_torque, g.obs = 1000, 1, 0.5, -2.5, [0.1, 0.2, 0.3, 0.4, 0.5]
    d = m.plant_truth_t.decode(g.encode())
    assert (d.utime, d.seq, d.theta, d.motor_torque) == (1000, 1, 0.5, -2.5)
    t = m.torque_t()
    t.n_actions, t.probs_q15 = 2, [16384, 16384] + [0] * 14
    assert m.torque_t.decode(t.encode()).probs_q15[:2] == (16384, 16384)


def test_generated_types_refuse_foreign_and_truncated_data(build_dir, monkeypatch):
    monkeypatch.setenv("POUR_BUILD_DIR", str(build_dir))
    m = messages.load()
    data = m.sensor_sample_t().encode()
    with pytest.raises(ValueError):
        m.torque_t.decode(data)
    with pytest.raises(ValueError):
        m.plant_truth_t.decode(data)  # the truth is a type of its own: a sensor sample never passes for it
    with pytest.raises(Exception):
        m.sensor_sample_t.decode(data[:-3])


def test_missing_build_gives_a_clear_message(monkeypatch, tmp_path):
    monkeypatch.setenv("POUR_LCMTYPES_PYTHON", str(tmp_path))
    monkeypatch.setenv("POUR_BUILD_DIR", str(tmp_path))
    monkeypatch.setattr(paths, "SOURCE_DIR", tmp_path)
    with pytest.raises(SystemExit, match="generated LCM types not found"):
        messages.load()
