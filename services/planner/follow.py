"""Drive toward a point: the robot's motion between decisions; and how far it can drive
straight before it comes too near a return, and whether a goal has room for it (pure,
no I/O)."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from zenav.services.geometry import wrap_angle


def command_toward(
    x: float,
    y: float,
    heading: float,
    target: tuple[float, float],
    speed: float,
    heading_gain: float,
    max_omega: float,
    brake: float | None = None,
    within: float = 1.0,
) -> tuple[float, float]:
    """(v, omega) that heads for ``target`` at up to ``speed`` m/s.

    The turn rate is proportional to the heading error; the forward speed falls with
    the cosine of the error, so the robot turns on the spot when the target is behind it.
    Near the target the speed falls so as not to overshoot it: to the speed that covers
    the distance in ``within`` s (one second of travel by default), or, with ``brake``
    (m/s^2), to the speed from which braking at that rate stops the robot on the target,
    sqrt(2 brake distance).
    """
    dx, dy = target[0] - x, target[1] - y
    distance = math.hypot(dx, dy)
    if distance < 1e-9:
        return 0.0, 0.0
    error = wrap_angle(math.atan2(dy, dx) - heading)
    omega = max(-max_omega, min(max_omega, heading_gain * error))
    near = distance / within if brake is None else math.sqrt(2.0 * brake * distance)
    v = min(speed, near) * max(0.0, math.cos(error))
    return v, omega


def backing_toward(
    x: float,
    y: float,
    heading: float,
    target: tuple[float, float],
    speed: float,
    heading_gain: float,
    max_omega: float,
) -> tuple[float, float]:
    """(v, omega) that backs toward ``target`` at up to ``speed`` m/s: the rear turned
    toward it as ``command_toward`` turns the front, v negative."""
    v, omega = command_toward(x, y, heading + math.pi, target, speed, heading_gain, max_omega)
    return -v, omega


def arc_points(x: float, y: float, heading: float, v: float, omega: float,
               duration: float, step: float) -> npt.NDArray[np.float64]:
    """(k, 2) where the robot's centre is when it drives ``v`` m/s and turns ``omega``
    rad/s from (``x``, ``y``, ``heading``), every ``step`` s up to ``duration`` s (the
    first ``step`` s on): a circular arc, or a straight line with no turn."""
    t = step * np.arange(1, max(round(duration / step), 1) + 1, dtype=np.float64)
    if abs(omega) < 1e-9:
        return np.column_stack([x + v * t * math.cos(heading), y + v * t * math.sin(heading)])
    turned = heading + omega * t
    r = v / omega
    return np.column_stack([x + r * (np.sin(turned) - math.sin(heading)),
                            y - r * (np.cos(turned) - math.cos(heading))])


def reach_along(start: tuple[float, float], end: tuple[float, float],
                points: npt.NDArray[np.float64], clearance: float) -> float:
    """How far (m) a disc centre can go from ``start`` straight toward ``end``, at most
    to ``end``, keeping ``clearance`` from every point of ``points`` (n, 2): 0 when one
    is nearer than that already. A point ``along`` the way and ``aside`` off it is met
    at ``along - sqrt(clearance^2 - aside^2)``; points behind the start or farther
    aside are never met."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    length = math.hypot(dx, dy)
    if length < 1e-12:
        return 0.0
    ux, uy = dx / length, dy / length
    qx, qy = points[:, 0] - start[0], points[:, 1] - start[1]
    along = qx * ux + qy * uy
    aside = qx * uy - qy * ux
    half = np.sqrt(np.maximum(clearance * clearance - aside * aside, 0.0))
    met = (np.abs(aside) < clearance) & (along + half > 0.0)
    if not met.any():
        return length
    return float(min(max(float((along[met] - half[met]).min()), 0.0), length))


def room_near(goal: tuple[float, float], points: npt.NDArray[np.float64], clearance: float,
              reach: float, step: float = 0.01) -> bool:
    """Whether some point within ``reach`` of ``goal`` keeps ``clearance`` from every
    point of ``points`` (n, 2): the goal itself, or one on the rings round it at most
    ``step`` apart out to ``reach`` itself, each sampled every ``step`` along it (a room
    thinner than a step can be missed: no robot stops that precisely)."""
    gx, gy = goal
    near = points[np.hypot(points[:, 0] - gx, points[:, 1] - gy) < reach + clearance]
    if near.shape[0] == 0:
        return True
    ox, oy = _ring_offsets(reach, step)
    cx, cy = gx + ox, gy + oy
    gaps = np.hypot(cx[:, None] - near[None, :, 0], cy[:, None] - near[None, :, 1])
    return bool((gaps.min(axis=1) >= clearance).any())


def off_discs(points: npt.NDArray[np.float64], discs: Sequence[tuple[float, float, float]],
              slack: float) -> npt.NDArray[np.float64]:
    """The rows of ``points`` (n, 2) farther than ``slack`` from every disc (x, y, radius)
    of ``discs``: the rule by which the map's ray tracing leaves a mover's returns out
    (``_loops.trace_scan``)."""
    if not discs or points.shape[0] == 0:
        return points
    d = np.asarray(discs, dtype=np.float64)
    gaps = np.hypot(points[:, None, 0] - d[None, :, 0],
                    points[:, None, 1] - d[None, :, 1]) - d[None, :, 2]
    return points[(gaps >= slack).all(axis=1)]


@functools.lru_cache(maxsize=8)
def _ring_offsets(reach: float, step: float) -> tuple[npt.NDArray[np.float64],
                                                     npt.NDArray[np.float64]]:
    """``room_near``'s points round a goal at the origin, made once for a reach and step
    (read-only: they are shared)."""
    radii = np.linspace(0.0, reach, max(math.ceil(reach / step), 1) + 1)
    counts = np.maximum(np.ceil(2.0 * math.pi * radii / step), 1).astype(np.int64)
    ring = np.repeat(radii, counts)
    turn = np.concatenate([np.arange(k) / k for k in counts.tolist()]) * 2.0 * math.pi
    ox, oy = ring * np.cos(turn), ring * np.sin(turn)
    ox.flags.writeable = False
    oy.flags.writeable = False
    return ox, oy
