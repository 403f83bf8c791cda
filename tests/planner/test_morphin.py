"""Simplified Morphin (Eq. 17), including the paper's worked example."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from zenav.services.planner.morphin import (
    Choice,
    Mover,
    cells_on_segment,
    choose_detour,
    morphin_cost,
)

KAPPA = (1.0, 1.3, 0.6)
NO_BOXES = (np.zeros((0, 2)), np.zeros((0, 2)))


def test_cells_on_a_horizontal_segment():
    cells = cells_on_segment(np.array([0.0, 0.0]), np.array([2.0, 0.0]), 1.0)
    assert cells == {(0, 0), (1, 0), (2, 0)}


def test_paper_worked_example_w1_is_0_2_w2_is_0_25_and_l1_wins():
    """Global path along y = 0 (cells of 1 m). l1 leaves the path's row of cells after
    4 shared cells, l2 after 3, and l1 has the smaller angle and ends nearer the target:
    W1 = 1/(4+1) = 0.2, W2 = 1/(3+1) = 0.25, and y(l1) < y(l2)."""
    cell = 1.0
    robot, goal = np.array([0.0, 0.0]), np.array([12.0, 0.0])
    global_cells = cells_on_segment(robot, goal, cell)
    length = 6.0
    g1, g2 = math.radians(10.0), math.radians(14.0)
    ends = [robot + length * np.array([math.cos(g), math.sin(g)]) for g in (g1, g2)]
    shared = [len(cells_on_segment(robot, end, cell) & global_cells) for end in ends]
    assert shared == [4, 3]
    w1, w2 = (1 / (1 + m) for m in shared)
    assert w1 == pytest.approx(0.2) and w2 == pytest.approx(0.25)
    dl1, dl2 = (float(np.hypot(*(goal - end))) / cell for end in ends)
    assert dl1 < dl2
    y1, y2 = morphin_cost(g1, dl1, w1, KAPPA), morphin_cost(g2, dl2, w2, KAPPA)
    assert y1 < y2


def test_the_centreline_through_an_obstacle_is_infinitely_expensive():
    robot, goal = np.array([0.0, 0.0]), np.array([10.0, 0.0])
    box = (np.array([[2.75, -0.25]]), np.array([[3.25, 0.25]]))
    choice = choose_detour(robot, np.array([3.0, 0.0]), goal, cells_on_segment(robot, goal, 0.5),
                           box, [], speed=0.1, cell=0.5, robot_radius=0.2, margin=0.1,
                           kappa=KAPPA, fan_step=math.radians(5), fan_max=math.radians(85),
                           extra_length=0.8)
    by_angle = {round(math.degrees(c.g)): c for c in choice.candidates}
    assert math.isinf(by_angle[0].cost)
    assert math.isinf(by_angle[5].cost) and math.isinf(by_angle[-5].cost)
    assert choice.best is not None
    best = choice.best
    assert abs(math.degrees(best.g)) <= 20  # the smallest angle that clears wins
    # it clears the box by the robot radius plus the margin all along
    for s in np.linspace(0, 1, 50):
        p = np.array(best.end) * s
        dx = max(2.75 - p[0], 0, p[0] - 3.25)
        dy = max(-0.25 - p[1], 0, p[1] - 0.25)
        assert math.hypot(dx, dy) >= 0.3 - 1e-9


def test_a_detour_under_way_keeps_its_side():
    robot, goal = np.array([0.0, 0.0]), np.array([10.0, 0.0])
    box = (np.array([[2.75, -0.25]]), np.array([[3.25, 0.25]]))
    cells = cells_on_segment(robot, goal, 0.5)

    def choose(side: int):
        return choose_detour(robot, np.array([3.0, 0.0]), goal, cells, box, [], speed=0.1,
                             cell=0.5, robot_radius=0.2, margin=0.1, kappa=KAPPA,
                             fan_step=math.radians(5), fan_max=math.radians(85),
                             extra_length=0.8, side=side, switch_penalty=10.0)

    left, right = choose(1), choose(-1)
    assert left.best is not None and right.best is not None
    assert left.best.g > 0 > right.best.g


def test_a_mover_blocks_the_candidates_it_would_meet():
    robot, goal = np.array([0.0, 0.0]), np.array([10.0, 0.0])
    cells = cells_on_segment(robot, goal, 0.5)
    head_on = Mover(np.array([4.0, 0.0]), np.array([-0.5, 0.0]), 0.2)
    choice = choose_detour(robot, np.array([2.0, 0.0]), goal, cells, NO_BOXES, [head_on],
                           speed=0.2, cell=0.5, robot_radius=0.2, margin=0.1, kappa=KAPPA,
                           fan_step=math.radians(5), fan_max=math.radians(85), extra_length=0.5)
    best = choice.best
    assert best is not None
    narrower = [c for c in choice.candidates if abs(c.g) < abs(best.g)]
    assert narrower and all(math.isinf(c.cost) for c in narrower)
    # along the chosen line at 0.2 m/s the robot stays clear of the mover at every instant
    length = math.hypot(*best.end)
    for t in np.linspace(0.0, length / 0.2, 200):
        robot_at = np.array(best.end) * (t * 0.2 / length)
        mover_at = np.array([4.0 - 0.5 * t, 0.0])
        assert np.hypot(*(robot_at - mover_at)) >= 0.5 - 0.02


def test_a_candidate_the_caller_finds_crossing_something_is_blocked():
    """``crosses`` (the planner's map) blocks what the boxes do not hold: with everything
    to the left of the centreline crossing, the best detour goes right, though the box
    sits a little right of the line and the left would be the smaller turn."""
    robot, goal = np.array([0.0, 0.0]), np.array([10.0, 0.0])
    box = (np.array([[2.75, -0.35]]), np.array([[3.25, 0.15]]))

    def fan(crosses: Callable[[np.ndarray], bool] | None = None) -> Choice:
        return choose_detour(robot, np.array([3.0, 0.0]), goal, set(), box, [], speed=0.1,
                             cell=0.5, robot_radius=0.2, margin=0.1, kappa=KAPPA,
                             fan_step=math.radians(5), fan_max=math.radians(85),
                             extra_length=0.8, crosses=crosses)

    free = fan()
    assert free.best is not None and free.best.g > 0  # left, without the map

    def left_wall(points: np.ndarray) -> bool:  # a wall along y = 0.6
        return bool((points[:, 1] > 0.6).any())

    walled = fan(left_wall)
    assert walled.best is not None and walled.best.g < 0
    assert all(math.isinf(c.cost) for c in walled.candidates if c.end[1] > 0.6)
