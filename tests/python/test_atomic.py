# SPDX-License-Identifier: MIT
"""pour.atomic: outputs written beside their target and renamed; a failure leaves the old file whole."""
import os
import stat

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402
from matplotlib.artist import Artist  # noqa: E402

from pour import atomic  # noqa: E402
from pour.eval import plots  # noqa: E402


def test_write_atomic_replaces_the_file_with_normal_permissions(tmp_path):
    out = tmp_path / "r.md"
    out.write_text("old")
    atomic.write_atomic(out, "new ✓")
    assert out.read_text(encoding="utf-8") == "new ✓"
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~mask
    assert [p.name for p in tmp_path.iterdir()] == ["r.md"]


@pytest.mark.parametrize("exc", [OSError(28, "No space left on device"), KeyboardInterrupt()])
def test_a_failure_while_writing_keeps_the_old_file_and_removes_the_temporary(tmp_path, exc):
    out = tmp_path / "results.json"
    out.write_text("good")
    with pytest.raises(type(exc)):
        with atomic.atomic_path(out) as tmp:
            assert tmp.parent == tmp_path and tmp.suffix == ".json" and tmp != out
            tmp.write_text("partial")
            raise exc
    assert out.read_text() == "good"
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]


@pytest.mark.parametrize("path, message", [("", "empty"), ("{tmp}", "is a directory"),
                                           ("{tmp}/no/x.png", "does not exist")])
def test_check_output_path_names_the_problem(tmp_path, path, message):
    with pytest.raises(ValueError, match=message):
        atomic.check_output_path(path.format(tmp=tmp_path))


class _Exploding(Artist):
    def draw(self, renderer):
        raise RuntimeError("drawing failed half-way")


def test_a_plot_that_fails_to_draw_leaves_the_previous_png(tmp_path):
    out = tmp_path / "reward_curve.png"
    out.write_bytes(b"previous png")
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    ax.add_artist(_Exploding())
    with pytest.raises(RuntimeError, match="half-way"):
        plots._save(fig, out)
    assert out.read_bytes() == b"previous png"
    assert [p.name for p in tmp_path.iterdir()] == ["reward_curve.png"]
    assert not plt.get_fignums()
