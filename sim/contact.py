"""Contact and clearance between the robot disc and the obstacles, on exact geometry.

Touching counts as contact: a gap of exactly 0 is a collision. Positions in m,
radii in m, times in s.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from zenav.sim.raycast import box_entry_time, circle_entry_time
from zenav.sim.world import World, WorldSnapshot

__all__ = ["clearance", "clearances", "first_contact"]

FloatArray = NDArray[np.float64]


def clearances(
    point: ArrayLike, radius: float, snapshot: WorldSnapshot
) -> tuple[FloatArray, NDArray[np.int64]]:
    """Gap (m) from a robot disc at ``point`` (m) of ``radius`` (m) to each obstacle.

    Returns (gaps, obstacle ids), discs first then boxes; a gap is negative when
    the disc overlaps that obstacle.
    """
    p = np.asarray(point, dtype=np.float64).reshape(2)
    disc_gaps = np.hypot(*(p - snapshot.disc_centers).T) - snapshot.disc_radii - radius
    # Signed distance to each box: outside part plus (negative) inside part.
    centers = 0.5 * (snapshot.box_mins + snapshot.box_maxs)
    half = 0.5 * (snapshot.box_maxs - snapshot.box_mins)
    q = np.abs(p - centers) - half
    outside = np.hypot(*np.maximum(q, 0.0).T)
    inside = np.minimum(q.max(axis=1, initial=-np.inf), 0.0)
    box_gaps = outside + inside - radius
    gaps = np.concatenate([disc_gaps, box_gaps]).astype(np.float64)
    ids = np.concatenate([snapshot.disc_ids, snapshot.box_ids]).astype(np.int64)
    return gaps, ids


def clearance(point: ArrayLike, radius: float, snapshot: WorldSnapshot) -> float:
    """Smallest gap (m) from the robot disc surface to any obstacle surface.

    ``point`` (2,) is the robot centre, m; ``radius`` its radius, m. Negative when
    overlapping, ``inf`` when no obstacle exists.
    """
    gaps, _ = clearances(point, radius, snapshot)
    return float(gaps.min()) if len(gaps) else float("inf")


def first_contact(
    p0: ArrayLike,
    p1: ArrayLike,
    radius: float,
    world: World,
    t0: float,
    t1: float,
) -> tuple[float, int] | None:
    """Earliest contact while the robot centre moves linearly from ``p0`` to ``p1`` (m).

    The robot (a disc of ``radius`` m) is at ``p0`` at ``t0`` and at ``p1`` at ``t1``
    (s); obstacles move with their own constant velocities and only count while
    they exist (``appear <= t < vanish``). Works in the robot-relative frame, where
    the motion is linear, so fast movers crossing the robot between t0 and t1 are
    caught. Returns (contact time s, scenario obstacle index), the lowest index on
    ties, or None. A robot already touching an obstacle at the start of the part of
    the interval where it exists gives that start time.
    """
    if t1 < t0:
        raise ValueError(f"t1 must be >= t0 (got t0={t0}, t1={t1})")
    a = np.asarray(p0, dtype=np.float64).reshape(2)
    b = np.asarray(p1, dtype=np.float64).reshape(2)
    u = (b - a) / (t1 - t0) if t1 > t0 else np.zeros(2)  # robot velocity, m/s

    # Each kind of obstacle in turn; only those the broad phase finds within reach get
    # their exact entry times (the others never touch: most ticks none is near, and
    # the entry times of none would cost as much as those of a few).
    times: list[FloatArray] = []
    ids: list[NDArray[np.int64]] = []

    # Discs: the robot centre against a circle of radius r_obstacle + radius.
    if len(world.disc_ids):
        start, span, q, v = _relative_motion(
            a, u, (t0, t1), centers=world.disc_centers, velocities=world.disc_velocities,
            appear=world.disc_appear, vanish=world.disc_vanish)
        reach = world.disc_radii + radius
        near = _within_reach(q, v, span, reach)
        if near.any():
            s = np.full(len(q), np.inf)
            s[near] = circle_entry_time((q[near, 0], q[near, 1]), (v[near, 0], v[near, 1]),
                                        reach[near])
            times.append(_contact_times(start, span, s, world.disc_vanish))
            ids.append(world.disc_ids)

    # Boxes: the robot centre against the box inflated by the radius (rounded rectangle).
    if len(world.box_ids):
        start, span, q, v = _relative_motion(
            a, u, (t0, t1), centers=world.box_centers, velocities=world.box_velocities,
            appear=world.box_appear, vanish=world.box_vanish)
        half = world.box_half_sizes
        near = _within_reach(q, v, span, np.hypot(half[:, 0], half[:, 1]) + radius)
        if near.any():
            s = np.full(len(q), np.inf)
            s[near] = _rounded_box_entry_time(q[near], v[near], half[near], radius)
            times.append(_contact_times(start, span, s, world.box_vanish))
            ids.append(world.box_ids)

    if not times:
        return None
    all_times = np.concatenate(times)
    all_ids = np.concatenate(ids)
    if not np.isfinite(all_times).any():
        return None
    earliest = all_times.min()
    index = int(all_ids[all_times == earliest].min())
    return min(float(earliest), t1), index


def _relative_motion(
    robot_p0: FloatArray,
    robot_v: FloatArray,
    interval: tuple[float, float],
    *,
    centers: FloatArray,
    velocities: FloatArray,
    appear: FloatArray,
    vanish: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Per obstacle: start of its overlap with [t0, t1] (s), its length (s; -inf when
    it does not exist then), the robot centre relative to the obstacle centre at
    that start (m) and the relative velocity (m/s)."""
    t0, t1 = interval
    start = np.maximum(t0, appear)
    end = np.minimum(t1, vanish)
    exists = (start <= end) & (start < vanish)
    span = np.where(exists, end - start, -np.inf)
    robot = robot_p0 + robot_v * (start - t0)[:, None]
    obstacle = centers + velocities * (start - appear)[:, None]
    return start, span, robot - obstacle, robot_v - velocities


def _within_reach(q: FloatArray, v: FloatArray, span: FloatArray, reach: FloatArray
                  ) -> NDArray[np.bool_]:
    """Which obstacles may come within ``reach`` (m, of their centre) of the robot in
    their part of the interval: the relative position ``q`` moves at most ``|v| span``.
    A broad phase: the others cannot touch, so their exact entry times need not be
    found (they would fall beyond ``span``)."""
    with np.errstate(invalid="ignore"):  # span -inf: the obstacle does not exist then
        closest = np.hypot(q[:, 0], q[:, 1]) - np.hypot(v[:, 0], v[:, 1]) * span
    return np.asarray((span >= 0.0) & (closest <= reach + 1e-9))


def _contact_times(
    start: FloatArray, span: FloatArray, s: FloatArray, vanish: FloatArray
) -> FloatArray:
    """Absolute contact times (s), inf where the entry ``s`` falls outside the part of
    the interval in which the obstacle exists (it is already gone at ``vanish``)."""
    t = start + s
    return np.where((s <= span) & (t < vanish), t, np.inf)


def _rounded_box_entry_time(
    q: FloatArray, v: FloatArray, half: FloatArray, radius: float
) -> FloatArray:
    """First s >= 0 at which ``q + s * v`` is within ``radius`` of a box centred at 0.

    The inflated box is the union of two expanded rectangles and four corner circles.
    """
    qx, qy = q[:, 0], q[:, 1]
    vel = (v[:, 0], v[:, 1])
    hx, hy = half[:, 0], half[:, 1]
    wide = box_entry_time((qx, qy), vel, (-hx - radius, -hy), (hx + radius, hy))
    tall = box_entry_time((qx, qy), vel, (-hx, -hy - radius), (hx, hy + radius))
    s = np.minimum(wide, tall)
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            corner = circle_entry_time((qx - sx * hx, qy - sy * hy), vel, radius)
            s = np.minimum(s, corner)
    return s
