"""One planning cycle per scan: predict, pick the paper's response, steer (no I/O).

The responses follow Section 3.5 of the paper:

- (a), (c), (d): keep speed and heading;
- (e): speed up if the robot clears the crossing point well before the obstacle
  reaches it, else slow down so it arrives after the obstacle has left, else stop
  until the obstacle has passed;
- (g): slow down to keep a gap behind the slower obstacle, stop when too close;
- (b), (f): simplified Morphin (``morphin.py``): a straight detour to a sub-target;
- (h): all of them at once: the lowest speed any threat asks for, and a detour planned
  around every obstacle in view when any threat needs one.

Between decisions the robot heads for its target: a detour's sub-target, or else a
point ``lookahead`` metres along the global path beyond the robot's projection on it,
which brings it back to the path after a detour.

Beyond the paper, ``Planner.step`` runs these named stages (docs/navigation.md):
``update_map`` (costmap.py) -> ``update_path`` (global_path.py: the straight start-goal
line until the map says otherwise) -> ``recover`` (recovery.py) or ``local_layer`` (the
paper's assess, respond, detour, speed and safety) -> ``guard_stop_zone`` (the motor
bridge's zone) -> the command.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from zenav.schemas.messages import Action, ObstacleKind, ScenarioLetter
from zenav.services.geometry import disc_distance, wrap_angle
from zenav.services.motor_bridge.stop_zone import stop_distance
from zenav.services.planner import safety
from zenav.services.planner._loops import box_gaps, c_hypot
from zenav.services.planner.costmap import Costmap, ScanData
from zenav.services.planner.field import distance_field
from zenav.services.planner.follow import (
    arc_points,
    backing_toward,
    command_toward,
    off_discs,
    reach_along,
    room_near,
)
from zenav.services.planner.give_way import (
    Hold,
    corridor_axis,
    hemmed_in,
    offsets,
    passed,
    spot_aside,
)
from zenav.services.planner.global_path import (
    GlobalPlan,
    arc_lengths,
    first_blocked,
    goal_clear,
    plan_path,
    point_at,
    project,
    settle_point,
    straight_ahead,
)
from zenav.services.planner.morphin import Mover, cells_on_segment, choose_detour
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import (
    Assessment,
    Obstacle,
    assess_all,
    cell_squares,
    path_count,
    path_points,
)
from zenav.services.planner.recovery import STEPS, Recovery, RecoverySettings, Step

Vec = npt.NDArray[np.float64]

YIELDING: tuple[Step, ...] = ("spin", "back_up", "wait")
"""The recovery steps that end when a walker would walk into the robot (``walked_into``):
each keeps the robot about where it is."""
ON_THE_MAP = 0.15
"""m: a "walker" with a cell the map holds this near its centre is taken for part of a
wall by ``walked_into``."""

SPEED_GAP = 0.5
"""The longest time between two poses that the driven speed is measured over, s (five
scans at 10 Hz)."""

SETTLE_REACH = 0.75
"""How far from the goal, as a fraction of ``goal_tolerance``, the stop may move off a
wall with the comfortable clearance (``Planner.settle_goal``): the rest of the
tolerance is the arrival's own room."""
SETTLE_REACH_CLOSE = 0.9
"""The same with the close clearance, the last resort before driving at the goal."""

NO_ROOM = "no room at the goal for the robot and its stop zone"
"""Why the goal is unreachable when ``Planner.look_for_room`` finds none."""

LAST_STRETCH = "the last stretch, judged on the scan"
"""The reason of the straight path to a goal whose cell the map holds (``last_stretch``)."""

BACKING_LOOK = 0.5
"""s: how far ahead backing to a spot aside is checked against the map
(``Planner._backs_into_map``): a cycle and the stop from the top reverse speed."""

NO_ROOM_LOOK = 1.0
"""m beyond the goal's tolerance: no room at the goal starts the recovery steps, one
after another, once the robot is this near (it has looked from close by)."""


@dataclass(frozen=True)
class Decision:
    v: float
    omega: float
    target: tuple[float, float]
    scenario: ScenarioLetter
    action: Action
    obstacle: int | None
    kind: ObstacleKind | None
    speed: float  # the speed asked for before steering, m/s
    notes: tuple[Assessment, ...] = ()  # every obstacle that relates to the path
    refused: bool = False  # forward motion withheld: the stop zone holds a return


@dataclass
class Commitment:
    """How the planner answers one threatening obstacle, kept while it threatens."""

    letter: ScenarioLetter
    action: Action
    last: Assessment | None = None  # how the obstacle was last judged a threat


@dataclass
class Detour:
    subtarget: Vec
    obstacle: int
    letter: ScenarioLetter
    side: int  # +1: passes the obstacle on its left (robot turns left), -1: right
    kind: ObstacleKind = "new"  # the obstacle's type when the detour was chosen


def mover_discs(obstacles: Sequence[Obstacle]) -> list[tuple[float, float, float]]:
    """(x, y, radius) of the tracks typed dynamic: the discs whose returns the map and the
    look for room at the goal leave out."""
    return [(o.position[0], o.position[1], o.radius) for o in obstacles
            if o.kind == "dynamic"]


def should_be_seen(scan: ScanData, point: tuple[float, float], radius: float) -> bool:
    """Whether a disc of ``radius`` at ``point`` lies wholly within the scan's field of view
    and range, with no return nearer than its near face on the beam toward it: if it were
    there, the laser would see it."""
    x, y, heading = scan.pose
    distance = math.hypot(point[0] - x, point[1] - y)
    if distance <= radius or distance + radius >= scan.range_max:
        return False
    bearing = wrap_angle(math.atan2(point[1] - y, point[0] - x) - heading)
    half = math.asin(min(radius / distance, 1.0))
    count = int(scan.ranges.shape[0])
    angle_max = scan.angle_min + scan.angle_increment * (count - 1)
    if bearing - half < scan.angle_min or bearing + half > angle_max:
        return False
    beam = round((bearing - scan.angle_min) / scan.angle_increment)
    return bool(scan.ranges[min(max(beam, 0), count - 1)] >= distance - radius - 0.05)


def first_in_scan_order(threats: list[Assessment], robot: Vec, heading: float) -> Assessment:
    """The threat Algorithm 1 meets first: O_chain runs in scan order, the paper's 0 to
    180 degrees, right to left; the threat at the smallest bearing from the robot's right
    comes first."""
    def bearing(a: Assessment) -> float:
        dx, dy = a.obstacle.position[0] - robot[0], a.obstacle.position[1] - robot[1]
        return math.remainder(math.atan2(dy, dx) - heading + math.pi / 2, math.tau)
    return min(threats, key=lambda a: (bearing(a), a.obstacle.id))


class Planner:
    """The paper's navigation decisions, one call per scan."""

    def __init__(self, params: Params) -> None:
        self.p = params
        self.mission_goal = np.asarray(params.goal, dtype=np.float64)  # the run's goal
        # Where the robot stops: the goal, or beside it when it lies too close to what
        # the map holds (``settle_goal``).
        self.goal = self.mission_goal.copy()
        self.start: Vec | None = (
            None if params.start is None else np.asarray(params.start, dtype=np.float64)
        )
        self.global_cells: set[tuple[int, int]] = set()
        self.detour: Detour | None = None
        self.commitments: dict[int, Commitment] = {}  # obstacle id -> how it is answered
        self.first_seen: dict[int, float] = {}  # obstacle id -> stamp
        self.sides: dict[int, int] = {}  # obstacle id -> side it was last passed on
        self.asked = params.cruise_speed  # V_R of Algorithm 1, for slow_step
        self.costmap: Costmap | None = None
        self.plan: GlobalPlan | None = None
        self.path: Vec | None = None  # the global path's vertices, robot to goal
        self.lengths: Vec | None = None  # the path's arc length at each vertex, m
        self.plan_count = 0  # bumped at every new path
        self.last_replan = -math.inf
        self.last_compared = -math.inf  # when a detour was last weighed against the map
        self.replan_asked: str | None = None  # why the next cycle must re-plan
        self.recovery = Recovery(RecoverySettings(
            progress_distance=params.progress_distance,
            progress_timeout=params.effective_progress_timeout(),
            stop_zone_timeout=params.stop_zone_timeout, wait_allowance=params.wait_allowance,
            spin_angle=params.spin_angle(), backup_distance=params.backup_distance,
            backup_speed=params.backup_speed, wait_time=params.wait_time,
            max_rounds=params.recovery_rounds))
        self.walled = False  # the goal cut off by the wall memory (``walled_in``)
        self.no_room = False  # no room at the goal, when last looked at (``look_for_room``)
        self.on_last_stretch = False  # ``last_stretch``, this cycle
        self.room_seen = False  # room at a goal beside a wall, when last looked at
        self.walled_stamp = -math.inf
        self.trail: list[tuple[float, float]] = []  # where the robot has been, m
        self.last_v = 0.0  # the speed last commanded, m/s
        self.speed_now = 0.0  # the speed the robot drove at over the last scan, m/s
        self.last_pose: tuple[float, float, float, float] | None = None  # x, y, heading, stamp
        self.safety_heading: float | None = None  # the safety stage's last heading
        self.held_by_map = False  # this cycle, the safety stage stood for the map alone
        self.safety_settings = safety.Settings(
            horizon=params.safety_horizon, step=params.safety_step,
            margin=params.safety_margin, growth=params.safety_growth,
            comfort=params.safety_comfort, tau=params.safety_tau,
            fan_step=math.radians(params.safety_fan_deg), speeds=params.safety_speeds,
            turn_cost=params.safety_turn_cost, from_inside=params.safety_from_inside)
        self.top_speeds: dict[int, float] = {}  # track id -> top speed seen while dynamic
        self.top_stamp: float | None = None  # the stamp top_speeds were last updated at
        # Movers last seen, for ``mover_memory``: track id -> (last seen as, stamp).
        self.last_seen_movers: dict[int, tuple[Obstacle, float]] = {}
        self.unseen: list[tuple[Obstacle, float]] = []  # (predicted to now, age s)
        self.hold: Hold | None = None  # a spot aside held while a mover passes
        if self.start is not None:
            self._set_path(np.vstack([self.start, self.goal]), "start")

    # -- geometry ----------------------------------------------------------------------

    def _set_path(self, points: Vec, reason: str) -> None:
        self.path = np.asarray(points, dtype=np.float64)
        self.lengths = arc_lengths(self.path)  # kept: they change only with the path
        self.plan_count += 1
        cells: set[tuple[int, int]] = set()
        for a, b in zip(self.path[:-1], self.path[1:], strict=True):
            cells |= cells_on_segment(a, b, self.p.cell)
        self.global_cells = cells

    def path_target(self, robot: Vec, statics: list[Obstacle] | None = None) -> Vec:
        """Where to steer on the global path: ``lookahead`` m beyond the robot's
        projection on it; or, when ``statics`` are given and the robot is off the path,
        the farthest point of the path within the window that it can drive to in a
        straight line clear of them and of what the map holds (beyond the paper: it
        rejoins the path past the obstacles it went round instead of cutting back into
        them)."""
        assert self.path is not None and self.lengths is not None
        p = self.p
        lengths = self.lengths
        length = float(lengths[-1])
        if length < 1e-9:
            return self.goal
        s0, off_path = project(self.path, robot, lengths)
        default = self.goal if s0 + p.lookahead >= length else point_at(
            self.path, s0 + p.lookahead, lengths)
        if len(self.path) > 2 and not self._chord_clear(robot, default):
            # The path bends within the look-ahead and the chord would cut the corner
            # into what the map holds: steer for the bend itself first; one a map cell
            # past the robot at least (a robot at the bend, steering for the bend, stands).
            k = int(np.searchsorted(lengths, s0 + p.map_resolution, side="right"))
            if k < len(self.path):
                default = self.path[k]
        if not statics or off_path < p.cell / 2:
            return default
        rejoin = self._rejoin_point(robot, statics)
        if rejoin is None:
            return default
        s_rejoin = project(self.path, rejoin, lengths)[0]
        if s_rejoin < s0 + p.lookahead:
            return default
        if self._chord_clear(robot, rejoin):
            return rejoin
        # Clear of the boxes, not of what the map holds: the farthest point short of it
        # whose chord the map lets through, or the look-ahead point.
        s = s_rejoin - p.map_resolution
        while s > s0 + p.lookahead:
            point = point_at(self.path, s, lengths)
            if self._chord_clear(robot, point):
                return point
            s -= p.map_resolution
        return default

    def _to_goal(self, robot: Vec, lows: Vec, highs: Vec) -> Callable[[Vec], float]:
        """Delta L's distance to the goal: around the standing obstacles (``field.py``),
        or the paper's straight line when ``around_obstacles`` is off."""
        p = self.p
        if not p.around_obstacles or len(lows) == 0:
            return lambda end: c_hypot(*(self.goal - end))
        reach = p.window_radius + 2.0
        field = distance_field(
            self.goal, lows, highs, np.minimum(robot, self.goal) - reach,
            np.maximum(robot, self.goal) + reach, p.cell / 2,
            p.robot_radius + p.safety_margin,
        )
        return field.at

    def _way_on_cost(self, robot: Vec, end: Vec, to_goal: Callable[[Vec], float]) -> float:
        """Beyond the paper: a sub-target that does not bring the robot nearer the goal
        (measured like Delta L) costs ``dead_end_penalty`` more: a detour into a pocket
        or back the way the robot came is the last resort, not a tie."""
        here, there = to_goal(robot), to_goal(end)
        if math.isinf(there) or there > here - self.p.cell / 2:
            return self.p.dead_end_penalty
        return 0.0

    def _rejoin_point(self, point: Vec, statics: list[Obstacle]) -> Vec | None:
        """The farthest point of the global path within the window that ``point`` sees
        in a straight line clear of ``statics``; None if there is none."""
        assert self.path is not None and self.lengths is not None
        p = self.p
        length = float(self.lengths[-1])
        if length < 1e-9:
            return None
        s0 = project(self.path, point, self.lengths)[0]
        # The gaps from points along each leg to the statics' grid areas, measured as
        # ``gap_to_boxes`` does, in the compiled loop of the (b) test (``box_gaps``, no
        # clearance taken off): each leg is clear when no point of it is nearer any
        # area than ``need`` or than ``point`` itself is (``here``).
        cells = np.array([o.cells for o in statics], dtype=np.int64).reshape(-1, 4)
        zero = np.zeros(len(cells))
        first = np.empty(len(cells), dtype=np.int64)
        least = np.empty(len(cells), dtype=np.float64)
        px, py = point.tolist()
        box_gaps(px, py, 1.0, 0.0, 0.0, 2, cells, p.cell, zero, first, least)  # point alone
        here = min(least.tolist(), default=math.inf)
        need = p.robot_radius + p.safety_margin
        for s in np.arange(min(s0 + p.window_radius, length), s0 - p.cell, -p.cell / 2):
            on_path = point_at(self.path, max(float(s), 0.0), self.lengths)
            leg = on_path - point
            leg_length = c_hypot(*leg)
            if leg_length > p.window_radius:
                continue
            if leg_length < 1e-9:
                return on_path
            dx, dy = (leg / leg_length).tolist()
            box_gaps(px, py, dx, dy, leg_length, path_count(leg_length, p.cell / 4), cells,
                     p.cell, zero, first, least)
            if min(least.tolist(), default=math.inf) >= min(need, here):
                return on_path
        return None

    def _boxes(self, statics: list[Obstacle]) -> tuple[Vec, Vec]:
        corners = [cell_squares(o.cells, self.p.cell) for o in statics]
        lows = np.array([c[0] for c in corners], dtype=np.float64).reshape(-1, 2)
        highs = np.array([c[1] for c in corners], dtype=np.float64).reshape(-1, 2)
        return lows, highs

    def _statics(self, obstacles: list[Obstacle]) -> list[Obstacle]:
        return [o for o in obstacles if not self._moving(o)]

    def _assess_all(
        self, robot: Vec, target: Vec, obstacles: list[Obstacle], extra_margin: float,
        to_goal: bool,
    ) -> list[Assessment]:
        """Assess every obstacle against the robot heading for ``target``. Obstacles the
        planner already answers keep ``threat_hysteresis`` more margin, so that a threat
        does not flicker on and off with the estimates' noise."""
        offset = target - robot
        distance = c_hypot(*offset)
        if distance < 1e-9:
            return []
        direction = offset / distance
        length = self._way_length(robot, direction, distance, to_goal)
        p = self.p
        held = [self.commitments.get(ob.id) for ob in obstacles]
        return assess_all(
            robot, direction, p.cruise_speed, length, obstacles,
            margins=[p.safety_margin + extra_margin
                     + (p.threat_hysteresis if c is not None and ob.kind == "dynamic" else 0.0)
                     for ob, c in zip(obstacles, held, strict=True)],
            horizons=[p.horizon * (1.25 if c is not None else 1.0) for c in held],
            following=[c is not None and c.letter == "g" for c in held],
            robot_radius=p.robot_radius, cell=p.cell, moving_speed=p.moving_speed,
            head_on_cos=p.head_on_cos, same_way_cos=p.same_way_cos, meet_rule=p.meet_rule)

    def _way_length(self, robot: Vec, direction: Vec, distance: float, to_goal: bool) -> float:
        """How far along ``direction`` the way to a target ``distance`` m off is judged:
        to the target; toward the path's look-ahead point (``to_goal``), on as far as the
        path runs straight, within the window (the robot goes on past the point)."""
        if not to_goal:
            return distance
        ahead: float = min(self._straight_ahead(robot, direction), self.p.window_radius)
        return max(distance, ahead)

    def _straight_ahead(self, robot: Vec, direction: Vec) -> float:
        """How far the global path runs on from the robot in ``direction`` before it
        bends: the distance to the goal on the paper's straight path, to the next vertex
        on one that goes round what the map holds."""
        if self.path is None or self.lengths is None or len(self.path) <= 2:
            return c_hypot(*(self.goal - robot))
        return straight_ahead(self.path, robot, direction, self.lengths)

    def _chord_clear(self, robot: Vec, point: Vec) -> bool:
        """Whether the straight way to ``point`` is free on the map (True without one)."""
        if self.costmap is None:
            return True
        offset = point - robot
        distance = c_hypot(*offset)
        if distance <= self.p.map_resolution:
            return True
        if self._blocked_along(robot, offset / distance, self.p.map_resolution, distance):
            return False
        # The returns not yet confirmed as lethal count too: round a bend, the inner
        # corner is seen a moment before the chord to the look-ahead point cuts it.
        return not self.costmap.returns_near_segment(robot, point, self.costmap.inflation)

    def _blocked_along(self, robot: Vec, direction: Vec, first: float, length: float) -> bool:
        """Whether the map blocks any of the points every half map cell from ``first`` to
        ``length`` m along ``direction`` from ``robot`` (``Costmap.blocked_along``)."""
        assert self.costmap is not None
        rx, ry = robot.tolist()
        dx, dy = direction.tolist()
        return self.costmap.blocked_along(
            (rx + dx * first, ry + dy * first), (dx, dy), length - first,
            path_count(length - first, self.p.map_resolution / 2))

    def _threats(self, notes: list[Assessment], clear: bool, stamp: float, robot: Vec,
                 target: Vec, to_goal: bool, last_stretch: bool = False) -> list[Assessment]:
        """The assessments to answer: threats of a known type, confirmed, and not a (b)
        while the map finds the way to ``target`` clear (``clear``) on an obstacle the
        map holds, or on one too young for the map whose returns all keep off the way;
        no (b) at all on the ``last_stretch`` to a goal beside what the laser sees."""
        return [self._sticky(a) for a in notes
                if a.threat and a.obstacle.kind != "new" and not self._unconfirmed(a, stamp)
                and not (a.letter == "b" and last_stretch)
                and not (a.letter == "b" and clear
                         and (self._mapped(a, stamp)
                              or self._returns_off_the_way(a, robot, target, to_goal)))]

    def last_stretch(self, robot: Vec, heading: float, scan: ScanData | None) -> bool:
        """Beyond the paper (``final_approach_speed``): whether the robot is on the last
        stretch to a goal that lies beside what the laser sees (the goal is not clear by
        the robot's radius plus half ``safety_margin`` on the map, as for
        ``settle_goal``): the goal within the window and the laser's field of view, and
        the straight way to the goal (as settled) keeps ``_approach_clearance`` off every
        return of the scan as far as a point within the tolerance of the run's goal
        (``follow.reach_along``). The (b) test's 0.5 m cell box S_k of a wall close
        to the goal covers the goal, and the detours round the wall never reach it; the
        scan's returns lie where the wall is, to the centimetre."""
        if not self._beside_in_view(robot, heading, scan):
            return False
        assert scan is not None
        return self._straight_in(robot, scan)[1]

    def _beside_in_view(self, robot: Vec, heading: float, scan: ScanData | None) -> bool:
        """The final approach is on, the goal is within the window and the laser's field
        of view, and the map holds something within the robot's radius plus half
        ``safety_margin`` of it (``settle_goal``'s test)."""
        p = self.p
        if (p.final_approach_speed <= 0.0 or scan is None or self.costmap is None
                or not p.use_map):
            return False
        if goal_clear(self.costmap, self.mission_goal, p.robot_radius + p.safety_margin / 2):
            return False  # a goal in the open: the paper's tests decide
        return self._goal_in_view(robot, heading, scan)

    def _goal_in_view(self, robot: Vec, heading: float, scan: ScanData) -> bool:
        """Whether the goal lies within the window and the laser's field of view."""
        offset = self.mission_goal - robot
        if c_hypot(*offset) > self.p.window_radius:
            return False
        bearing = wrap_angle(math.atan2(offset[1], offset[0]) - heading)
        angle_max = scan.angle_min + scan.angle_increment * (scan.ranges.shape[0] - 1)
        return bool(scan.angle_min <= bearing <= angle_max)

    def _given_up_for_room(self) -> bool:
        """Whether the goal was given up for want of room at it (``NO_ROOM``)."""
        return self.plan is not None and self.plan.reason == NO_ROOM

    def room_again(self, robot: Vec, heading: float, scan: ScanData | None,
                   tracked: list[Obstacle]) -> bool:
        """Beyond the paper: a goal given up for want of room at it (``NO_ROOM``) is kept
        in view. Whatever stood there may leave: a slow mover kept as a standing obstacle
        while it was out of view (as the recovery's spin turned the laser away), or one
        too slow to be seen moving. While given up the map is kept up to date (``step``),
        and once the laser sees the goal (within the window and the field of view) with
        room at it (clear on the map, or room between the scan's returns:
        ``look_for_room``), navigation starts again with the recovery steps afresh, and
        True is returned. ``given_up`` turns the robot to face the goal meanwhile."""
        if scan is None or not self._goal_in_view(robot, heading, scan):
            return False
        self.look_for_room(robot, heading, scan, tracked)
        if self.no_room:
            return False
        self.recovery = Recovery(self.recovery.s)
        self.replan_asked = "room at the goal again"
        return True

    def _arrived_beside(self, robot: Vec, heading: float, scan: ScanData | None) -> bool:
        """On the last stretch (``last_stretch``) and within the run's tolerance of its
        goal (a hundredth of it to spare), with no nearer point to be had: the centre can
        go no farther along the straight way to the goal keeping ``_approach_clearance``
        off the scan's returns."""
        p = self.p
        if (c_hypot(*(self.mission_goal - robot)) >= 0.99 * p.goal_tolerance
                or not self._beside_in_view(robot, heading, scan)):
            return False
        assert scan is not None
        reach, within = self._straight_in(robot, scan)
        return within and reach < 1e-3

    def _approach_clearance(self) -> float:
        """How near the returns the last stretch takes the robot's centre: its radius
        plus the stop zone's reach at ``final_approach_speed``, as near as the bridge
        lets a robot at that speed come head-on."""
        p = self.p
        return p.robot_radius + stop_distance(p.final_approach_speed, p.zone_reaction,
                                              p.decel, p.zone_margin)

    def _straight_in(self, robot: Vec, scan: ScanData) -> tuple[float, bool]:
        """Driving straight for the goal (as settled), the robot's centre keeping
        ``_approach_clearance`` off the scan's returns: how far it gets (m), and whether
        it ends within the run's tolerance of its goal (a hundredth of it to spare)."""
        end = (float(self.goal[0]), float(self.goal[1]))
        start = (float(robot[0]), float(robot[1]))
        length = math.dist(start, end)
        reach = reach_along(start, end, scan.returns, self._approach_clearance())
        stop = robot if length < 1e-12 else robot + (self.goal - robot) * (reach / length)
        return reach, c_hypot(*(stop - self.mission_goal)) < 0.99 * self.p.goal_tolerance

    def _returns_off_the_way(self, a: Assessment, robot: Vec, target: Vec,
                             to_goal: bool) -> bool:
        """Beyond the paper: whether the map's returns inside a standing obstacle's cell
        box S_k (marked at once, though confirmed as lethal only after ``map_confirm``)
        all keep the inflation distance off the straight way the (b) test judged. The
        box of a wall's corner first seen round a bend (an L of returns) covers the free
        inside of the bend, and answering it with a detour turned the robot back at a
        corridor's turn. False for an obstacle smaller than ``wall_radius`` and when the
        box holds no return: the box decides, as in the paper."""
        if self.costmap is None or a.obstacle.radius < self.p.wall_radius:
            return False
        lo, hi = cell_squares(a.obstacle.cells, self.p.cell)
        offset = target - robot
        distance = c_hypot(*offset)
        if distance < 1e-9 or not self.costmap.has_returns_in(lo, hi):
            return False
        direction = offset / distance
        end = robot + direction * self._way_length(robot, direction, distance, to_goal)
        return not self.costmap.returns_near_segment(robot, end, self.costmap.inflation,
                                                     lo, hi)

    def _mapped(self, a: Assessment, stamp: float) -> bool:
        """Whether a standing obstacle has been seen long enough to be in the map, and
        the map holds it: an occupied cell within its radius of its centre, or within
        its cell box S_k, the box the (b) test found on the way. The box counts too
        because a track of a wall is a stretch of the face the laser sees, and its
        estimated centre can drift off that face (into a thick wall, or along it), where
        the map holds nothing; the face itself is in the map and in S_k."""
        seen = stamp - self.first_seen.get(a.obstacle.id, stamp)
        if self.costmap is None or seen < self.p.map_confirm + 0.5:
            return False
        ob = a.obstacle
        step = self.p.map_resolution
        reach = ob.radius + step
        offsets = np.arange(-reach, reach + 1e-9, step)
        dx, dy = np.meshgrid(offsets, offsets, indexing="ij")
        disc = dx * dx + dy * dy <= reach * reach
        ring = np.column_stack([ob.position[0] + dx[disc], ob.position[1] + dy[disc]])
        lo, hi = cell_squares(ob.cells, self.p.cell)
        # Edges included: a box may hold only a sliver of the face, along its edge.
        xs = np.linspace(lo[0], hi[0], math.ceil((hi[0] - lo[0]) / step) + 1)
        ys = np.linspace(lo[1], hi[1], math.ceil((hi[1] - lo[1]) / step) + 1)
        bx, by = np.meshgrid(xs, ys, indexing="ij")
        box = np.column_stack([bx.ravel(), by.ravel()])
        return bool(self.costmap.lethal_at(np.vstack([ring, box])).any())

    def _map_clear(self, robot: Vec, target: Vec, to_goal: bool) -> bool:
        """Beyond the paper: whether the straight way to ``target`` is free on the map's
        fine, inflated grid. The paper's (b) test reads an obstacle's cell box S_k (0.5 m
        cells), which can close a 1 m gap between two walls; an obstacle the map has
        confirmed is judged on the map instead. ``to_goal``: the way is checked as far
        as the (b) test looks, past the look-ahead point along the path."""
        if self.costmap is None or not self.p.use_map:
            return False
        offset = target - robot
        distance = c_hypot(*offset)
        if distance < 1e-9:
            return True
        direction = offset / distance
        length = self._way_length(robot, direction, distance, to_goal)
        if not self._blocked_along(robot, direction, min(self.p.map_resolution, length),
                                   length):
            return True
        return to_goal and self._path_passable(robot, target)

    def _path_passable(self, robot: Vec, target: Vec) -> bool:
        """Whether the way on along the global path is still passable on the map: the
        straight way to ``target`` (the look-ahead point) and the path from the robot's
        projection to the window's edge keep the robot's disc off the centre of every
        occupied cell. The path was planned on this map's inflated grid; what this asks
        is only that nothing has been mapped on it since. A path through a gap that is
        narrow for the inflation (a 0.8 m gap leaves one 0.1 m cell column outside it)
        runs through inflated cells, a cell or two from the faces: that is no reason to
        leave the path for a detour on the 0.5 m boxes, which close such a gap."""
        assert self.costmap is not None
        if self.path is None or self.lengths is None:
            return False
        p = self.p
        step = p.map_resolution / 2
        lengths = self.lengths
        s0 = project(self.path, robot, lengths)[0]
        s = np.arange(s0, min(s0 + p.window_radius, float(lengths[-1])) + step / 2, step)
        along = np.column_stack([np.interp(s, lengths, self.path[:, 0]),
                                 np.interp(s, lengths, self.path[:, 1])])
        return self._disc_clear(np.vstack([along, self._leg(robot, target)]))

    def _leg(self, robot: Vec, end: Vec) -> Vec:
        """Points every half map cell on the straight way from ``robot`` to ``end``."""
        offset = end - robot
        distance = c_hypot(*offset)
        return path_points(robot, offset / max(distance, 1e-9), distance,
                           self.p.map_resolution / 2)

    def _crosses_map(self, points: Vec, spare: float = 0.0) -> bool:
        """Beyond the paper: whether the robot's disc, grown by ``spare`` m, centred on
        each of ``points`` (its position first), would cover an occupied cell's centre
        of the map, deeper than it does where it stands. A Morphin candidate is checked
        on the obstacles' cell boxes S_k, and a box round an L-shaped wall, or one the
        robot stands inside, lets a candidate through the wall itself: at a corridor's
        turn the sub-target fell behind the inner wall, though the global path went
        round it."""
        assert self.costmap is not None
        cells = self.costmap.cell_of(points)
        inside = self.costmap.inside(cells)
        gap = np.full(len(points), math.inf)
        gap[inside] = self.costmap.gap()[cells[inside, 0], cells[inside, 1]]
        need = min(self.p.robot_radius + spare, float(gap[0])) - 1e-6
        return bool((gap < need).any())

    def _backs_into_map(self, pose: tuple[float, float, float], v: float,
                        omega: float) -> bool:
        """Whether backing at ``v`` (< 0) m/s, turning ``omega`` rad/s, for ``BACKING_LOOK``
        s would take the robot's disc deeper into what the map holds than it is, with a
        map cell to spare: behind the robot there is no laser and no stop zone to catch
        what the map's cells round off (a wall's corner, up to a cell)."""
        arc = arc_points(pose[0], pose[1], pose[2], v, omega, BACKING_LOOK,
                         self.p.map_resolution / max(abs(v), 1e-9) / 2)
        return self._crosses_map(np.vstack([np.asarray(pose[:2]), arc]),
                                 self.p.map_resolution)

    def _disc_clear(self, points: Vec) -> bool:
        """Whether the robot's disc, centred on each of ``points``, covers no occupied
        cell's centre of the map."""
        assert self.costmap is not None
        cells = self.costmap.cell_of(points)
        inside = self.costmap.inside(cells)
        gap = self.costmap.gap()[cells[inside, 0], cells[inside, 1]]
        return bool((gap >= self.p.robot_radius - 1e-6).all())

    def _replan_round_mapped(self, robot: Vec, path_target: Vec, threats: list[Assessment],
                             obstacles: list[Obstacle], stamp: float) -> bool:
        """Beyond the paper: a (b) on an obstacle the map holds, while the global path
        still runs into what the map holds within the window (it was planned before the
        map held the obstacle, and the path is planned again for the map alone only
        when it is blocked beyond the window): plan the path again on the map now,
        rather than a detour on the 0.5 m boxes, when the paper's detour would take the
        robot into what the map holds (the boxes can close a narrow gap and send the
        robot along a wall toward its end), or when the map knows a way shorter than any
        through the detour's sub-target (``_map_way_shorter``: a door in the wall the
        detour runs along). Otherwise the paper's detour is kept. Asked with no detour
        under way, and on one when a (b) blocks the way to its sub-target. At most once
        per ``replan_period``; whether a path was found."""
        p = self.p
        if self.costmap is None or not p.use_map or self.path is None:
            return False
        if stamp - self.last_replan < p.replan_period:
            return False
        mapped = [a for a in threats if a.letter == "b" and self._mapped(a, stamp)]
        if not mapped or self._path_passable(robot, path_target):
            return False
        # A trial of the paper's detour, on the boxes alone: the side it picks is not kept.
        sides = dict(self.sides)
        trial = self.plan_detour(robot, min(mapped, key=lambda a: a.robot_distance),
                                 obstacles, fast=False, on_map=False)
        self.sides = sides
        plan = None
        if trial is not None and self._disc_clear(self._leg(robot, trial.subtarget)):
            plan = self._map_way_shorter(robot, trial.subtarget, stamp)
            if plan is None:
                return False
        count = self.plan_count
        self.replan_asked = "mapped obstacle on the path"
        self.update_path(robot, stamp, plan)
        return self.plan_count != count

    def _map_way_shorter(self, robot: Vec, via: Vec, stamp: float) -> GlobalPlan | None:
        """The map's path to the goal, when it is shorter by more than ``path_deviation``
        than the straight legs robot -> ``via`` -> goal, the least any way through a
        detour's sub-target ``via`` can take; else None. Planned at most once per
        ``replan_period`` (a detour the map does not beat stays weighed that long)."""
        p = self.p
        assert self.costmap is not None
        if stamp - self.last_compared < p.replan_period:
            return None
        self.last_compared = stamp
        plan = plan_path(self.costmap, robot, self.goal, "mapped obstacle on the path")
        least = c_hypot(*(via - robot)) + c_hypot(*(self.goal - via))
        return plan if plan.found and plan.length + p.path_deviation < least else None

    # -- responses ---------------------------------------------------------------------

    def crossing_response(self, a: Assessment, committed: Action | None) -> tuple[Action, float]:
        """(e): speed up, slow down or stop so the robot and the obstacle are never in
        the crossing zone together. A choice made earlier for this obstacle is kept while
        it still works: speeding up while the robot still clears the zone first, slowing
        while the slower speed stays above the floor; a stop lasts until the obstacle has
        passed."""
        p = self.p
        ob_speed = c_hypot(*a.obstacle.velocity)
        if ob_speed < 1e-6:
            return "stop", 0.0
        clearance = p.robot_radius + a.obstacle.radius + p.safety_margin
        zone_in = a.obstacle_time - clearance / ob_speed
        zone_out = a.obstacle_time + clearance / ob_speed
        s = a.robot_distance
        buffer = p.speed_up_buffer / 2 if committed == "speed_up" else p.speed_up_buffer
        if committed in (None, "speed_up") and s > -clearance and (
            (s + clearance) / p.max_speed + buffer < zone_in
        ):
            return "speed_up", p.max_speed
        if committed != "stop" and zone_out > 0 and s - clearance > 0:
            v = (s - clearance) / (zone_out + 1.0)
            if v >= p.min_slow_fraction * p.cruise_speed:
                return "slow", min(v, p.cruise_speed)
        return "stop", 0.0

    def follow_response(self, a: Assessment) -> tuple[Action, float]:
        """(g): keep a gap behind a slower obstacle going the same way."""
        p = self.p
        free = a.along - p.robot_radius - a.obstacle.radius
        if free < p.stop_gap:
            return "stop", 0.0
        v = a.along_speed + p.follow_gain * (free - p.follow_gap)
        v = min(max(v, 0.0), p.cruise_speed)
        return ("slow", v) if v > 1e-3 else ("stop", 0.0)

    def speed_and_safety(
        self, pose: tuple[float, float, float], target: Vec, speed: float,
        movers: list[Obstacle], path_target: Vec, ages: list[float] | None = None,
    ) -> safety.Choice:
        """Check driving toward ``target`` at ``speed`` against every mover as the robot
        would drive it (``safety.py``); the local layer's command if it is safe, else the
        nearest safe heading and speed."""
        robot, group, heading, blocked = self._safety_inputs(pose, target, movers, ages)
        carrot = self._carrot(np.array(pose[:2], dtype=np.float64), path_target)
        return safety.choose(robot, (heading, speed), group, carrot, blocked,
                             self.safety_heading, self.safety_settings)

    def _safety_inputs(
        self, pose: tuple[float, float, float], target: Vec, movers: list[Obstacle],
        ages: list[float] | None,
    ) -> tuple[safety.Robot, safety.Movers, float, safety.Blocked | None]:
        """The robot, the movers, the heading to ``target`` and the map's check, as the
        speed and safety stage takes them."""
        p = self.p
        robot = safety.Robot(
            x=pose[0], y=pose[1], heading=pose[2], speed=self.speed_now,
            radius=p.robot_radius, max_speed=p.max_speed, max_omega=p.max_omega,
            heading_gain=p.heading_gain, accel=p.accel, decel=p.decel,
            goal=(float(self.goal[0]), float(self.goal[1])), arrive_within=self.arrival_radius())
        group = safety.Movers(
            np.array([o.position for o in movers], dtype=np.float64).reshape(-1, 2),
            np.array([o.velocity for o in movers], dtype=np.float64).reshape(-1, 2),
            np.array([o.radius for o in movers], dtype=np.float64),
            np.array([self.top_speeds.get(o.id, 0.0) for o in movers], dtype=np.float64),
            None if ages is None else np.asarray(ages, dtype=np.float64))
        heading = math.atan2(target[1] - pose[1], target[0] - pose[0])
        blocked = self.costmap.blocked_rows if self.costmap is not None else None
        return robot, group, heading, blocked

    def clear_at_cruise(self, pose: tuple[float, float, float], target: Vec,
                        walkers: list[Obstacle], ages: list[float]) -> bool:
        """Whether driving on toward ``target`` at V_R keeps clear of every walker (and
        of the map) over the safety stage's horizon, each walker's clearance grown
        ``drive_on_growth`` times as fast as the stage's own. The paper's (e) answers
        one predicted meeting on a straight line; in a crowd many of the stops it asks
        for leave the way ahead free (docs/navigation.md, "Driving on when the way is
        clear")."""
        p = self.p
        if not p.speed_check or p.drive_on_growth <= 0.0:
            return False
        if c_hypot(*(target - np.asarray(pose[:2], dtype=np.float64))) <= 1e-9:
            return False
        robot, group, heading, blocked = self._safety_inputs(pose, target, walkers, ages)
        wary = dataclasses.replace(self.safety_settings,
                                   growth=self.safety_settings.growth * p.drive_on_growth)
        return safety.keeps_clear(robot, (heading, p.cruise_speed), group, blocked, wary)

    def _toward_choice(self, robot: Vec, choice: safety.Choice) -> Vec:
        """The point the robot steers for to drive the safety stage's ``choice``: along its
        heading, as far as two seconds at its speed and at least the look-ahead."""
        reach = max(choice.speed * 2.0, self.p.lookahead)
        return robot + reach * np.array([math.cos(choice.heading), math.sin(choice.heading)])

    def _carrot(self, robot: Vec, path_target: Vec) -> Vec:
        """The point on the global path the safety stage measures progress to: as far
        along as the top speed reaches within the horizon, past the look-ahead point."""
        p = self.p
        if self.path is None or self.lengths is None:
            return path_target
        length = float(self.lengths[-1])
        s0 = project(self.path, robot, self.lengths)[0]
        s = s0 + p.lookahead + p.max_speed * p.safety_horizon
        return self.goal if s >= length else point_at(self.path, s, self.lengths)

    def _crossed(self, robot: Vec, target: Vec, ob: Obstacle) -> bool:
        """Whether a crosser has got across the line the robot is driving along (it is
        on the far side of it, moving away, clear by the clearance)."""
        offset = target - robot
        length = c_hypot(*offset)
        if length < 1e-9:
            return True
        d = offset / length
        rel = np.asarray(ob.position) - robot
        side = float(d[0] * rel[1] - d[1] * rel[0])
        away = float(d[0] * ob.velocity[1] - d[1] * ob.velocity[0])
        clearance = self.p.robot_radius + ob.radius + self.p.safety_margin
        return side * away > 0 and abs(side) > clearance

    @staticmethod
    def _toward(direction: Vec, ob: Obstacle) -> bool:
        """Whether ``ob`` comes at the robot against ``direction`` (head-on)."""
        return float(direction @ np.asarray(ob.velocity)) < 0.0

    def _unconfirmed(self, a: Assessment, stamp: float) -> bool:
        """A standing obstacle seen for less than ``confirm_time`` may yet turn out to move
        (slow movers need a while to show it); while it is farther ahead than
        ``confirm_distance`` the robot goes on and waits to see."""
        p = self.p
        young = stamp - self.first_seen.get(a.obstacle.id, stamp) < p.confirm_time
        return (a.letter == "b" and young and a.obstacle.id not in self.commitments
                and a.robot_distance > p.confirm_distance)

    def _sticky(self, a: Assessment) -> Assessment:
        """The scenario letter first given to a threat stays with it while it threatens."""
        committed = self.commitments.get(a.obstacle.id)
        if committed is None or committed.letter == a.letter:
            return a
        if committed.letter not in "efg" or a.letter not in "efg":
            return a  # it started or stopped moving: a different situation
        return dataclasses.replace(a, letter=committed.letter)

    def plan_detour(self, robot: Vec, threat: Assessment, obstacles: list[Obstacle],
                    fast: bool, on_map: bool = True) -> Detour | None:
        """Morphin round ``threat`` (Eq. 17) on the standing obstacles' cell boxes and the
        movers; ``on_map`` (beyond the paper): also never through what the map holds."""
        p = self.p
        statics = self._statics(obstacles)
        lows, highs = self._boxes(statics)
        movers = [Mover(np.asarray(o.position, dtype=np.float64),
                        np.asarray(o.velocity, dtype=np.float64), o.radius)
                  for o in obstacles if o not in statics]
        clearance = p.robot_radius + p.safety_margin
        axis = np.asarray(threat.direction, dtype=np.float64)
        if threat.letter == "b":
            # The centreline runs along the robot's way to the potential collision point
            # (abreast of S_k's centre), and on past S_k's far side.
            lo, hi = cell_squares(threat.obstacle.cells, p.cell)
            corners = np.array([[lo[0], lo[1]], [lo[0], hi[1]], [hi[0], lo[1]], [hi[0], hi[1]]])
            reach = (corners - robot) @ axis
            middle = max(float(((lo + hi) / 2 - robot) @ axis), p.cell)
            centre = robot + axis * middle
            extra = max(float(reach.max()) - middle, 0.0) + clearance
        else:  # to the potential collision point, and past the mover's footprint
            centre = robot + axis * max(threat.robot_distance, p.cell)
            extra = clearance + threat.obstacle.radius
        # Beyond the paper: a detour never reaches farther from the robot than the goal.
        # Past a walker standing by the goal, the paper's length (to S_k's far side and a
        # clearance more) puts the sub-target beyond the goal, and the robot drives by
        # the goal to reach it.
        to_the_goal = c_hypot(*(self.goal - robot))
        ahead = c_hypot(*(centre - robot))
        if ahead + extra > to_the_goal:
            ahead = min(ahead, max(to_the_goal, p.cell))
            centre = robot + axis * ahead
            extra = max(to_the_goal - ahead, 0.0)
        to_goal = self._to_goal(robot, lows, highs)
        # Keep to the side already taken round this obstacle (or the detour under way):
        # swinging from one side to the other between obstacles gets nowhere.
        side = self.sides.get(threat.obstacle.id, 0)
        if side == 0 and self.detour is not None:
            side = self.detour.side
        best = None
        # The paper's fan first; if it is blocked all round (the robot is in a pocket),
        # a fan that also turns back, so the robot can leave the way it came.
        for fan_max in (p.fan_max_deg, p.escape_fan_deg):
            choice = choose_detour(
                robot, centre, self.goal, self.global_cells, (lows, highs), movers,
                speed=p.max_speed if fast else p.cruise_speed, cell=p.cell,
                robot_radius=p.robot_radius, margin=p.safety_margin, kappa=p.kappa,
                fan_step=math.radians(p.fan_step_deg), fan_max=math.radians(fan_max),
                extra_length=extra if p.extend_past else 0.0, side=side,
                switch_penalty=p.switch_penalty,
                end_cost=lambda end: self._way_on_cost(robot, end, to_goal),
                to_goal=to_goal,
                crosses=(self._crosses_map if on_map and self.costmap is not None and p.use_map
                         else None),
            )
            best = choice.best
            if best is not None:
                break
        if best is None:
            return None
        chosen = 1 if best.g > 0 else -1
        self.sides[threat.obstacle.id] = chosen
        return Detour(np.asarray(best.end), threat.obstacle.id, threat.letter, chosen,
                      threat.obstacle.kind)

    # -- the cycle ---------------------------------------------------------------------

    def local_layer(
        self, pose: tuple[float, float, float], obstacles: list[Obstacle], stamp: float
    ) -> Decision:
        """The paper's local layer toward the look-ahead point on the global path:
        assess every obstacle in the window, respond per scenario letter, plan a Morphin
        detour when one is needed, check the speed against the movers, steer."""
        p = self.p
        robot = np.array(pose[:2], dtype=np.float64)
        in_window = [o for o in obstacles if self._in_window(o, pose)]
        path_target = self.path_target(robot, self._statics(in_window))
        last_stretch = self.on_last_stretch

        if self.detour is not None:
            reached = c_hypot(*(self.detour.subtarget - robot)) < p.subtarget_reached
            direct = self._assess_all(robot, path_target, in_window, p.resume_hysteresis,
                                      to_goal=True)
            if (reached or last_stretch
                    or not any(a.threat and a.letter in "bf" for a in direct)):
                self.detour = None
                # The way back is judged on a path from here: the cycle's own check ran
                # while the detour was under way, and the old path's rejoin point can lie
                # behind the obstacle just passed, on its far side.
                count = self.plan_count
                self.update_path(robot, stamp)
                if self.plan_count != count:
                    path_target = self.path_target(robot, self._statics(in_window))

        target = self.detour.subtarget if self.detour is not None else path_target
        # On a detour, only a clear obstruction of the way to the sub-target re-plans it,
        # not the few centimetres the robot drifts from the line it planned.
        slack = -p.replan_slack if self.detour is not None else 0.0
        notes = self._assess_all(robot, target, in_window, slack, to_goal=self.detour is None)
        # A "new" obstacle has been seen once: it is answered from the next scan on, when
        # its type is known (the motor bridge's stop zone covers the meantime).
        # The map may clear the way to the target (the path's look-ahead point, or the
        # detour's sub-target); whether a detour may end is still the boxes' call.
        clear = self._map_clear(robot, target, to_goal=self.detour is None)
        threats = self._threats(notes, clear, stamp, robot, target, self.detour is None,
                                last_stretch)
        if self._replan_round_mapped(robot, path_target, threats, in_window, stamp):
            # The path now goes round what the map holds: judge the way along it again.
            self.detour = None
            path_target = target = self.path_target(robot, self._statics(in_window))
            notes = self._assess_all(robot, target, in_window, 0.0, to_goal=True)
            clear = self._map_clear(robot, target, to_goal=True)
            threats = self._threats(notes, clear, stamp, robot, target, True, last_stretch)
        # A crosser the robot gives way to stays answered until it has crossed the
        # robot's way, not only while the prediction (noisy) still says they would meet.
        found = {a.obstacle.id: a for a in notes}
        by_id = {o.id: o for o in in_window}
        for ob_id, held in self.commitments.items():
            crosser = by_id.get(ob_id)
            if (held.letter != "e" or held.last is None or crosser is None
                    or crosser.kind != "dynamic"
                    or math.hypot(*crosser.velocity) < p.moving_speed  # it stopped
                    or any(a.obstacle.id == ob_id for a in threats)
                    or self._crossed(robot, target, crosser)):
                continue
            seen = found.get(ob_id)
            base = seen if seen is not None else dataclasses.replace(held.last, obstacle=crosser)
            threats.append(dataclasses.replace(base, letter="e", threat=True))
        if p.threats_per_cycle == "one" and threats:  # Algorithm 1: first in O_chain, break
            threats = [first_in_scan_order(threats, robot, pose[2])]
        if self.hold is None and self._start_hold(robot, pose[2], target, threats, in_window,
                                                  stamp):
            aside = self.hold_aside(pose, obstacles, stamp)
            if aside is not None:
                self.detour = None
                self.commitments = {}
                return aside
        threat_ids = {a.obstacle.id for a in threats}
        self.commitments = {i: c for i, c in self.commitments.items() if i in threat_ids}

        speed = p.cruise_speed
        action: Action = "keep"
        lead: Assessment | None = None
        needs_detour = [a for a in threats if a.letter in "bf"]
        if needs_detour:
            lead = min(needs_detour, key=lambda a: a.robot_distance)
            # At cruise speed if a detour at that speed clears everything, else at top
            # speed (a head-on mover may leave no time to step aside slowly).
            fast = False
            detour = self.plan_detour(robot, lead, in_window, fast)
            if detour is None and lead.letter == "f" and p.fast_fallback:
                fast = True
                detour = self.plan_detour(robot, lead, in_window, fast)
            if detour is None:
                speed, action = 0.0, "stop"
            else:
                self.detour = detour
                target = detour.subtarget
                action = "morphin"
                speed = p.max_speed if fast else p.cruise_speed
            for a in needs_detour:
                self.commitments[a.obstacle.id] = Commitment(a.letter, action)

        responses: list[tuple[float, Action, Assessment]] = []  # (speed, action, why)
        for a in threats:
            if a.letter not in "eg":
                continue
            committed = self.commitments.get(a.obstacle.id)
            if a.letter == "e":
                act, v = self.crossing_response(a, committed.action if committed else None)
            else:
                act, v = self.follow_response(a)
            if p.slow_step > 0.0:  # Algorithm 1: "avoidable" -> V_R = V_R - Delta V_R
                v = max(self.asked - p.slow_step, 0.0)
                act = "slow" if v > 0.0 else "stop"
            self.commitments[a.obstacle.id] = Commitment(a.letter, act, a)
            responses.append((v, act, a))
        if responses:
            v, act, slowest = min(responses, key=lambda r: r[0])
            if action == "morphin":
                speed = min(speed, v)
                if speed <= 0.0:
                    action, lead = "stop", slowest
            else:
                speed, action, lead = v, act, slowest

        unseen = [(o, age) for o, age in self.unseen
                  if self._in_window(o, pose)]
        movers = [o for o in in_window if self._moving(o)]
        # Every track typed dynamic, standing ones too: their returns are not in the map.
        # Then the movers out of view, predicted from where they were last seen.
        walkers = [o for o in in_window if o.kind == "dynamic"] + [o for o, _ in unseen]
        ages = [0.0] * (len(walkers) - len(unseen)) + [age for _, age in unseen]
        # (e) asks for a stop or a lower speed on one predicted meeting at a time; when
        # the way ahead at V_R is free of every walker after all, the robot drives on.
        # Only for meetings the roll-out covers (both at the crossing within its
        # horizon), and not for (g), whose gap keeping is a speed law, not an answer.
        if (responses and action in ("stop", "slow") and not needs_detour
                and self.detour is None
                and all(a.letter == "e" and max(a.robot_time, a.obstacle_time)
                        <= p.safety_horizon for _, _, a in responses)
                and self.clear_at_cruise(pose, target, walkers, ages)):
            speed, action = p.cruise_speed, "keep"
        self.safety_heading = None if not (movers or unseen) else self.safety_heading
        if p.speed_check and (movers or unseen) and c_hypot(*(target - robot)) > 1e-9:
            choice = self.speed_and_safety(pose, target, speed, walkers, path_target, ages)
            if not choice.kept:
                # The command refused with no mover on it: its roll-out ran into what the
                # map holds, and the robot stands for the map, not for a mover.
                self.held_by_map = (choice.mover is None and choice.speed <= 0.0 < speed)
                culprit = walkers[choice.mover] if choice.mover is not None else None
                ahead = math.atan2(target[1] - robot[1], target[0] - robot[0])
                turned = abs(wrap_angle(choice.heading - ahead))
                target = self._toward_choice(robot, choice)
                if turned > math.radians(p.safety_fan_deg) / 2:
                    action = "morphin"  # step aside
                elif choice.speed > speed:
                    action = "speed_up"
                else:
                    action = "stop" if choice.speed <= 0.0 else "slow"
                speed = choice.speed
                why = None if culprit is None else next(
                    (a for a in notes if a.obstacle.id == culprit.id), None)
                if why is not None:
                    lead = why
                    if why not in threats:
                        threats.append(why)
            self.safety_heading = choice.heading

        if lead is None and self.detour is not None:
            action = "morphin"  # still on the way to a sub-target
        letter: ScenarioLetter
        answering = {a.obstacle.id for a in threats}
        if self.detour is not None:
            answering.add(self.detour.obstacle)  # still on the way round it
        if len(answering) > 1:
            letter = "h"
        elif lead is not None:
            letter = lead.letter
        elif self.detour is not None:
            letter = self.detour.letter
        else:
            letter = "a"

        self.asked = speed
        tx, ty = float(target[0]), float(target[1])
        # The speed falls to the target's distance in a second of travel; toward the
        # look-ahead point on the path (short of the goal), in the time the speed asked
        # takes to cover the look-ahead, when that is shorter: else no robot could go
        # faster than the look-ahead per second (1 m/s) on a straight path. Below that
        # speed nothing changes; in a bend the point comes closer and slows the robot.
        within = 1.0
        if (self.detour is None and target is path_target and speed > p.lookahead
                and not self._is_goal(target)):
            within = p.lookahead / speed
        v, omega = command_toward(robot[0], robot[1], pose[2], (tx, ty), speed,
                                  p.heading_gain, p.max_omega, within=within)
        obstacle = lead.obstacle.id if lead is not None else (
            self.detour.obstacle if self.detour is not None else None)
        # An event names the obstacle's type whenever it names an obstacle: on a detour,
        # its type now if it is still tracked, else its type when the detour was chosen.
        kind: ObstacleKind | None = None
        if lead is not None:
            kind = lead.obstacle.kind
        elif self.detour is not None:
            kind = next((o.kind for o in obstacles if o.id == self.detour.obstacle),
                        self.detour.kind)
        return Decision(v, omega, (tx, ty), letter, action, obstacle, kind, speed, tuple(notes))

    # -- the cycle, stage by stage -----------------------------------------------------

    def step(
        self,
        pose: tuple[float, float, float],
        obstacles: list[Obstacle],
        stamp: float = 0.0,
        scan: ScanData | None = None,
    ) -> Decision:
        """One decision per scan: map -> global path -> (recovery, or the local layer:
        assess, respond, detour, speed and safety) -> stop zone -> command."""
        p = self.p
        tracked, obstacles = obstacles, self.footprints(pose, obstacles, scan)
        for ob in obstacles:
            self.first_seen.setdefault(ob.id, stamp)
        live = {ob.id for ob in obstacles}
        self.first_seen = {i: t for i, t in self.first_seen.items() if i in live}
        self.sides = {i: side for i, side in self.sides.items() if i in live}
        self.top_speeds.update(safety.faded_top_speeds(
            self.top_speeds, {ob.id: math.hypot(*ob.velocity) for ob in obstacles
                              if ob.kind == "dynamic"},
            stamp - (self.top_stamp if self.top_stamp is not None else stamp),
            p.top_speed_fade))
        self.top_stamp = stamp
        self.unseen = self.remember_movers(obstacles, stamp, scan, pose[:2])
        dynamic = {ob.id for ob in obstacles if ob.kind == "dynamic"}
        self.top_speeds = {i: v for i, v in self.top_speeds.items()
                           if i in dynamic or (i in self.last_seen_movers and i not in live)}
        self.speed_now = self.driven_speed(pose, stamp)
        robot = np.array(pose[:2], dtype=np.float64)
        if self.start is None:
            self.start = robot.copy()
            self._set_path(np.vstack([self.start, self.goal]), "start")
        self._remember_trail(robot)
        goal_xy = (float(self.goal[0]), float(self.goal[1]))
        if (c_hypot(*(self.goal - robot)) <= self.arrival_radius()
                or self._arrived_beside(robot, pose[2], scan)):
            self.detour = None
            return self._record(Decision(0.0, 0.0, goal_xy, "a", "goal", None, None, 0.0))
        # A goal given up for want of room is watched (``room_again``); one given up
        # for want of a way is not.
        watching = self.recovery.unreachable and self._given_up_for_room()
        if self.recovery.unreachable and not watching:
            return self._record(self.guard_stop_zone(self.given_up(pose, obstacles), pose, scan))

        # The map leaves out the returns on the movers' visible surfaces: the tracks'
        # own discs, centred on those surfaces, cover them (the footprints' discs only
        # graze them, and a radius a little short would leave marks in a mover's wake).
        self.update_map(pose, tracked, scan, stamp)
        if watching and not self.room_again(robot, pose[2], scan, tracked):
            return self._record(self.guard_stop_zone(self.given_up(pose, obstacles), pose, scan))
        self.settle_goal(robot)
        self.look_for_room(robot, pose[2], scan, tracked)
        self.on_last_stretch = self.last_stretch(robot, pose[2], scan)
        self.update_path(robot, stamp)
        decision = self.recover(pose, stamp, scan)
        if (decision is not None and decision.action in YIELDING
                and self.walked_into(pose, obstacles)):
            # The step would keep the robot where a walker is about to walk into it: it
            # ends, and the local layer answers the walker (the watch starts afresh).
            self.recovery.finish(stamp, self.to_go(robot))
            decision = None
        if decision is None:
            self.held_by_map = False  # set by this cycle's local layer, if it runs
            decision = self.hold_aside(pose, obstacles, stamp)
            if (decision is not None and decision.speed <= 0.0
                    and self.walked_into(pose, obstacles)):
                # Standing at a spot aside that the walker would still walk into (found
                # too late for a better one): the hold ends and the local layer answers.
                self.hold = None
                decision = None
            decision = decision or self.local_layer(pose, obstacles, stamp)
            if decision.action == "stop" and decision.scenario == "b":
                self.replan_asked = "no way round"  # the local layer found no detour
            decision = self.guard_stop_zone(self.brake_for_goal(decision, pose, scan),
                                            pose, scan)
            if decision.refused and self._blocked_within_window(robot, stamp):
                # The stop zone refuses the way along a path that runs into what the map
                # has come to hold since it was planned (a wall's end seen late): the
                # local layer saw no threat on it, so it is planned again on the map.
                self.replan_asked = "blocked within the window"
            if self.held_by_map and stamp - self.last_replan >= p.replan_period:
                # The safety stage stands because the way along the path passes within
                # the inflation of what the map holds (a path planned before a box beside
                # it was seen, through a gap it leaves too narrow): the path's own check
                # asks only that the robot's disc pass, so it is planned again on the
                # inflated map, once per ``replan_period``.
                self.replan_asked = "the map holds the way ahead"
            waiting = (decision.action in ("stop", "slow", "give_way")
                       and decision.kind == "dynamic" and not self.held_by_map)
            # Walled in: the goal is cut off by walls seen (the wall memory), so gains
            # along a path through forgotten walls are no progress: the steps follow one
            # another at once instead of after a stall (and progress does not reset them).
            walled = p.recovery and self.walled_in(robot, stamp)
            # No room at the goal, and the robot near enough to have looked: the same.
            cramped = p.recovery and self.no_room and c_hypot(
                *(self.mission_goal - robot)) <= p.goal_tolerance + NO_ROOM_LOOK
            if p.recovery and (walled or cramped or self.recovery.watch(
                    stamp, self.to_go(robot), waiting, decision.refused)):
                way = self._way_known() and not walled and not cramped
                if cramped and self.recovery.level >= len(STEPS):
                    # A round of the steps has looked again, and there is still no room.
                    self.recovery.give_up()
                    step = None
                else:
                    step = self.recovery.start_next(stamp, pose, way_known=way)
                if step is None:
                    self._walled_off()
                    decision = Decision(0.0, 0.0, goal_xy, "a", "unreachable", None, None, 0.0)
                else:
                    self.detour = None
                    self.hold = None
                    decision = self.recover(pose, stamp, scan) or decision
        return self._record(decision)

    def footprints(self, pose: tuple[float, float, float], obstacles: list[Obstacle],
                   scan: ScanData | None) -> list[Obstacle]:
        """The obstacles as every later stage sees them: with ``mover_centre``, each mover
        this scan sees whole (``should_be_seen``: its disc inside the field of view,
        nothing nearer on its middle beam) at the centre of the disc its track
        describes. The track's point is that disc's Eq. 5 centre seen from about here,
        so the centre lies farther along the same bearing, by ``disc_distance``. A mover
        seen in part (cut by the edge of the view or by something in front) or not at
        all keeps its track's point: where its centre lies is less sure, and the point
        errs toward the robot."""
        if not self.p.mover_centre or scan is None:
            return obstacles
        out = []
        for ob in obstacles:
            dx, dy = ob.position[0] - pose[0], ob.position[1] - pose[1]
            seen_at = math.hypot(dx, dy)
            # (seen whole also means farther than its radius: k below is finite)
            if ob.kind != "dynamic" or not should_be_seen(scan, ob.position, ob.radius):
                out.append(ob)
                continue
            k = disc_distance(seen_at, ob.radius) / seen_at
            out.append(dataclasses.replace(ob, position=(pose[0] + dx * k, pose[1] + dy * k)))
        return out

    def given_up(self, pose: tuple[float, float, float], obstacles: list[Obstacle]) -> Decision:
        """The command once the goal is unreachable: stand, unless a walker would walk
        into the robot standing (``walked_into``). Then the speed and safety stage's fan
        picks the cheapest way out of its way, its progress measured to the spot where
        the robot stands (the least move that keeps clear), and the robot takes it this
        cycle (action ``give_way``); it stands again once the walker has passed."""
        goal_xy = (float(self.goal[0]), float(self.goal[1]))
        omega = 0.0
        if self._given_up_for_room():
            # It turns in place to keep the goal in view (``room_again``), the laser's
            # middle beam on it.
            _, omega = command_toward(pose[0], pose[1], pose[2], goal_xy, 0.0,
                                      self.p.heading_gain, self.p.max_omega)
        standing = Decision(0.0, omega, goal_xy, "a", "unreachable", None, None, 0.0)
        walkers = self._walkers_at(pose, obstacles)
        if not walkers or not self._walks_into(pose, walkers):
            return standing
        p = self.p
        here = np.array(pose[:2], dtype=np.float64)
        robot, group, _, blocked = self._safety_inputs(pose, here, walkers, None)
        choice = safety.choose(robot, (pose[2], 0.0), group, here, blocked, None,
                               self.safety_settings)
        if choice.kept or choice.speed <= 0.0:
            return standing  # no move keeps clearer than standing
        target = self._toward_choice(here, choice)
        tx, ty = float(target[0]), float(target[1])
        v, omega = command_toward(pose[0], pose[1], pose[2], (tx, ty), choice.speed,
                                  p.heading_gain, p.max_omega)
        culprit = walkers[choice.mover].id if choice.mover is not None else None
        return Decision(v, omega, (tx, ty), "a", "give_way", culprit, "dynamic", choice.speed)

    def walked_into(self, pose: tuple[float, float, float], obstacles: list[Obstacle]) -> bool:
        """Whether a walker in the window, or one remembered out of view, would touch the
        robot standing where it is within ``safety_horizon``: the speed and safety
        stage's roll-out of a robot at rest, each walker at constant velocity without the
        stage's clearance growth. A recovery step that turns the robot in place, backs
        it up or waits ends on it, and so does a hold at a spot aside where the robot
        stands. Off with the stage (``speed_check``)."""
        walkers = self._walkers_at(pose, obstacles)
        return bool(walkers) and self._walks_into(pose, walkers)

    def _walkers_at(self, pose: tuple[float, float, float],
                    obstacles: list[Obstacle]) -> list[Obstacle]:
        """``walked_into``'s walkers: the movers in the window and those remembered out
        of view, none on a cell the map holds; none with the stage off (``speed_check``)."""
        if not self.p.speed_check:
            return []
        walkers = [o for o in obstacles if self._moving(o) and self._in_window(o, pose)]
        walkers += [o for o, _ in self.unseen]
        if self.costmap is not None:
            # A piece of wall sweeping through the view of a robot that turns in place is
            # tracked as a fast mover for a scan or two; a walker's centre is never on a
            # cell the map holds.
            walkers = [o for o in walkers if len(self.costmap.lethal_near(
                np.asarray(o.position, dtype=np.float64), ON_THE_MAP)) == 0]
        return walkers

    def _walks_into(self, pose: tuple[float, float, float], walkers: list[Obstacle]) -> bool:
        robot, group, _, _ = self._safety_inputs(pose, np.asarray(pose[:2]), walkers, None)
        at_rest = dataclasses.replace(robot, speed=0.0)
        plain = dataclasses.replace(self.safety_settings, growth=0.0)
        return not safety.keeps_clear(at_rest, (pose[2], 0.0), group, None, plain)

    def driven_speed(self, pose: tuple[float, float, float], stamp: float) -> float:
        """The robot's forward speed over the last scan, m/s, from its last two poses (at
        least 0: the speed and safety stage models forward motion). The command is not
        the speed: from rest the motor bridge takes two seconds to reach 1 m/s, and a
        roll-out that starts at the speed commanded has the robot pass in front of a
        walker it cannot outrun. Without a pose from the last ``SPEED_GAP`` s, the
        speed last commanded."""
        last, self.last_pose = self.last_pose, (pose[0], pose[1], pose[2], stamp)
        if last is None or not 0.0 < stamp - last[3] <= SPEED_GAP:
            return self.last_v
        x0, y0, h0, t0 = last
        mid = h0 + wrap_angle(pose[2] - h0) / 2
        along = (pose[0] - x0) * math.cos(mid) + (pose[1] - y0) * math.sin(mid)
        return max(along / (stamp - t0), 0.0)

    def _record(self, decision: Decision) -> Decision:
        self.last_v = decision.v
        return decision

    def _remember_trail(self, robot: Vec) -> None:
        if not self.trail or math.dist(self.trail[-1], robot) >= 0.05:
            self.trail.append((float(robot[0]), float(robot[1])))
            del self.trail[:-400]

    def _in_window(self, o: Obstacle, pose: tuple[float, float, float]) -> bool:
        """Whether some of ``o`` lies within ``window_radius`` of the robot."""
        return math.dist(o.position, pose[:2]) - o.radius <= self.p.window_radius

    def _moving(self, o: Obstacle) -> bool:
        """Whether ``o`` is a mover: typed dynamic and at least ``moving_speed`` fast."""
        return o.kind == "dynamic" and math.hypot(*o.velocity) >= self.p.moving_speed

    # -- stage: giving way in a corridor -----------------------------------------------

    def _start_hold(self, robot: Vec, heading: float, target: Vec, threats: list[Assessment],
                    in_window: list[Obstacle], stamp: float) -> bool:
        """Beyond the paper: when the one mover in the window comes head-on and threatens,
        or comes up from behind on the robot's line faster than the robot can go
        (``_overtaking``: no outrunning it), and the map holds walls on both sides of
        the robot (``give_way.hemmed_in``), pick a spot aside (``give_way.spot_aside``:
        on the side of the mover's way the robot is on, else the other) and hold it
        (``hold_aside``); whether one was found. ``target``: where the robot is heading."""
        p = self.p
        if not (p.give_way and p.use_map) or self.costmap is None:
            return False
        movers = [o for o in in_window if self._moving(o)]
        if len(movers) != 1:
            return False
        mover = movers[0]
        velocity = np.asarray(mover.velocity, dtype=np.float64)
        speed = c_hypot(*velocity)
        overtaking = self._overtaking(robot, target, mover)
        if not overtaking:
            threat = next((a for a in threats if a.obstacle.id == mover.id), None)
            if threat is None:
                return False
            if float(np.asarray(threat.direction) @ velocity) > p.head_on_cos * speed:
                return False  # not head-on
        axis = corridor_axis(self.costmap.lethal_near(robot, 2.0 * p.give_way_reach),
                             p.map_resolution)
        if axis is None or abs(float(axis @ velocity)) < -p.head_on_cos * speed:
            return False  # no walls that run one way, or the mover does not walk along them
        way = axis if float(axis @ velocity) > 0.0 else -axis
        if not hemmed_in(robot, way, self.costmap.blocked_at, p.give_way_reach,
                         p.map_resolution / 2):
            return False
        radius = max(mover.radius, p.robot_radius)  # a track of part of it is smaller
        position = np.asarray(mover.position, dtype=np.float64)
        near = 1 if offsets(robot[None, :], position, way)[0] >= 0.0 else -1
        for side in (near, -near):
            spot = self._spot_aside(robot, heading, position, way, speed, radius, side,
                                    overtaking)
            if spot is not None:
                self.hold = Hold(
                    spot=(float(spot[0]), float(spot[1])), side=side, radius=radius,
                    mover=mover.id, way=(float(way[0]), float(way[1])),
                    until=stamp + p.give_way_limit, position=mover.position,
                    velocity=mover.velocity, at=stamp, seen=stamp, moving=stamp,
                    overtaking=overtaking)
                return True
        return False

    def _overtaking(self, robot: Vec, target: Vec, mover: Obstacle) -> bool:
        """Whether ``mover`` comes up from behind the robot going its way (toward
        ``target``, within ``same_way_cos``) faster than ``max_speed``, on a line that
        passes the robot within the clearance (robot and mover radii, a track of part of
        the mover taken as big as the robot, and the safety margin), and will be abreast
        of it within ``horizon`` s even with the robot at its top speed."""
        p = self.p
        velocity = np.asarray(mover.velocity, dtype=np.float64)
        speed = c_hypot(*velocity)
        ahead = target - robot
        length = c_hypot(*ahead)
        if speed <= p.max_speed or length < 1e-9:
            return False
        way = velocity / speed
        if float(ahead @ way) < p.same_way_cos * length:
            return False  # not the robot's way
        clearance = p.robot_radius + max(mover.radius, p.robot_radius) + p.safety_margin
        position = np.asarray(mover.position, dtype=np.float64)
        behind = float((robot - position) @ way)  # the robot's lead on it along its way
        if behind <= 0.0 or abs(float(offsets(robot[None, :], position, way)[0])) >= clearance:
            return False  # beside or ahead of the robot already, or passing it clear
        return (behind - clearance) / (speed - p.max_speed) <= p.horizon

    def _spot_aside(self, robot: Vec, heading: float, position: Vec, way: Vec, speed: float,
                    radius: float, side: int, overtaking: bool = False) -> Vec | None:
        """``give_way.spot_aside`` with the planner's map and parameters: a spot the mover
        passes with the whole safety margin to spare where there is one, else half,
        reached at ``cruise_speed`` after a square turn (across the mover's line and
        behind the robot, at ``max_reverse_speed``: it backs there); from a mover
        ``overtaking``,
        which comes faster than the robot can go, a spot ahead within 45 degrees, reached
        at ``max_speed`` after that turn."""
        assert self.costmap is not None
        p = self.p
        turn = math.pi / 4 if overtaking else math.pi / 2
        for margin in (p.safety_margin, p.safety_margin / 2):
            spot = spot_aside(
                robot, position, way, speed, p.robot_radius + radius + margin, side,
                self.costmap.blocked_at, lambda a, b: self._disc_clear(self._leg(a, b)),
                p.give_way_reach, p.map_resolution / 2,
                p.max_speed if overtaking else p.cruise_speed, lead=turn / p.max_omega,
                ahead=overtaking, backing=(heading, p.max_reverse_speed))
            if spot is not None:
                return spot
        return None

    def hold_aside(self, pose: tuple[float, float, float], obstacles: list[Obstacle],
                   stamp: float) -> Decision | None:
        """The command of the spot aside under way: drive to it (backing, when it lies
        behind: the way the robot came is known, and the mover stays in the laser's view),
        then keep to that lane, on along it while the map leaves it free, else standing
        facing the mover; None once the hold ends: the mover has passed, has
        been seen standing for ``give_way_patience`` s or not seen for ``mover_memory``
        s, another mover has come into the window, or ``give_way_limit`` is up."""
        hold = self.hold
        if hold is None:
            return None
        p = self.p
        where = hold.predicted(stamp)
        reach = p.safety_growth * math.hypot(*hold.velocity) * (stamp - hold.at) + 0.5

        track = next((o for o in obstacles if o.id == hold.mover), None)
        if track is None:  # tracked again under another id, where it is predicted
            track = next((o for o in obstacles if self._moving(o)
                          and math.dist(o.position, where) <= reach + o.radius), None)
        if track is not None:
            hold.mover, hold.at, hold.seen = track.id, stamp, stamp
            if track.radius >= 0.7 * hold.radius:
                hold.position = track.position
            else:
                # A track of part of the mover (its cluster split or merged with a wall's
                # as it passes near one) says how far it has come, not where across the
                # corridor it walks: that stays as last seen whole.
                hold.position = hold.along(track.position)
            hold.radius = max(hold.radius, track.radius)
            if self._moving(track):
                hold.velocity, hold.moving = track.velocity, stamp
        else:  # out of view (beside or behind the robot): where it is predicted
            hold.position, hold.at = (float(where[0]), float(where[1])), stamp
        others = [o for o in obstacles if o.id != hold.mover and self._moving(o)
                  and self._in_window(o, pose)]
        clearance = p.robot_radius + hold.radius + p.safety_margin / 2
        robot = np.array(pose[:2], dtype=np.float64)
        standing = track is not None and stamp - hold.moving > p.give_way_patience
        lost = stamp - hold.seen > max(p.mover_memory, p.give_way_patience)
        if (stamp > hold.until or others or standing or lost
                or passed(robot, np.asarray(hold.position, dtype=np.float64),
                          np.asarray(hold.way, dtype=np.float64), clearance)):
            self.hold = None
            return None
        # The mover's place is known better as it comes: a spot it would now pass
        # touching (the margin used up; a track's centre errs by centimetres toward the
        # side it is seen from) is looked for again, on the same side.
        position = np.asarray(hold.position, dtype=np.float64)
        way = np.asarray(hold.way, dtype=np.float64)
        held = np.asarray(hold.spot, dtype=np.float64)[None, :]
        if offsets(held, position, way)[0] * hold.side < p.robot_radius + hold.radius:
            better = self._spot_aside(robot, pose[2], position, way,
                                      math.hypot(*hold.velocity), hold.radius, hold.side,
                                      hold.overtaking)
            if better is not None:
                hold.spot = (float(better[0]), float(better[1]))
        spot = np.asarray(hold.spot, dtype=np.float64)
        hold.reached = hold.reached or math.dist(pose[:2], hold.spot) <= p.subtarget_reached / 3
        # The spot's lane: square to it along the mover's line, and on the robot's way.
        go = np.asarray(hold.lane, dtype=np.float64)
        on_lane = spot + float((robot - spot) @ way) * way
        ahead = on_lane + p.lookahead * go
        assert self.costmap is not None  # a hold starts only on a map
        lane_free = not self.costmap.blocked_at(
            path_points(on_lane, go, p.lookahead, p.map_resolution / 2)).any()
        drive: Callable[[float, float, float, tuple[float, float], float, float, float],
                        tuple[float, float]]
        if hold.overtaking:
            # The spot lies ahead: swerve into its lane and go on along it, at top speed
            # until in the lane (to half a map cell), then at cruise speed. Where the map
            # blocks the lane, to the spot at top speed, and there stand, facing the mover.
            if lane_free:
                short = float(offsets(np.vstack([spot, robot]), position, way) @ [1.0, -1.0])
                target = (float(ahead[0]), float(ahead[1]))
                into = short * hold.side > p.map_resolution / 2
                speed = p.max_speed if into else p.cruise_speed
            elif not hold.reached:
                target, speed = hold.spot, p.max_speed
            else:
                target, speed = hold.position, 0.0
            drive = command_toward
        elif not hold.reached:
            target, speed = hold.spot, p.cruise_speed
            bearing = math.atan2(target[1] - pose[1], target[0] - pose[0])
            drive = backing_toward if math.cos(bearing - pose[2]) < 0.0 else command_toward
        else:
            # Keep to this side of the mover's line and go on along it while the map
            # leaves the lane free a look-ahead on; else stand there, facing the mover.
            if lane_free:
                target, speed = (float(ahead[0]), float(ahead[1])), p.cruise_speed
                along = math.atan2(go[1], go[0])
                if abs(wrap_angle(along - pose[2])) > math.radians(p.safety_fan_deg):
                    speed = 0.0  # square to the lane first: turning on the move drifts
            else:
                target, speed = hold.position, 0.0
            drive = command_toward
        v, omega = drive(pose[0], pose[1], pose[2], target, speed, p.heading_gain, p.max_omega)
        if v < 0.0 and self._backs_into_map(pose, v, omega):
            v = 0.0  # nothing behind the robot would stop it: stand, turning as asked
        letter: ScenarioLetter = "g" if hold.overtaking else "f"
        return Decision(v, omega, target, letter, "give_way", hold.mover, "dynamic", speed)

    # -- the movers out of view --------------------------------------------------------

    def remember_movers(self, obstacles: list[Obstacle], stamp: float,
                        scan: ScanData | None,
                        robot: tuple[float, float]) -> list[tuple[Obstacle, float]]:
        """The movers whose tracks are lost, predicted at constant velocity to ``stamp``,
        each with the seconds since it was last seen. The 180-degree laser does not see
        beside and behind the robot: a crosser that leaves its view while the robot turns
        is still on its way. One is forgotten after ``mover_memory`` s, when the laser
        should see it where it is predicted and does not, or when a mover tracked now is
        where it is predicted (seen again, under a new track)."""
        p = self.p
        moving = [o for o in obstacles if self._moving(o)]
        live = {o.id for o in obstacles}
        for ob in moving:
            self.last_seen_movers[ob.id] = (ob, stamp)
        moving_ids = {o.id for o in moving}
        kept: dict[int, tuple[Obstacle, float]] = {}
        unseen: list[tuple[Obstacle, float]] = []
        for ob_id, (ob, seen) in self.last_seen_movers.items():
            if ob_id in live:
                if ob_id in moving_ids:
                    kept[ob_id] = (ob, seen)
                continue  # tracked, but no longer moving: the track says where it is
            age = stamp - seen
            where = (ob.position[0] + ob.velocity[0] * age, ob.position[1] + ob.velocity[1] * age)
            reach = ob.radius + p.safety_growth * self.top_speeds.get(ob_id, 0.0) * age
            # Past mover_memory a mover is forgotten unless it is still coming at the
            # robot: a walker that follows it out of view is there until it has passed.
            if age > p.mover_memory and (p.mover_memory <= 0.0
                                         or not self._coming_at(ob, where, reach, robot)):
                continue
            if scan is not None and should_be_seen(scan, where, ob.radius):
                continue
            if any(self._same_mover(ob, o, where, reach) for o in moving):
                continue
            kept[ob_id] = (ob, seen)
            unseen.append((dataclasses.replace(ob, position=where), age))
        self.last_seen_movers = kept
        return unseen

    def _coming_at(self, ob: Obstacle, where: tuple[float, float], reach: float,
                   robot: tuple[float, float]) -> bool:
        """Whether a mover predicted at ``where`` (its disc grown to ``reach``) still walks
        toward the robot's place ``robot``, inside the window, on a line that passes it
        closer than the clearance the planner keeps, and fast enough to get there within
        ``safety_horizon``: a walker that has stopped out of view (at the end of its
        walk, say) is still predicted at the few cm/s its track last showed, and must not
        hold the robot for ever from metres away."""
        p = self.p
        dx, dy = robot[0] - where[0], robot[1] - where[1]
        vx, vy = ob.velocity
        speed = math.hypot(vx, vy)
        if speed < 1e-9 or dx * vx + dy * vy <= 0.0:
            return False  # standing, or past the robot
        if math.hypot(dx, dy) - ob.radius > p.window_radius:
            return False
        gap = (dx * vx + dy * vy) / speed - reach - p.robot_radius
        if gap > speed * p.safety_horizon:
            return False  # too slow to reach the robot's place within the horizon
        across = abs(dx * vy - dy * vx) / speed
        return across <= reach + p.robot_radius + p.safety_margin

    @staticmethod
    def _same_mover(lost: Obstacle, track: Obstacle, where: tuple[float, float],
                    reach: float) -> bool:
        """Whether ``track`` is plausibly the ``lost`` mover seen again: where it is
        predicted (within ``reach``), walking about the same way (the velocities differ by
        at most half the faster speed). A crowd's other walkers pass near a lost one's
        predicted place too; they do not make it seen again."""
        if math.dist(track.position, where) > reach + track.radius:
            return False
        faster = max(math.hypot(*lost.velocity), math.hypot(*track.velocity))
        return math.dist(lost.velocity, track.velocity) <= 0.5 * faster

    # -- stage: the map ----------------------------------------------------------------

    def update_map(self, pose: tuple[float, float, float], obstacles: list[Obstacle],
                   scan: ScanData | None, stamp: float) -> None:
        """Ray-trace the scan into the occupancy grid; the returns on movers (tracks
        typed dynamic) are left out."""
        p = self.p
        if not p.use_map:
            return
        if self.costmap is None:
            assert self.start is not None
            start = (float(self.start[0]), float(self.start[1]))
            goal = (float(self.goal[0]), float(self.goal[1]))
            self.costmap = Costmap(
                start, goal, resolution=p.map_resolution, decay=p.map_decay,
                inflation=p.robot_radius + p.safety_margin, confirm=p.map_confirm,
                wall_decay=p.map_wall_decay, wall_confirm=p.map_wall_confirm,
                padding=p.map_padding,
                max_size=p.map_max_size)
        if scan is None:
            return
        self.costmap.update(scan, stamp, mover_discs(obstacles))

    # -- stage: the global path --------------------------------------------------------

    def to_go(self, robot: Vec) -> float:
        """Distance still to go along the global path (plus the way back onto it), m."""
        if self.path is None or self.lengths is None:
            return c_hypot(*(self.goal - robot))
        s0, off = project(self.path, robot, self.lengths)
        return float(self.lengths[-1]) - s0 + off

    def replan_reason(self, robot: Vec, stamp: float) -> str | None:
        """Why the global path must be planned again now, or None. Obstacles in the
        window are the local layer's; the path is planned again when the local layer
        asks (no way round), when the stop zone refuses a way the map blocks within the
        window (``step``), when the robot has left the path (after a detour), or when the
        map blocks the path beyond the window."""
        p = self.p
        if self.replan_asked is not None:
            return self.replan_asked
        if self.path is None:
            return "no path"
        if self.costmap is None:
            return None
        if self.plan is not None and not self.plan.found:
            # No way known: keep the old path and look again (the map changes).
            return "retry" if stamp - self.last_replan >= p.replan_period else None
        if self.detour is not None:
            return None
        s0, off = project(self.path, robot, self.lengths)
        if off > p.path_deviation:
            return "off the path"
        if stamp - self.last_replan < p.replan_period:
            return None
        beyond = first_blocked(self.costmap, self.path, s0 + p.window_radius,
                               p.map_resolution, self.lengths)
        if beyond is not None:
            return "blocked beyond the window"
        if self._straight_way_open(robot, s0):
            return "straight way open"
        return None

    def _straight_way_open(self, robot: Vec, s0: float) -> bool:
        """Whether the straight way from the robot to the goal is free on the map and
        shorter than the rest of the path (from ``s0`` on) by more than
        ``path_deviation``: the path goes round something the map no longer holds (the
        marks of a walker standing at its start, cleared by the beams since). Nav2
        plans again every second; a path kept while it stays free needs this test
        instead. One line's cells (about 16 us) cost far less than a search, and are
        looked at each cycle from the first one a re-plan is due."""
        assert self.costmap is not None and self.path is not None and self.lengths is not None
        straight = c_hypot(*(self.goal - robot))
        if float(self.lengths[-1]) - s0 - straight <= self.p.path_deviation:
            return False
        line = np.vstack([robot, self.goal])
        return first_blocked(self.costmap, line, 0.0, self.p.map_resolution) is None

    def _blocked_within_window(self, robot: Vec, stamp: float) -> bool:
        """Whether the global path runs into what the map holds within the window, off
        a detour, with a replan due (at most once per ``replan_period``)."""
        p = self.p
        if (self.costmap is None or self.path is None or self.lengths is None
                or self.detour is not None or stamp - self.last_replan < p.replan_period):
            return False
        s0, _ = project(self.path, robot, self.lengths)
        at = first_blocked(self.costmap, self.path, s0, p.map_resolution, self.lengths)
        return at is not None and at < s0 + p.window_radius

    def arrival_radius(self) -> float:
        """How close to ``goal`` the robot stops for good: ``arrival_distance`` at the
        run's own goal; beside it (``settle_goal``), what keeps the stop within the
        goal's tolerance, with a hundredth of it to spare."""
        p = self.p
        off = c_hypot(*(self.goal - self.mission_goal))
        if off < 1e-9:
            return p.arrival_distance()
        return min(p.arrival_distance(), p.goal_tolerance * 0.99 - off)

    def settle_goal(self, robot: Vec) -> None:
        """Within the window of the goal, move the point the robot stops at off what
        the map holds there (``settle_point``): first within ``SETTLE_REACH`` of the
        tolerance, clear by the robot's radius plus half ``safety_margin``; failing that,
        within ``SETTLE_REACH_CLOSE`` of it, clear by the radius alone. The global
        path's end moves with it, and it moves back to the goal when the map clears.
        Without a map, or out of the window, the goal stays where it is."""
        p = self.p
        if self.costmap is None or not p.use_map:
            return
        if c_hypot(*(self.mission_goal - robot)) > p.window_radius:
            return
        margin = p.robot_radius + p.safety_margin / 2
        if goal_clear(self.costmap, self.mission_goal, margin):
            aim = self.mission_goal  # (most cycles: the goal in the open)
        else:
            aim = settle_point(self.costmap, self.mission_goal, robot, margin,
                               SETTLE_REACH * p.goal_tolerance)
            if np.array_equal(aim, self.mission_goal):  # none clear with the margin
                aim = settle_point(self.costmap, self.mission_goal, robot, p.robot_radius,
                                   SETTLE_REACH_CLOSE * p.goal_tolerance)
        if c_hypot(*(aim - self.goal)) < 1e-9:
            return
        self.goal = aim
        if self.path is not None and len(self.path) >= 2:
            path = self.path.copy()
            path[-1] = self.goal
            self._set_path(path, "goal settled")

    def update_path(self, robot: Vec, stamp: float, planned: GlobalPlan | None = None) -> None:
        """Plan the global path on the map when it is needed (see ``replan_reason``);
        ``planned``: the plan a caller has just made on this map for that reason."""
        if self.costmap is None:
            return
        reason = self.replan_reason(robot, stamp)
        if reason is None:
            return
        self.replan_asked = None
        self.last_replan = stamp
        plan = planned if planned is not None else plan_path(self.costmap, robot, self.goal,
                                                             reason)
        if not plan.found and plan.reason == "goal occupied" and self.on_last_stretch:
            # The goal's cell holds the wall it lies against, but the scan has room
            # within the tolerance along the straight way: that is the path.
            plan = GlobalPlan(np.vstack([robot, self.goal]),
                              c_hypot(*(self.goal - robot)), LAST_STRETCH)
        self.plan = plan
        if not plan.found:
            return  # keep driving the old path; recovery takes it from here
        before = self.to_go(robot)
        self._set_path(plan.points, reason)
        after = self.to_go(robot)
        if after > before:  # a longer way is no lack of progress on the old one
            self.recovery.check_to_go = max(self.recovery.check_to_go, after)

    # -- stage: recovery ---------------------------------------------------------------

    def _known_free_behind(self, pose: tuple[float, float, float]) -> bool:
        """Whether reversing ``backup_distance`` straight back stays where the robot's
        centre has already been (within half its radius): the laser does not see
        behind, the trail is the only knowledge of that space."""
        p = self.p
        if len(self.trail) < 2:
            return False
        back = np.array([-math.cos(pose[2]), -math.sin(pose[2])])
        here = np.asarray(pose[:2], dtype=np.float64)
        samples = path_points(here, back, p.backup_distance, p.robot_radius / 4)
        trail = np.asarray(self.trail, dtype=np.float64)
        gaps = np.hypot(samples[:, None, 0] - trail[None, :, 0],
                        samples[:, None, 1] - trail[None, :, 1]).min(axis=1)
        return bool((gaps <= p.robot_radius / 2).all())

    def walled_in(self, robot: Vec, stamp: float, fresh: bool = False) -> bool:
        """Whether the wall memory (``Costmap.cut_off``: every obstacle confirmed and no
        beam through it since, with no decay) closes the goal off from the robot, for a
        disc of the robot's radius. Looked at again at most every ``replan_period`` s
        (at once with ``fresh``)."""
        if self.costmap is None:
            return False
        if fresh or stamp - self.walled_stamp >= self.p.replan_period:
            self.walled_stamp = stamp
            self.walled = self.costmap.cut_off(robot, self.goal, self.p.robot_radius)
        return self.walled

    def _walled_off(self) -> None:
        """The goal is given up on: when the map still shows a way (through walls it has
        forgotten) but the wall memory closes the goal off, the plan becomes "no way", so
        the path published is empty, not the one through the forgotten walls."""
        if self.walled and (self.plan is None or self.plan.found):
            self.plan = GlobalPlan(np.empty((0, 2)), math.inf, "the walls seen close it off")
        elif self.no_room and (self.plan is None or self.plan.found):
            self.plan = GlobalPlan(np.empty((0, 2)), math.inf, NO_ROOM)

    def look_for_room(self, robot: Vec, heading: float, scan: ScanData | None,
                      obstacles: Sequence[Obstacle]) -> None:
        """Beyond the paper (``final_approach_speed``), once a scan: when the goal lies
        beside what the laser sees (within the window and its view, not clear on the map,
        as for ``last_stretch``), whether no point within the run's tolerance of it
        keeps ``_approach_clearance`` off the scan's returns
        (``follow.room_near``): no robot the stop zone lets come that near a return
        stands within the tolerance. Kept in ``no_room`` until the goal is seen again
        (recovery gives the goal up on it, after a round of steps); a goal in the open
        has room. The returns on the movers (tracks typed dynamic in ``obstacles``) are
        left out as the map leaves them out: a mover walking over the goal leaves it."""
        p = self.p
        if self.costmap is None or c_hypot(*(self.mission_goal - robot)) > p.window_radius:
            return
        if not self._beside_in_view(robot, heading, scan):
            if goal_clear(self.costmap, self.mission_goal,
                          p.robot_radius + p.safety_margin / 2):
                self.no_room = False
            return
        assert scan is not None
        # (rings 1 cm apart, or a 25th of a tolerance over 0.25 m: at most ~2000 points)
        returns = off_discs(scan.returns, mover_discs(obstacles), p.map_resolution)
        self.no_room = not room_near((float(self.mission_goal[0]), float(self.mission_goal[1])),
                                     returns, self._approach_clearance(),
                                     p.goal_tolerance, step=max(0.01, p.goal_tolerance / 25))
        self.room_seen = not self.no_room

    def _way_known(self) -> bool:
        """Whether a way to the goal is known: the global plan found one, or the goal's
        cell holds the wall it lies against ("goal occupied") while the scan, when last
        looked at, left room within the tolerance (``look_for_room``): the map's 0.1 m
        cells are coarser than the room."""
        if self.plan is None or self.plan.found:
            return True
        return self.plan.reason == "goal occupied" and self.room_seen

    def recover(self, pose: tuple[float, float, float], stamp: float,
                scan: ScanData | None) -> Decision | None:
        """The command of the recovery step under way, or None when none is."""
        r = self.recovery
        p = self.p
        robot = np.array(pose[:2], dtype=np.float64)
        goal_xy = (float(self.goal[0]), float(self.goal[1]))
        if r.active is None and r.level >= len(STEPS) and (
                not self._way_known() or self.walled_in(robot, stamp, fresh=True)
                or self.no_room):
            # Every recovery step tried and still no way on the map: give up, clearly.
            r.unreachable = True
            self._walled_off()
            return Decision(0.0, 0.0, goal_xy, "a", "unreachable", None, None, 0.0)
        act = r.active
        if act is None:
            return None
        elapsed = stamp - act.started

        def done() -> None:
            r.finish(stamp, self.to_go(robot))

        if act.step == "replan":
            if self.costmap is not None:
                # Forget what the map has not seen in the last second beyond the window:
                # stale marks far off are dropped. Within the window the map is kept: the
                # 180-degree laser does not see beside and behind the robot, and a wall
                # forgotten there would draw the new path through it.
                self.costmap.forget_older_than(stamp - 1.0, keep=(robot, p.window_radius))
                self.last_replan = -math.inf
                self.replan_asked = "recovery"
                self.update_path(robot, stamp)
            done()
            return Decision(0.0, 0.0, goal_xy, "a", "replan", None, None, 0.0)
        if act.step == "spin":
            turn = wrap_angle(pose[2] - act.last_heading)
            act.turned += abs(turn)
            act.last_heading = pose[2]
            bound = r.s.spin_angle / (0.5 * p.max_omega) + 5.0
            if act.turned >= r.s.spin_angle or elapsed > bound:
                done()
                self.replan_asked = "after spin"
                return None
            return Decision(0.0, p.max_omega, goal_xy, "a", "spin", None, None, 0.0)
        if act.step == "back_up":
            moved = math.dist(act.pose[:2], pose[:2])
            bound = 2.0 * r.s.backup_distance / r.s.backup_speed + 2.0
            if elapsed == 0.0 and not self._known_free_behind(pose):
                done()  # nothing known behind: skip the step (the wait comes next)
                return Decision(0.0, 0.0, goal_xy, "a", "back_up", None, None, 0.0)
            if moved >= r.s.backup_distance or elapsed > bound:
                done()
                self.replan_asked = "after back-up"
                return None
            return Decision(-r.s.backup_speed, 0.0, goal_xy, "a", "back_up", None, None,
                            r.s.backup_speed)
        # wait
        if elapsed >= r.s.wait_time:
            done()
            self.replan_asked = "after wait"
            return None
        return Decision(0.0, 0.0, goal_xy, "a", "wait", None, None, 0.0)

    # -- stage: the stop zone ----------------------------------------------------------

    def brake_for_goal(self, d: Decision, pose: tuple[float, float, float],
                       scan: ScanData | None) -> Decision:
        """``goal_braking``: on a free run at the goal itself (``keep``), the speed from
        which braking at the bridge's ``decel`` stops the robot on the goal, sqrt(2 decel
        d), where the local layer slowed to the distance d (one second of travel): a fast
        robot does not spend its last metre slowing down. Only where the stop zone at that
        speed holds no return even after ``zone_reaction`` s more at it, so what stands
        beyond the goal never makes the zone refuse an approach the slower one made; and
        not toward a goal settled off what the map holds there (``settle_goal``)."""
        p = self.p
        if (not p.goal_braking or d.action != "keep" or d.v <= 0.0 or scan is None
                or not p.stop_zone or not self._is_goal(d.target)
                or not np.array_equal(self.goal, self.mission_goal)):
            return d
        v, omega = command_toward(pose[0], pose[1], pose[2], d.target, d.speed,
                                  p.heading_gain, p.max_omega, brake=p.decel)
        if v <= d.v:
            return d
        nearer = scan.ranges.astype(np.float32) - np.float32(v * p.zone_reaction)
        if p.blocks(nearer, scan.angle_min, scan.angle_increment, scan.range_max, v,
                    p.robot_radius):
            return d
        return dataclasses.replace(d, v=v, omega=omega)

    def _is_goal(self, point: Vec | tuple[float, float]) -> bool:
        """Whether ``point`` is the goal the robot stops at (the settled one)."""
        return math.dist((float(point[0]), float(point[1])),
                         (float(self.goal[0]), float(self.goal[1]))) <= 1e-9

    def _creep_to_goal(self, d: Decision, pose: tuple[float, float, float],
                       ranges: npt.NDArray[np.float32], scan: ScanData) -> Decision | None:
        """``final_approach_speed``: the decision at that speed when the robot heads for
        the goal (as settled), the goal lies within the zone's reach at the speed asked
        (what refuses the motion may stand beyond it: a wall behind a goal close to it),
        and the zone at the creep holds no return; None otherwise. The zone is shortest
        at a creep: the robot comes as near as the bridge lets any robot come."""
        p = self.p
        creep = p.final_approach_speed
        if creep <= 0.0 or creep >= d.v or not self._is_goal(d.target):
            return None
        reach = p.robot_radius + stop_distance(d.v, p.zone_reaction, p.decel, p.zone_margin)
        if math.dist(pose[:2], (float(d.target[0]), float(d.target[1]))) > reach:
            return None
        if p.blocks(ranges, scan.angle_min, scan.angle_increment, scan.range_max,
                    max(creep, self.last_v), p.robot_radius):
            return None
        return dataclasses.replace(d, v=creep)

    def guard_stop_zone(self, d: Decision, pose: tuple[float, float, float],
                        scan: ScanData | None) -> Decision:
        """Never command forward motion into the motor bridge's stop zone (the same
        geometry, the same pure check): turn in place toward the free heading nearest
        the target instead."""
        p = self.p
        if scan is None or d.v <= 0.0 or not p.stop_zone:
            return d
        ranges = scan.ranges.astype(np.float32)
        if not p.blocks(ranges, scan.angle_min, scan.angle_increment, scan.range_max,
                        max(d.v, self.last_v), p.robot_radius):
            return d
        creep = self._creep_to_goal(d, pose, ranges, scan)
        if creep is not None:
            return creep
        error = math.atan2(d.target[1] - pose[1], d.target[0] - pose[0]) - pose[2]
        error = wrap_angle(error)
        turns = sorted((math.radians(g) for g in range(-90, 91, 10)),
                       key=lambda g: (abs(g - error), g))
        free = next((g for g in turns if abs(g) > 1e-9 and not p.blocks(
            ranges, scan.angle_min - g, scan.angle_increment, scan.range_max, p.cruise_speed,
            p.robot_radius)), None)
        goal_side = error if abs(error) > 1e-3 else 1.0
        g = free if free is not None else math.copysign(math.pi / 2, goal_side)
        omega = math.copysign(max(min(abs(p.heading_gain * g), p.max_omega),
                                  0.3 * p.max_omega), g)
        return dataclasses.replace(d, v=0.0, omega=omega, refused=True,
                                   action="safety_stop" if d.action == "keep" else d.action)
