"""run.png: the planner's map (seen free, occupied, unknown) read back from the picture's
pixels, its last global path, and the paths it planned before, read from the axes."""

from __future__ import annotations

import os
import signal
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib.image
import numpy as np
import pytest
from matplotlib.colors import to_rgb

import zenav.plot
from zenav.plot import (
    EARLIER_PATH_COLOUR,
    LABEL_LINES,
    MAP_FREE_COLOUR,
    MAP_OCCUPIED_COLOUR,
    label_groups,
    plot_run,
)
from zenav.run import sigint_held
from zenav.schemas.messages import GlobalPath, OccupancyMap
from zenav.sim.scenario import load_scenario

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "sim" / "scenarios" / "nav-wall-gap.yaml"  # 10 x 8 m, a wall at x = 5


def record(path: list[list[float]] | None) -> dict[str, Any]:
    rows = [[t, 2.0 + 0.05 * t, 3.0, 0.0, 0.05] for t in np.arange(0.0, 10.0, 0.1)]
    data: dict[str, Any] = {"scenario": "nav-wall-gap", "planner": "paper", "outcome": "timeout",
                            "time": 9.9, "path_length": 0.5, "min_clearance": 1.0,
                            "trajectory": rows, "events": []}
    if path is not None:
        data["path"] = path
    return data


def occupancy() -> OccupancyMap:
    """Free for x < 4 m, a block held occupied at x 3.0-3.5, y 6-7 (no obstacle there),
    unknown beyond x = 4 m."""
    grid = np.full((100, 80), -1, dtype=np.int8)  # [ix, iy], 0.1 m cells
    grid[:40, :] = 0
    grid[30:35, 60:70] = 100
    return OccupancyMap(stamp=9.9, seq=9, origin=(0.0, 0.0), resolution=0.1, width=100,
                        height=80, cells=np.ascontiguousarray(grid.T).ravel())


class Picture:
    """plot_run's PNG, read back, with the axes it was drawn on."""

    def __init__(self, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, run: dict[str, Any],
                 grid: OccupancyMap | None, paths: Sequence[GlobalPath] = ()) -> None:
        kept: list[tuple[Any, Any]] = []
        finish = zenav.plot._finish

        def keep(fig: Any, ax: Any, path: Path, legend: str) -> None:
            finish(fig, ax, path, legend)
            kept.append((fig, ax))

        monkeypatch.setattr(zenav.plot, "_finish", keep)
        out = tmp_path / "run.png"
        plot_run(load_scenario(SCENARIO), run, out, occupancy=grid, paths=paths)
        (self.fig, self.ax), = kept
        self.pixels = matplotlib.image.imread(out)[:, :, :3]
        self.labels = self.ax.get_legend_handles_labels()[1]

    def at(self, x: float, y: float) -> tuple[float, ...]:
        """The RGB of the picture at world point (x, y)."""
        scale = 110 / self.fig.dpi  # saved at 110 dpi
        px, py = self.ax.transData.transform((x, y)) * scale
        row = self.pixels.shape[0] - round(float(py))
        return tuple(float(v) for v in self.pixels[row, round(float(px))])

    def around(self, x: float, y: float) -> list[tuple[float, ...]]:
        """The RGB of the 3 x 3 pixels round world point (x, y): a thin line's centre may
        fall between two pixels, where each shows it only in part."""
        scale = 110 / self.fig.dpi
        px, py = self.ax.transData.transform((x, y)) * scale
        row, col = self.pixels.shape[0] - round(float(py)), round(float(px))
        return [tuple(float(v) for v in self.pixels[row + i, col + j])
                for i in (-1, 0, 1) for j in (-1, 0, 1)]


def near(colour: tuple[float, ...], expected: str, tol: float = 0.03) -> bool:
    return bool(np.allclose(colour, to_rgb(expected), atol=tol))


def test_run_png_shows_the_map_free_occupied_and_unknown(tmp_path, monkeypatch):
    picture = Picture(tmp_path, monkeypatch, record([[2.0, 3.0], [4.2, 5.0], [8.0, 3.0]]),
                      occupancy())
    assert near(picture.at(1.2, 6.2), MAP_FREE_COLOUR)
    assert near(picture.at(3.2, 6.7), MAP_OCCUPIED_COLOUR)
    assert near(picture.at(8.2, 6.7), "white")  # unknown: blank
    assert {"map: seen free", "map: occupied", "global path (last)"} <= set(
        picture.labels)
    # The last global path, dashed green, at its middle vertex.
    assert any(near(c, "tab:green", tol=0.2) for c in picture.around(4.2, 5.0))


def test_run_png_without_a_map_or_path_shows_the_straight_line(tmp_path, monkeypatch):
    picture = Picture(tmp_path, monkeypatch, record(None), None)
    assert near(picture.at(1.2, 6.2), "white") and near(picture.at(3.2, 6.7), "white")
    assert "global path" in picture.labels
    assert not any(label.startswith("map:") for label in picture.labels)


def global_path(stamp: float, reason: str, points: list[list[float]]) -> GlobalPath:
    return GlobalPath(stamp=stamp, seq=0, points=np.array(points), reason=reason)


def test_run_png_shows_the_paths_given_up_numbered_with_their_reasons(tmp_path, monkeypatch):
    last = [[3.7, 4.7], [8.0, 3.0]]
    paths = [global_path(0.0, "start", [[2.0, 3.0], [8.0, 3.0]]),
             global_path(4.0, "off the path", [[2.5, 3.5], [4.0, 4.3], [8.0, 3.0]]),
             global_path(9.0, "recovery", np.zeros((0, 2)).tolist()),  # no way: not drawn
             global_path(25.0, "recovery", last)]
    picture = Picture(tmp_path, monkeypatch, record(last), None, paths)
    lines = {line.get_label(): line for line in picture.ax.get_lines()}
    first = lines["path 1 (t=0.0 s, start)"]
    assert first.get_xdata().tolist() == [2.0, 8.0] and first.get_linestyle() == ":"
    assert lines["path 2 (t=4.0 s, off the path)"].get_ydata().tolist() == [3.5, 4.3, 3.0]
    assert lines["global path (last: t=25.0 s, recovery)"].get_xdata().tolist() == [3.7, 8.0]
    assert not any(label.startswith("path 3") for label in lines)
    numbers = [(t.get_text(), t.xy) for t in picture.ax.texts
               if t.get_color() == EARLIER_PATH_COLOUR]
    assert numbers == [("1", (2.0, 3.0)), ("2", (2.5, 3.5))]  # at each one's first vertex


def test_run_png_names_the_first_paths_and_counts_the_rest(tmp_path, monkeypatch):
    earlier = [global_path(float(k), "off the path", [[2.0, 3.0 + k / 10], [8.0, 3.0]])
               for k in range(9)]
    last = global_path(10.0, "off the path", [[2.0, 2.0], [8.0, 3.0]])
    picture = Picture(tmp_path, monkeypatch, record(last.points.tolist()), None,
                      [*earlier, last])
    labels = picture.labels
    assert [lb for lb in labels if lb.startswith("path")] == [
        *(f"path {k} (t={k - 1}.0 s, off the path)" for k in range(1, 7)), "paths 7-9"]


def test_ctrl_c_while_the_picture_is_drawn_lets_it_finish_then_stops(tmp_path: Path) -> None:
    # zenav run draws run.png under sigint_held: an interrupt raised inside matplotlib's
    # renderer came out as "ValueError: Invalid bounding box" and status 1. Held, the
    # picture is drawn whole and the KeyboardInterrupt (status 130) comes after it.
    # Python's own handler, as a run from a terminal has it: a test run started in the
    # background of a non-interactive shell inherits SIGINT ignored instead.
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        out = tmp_path / "run.png"
        with pytest.raises(KeyboardInterrupt), sigint_held():
            os.kill(os.getpid(), signal.SIGINT)
            plot_run(load_scenario(SCENARIO), record(None), out)
        assert out.stat().st_size > 0
        assert matplotlib.image.imread(out).shape[2] in (3, 4)  # a whole PNG
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, inherited)


def test_event_labels_at_one_place_share_one_label_in_time_order() -> None:
    points = [(2.0, 3.0, "a:keep"), (2.2, 3.0, "b:morphin"), (5.0, 2.0, "a:resume"),
              (2.1, 3.1, "h:slow")]
    assert label_groups(points, near=0.4) == [(2.0, 3.0, "a:keep\nb:morphin\nh:slow"),
                                              (5.0, 2.0, "a:resume")]


def test_a_crowded_label_counts_what_it_leaves_out() -> None:
    points = [(0.0, 0.0, f"e:stop{k}") for k in range(LABEL_LINES + 3)]
    [(_, _, text)] = label_groups(points, near=0.1)
    assert text.splitlines() == [*(f"e:stop{k}" for k in range(LABEL_LINES - 1)), "+4 more"]
