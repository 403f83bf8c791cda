"""``zenav bench bound``: the fastest arrival with the humans' future known, on hand-made
humans, and the command's figures and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from zenav.bench.bound import Limits, fastest_arrival, humans_paths, side_path
from zenav.cli import main
from zenav.sim.crowdnav import crowdnav_scenario

LINE = np.array([[0.0, 0.0], [0.0, 8.0]])
TICKS = 251  # 25 s at 0.1 s
FREE_TIME = 8.7  # 2 s to reach 1 m/s (1 m), then 6.7 m at 1 m/s, to within 0.3 m of 8 m


def nobody() -> np.ndarray:
    return np.full((TICKS, 1, 2), np.nan)


def standing(x: float, y: float) -> np.ndarray:
    return np.tile(np.array([[[x, y]]]), (TICKS, 1, 1))


def test_with_nobody_about_the_time_is_the_robots_own_limits() -> None:
    assert fastest_arrival(nobody(), LINE, 0.6, 0.3) == pytest.approx(FREE_TIME)
    faster = Limits(top_speed=1.0, accel=1.0, decel=2.0)  # 1 s to 1 m/s (0.5 m)
    assert fastest_arrival(nobody(), LINE, 0.6, 0.3, faster) == pytest.approx(8.2)


def test_a_human_standing_on_the_line_leaves_no_way_along_it_but_one_round() -> None:
    human = standing(0.0, 4.0)
    assert fastest_arrival(human, LINE, 0.6, 0.3) is None
    round_it = side_path((0.0, 0.0), (0.0, 8.0), 1.0)
    assert round_it[1] == pytest.approx([-1.0, 4.0])  # left of a line going +y
    t = fastest_arrival(human, round_it, 0.6, 0.3)
    assert t is not None and FREE_TIME < t < FREE_TIME + 1.0  # the longer way, 8.25 m


def test_a_crosser_is_waited_for_only_as_long_as_it_is_in_the_way() -> None:
    # Walking +x at 1 m/s across the line at y = 4, on it at t = 5 s (x = 0), just when
    # the robot driving freely would be there.
    t = np.arange(TICKS) * 0.1
    crosser = np.stack([t - 5.0, np.full(TICKS, 4.0)], axis=1)[:, None, :]
    got = fastest_arrival(crosser, LINE, 0.6, 0.3)
    # At best the robot, at 1 m/s, grazes the 0.6 m circle round the crosser where the
    # circle's edge on the line climbs at 1 m/s: t = 5.424 s, y = 3.576 m; then 4.124 m on.
    assert got == pytest.approx(5.424 + 4.124, abs=0.15)
    # The same crosser 10 s later: the robot is home before it comes.
    later = np.stack([t - 15.0, np.full(TICKS, 4.0)], axis=1)[:, None, :]
    assert fastest_arrival(later, LINE, 0.6, 0.3) == pytest.approx(FREE_TIME)


def test_a_human_at_the_start_ends_the_search_at_once() -> None:
    assert fastest_arrival(standing(0.0, 0.3), LINE, 0.6, 0.3) is None


def test_the_humans_paths_are_the_simulators_crowd_without_a_robot() -> None:
    scenario = crowdnav_scenario("circle", 3)
    paths = humans_paths(scenario, 2.0)
    assert paths.shape == (21, 5, 2)
    starts = np.array([o.center for o in scenario.obstacles])
    assert paths[0] == pytest.approx(starts)
    steps = np.hypot(*(paths[1:] - paths[:-1]).transpose(2, 0, 1))
    assert steps.max() <= 0.1 + 1e-9  # 1 m/s at most
    with pytest.raises(ValueError, match="sees the robot"):
        humans_paths(crowdnav_scenario("circle", 3, visible=True), 2.0)


def test_the_command_prints_every_path_and_the_best(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bench", "bound", "--cases", "2", "--seed", "7", "--jobs", "1",
                 "--offsets", "0,2"]) == 0
    out = capsys.readouterr().out
    rows = [line for line in out.splitlines() if line.startswith("| ")][1:]
    assert [r.split(" | ")[0] for r in rows] == [
        "| straight line", "| through +2 m to the side", "| the best of these, per case"]
    best = float(rows[-1].split(" | ")[2])
    straight = float(rows[0].split(" | ")[2]) if rows[0].split(" | ")[1] == "2/2" else math.inf
    assert FREE_TIME <= best <= straight
