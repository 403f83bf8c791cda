"""The global path on the map: the straight line when nothing is known, through the gap
of a wall, round a dead-end cup, and no way to a goal that is walled in. Randomised
layouts (gap positions, cup sizes) check that nothing is tuned to one scene."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from tests.planner.scans import cup, scan_of, wall_with_gap
from zenav.services.planner.costmap import Costmap
from zenav.services.planner.global_path import (
    arc_lengths,
    first_blocked,
    goal_clear,
    plan_path,
    point_at,
    project,
    settle_point,
    visible,
)

START = np.array([0.0, 4.0])
GOAL = np.array([8.0, 4.0])


def mapped(boxes, poses=((0.0, 4.0, 0.0),), stamps=(0.0, 1.5)) -> Costmap:
    cm = Costmap((0.0, 4.0), (8.0, 4.0), resolution=0.1, decay=60.0, inflation=0.35,
                 confirm=1.0, padding=3.0, max_size=100.0)
    for t in stamps:
        for pose in poses:
            cm.update(scan_of(pose, boxes=boxes), t)
    return cm


def clear_of_blocked(cm: Costmap, points: np.ndarray) -> bool:
    free = ~cm.blocked()
    return all(visible(free, cm, a, b) for a, b in itertools.pairwise(points))


def test_with_nothing_known_the_path_is_the_straight_start_goal_line() -> None:
    cm = mapped([], stamps=())
    plan = plan_path(cm, START, GOAL)
    assert plan.found
    np.testing.assert_array_equal(plan.points, np.vstack([START, GOAL]))
    assert plan.length == pytest.approx(8.0)


def test_a_clear_view_keeps_the_straight_line() -> None:
    plan = plan_path(mapped([(3.0, 6.0, 4.0, 7.0)]), START, GOAL)
    assert len(plan.points) == 2


def test_the_path_goes_through_the_gap_of_a_wall_across_the_way() -> None:
    cm = mapped(wall_with_gap(4.0, 5.3, 6.3))
    plan = plan_path(cm, START, GOAL)
    assert plan.found
    crossing = [p for a, b in zip(plan.points[:-1], plan.points[1:], strict=True)
                for p in [a + (b - a) * ((4.0 - a[0]) / (b[0] - a[0]))]
                if (a[0] - 4.0) * (b[0] - 4.0) < 0]
    assert len(crossing) == 1 and 5.3 + 0.35 <= crossing[0][1] <= 6.3 - 0.35
    assert clear_of_blocked(cm, plan.points)
    assert len(plan.points) <= 5  # any-angle: a few vertices, not a staircase of cells


def test_the_path_goes_round_a_dead_end_cup_not_into_it() -> None:
    cm = mapped(cup(4.5, 4.0, width=2.0, depth=1.5))
    plan = plan_path(cm, START, GOAL)
    assert plan.found and clear_of_blocked(cm, plan.points)
    assert max(abs(p[1] - 4.0) for p in plan.points) > 1.0  # round the outside


def test_a_goal_on_an_obstacle_or_walled_in_has_no_way() -> None:
    near = (3.0, 4.0, 0.0)  # within the laser's 8 m of the goal
    on_goal = mapped([(8.02, 3.5, 8.5, 4.5)], poses=(near,))  # its face crosses the goal cell
    assert not plan_path(on_goal, np.array(near[:2]), GOAL).found
    ring = [(6.5, 2.5, 9.5, 2.7), (6.5, 5.3, 9.5, 5.5), (6.5, 2.5, 6.7, 5.5),
            (9.3, 2.5, 9.5, 5.5)]
    walled = mapped(ring, poses=((0.0, 4.0, 0.0), (8.0, 4.0, 0.0), (8.0, 4.0, math.pi)))
    assert not plan_path(walled, START, GOAL).found


@pytest.mark.parametrize("seed", range(6))
def test_random_gaps_and_cups_are_found_whatever_their_place(seed: int) -> None:
    rng = np.random.default_rng(seed)
    gap_low = float(rng.uniform(1.0, 6.5))
    width = float(rng.uniform(0.9, 1.4))
    x = float(rng.uniform(3.0, 5.0))
    cm = mapped(wall_with_gap(x, gap_low, gap_low + width))
    plan = plan_path(cm, START, GOAL)
    assert plan.found and clear_of_blocked(cm, plan.points), (gap_low, width, x)
    size = float(rng.uniform(1.2, 2.6))
    cm = mapped(cup(float(rng.uniform(4.0, 6.0)), 4.0 + float(rng.uniform(-0.3, 0.3)),
                    width=size, depth=float(rng.uniform(0.8, 2.0))))
    plan = plan_path(cm, START, GOAL)
    assert plan.found and clear_of_blocked(cm, plan.points), size


def crosses(points: np.ndarray, box: tuple[float, float, float, float]) -> bool:
    """Whether the polyline passes through the box (sampled every centimetre)."""
    for a, b in itertools.pairwise(points):
        t = np.linspace(0.0, 1.0, max(2, math.ceil(float(np.hypot(*(b - a))) / 0.01)))
        p = a[None, :] + t[:, None] * (b - a)[None, :]
        if ((p[:, 0] >= box[0]) & (p[:, 0] <= box[2]) & (p[:, 1] >= box[1])
                & (p[:, 1] <= box[3])).any():
            return True
    return False


@pytest.mark.parametrize("heading", [-0.4, 0.0, 0.5])
def test_pressed_against_a_cups_back_wall_the_path_leaves_by_the_mouth(heading: float) -> None:
    # The robot drove into a cup and stands 0.3 m from its back wall, the goal straight
    # behind that wall. Re-planned from there, the path must go out of the cup's mouth
    # and round it, not through the back wall the laser sees side-on from close by.
    walls = cup(5.03, 4.0, width=2.2, depth=2.0)  # its face inside a cell, not on an edge
    back = walls[0]
    robot = (4.73, 3.7, heading)
    approach = [(x, 4.0 + 0.1 * x - 0.3, 0.0) for x in np.arange(1.0, 4.73, 0.35)]
    cm = Costmap((0.0, 4.0), (8.0, 4.0), resolution=0.1, decay=60.0, inflation=0.3,
                 confirm=1.0, padding=3.0, max_size=100.0)
    stamp = 0.0
    for k, pose in enumerate(approach + [robot] * 15):
        cm.update(scan_of(pose, boxes=walls, noise=0.01, seed=k), stamp)
        stamp += 0.1
    plan = plan_path(cm, np.array(robot[:2]), GOAL)
    assert plan.found
    assert not crosses(plan.points, back)
    assert min(p[0] for p in plan.points) < 5.03 - 2.0  # out by the mouth


def test_the_space_beyond_the_grid_is_no_way_for_the_global_path() -> None:
    # A grid held to 6 m a side cannot grow to a goal 12 m away: there is no map of the
    # space between, so no path through it (before: the straight line, as if free).
    cm = Costmap((0.0, 0.0), (1.0, 0.0), resolution=0.1, decay=60.0, inflation=0.3,
                 confirm=0.0, padding=2.0, max_size=6.0)
    cm.update(scan_of((0.0, 0.0, 0.0), boxes=[(2.0, 1.0, 2.2, 2.0)]), 0.0)
    far = np.array([12.0, 0.0])
    assert not plan_path(cm, np.zeros(2), far).found
    nx, ny = cm.shape
    top = cm.origin + np.array([nx, ny]) * cm.resolution
    inside, beyond = np.array([0.0, 0.0]), np.array([top[0] + 1.0, 0.0])
    free = ~cm.blocked()
    assert visible(free, cm, inside, np.array([top[0] - 0.5, 0.0]))
    assert not visible(free, cm, inside, beyond)
    # A path that runs off the grid is blocked from where it leaves it.
    leaves = first_blocked(cm, np.vstack([inside, beyond]), 0.0, 0.1)
    assert leaves is not None and leaves == pytest.approx(top[0], abs=0.11)


def test_a_start_in_the_inflation_is_joined_to_free_space_on_its_side_of_a_thin_wall() -> None:
    # The robot stands in a slot narrower than the inflation allows, 0.4 m from its
    # mouth, between two thin walls with open space beyond them. The free cells just
    # across a wall are nearer than those out of the mouth; the path must leave by the
    # mouth, not start behind a wall.
    walls = [(-0.8, 0.28, 3.0, 0.36), (-0.8, -0.36, 3.0, -0.28)]
    cm = Costmap((0.0, 0.0), (4.0, 0.0), resolution=0.1, decay=60.0, inflation=0.3,
                 confirm=0.0, padding=3.0, max_size=100.0)
    robot = np.array([-0.4, 0.0])
    for k, heading in enumerate((0.0, math.pi, math.pi / 2, -math.pi / 2)):
        cm.update(scan_of((-0.4, 0.0, heading), boxes=walls), 0.1 * k)
    assert cm.blocked_at(robot[None, :])[0]
    plan = plan_path(cm, robot, np.array([-3.0, 2.0]))
    assert plan.found
    assert not any(crosses(plan.points, box) for box in walls)


def numpy_project(points: np.ndarray, p: np.ndarray) -> tuple[float, float]:
    """The projection as numpy array operations (the code ``project_on`` replaced)."""
    a, b = points[:-1], points[1:]
    ab = b - a
    l2 = np.maximum((ab * ab).sum(axis=1), 1e-18)
    t = np.clip(((p[None, :] - a) * ab).sum(axis=1) / l2, 0.0, 1.0)
    near = a + t[:, None] * ab
    d = np.hypot(*(near - p[None, :]).T)
    k = int(np.argmin(d))
    s = arc_lengths(points)
    return float(s[k] + t[k] * math.sqrt(l2[k])), float(d[k])


@pytest.mark.parametrize("seed", range(20))
def test_project_is_the_numpy_projection_to_the_bit(seed: int) -> None:
    """``project`` (compiled, with the arc lengths given or not) against the numpy code it
    replaced: random polylines, some with repeated vertices (zero-length segments), and
    points on them, beside them, at a vertex and far off."""
    rng = np.random.default_rng(seed)
    for _ in range(100):
        points = rng.uniform(-5.0, 5.0, (int(rng.integers(2, 9)), 2))
        if rng.random() < 0.3:
            points[1] = points[0]
        p = rng.uniform(-8.0, 8.0, 2) if rng.random() < 0.8 else points[-1].copy()
        want = numpy_project(points, p)
        assert project(points, p) == want
        assert project(points, p, arc_lengths(points)) == want


def test_project_needs_a_path_of_two_points() -> None:
    with pytest.raises(ValueError):
        project(np.array([[0.0, 0.0]]), np.array([1.0, 1.0]))


def numpy_point_at(points: np.ndarray, s: float) -> np.ndarray:
    """The point at an arc length as numpy operations (the code ``point_on`` replaced)."""
    lengths = arc_lengths(points)
    s = min(max(s, 0.0), float(lengths[-1]))
    k = int(np.searchsorted(lengths, s, side="right") - 1)
    k = min(k, len(points) - 2)
    seg = float(lengths[k + 1] - lengths[k])
    t = 0.0 if seg < 1e-12 else (s - float(lengths[k])) / seg
    return np.asarray(points[k] + t * (points[k + 1] - points[k]), dtype=np.float64)


@pytest.mark.parametrize("seed", range(20))
def test_point_at_is_the_numpy_point_to_the_bit(seed: int) -> None:
    """``point_at`` (compiled) against the numpy code it replaced: random polylines with
    repeated vertices now and then, arc lengths before the start, at every vertex, in
    between and past the end."""
    rng = np.random.default_rng(seed)
    for _ in range(100):
        points = rng.uniform(-5.0, 5.0, (int(rng.integers(2, 9)), 2))
        if rng.random() < 0.3:
            points[int(rng.integers(1, len(points)))] = points[0]
        lengths = arc_lengths(points)
        for s in [*lengths.tolist(), *rng.uniform(-1.0, float(lengths[-1]) + 1.0, 5)]:
            want = numpy_point_at(points, s).tobytes()
            assert point_at(points, s).tobytes() == want
            assert point_at(points, s, lengths).tobytes() == want


def cell_square_gap(cm: Costmap, point: np.ndarray) -> float:
    """Distance from ``point`` to the nearest occupied cell's square, cell by cell."""
    best = math.inf
    for i, j in np.argwhere(cm.lethal_grid()):
        x0, y0 = cm.origin + np.array([i, j]) * cm.resolution
        dx = max(x0 - point[0], 0.0, point[0] - (x0 + cm.resolution))
        dy = max(y0 - point[1], 0.0, point[1] - (y0 + cm.resolution))
        best = min(best, math.hypot(dx, dy))
    return best


def test_a_goal_clear_of_the_map_is_where_the_robot_stops() -> None:
    cm = mapped([(5.0, 2.0, 5.5, 3.0)], stamps=(0.0, 1.5))
    assert np.array_equal(settle_point(cm, GOAL, START, 0.25, 0.2), GOAL)


def test_a_goal_beside_a_wall_settles_on_the_free_side_within_reach() -> None:
    """The wall's face is 0.1 m beyond the goal: the robot disc (0.2 m) cannot stand on
    the goal, and the point it stops at instead is clear of the wall's cells by the
    clearance, within reach of the goal, on the robot's side."""
    cm = mapped([(8.1, 2.0, 9.0, 6.0)], poses=((3.0, 4.0, 0.0),))
    assert cell_square_gap(cm, GOAL) < 0.2
    aim = settle_point(cm, GOAL, np.array([3.0, 4.0]), 0.2, 0.225)
    assert not np.array_equal(aim, GOAL)
    assert float(np.hypot(*(aim - GOAL))) <= 0.225 + 1e-9
    assert cell_square_gap(cm, aim) >= 0.2
    assert aim[0] + 0.2 <= 8.1  # the disc there clears the true face too
    # Too far to find such a point: the goal stays.
    assert np.array_equal(settle_point(cm, GOAL, np.array([3.0, 4.0]), 0.2, 0.05), GOAL)


def wall_beside_goal(seed: int, farthest: float) -> tuple[Costmap, np.ndarray]:
    """The map of a 0.5 m box whose face lies 0 to ``farthest`` m from the goal on a
    random side, seen from 3 m away on the other side, and the robot's place there."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * math.pi)
    face = rng.uniform(0.0, farthest)
    centre = GOAL + (face + 0.25) * np.array([math.cos(angle), math.sin(angle)])
    box = (centre[0] - 0.25, centre[1] - 0.25, centre[0] + 0.25, centre[1] + 0.25)
    robot = GOAL - 3.0 * np.array([math.cos(angle), math.sin(angle)])
    return mapped([box], poses=((*robot, angle),)), robot


@pytest.mark.parametrize("seed", range(8))
def test_settled_points_are_clear_and_within_reach_whatever_the_wall(seed: int) -> None:
    """A wall at a random side and distance of the goal (0.0-0.3 m from it): a point
    that differs from the goal is clear by the clearance and within reach, and the one
    returned is on the nearest ring that has a clear point."""
    cm, robot = wall_beside_goal(seed, 0.3)
    aim = settle_point(cm, GOAL, robot, 0.2, 0.25)
    if np.array_equal(aim, GOAL):
        assert cell_square_gap(cm, GOAL) >= 0.2 or all(
            cell_square_gap(cm, GOAL + r * np.array([math.cos(a), math.sin(a)])) < 0.2
            for r in np.arange(0.05, 0.25 + 1e-9, 0.05)
            for a in np.linspace(0, 2 * math.pi, 36, endpoint=False))
    else:
        reach = float(np.hypot(*(aim - GOAL)))
        assert reach <= 0.25 + 1e-9 and cell_square_gap(cm, aim) >= 0.2
        for r in np.arange(0.05, reach - 1e-6, 0.05):  # no nearer ring has a clear point
            assert all(cell_square_gap(cm, GOAL + r * np.array([math.cos(a), math.sin(a)]))
                       < 0.2 for a in np.linspace(0, 2 * math.pi, 36, endpoint=False))


@pytest.mark.parametrize("seed", range(8))
def test_the_goal_is_clear_exactly_when_every_cell_square_lies_beyond_the_clearance(
        seed: int) -> None:
    """``goal_clear`` (the planner's test before it looks for a point to settle at)
    against the distance to every occupied cell's square, one by one; and a clear goal
    is where ``settle_point`` stops, whatever its reach."""
    cm, robot = wall_beside_goal(seed, 0.5)
    gap = cell_square_gap(cm, GOAL)
    assert math.isfinite(gap)
    for clearance in (0.05, 0.1, 0.2, 0.3, 0.45, gap, np.nextafter(gap, math.inf)):
        assert goal_clear(cm, GOAL, clearance) == (gap >= clearance)
        if gap >= clearance:
            assert np.array_equal(settle_point(cm, GOAL, robot, clearance, 0.5), GOAL)
