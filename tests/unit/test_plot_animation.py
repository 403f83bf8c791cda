"""The animation of ``zenav paper``: one frame a simulated second, the axes drawn once
and only what moves drawn again per frame; obstacles appear when they do and move."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import GifImagePlugin, Image

from zenav.plot import draw_animation
from zenav.sim.scenario import parse_scenario

MOVER = np.array([0x94, 0x67, 0xBD])  # tab:purple, the movers' colour


def mover_pixels(frame: np.ndarray) -> np.ndarray:
    """(row, column) of the pixels of the mover's colour."""
    near = np.abs(frame[:, :, :3].astype(int) - MOVER).sum(axis=2) < 40
    return np.argwhere(near)


def test_each_frame_shows_the_run_at_its_second(tmp_path: Path) -> None:
    scenario = parse_scenario({
        "name": "anim", "world": {"size": [10.0, 10.0], "cell": 0.5},
        "robot": {"start": [1.0, 1.0], "heading_deg": 0.0, "goal": [9.0, 1.0], "speed": 0.5,
                  "radius": 0.2},
        "obstacles": [{"shape": "disc", "center": [2.0, 6.0], "radius": 0.4,
                       "velocity": [1.0, 0.0], "appear": 2.0}],
        "duration": 10.0}, "anim.yaml")
    rows = [[0.1 * k, 1.0 + 0.05 * k, 1.0, 0.0, 0.5] for k in range(41)]
    record = {"time": 4.0, "outcome": "timeout", "trajectory": rows}
    path = tmp_path / "anim.gif"
    draw_animation(scenario, record, path, window_radius=2.0)

    gif = Image.open(path)
    assert isinstance(gif, GifImagePlugin.GifImageFile)
    assert gif.n_frames == 5  # t = 0, 1, 2, 3, 4 s
    # 8 frames a second: 125 ms, which GIF keeps in hundredths of a second
    assert gif.info["duration"] == 120 and gif.info["loop"] == 0
    frames = []
    for k in range(gif.n_frames):
        gif.seek(k)
        frames.append(np.asarray(gif.convert("RGB")))
    assert [len(mover_pixels(f)) > 0 for f in frames] == [False, False, True, True, True]
    columns = [float(mover_pixels(f)[:, 1].mean()) for f in frames[2:]]
    assert columns[0] < columns[1] < columns[2]  # it walks toward +x
    # The axes' tick labels (left of the plot) are the same in every frame, up to each
    # frame's own GIF palette; the title (its time) is not.
    def differ(a: np.ndarray, b: np.ndarray) -> int:
        return int(np.abs(a.astype(int) - b.astype(int)).max())

    assert all(differ(f[:, :40], frames[0][:, :40]) <= 48 for f in frames)
    above = int(0.11 * frames[0].shape[0])  # the title's band, above the axes (top 0.88)
    assert differ(frames[0][:above], frames[1][:above]) > 100
