"""The monitor's map view: the planner's occupancy map round the robot, with the global
path, the goal, the tracked obstacles and the robot, as rows of characters (no I/O, no
terminal; the screen colours them by :data:`STYLES`).

A character is ``scale`` m wide and ``2 * scale`` m tall (a terminal's character cell is
about twice as tall as wide), so the view keeps the world's proportions. The top row is
the largest y.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from zenav.schemas.messages import OccupancyMap

UNKNOWN = " "
FREE = "·"
OCCUPIED = "█"
PATH = "•"
GOAL = "★"
TRACK = {"dynamic": "D", "static": "S", "new": "N"}
ARROWS = "→↗↑↖←↙↓↘"
"""The robot, pointing its heading (to the nearest 45°)."""

STYLES = {FREE: "grey42", OCCUPIED: "bright_white", PATH: "bold green", GOAL: "bold green",
          "D": "bold magenta", "S": "bold yellow", "N": "bold cyan",
          "o": "bold bright_blue", **{arrow: "bold bright_blue" for arrow in ARROWS}}
"""The screen's colour of each character."""

LEGEND = (f"{OCCUPIED} occupied  {FREE} free  (blank) unknown  {PATH} global path  {GOAL} goal  "
          "D/S/N tracks  → robot")


@dataclass(frozen=True)
class Window:
    """What the view covers: ``columns`` x ``rows`` characters centred on ``centre``."""

    centre: tuple[float, float]
    scale: float = 0.25  # m per character column; rows are twice as tall
    columns: int = 41
    rows: int = 21

    @property
    def cell(self) -> tuple[float, float]:
        return self.scale, 2 * self.scale

    @property
    def corner(self) -> tuple[float, float]:
        """World position of the lower-left corner of the lowest-left character."""
        w, h = self.cell
        return self.centre[0] - w * self.columns / 2, self.centre[1] - h * self.rows / 2

    def index(self, x: float, y: float) -> tuple[int, int] | None:
        """(row, column) of the character holding (x, y), row 0 at the top; None outside."""
        w, h = self.cell
        x0, y0 = self.corner
        col = math.floor((x - x0) / w)
        up = math.floor((y - y0) / h)
        if not (0 <= col < self.columns and 0 <= up < self.rows):
            return None
        return self.rows - 1 - up, col


def occupancy_chars(occupancy: OccupancyMap, window: Window) -> npt.NDArray[np.str_]:
    """(rows, columns) of :data:`UNKNOWN`, :data:`FREE` or :data:`OCCUPIED`: a character is
    occupied when any map cell in it is, free when any is known and none occupied. Map
    cells are taken at their centres, and each character's centre is looked up too, so
    map cells larger than a character leave no holes."""
    rows, cols = window.rows, window.columns
    w, h = window.cell
    x0, y0 = window.corner
    grid = occupancy.grid()  # [ix, iy]
    res = occupancy.resolution
    ox, oy = occupancy.origin
    occupied = np.zeros(rows * cols, dtype=bool)
    known = np.zeros(rows * cols, dtype=bool)

    def mark(cell_values: npt.NDArray[np.int8], col: npt.NDArray[np.int64],
             up: npt.NDArray[np.int64]) -> None:
        inside = (col >= 0) & (col < cols) & (up >= 0) & (up < rows)
        flat = ((rows - 1 - up) * cols + col)[inside]
        values = cell_values[inside]
        occupied[flat[values > 50]] = True
        known[flat[values >= 0]] = True

    # Every map cell whose centre falls in the window.
    i_lo = max(0, math.floor((x0 - ox) / res))
    i_hi = min(occupancy.width, math.ceil((x0 + cols * w - ox) / res) + 1)
    j_lo = max(0, math.floor((y0 - oy) / res))
    j_hi = min(occupancy.height, math.ceil((y0 + rows * h - oy) / res) + 1)
    if i_lo < i_hi and j_lo < j_hi:
        ii, jj = np.meshgrid(np.arange(i_lo, i_hi), np.arange(j_lo, j_hi), indexing="ij")
        cx = ox + (ii + 0.5) * res
        cy = oy + (jj + 0.5) * res
        mark(grid[i_lo:i_hi, j_lo:j_hi].ravel(),
             np.floor((cx - x0) / w).astype(np.int64).ravel(),
             np.floor((cy - y0) / h).astype(np.int64).ravel())
    # The map cell under each character's centre.
    cc, uu = np.meshgrid(np.arange(cols), np.arange(rows), indexing="ij")
    ix = np.floor((x0 + (cc + 0.5) * w - ox) / res).astype(np.int64)
    iy = np.floor((y0 + (uu + 0.5) * h - oy) / res).astype(np.int64)
    on_grid = (ix >= 0) & (ix < occupancy.width) & (iy >= 0) & (iy < occupancy.height)
    if on_grid.any():
        mark(grid[ix[on_grid], iy[on_grid]], cc[on_grid], uu[on_grid])
    chars = np.full(rows * cols, UNKNOWN, dtype="<U1")
    chars[known] = FREE
    chars[occupied] = OCCUPIED
    return chars.reshape(rows, cols)


def _put(chars: npt.NDArray[np.str_], window: Window, x: float, y: float, char: str) -> bool:
    at = window.index(x, y)
    if at is None:
        return False
    chars[at] = char
    return True


def map_view(window: Window, occupancy: OccupancyMap | None = None,
             path: npt.NDArray[np.float64] | None = None,
             tracks: Sequence[tuple[float, float, str]] = (),
             heading: float | None = None) -> list[str]:
    """The view's rows, top first: the map (blank where there is none), the path over it
    (never over an occupied character: a path through one would hide the problem), the
    goal (the path's last vertex), the tracks (x, y, kind) and the robot at the centre,
    an arrow along ``heading`` (``o`` when it is unknown)."""
    if occupancy is not None:
        chars = occupancy_chars(occupancy, window)
    else:
        chars = np.full((window.rows, window.columns), UNKNOWN, dtype="<U1")
    if path is not None and len(path) >= 2:
        step = window.scale / 2
        for a, b in itertools.pairwise(path):
            n = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
            for t in np.linspace(0.0, 1.0, n + 1):
                x, y = a + t * (b - a)
                at = window.index(float(x), float(y))
                if at is not None and chars[at] != OCCUPIED:
                    chars[at] = PATH
        _put(chars, window, float(path[-1][0]), float(path[-1][1]), GOAL)
    for x, y, kind in tracks:
        _put(chars, window, x, y, TRACK.get(kind, "?"))
    robot = "o" if heading is None else ARROWS[round(heading / (math.pi / 4)) % 8]
    _put(chars, window, window.centre[0], window.centre[1], robot)
    return ["".join(row) for row in chars]
