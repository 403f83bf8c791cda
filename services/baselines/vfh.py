"""Vector Field Histogram (VFH), the method the paper builds on (pure, no I/O).

J. Borenstein and Y. Koren, "The Vector Field Histogram — Fast Obstacle Avoidance for
Mobile Robots", IEEE Transactions on Robotics and Automation 7(3), 278–288, 1991.

Three stages, as in the paper:

1. **Histogram grid** (world frame, ``grid_cell`` = 10 cm cells) built by histogramic
   in-motion mapping (HIMM): each laser return adds ``increment`` (3) to the certainty
   of its cell, each cell a beam crosses before its return (within the active window's
   reach) loses ``decrement`` (1); certainties stay within [0, ``certainty_max``] (15).
   The grid remembers what left the 180° field of view, as the paper's grid remembers
   what the sonars saw.
2. **Polar histogram** over the active window (``window_cells`` × ``window_cells``
   = 33 × 33 cells round the robot): each active cell adds ``m = c² (a − b d)`` to the
   sector (``sector_deg`` = 5°, 72 sectors) its direction falls in, with
   ``a − b d_max = 0`` (``d_max`` the window's half diagonal), then the histogram is
   smoothed with the paper's triangular window of half-width ``smoothing`` (l = 5).
3. **Valley selection**: sectors below ``threshold`` are free; the valley nearest to the
   target direction is chosen. In a wide valley (more than ``s_max`` = 18 sectors) the
   robot steers ``s_max / 2`` sectors inside the border nearest the target (k_n and
   k_f = k_n ± s_max, θ = (k_n + k_f) / 2), or straight at the target when it lies in
   the valley that far from both borders; in a narrow valley it steers down the middle.

Speed, as in the paper: ``V' = V_max (1 − min(h_c, h_m) / h_m)`` with ``h_c`` the
smoothed density in the current direction of travel, then
``V = V' (1 − |Ω| / Ω_max) + V_min``; the turn rate ``Ω`` is proportional to the
steering error. ``V_max`` is the mission's cruise speed.

Moving obstacles are what the scan sees of them, as in the original: VFH has no notion
of motion. With no free valley at all the robot stops and turns toward the emptiest
sector. ``threshold`` and ``h_m`` are, as in the paper, empirical; the values here were
chosen for a 0.2 m robot among 0.3–0.8 m obstacles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from zenav.services.baselines.common import Cycle, FloatArray, returns
from zenav.services.baselines.params import VFHParams
from zenav.services.geometry import wrap_angle, wrap_positive

Params = VFHParams
"""The parameters (also read as ``vfh.Params`` by zenav/bench/compute.py)."""

IntArray = npt.NDArray[np.int64]


class HistogramGrid:
    """The certainty grid, updated by HIMM from each scan."""

    def __init__(self, p: Params) -> None:
        self.p = p
        self.size = max(p.window_cells, math.ceil(p.grid_extent / p.grid_cell))
        self.c = np.zeros((self.size, self.size), dtype=np.int16)
        self.origin: FloatArray | None = None

    def update(self, cycle: Cycle) -> None:
        p = self.p
        x, y, heading = cycle.pose
        if self.origin is None:
            self.origin = np.array([x, y]) - self.size * p.grid_cell / 2
        origin = self.origin
        reach = min(p.window_radius, cycle.range_max)
        angles = cycle.angles + heading
        cos, sin = np.cos(angles), np.sin(angles)
        # Only the grid round the robot changes: work on that patch.
        half = math.ceil(reach / p.grid_cell) + 1
        ci, cj = np.floor((np.array([x, y]) - origin) / p.grid_cell).astype(int)
        i0, i1 = max(ci - half, 0), min(ci + half + 1, self.size)
        j0, j1 = max(cj - half, 0), min(cj + half + 1, self.size)
        if i0 >= i1 or j0 >= j1:
            return
        patch = self.c[i0:i1, j0:j1]
        rows, cols = patch.shape

        def counts(px: FloatArray, py: FloatArray) -> IntArray:
            i = np.floor((px - origin[0]) / p.grid_cell).astype(np.int64) - i0
            j = np.floor((py - origin[1]) / p.grid_cell).astype(np.int64) - j0
            ok = (i >= 0) & (i < rows) & (j >= 0) & (j < cols)
            found: IntArray = np.bincount(i[ok] * cols + j[ok],
                                          minlength=rows * cols).reshape(rows, cols)
            return found

        # HIMM: each cell a beam crosses before its return (within the active window's
        # reach) loses ``decrement``, sampled once per cell length; each return's cell
        # gains ``increment``.
        change = np.zeros((rows, cols), dtype=np.int64)
        if p.decrement:
            free_reach = min(reach, p.d_max + p.grid_cell)
            samples = np.arange(p.grid_cell, free_reach, p.grid_cell)
            free_to = np.minimum(cycle.ranges, free_reach) - p.grid_cell
            beam, k = np.nonzero(samples[None, :] < free_to[:, None])
            s = samples[k]
            change -= p.decrement * counts(x + s * cos[beam], y + s * sin[beam])
        hit = returns(cycle, reach)
        if hit.any():
            r = cycle.ranges[hit]
            change += p.increment * counts(x + r * cos[hit], y + r * sin[hit])
        patch[...] = np.clip(patch + change, 0, p.certainty_max)

    def polar_histogram(self, x: float, y: float) -> FloatArray:
        """Primary polar histogram h_k of the active window round (x, y)."""
        p = self.p
        assert self.origin is not None
        half = p.window_cells // 2
        ci, cj = (np.floor((np.array([x, y]) - self.origin) / p.grid_cell)).astype(int)
        i0, i1 = max(ci - half, 0), min(ci + half + 1, self.size)
        j0, j1 = max(cj - half, 0), min(cj + half + 1, self.size)
        h = np.zeros(p.sectors)
        if i0 >= i1 or j0 >= j1:
            return h
        window = self.c[i0:i1, j0:j1]
        ii, jj = np.nonzero(window)
        if ii.size == 0:
            return h
        certainty = window[ii, jj].astype(np.float64)
        cx = self.origin[0] + (ii + i0 + 0.5) * p.grid_cell
        cy = self.origin[1] + (jj + j0 + 0.5) * p.grid_cell
        dx, dy = cx - x, cy - y
        d = np.hypot(dx, dy)
        m = certainty**2 * np.maximum(p.a - p.b * d, 0.0)
        beta = wrap_positive(np.arctan2(dy, dx))
        k = np.minimum((beta / math.radians(p.sector_deg)).astype(np.int64), p.sectors - 1)
        return np.bincount(k, weights=m, minlength=p.sectors).astype(np.float64)


def smooth(h: FloatArray, l: int) -> FloatArray:  # noqa: E741 (the paper's name)
    """The paper's smoothing: h'_k = (h_{k-l+1} + 2 h_{k-l+2} + ... + l h_k + ... +
    h_{k+l-1}) / (2l + 1), circular."""
    weights = np.concatenate((np.arange(1, l + 1), np.arange(l - 1, 0, -1))).astype(np.float64)
    out = np.zeros_like(h)
    for offset, w in zip(range(-(l - 1), l), weights, strict=True):
        out += w * np.roll(h, -offset)
    return out / (2 * l + 1)


@dataclass(frozen=True)
class Valley:
    """Free sectors ``start`` .. ``start + width - 1`` (mod n), as angles [lo, lo + width)."""

    start: int
    width: int


def valleys(free: npt.NDArray[np.bool_]) -> list[Valley]:
    """Runs of free sectors on the circle (one valley of every sector if all are free)."""
    n = free.size
    if free.all():
        return [Valley(0, n)]
    if not free.any():
        return []
    first_blocked = int(np.flatnonzero(~free)[0])
    rolled = np.roll(free, -first_blocked)
    edges = np.diff(np.concatenate(([0], rolled.astype(np.int8), [0])))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1)
    return [Valley(int((s + first_blocked) % n), int(e - s)) for s, e in zip(starts, ends,
                                                                             strict=True)]


def steer(valley_list: list[Valley], target: float, sector: float, s_max: int,
          previous: float | None = None, keep_margin: float = 0.0) -> float | None:
    """Steering direction (rad, world frame) toward ``target`` (rad) through the valley
    nearest to it; None when no sector is free.

    Each valley offers a direction per border (a wide valley may be entered by either
    border). The candidate nearest the ``previous`` direction is kept unless another is
    nearer the target by more than ``keep_margin`` rad.
    """
    margin = s_max * sector / 2
    found: list[tuple[float, float, float]] = []  # distance to the target, -width, direction
    for v in valley_list:
        lo = v.start * sector
        width = v.width * sector
        if width >= 2 * math.pi - 1e-9:
            return target
        to_lo = wrap_positive(lo - target)  # counter-clockwise from the target to the border
        to_hi = wrap_positive(target - (lo + width))  # clockwise to the other border
        if wrap_positive(target - lo) < width:  # the target is in the valley
            offset = wrap_positive(target - lo)
            if v.width > s_max:  # wide: straight on, but s_max/2 clear of the borders
                found.append((0.0, -width, lo + min(max(offset, margin), width - margin)))
            else:
                found.append((0.0, -width, lo + width / 2))
            continue
        if v.width <= s_max:  # narrow: down the middle
            found.append((min(to_lo, to_hi), -width, lo + width / 2))
            continue
        # wide: k_n is the border nearest the target, k_f = k_n +- s_max
        found.append((to_lo, -width, lo + margin))
        found.append((to_hi, -width, lo + width - margin))
    if not found:
        return None
    best = min(found, key=lambda f: f[:2])
    if previous is not None:
        held = min(found, key=lambda f: abs(wrap_angle(f[2] - previous)))
        if held[0] <= best[0] + keep_margin:
            return wrap_positive(held[2])
    return wrap_positive(best[2])


@dataclass(frozen=True)
class Decision:
    v: float
    omega: float
    direction: float | None  # chosen steering direction, rad (None: no free sector)
    density_ahead: float  # h'_c


class VFH:
    """One VFH planner: the grid it keeps and the command for each scan."""

    def __init__(self, params: Params) -> None:
        self.p = params
        self.grid = HistogramGrid(params)
        self.previous: float | None = None

    def step(self, cycle: Cycle) -> Decision:
        p = self.p
        x, y, heading = cycle.pose
        self.grid.update(cycle)
        h = smooth(self.grid.polar_histogram(x, y), p.smoothing)
        sector = math.radians(p.sector_deg)
        target = wrap_positive(math.atan2(cycle.goal[1] - y, cycle.goal[0] - x))
        direction = steer(valleys(h < p.threshold), target, sector, p.s_max, self.previous,
                          math.radians(p.keep_valley_deg))
        self.previous = direction
        ahead = float(h[int(wrap_positive(heading) / sector) % p.sectors])
        if direction is None:
            emptiest = (int(np.argmin(h)) + 0.5) * sector
            omega = math.copysign(p.max_omega, wrap_angle(emptiest - heading))
            return Decision(0.0, omega, None, ahead)
        turn = p.heading_gain * wrap_angle(direction - heading)
        omega = max(-p.max_omega, min(p.max_omega, turn))
        v_prime = p.cruise_speed * (1.0 - min(ahead, p.h_m) / p.h_m)
        v = v_prime * (1.0 - abs(omega) / p.max_omega) + p.v_min
        distance = math.hypot(cycle.goal[0] - x, cycle.goal[1] - y)
        return Decision(min(v, p.cruise_speed, distance), omega, direction, ahead)
