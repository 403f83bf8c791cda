"""Whether a robot hit by a mover could have got out of its way at all, once it could know
of it (pure: a scenario and a run record in, a verdict out).

``zenav bench nav`` counts the collisions no scan could have warned of
(:func:`zenav.bench.nav.no_warning`). A mover that was in view can still leave no way out:
a robot whose top speed is 0.2 m/s cannot leave the way of a disc at 0.6 m/s seen 1 m off.
:func:`no_escape` asks, for a collision with a mover whose path does not depend on the
robot, whether any of a set of simple manoeuvres would have kept the robot out of contact
with that mover, driven from the moment a planner could first act on it, with the mover's
true path known. Such movers are the scenario's discs and boxes at constant velocity, and
its ORCA agents when all of them are blind to the robot (``sees_robot: false``,
CrowdNav's invisible humans): those walk the same paths whatever the robot does, so their
paths are made again without it (:func:`zenav.bench.bound.humans_paths`). Where any agent
sees the robot, no agent gets a verdict: one that sees it moves the others it meets.

- the moment: the first tick the mover's centre was in the laser's field of view and range
  (occlusion aside, as ``never_in_view``), plus two laser periods (a scan to see it, one
  more to know it moves);
- the manoeuvres: stand (brake at the planner's ``decel``), or turn toward a heading (every
  ``HEADING_STEP_DEG`` degrees round the circle) and drive it at the robot's top speed, as
  the planner's own roll-outs drive the robot (:func:`zenav.services.planner.safety.drive_out`:
  turn rate, heading gain, acceleration and braking limits);
- kept out of contact: the robot's disc never touches the mover's shape at any step of
  ``STEP`` s until a disc or box has gone ``PASSED`` m beyond the robot's place at that
  moment (at most ``HORIZON`` s), or has vanished; an agent, which may turn and come back,
  is followed to the end of the run (its ``duration``; at most ``HORIZON`` s).

Everything else is left out in the robot's favour: the walls and the other obstacles,
other manoeuvres' shapes, and the robot's own view of the mover (its estimate, not the
truth). So a "no escape" verdict is conservative: not even this robot, knowing the
future, in open space, could have kept clear. A run with an escape is not thereby a
planner's fault: the escape may run into a wall or another mover.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from zenav.bench.bound import agents_ignore_robot, humans_paths
from zenav.services.geometry import wrap_angle
from zenav.services.planner import safety
from zenav.services.planner.params import Params
from zenav.sim.scenario import ObstacleSpec, Scenario

HEADING_STEP_DEG = 5.0  # between the headings tried, degrees
STEP = 0.05  # s between the points checked
PASSED = 3.0  # m the mover must have gone beyond the robot's place
HORIZON = 30.0  # s: the longest a manoeuvre is followed
SCANS_TO_ACT = 2  # laser periods from the first sight to the first answer

Vec = npt.NDArray[np.float64]
Gap = Callable[[Vec, Vec, Vec], Vec]
"""(xs, ys, times) -> the signed distance (m, < 0 inside) from each point ``(xs[i, j],
ys[i, j])`` to a mover's shape at ``times[j]`` s."""


def first_in_view(scenario: Scenario, record: dict[str, Any], index: int) -> int | None:
    """The first row of the record's trajectory at which obstacle ``index`` exists and its
    centre is within the laser's field of view and range, occlusion aside; None if it
    never is. ORCA agents are placed by the record's own rows (its ``agents`` field)."""
    half = math.radians(scenario.laser.fov_deg) / 2
    reach = scenario.laser.max_range
    ob = scenario.obstacles[index]
    rows = record.get("agents", {}).get(str(index))
    for k, (t, x, y, heading, _) in enumerate(record.get("trajectory") or []):
        if rows is not None:
            cx, cy = rows[k][1], rows[k][2]
        elif ob.exists_at(t):
            cx, cy = ob.center_at(t)
        else:
            continue
        bearing = wrap_angle(math.atan2(cy - y, cx - x) - heading)
        if abs(bearing) <= half and math.hypot(cx - x, cy - y) <= reach:
            return k
    return None


def surface_distance(ob: ObstacleSpec, xs: Vec, ys: Vec, times: Vec) -> Vec:
    """Signed distance (m, < 0 inside) from each point ``(xs[i, j], ys[i, j])`` to the
    obstacle's shape at ``times[j]`` s, as :meth:`ObstacleSpec.signed_distance` gives it
    point by point."""
    dt = times - ob.appear
    dx = xs - (ob.center[0] + ob.velocity[0] * dt)
    dy = ys - (ob.center[1] + ob.velocity[1] * dt)
    if ob.shape == "disc":
        assert ob.radius is not None
        return np.asarray(np.hypot(dx, dy) - ob.radius)
    assert ob.size is not None
    qx = np.abs(dx) - ob.size[0] / 2.0
    qy = np.abs(dy) - ob.size[1] / 2.0
    outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0))
    return np.asarray(outside + np.minimum(np.maximum(qx, qy), 0.0))


def escape_horizon(ob: ObstacleSpec, robot: tuple[float, float], t0: float) -> float:
    """s from ``t0`` until the mover is ``PASSED`` m beyond ``robot`` along its way (at
    most ``HORIZON``, and never past its vanishing; a standing obstacle never passes)."""
    speed = math.hypot(*ob.velocity)
    horizon = HORIZON
    if speed > 0.0:
        cx, cy = ob.center_at(t0)
        along = ((robot[0] - cx) * ob.velocity[0] + (robot[1] - cy) * ob.velocity[1]) / speed
        horizon = min(max(along + PASSED, 0.0) / speed, HORIZON)
    return max(min(horizon, ob.vanish_time - t0), STEP)


def robot_model(scenario: Scenario, pose: tuple[float, float, float], speed: float
                ) -> safety.Robot:
    """The robot as the planner's roll-outs drive it: the planner's default turn rate,
    heading gain and acceleration limits, the scenario's radius and top speed."""
    p = Params()
    return safety.Robot(x=pose[0], y=pose[1], heading=pose[2], speed=speed,
                        radius=scenario.robot.radius,
                        max_speed=scenario.robot.effective_max_speed, max_omega=p.max_omega,
                        heading_gain=p.heading_gain, accel=p.accel, decel=p.decel)


def agent_gap(scenario: Scenario, index: int) -> Gap:
    """The distance function of obstacle ``index``, an ORCA agent blind to the robot: its
    path made again without the robot at ``STEP`` s ticks to the end of the run (a time
    is taken at its nearest tick), infinite while it is absent. ValueError where any
    agent sees the robot (the paths then depend on the robot's)."""
    ob = scenario.obstacles[index]
    assert ob.radius is not None
    paths = humans_paths(scenario, scenario.duration, STEP)
    column = [i for i, o in enumerate(scenario.obstacles) if o.is_agent].index(index)
    path = paths[:, column]
    radius = ob.radius

    def gap(xs: Vec, ys: Vec, times: Vec) -> Vec:
        ticks = np.clip(np.rint(times / STEP).astype(np.int64), 0, len(path) - 1)
        centres = path[ticks]
        distance = np.hypot(xs - centres[:, 0], ys - centres[:, 1]) - radius
        return np.asarray(np.where(np.isnan(distance), np.inf, distance))

    return gap


def can_escape(scenario: Scenario, index: int, pose: tuple[float, float, float],
               speed: float, t0: float) -> bool:
    """Whether standing, or one of the headings every ``HEADING_STEP_DEG`` at the top
    speed, driven from ``pose`` (moving at ``speed``) at ``t0`` s, keeps the robot's disc
    off obstacle ``index`` (a disc or box at constant velocity until it has passed, or an
    agent blind to the robot until the run's end)."""
    ob = scenario.obstacles[index]
    gap: Gap
    if ob.is_agent:
        gap = agent_gap(scenario, index)
        horizon = max(min(HORIZON, scenario.duration - t0), STEP)
    else:
        def gap(xs: Vec, ys: Vec, times: Vec) -> Vec:
            return surface_distance(ob, xs, ys, times)
        horizon = escape_horizon(ob, pose[:2], t0)
    robot = robot_model(scenario, pose, speed)
    times = STEP * np.arange(1, max(round(horizon / STEP), 1) + 1, dtype=np.float64)
    fan = np.radians(np.arange(0.0, 360.0, HEADING_STEP_DEG))
    headings = np.concatenate(([pose[2]], fan))
    speeds = np.concatenate(([0.0], np.full(fan.shape[0], robot.max_speed)))
    xs, ys, _ = safety.drive_out(robot, headings, speeds, times)
    gaps = gap(xs, ys, t0 + times) - robot.radius
    return bool((gaps.min(axis=1) > 0.0).any())


def no_escape(scenario: Scenario, record: dict[str, Any]) -> bool:
    """Whether the run ended in contact with a mover whose path does not depend on the
    robot (a disc or box at constant velocity, or an agent when every agent is blind to
    the robot) that, from the first moment a planner could act on it (``SCANS_TO_ACT``
    laser periods after it first came into view), no manoeuvre of ``can_escape`` would
    have kept clear of. False for every other run, and for a mover never in view
    (``never_in_view`` counts those)."""
    index = record.get("collided_with")
    trajectory = record.get("trajectory") or []
    if record.get("outcome") != "collision" or index is None or not trajectory:
        return False
    ob = scenario.obstacles[index]
    if ob.is_static or (ob.is_agent and not agents_ignore_robot(scenario)):
        return False  # an agent that sees the robot moves the others it meets
    seen = first_in_view(scenario, record, index)
    if seen is None:
        return False
    t_act = trajectory[seen][0] + SCANS_TO_ACT / scenario.laser.rate_hz
    row = next((r for r in trajectory if r[0] >= t_act - 1e-9), None)
    if row is None:
        return True  # the run ended before a planner could answer
    t, x, y, heading, speed = row
    return not can_escape(scenario, index, (x, y, heading), speed, t)
