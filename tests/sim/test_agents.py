"""ORCA agents in the simulator: the scenario fields, their motion, contact and the record."""

from __future__ import annotations

import copy
import itertools
import math
from typing import Any

import numpy as np
import pytest

from zenav.schemas.codec import decode, encode
from zenav.schemas.messages import RunResult
from zenav.sim.params import Params
from zenav.sim.raycast import simulate_scan
from zenav.sim.scenario import ScenarioError, dump_scenario, load_scenario, parse_scenario
from zenav.sim.simulation import Simulation

AGENT: dict[str, Any] = {"shape": "disc", "behavior": "orca", "center": [1.0, 5.0],
                         "radius": 0.3, "goals": [[9.0, 5.0]], "preferred_speed": 1.0}


def scenario(*obstacles: dict[str, Any], start=(5.0, 1.0), goal=(9.5, 9.5), duration=15.0,
             radius=0.3) -> Any:
    return parse_scenario({
        "name": "agents", "world": {"size": [10.0, 10.0], "cell": 0.5},
        "robot": {"start": list(start), "goal": list(goal), "speed": 1.0, "radius": radius},
        "obstacles": list(obstacles), "duration": duration}, "agents.yaml")


def agent(**changes: Any) -> dict[str, Any]:
    a = copy.deepcopy(AGENT)
    a.update(changes)
    return a


def run_still(sc: Any) -> Simulation:
    """Run with the robot standing still (v = omega = 0) to the end."""
    sim = Simulation(sc, Params(scenario="agents.yaml"))
    while sim.outcome is None:
        sim.step(0.0, 0.0)
    return sim


def circle(count: int, radius: float = 3.5, sees_robot: bool = False) -> list[dict[str, Any]]:
    """Agents on a circle round (5, 5), each a little off its place (seeded), crossing."""
    rng = np.random.default_rng(7)
    out = []
    for k in range(count):
        a = 2 * math.pi * k / count
        p = [5.0 + radius * math.cos(a) + rng.uniform(-0.3, 0.3),
             5.0 + radius * math.sin(a) + rng.uniform(-0.3, 0.3)]
        out.append(agent(center=p, goals=[[10.0 - p[0], 10.0 - p[1]]], sees_robot=sees_robot))
    return out


# --- the scenario format ------------------------------------------------------------


def test_an_agent_loads_with_its_fields_and_sees_robot_defaults_to_false():
    sc = scenario(agent(appear=1.5))
    ob = sc.obstacles[0]
    assert ob.is_agent and not ob.is_static and ob.sees_robot is False
    assert ob.goals == [(9.0, 5.0)] and ob.preferred_speed == 1.0 and ob.appear == 1.5


@pytest.mark.parametrize(("change", "line"), [
    ({"shape": "box", "size": [0.5, 0.5], "radius": None},
     "agents.yaml: obstacles[0].shape: behavior orca needs shape disc (got box)"),
    ({"goals": []}, "agents.yaml: obstacles[0].goals: behavior orca needs a non-empty list "
     "of goals"),
    ({"goals": None}, "agents.yaml: obstacles[0].goals: behavior orca needs a non-empty list "
     "of goals"),
    ({"preferred_speed": None}, "agents.yaml: obstacles[0].preferred_speed: required for "
     "behavior orca"),
    ({"velocity": [1.0, 0.0]}, "agents.yaml: obstacles[0].velocity: not allowed with behavior "
     "orca (an agent's velocity comes from ORCA)"),
    ({"preferred_speed": -1.0}, "agents.yaml: obstacles[0].preferred_speed: must be > 0 "
     "(got -1)"),
    ({"behavior": "social-force"}, "agents.yaml: obstacles[0].behavior: must be one of 'orca' "
     "(got 'social-force')"),
    ({"sees_robot": "yes"}, "agents.yaml: obstacles[0].sees_robot: "),
])
def test_a_bad_agent_is_refused_with_one_line_naming_the_field(change, line):
    bad = agent(**change)
    for key in [k for k, v in change.items() if v is None]:
        del bad[key]
    with pytest.raises(ScenarioError) as caught:
        scenario(bad)
    assert line in str(caught.value)


def test_agent_fields_on_a_plain_obstacle_are_refused():
    with pytest.raises(ScenarioError) as caught:
        scenario({"shape": "disc", "center": [3.0, 3.0], "radius": 0.2, "goals": [[1.0, 1.0]],
                  "sees_robot": True})
    assert str(caught.value).splitlines() == [
        "agents.yaml: obstacles[0].goals: only for behavior: orca",
        "agents.yaml: obstacles[0].sees_robot: only for behavior: orca",
    ]


def test_a_scenario_with_agents_is_written_and_read_back_the_same(tmp_path):
    sc = scenario(agent(sees_robot=True), {"shape": "disc", "center": [3.0, 3.0],
                                           "radius": 0.2, "velocity": [0.1, 0.0]})
    assert load_scenario(dump_scenario(sc, tmp_path / "a.yaml")) == sc


# --- motion -------------------------------------------------------------------------


def test_same_scenario_same_agent_paths():
    sc = scenario(*circle(6))
    first, second = run_still(sc).result(), run_still(sc).result()
    for a, b in zip(first.agents, second.agents, strict=True):
        assert a.index == b.index and np.array_equal(a.rows, b.rows)


def test_agents_in_a_crowd_never_touch_each_other_and_reach_their_goals():
    sc = scenario(*circle(6), start=(0.5, 0.5), goal=(9.5, 0.5), duration=20.0)
    result = run_still(sc).result()
    paths = [a.rows for a in result.agents]
    for a, b in itertools.combinations(paths, 2):
        assert (np.hypot(a[:, 1] - b[:, 1], a[:, 2] - b[:, 2]) - 0.6).min() > 0.0
    for spec, rows in zip(sc.obstacles, paths, strict=True):
        assert math.dist(rows[-1, 1:], spec.goals[-1]) < 0.3


def test_visible_agents_walk_round_a_robot_standing_in_their_way():
    sc = scenario(agent(center=[1.0, 5.1], sees_robot=True),
                  agent(center=[5.1, 9.0], goals=[[5.0, 1.0]], sees_robot=True),
                  start=(5.0, 5.0))
    sim = run_still(sc)
    assert sim.outcome == "timeout" and sim.min_clearance > 0.0
    rows = sim.result().agents
    assert math.dist(rows[0].rows[-1, 1:], (9.0, 5.0)) < 0.3
    assert math.dist(rows[1].rows[-1, 1:], (5.0, 1.0)) < 0.3


def test_invisible_agents_walk_through_the_robots_place():
    sim = run_still(scenario(agent(center=[1.0, 5.1]), start=(5.0, 5.0)))
    assert sim.outcome == "collision" and sim.collided_with == 0
    # straight at 1 m/s from x = 1 until the discs touch (0.6 m apart, 0.1 m off the line)
    assert math.isclose(sim.result().time, 4.0 - math.sqrt(0.6**2 - 0.1**2), abs_tol=0.02)


def test_agents_walk_their_goals_in_order_and_stay_at_the_last():
    sc = scenario(agent(center=[1.0, 9.0], goals=[[4.0, 9.0], [4.0, 6.0], [1.0, 6.0]]),
                  duration=14.0)
    rows = run_still(sc).result().agents[0].rows
    t_near = [float(rows[np.argmin(np.hypot(rows[:, 1] - gx, rows[:, 2] - gy)), 0])
              for gx, gy in ((4.0, 9.0), (4.0, 6.0))]
    assert t_near[0] < t_near[1]
    assert math.dist(rows[-1, 1:], (1.0, 6.0)) < 0.05


def test_an_agent_is_absent_before_it_appears():
    sc = scenario(agent(center=[5.0, 3.0], goals=[[5.0, 3.0]], appear=2.0), start=(5.0, 1.0))
    sim = Simulation(sc, Params(scenario="agents.yaml"))
    assert sim.snapshot().count == 0
    while sim.t < 2.0:
        sim.step(0.0, 0.0)
    assert sim.snapshot().count == 1


def test_contact_with_a_fast_agent_between_ticks_is_caught():
    """An agent at 20 m/s passes the robot between two ticks: at t = 0.2 s it is 0.35 m
    short of touching, at 0.3 s 1.35 m past; the exact check finds the contact at 0.2175 s."""
    sc = scenario(agent(center=[0.5, 5.0], radius=0.05, goals=[[100.0, 5.0]],
                        preferred_speed=20.0), start=(5.0, 5.0), radius=0.1)
    sim = run_still(sc)
    assert sim.outcome == "collision" and sim.collided_with == 0
    assert math.isclose(sim.result().time, (4.85 - 0.5) / 20.0, abs_tol=1e-6)


def test_ground_truth_and_the_laser_include_agents():
    sc = scenario(agent(center=[5.0, 3.0], goals=[[5.0, 3.0]]),
                  {"shape": "box", "center": [8.0, 8.0], "size": [0.5, 0.5]},
                  start=(5.0, 1.0))
    sim = Simulation(sc, Params(scenario="agents.yaml"))
    truth = sim.truth(0)
    assert [(o.index, o.shape) for o in truth.obstacles] == [(0, "disc"), (1, "box")]
    ranges = simulate_scan((5.0, 1.0), math.pi / 2, np.array([0.0]), sim.snapshot(), 8.0, 0.0,
                           np.random.default_rng(0))
    assert math.isclose(float(ranges[0]), 2.0 - 0.3, abs_tol=1e-6)


# --- the run record -----------------------------------------------------------------


def test_agent_rows_are_at_the_trajectory_ticks_and_travel_in_the_result():
    sc = scenario(*circle(3), {"shape": "box", "center": [8.0, 8.0], "size": [0.5, 0.5]},
                  agent(center=[1.0, 5.1]), start=(5.0, 5.0))
    result = run_still(sc).result()
    assert result.outcome == "collision"
    assert [a.index for a in result.agents] == [0, 1, 2, 4]
    for a in result.agents:
        assert np.array_equal(a.rows[:, 0], result.trajectory[:, 0])
    back = decode(encode(result), RunResult, "sim/result")
    for a, b in zip(result.agents, back.agents, strict=True):
        assert a.index == b.index and np.array_equal(a.rows, b.rows)


def test_the_record_has_agents_only_with_agents():
    from zenav.run import make_record

    with_agents = run_still(scenario(agent(), duration=1.0)).result()
    record = make_record(with_agents, [], "paper")
    assert list(record["agents"]) == ["0"]
    assert [row[0] for row in record["agents"]["0"]] == [row[0] for row in record["trajectory"]]
    plain = run_still(scenario(duration=1.0)).result()
    assert "agents" not in make_record(plain, [], "paper")


def test_the_simulator_parameters_reach_orca():
    """Two agents head-on: with CrowdNav's neighbour distance they pass each other; seeing
    only 0.5 m around them, they meet."""
    sc = scenario(agent(center=[1.0, 5.0], goals=[[9.0, 5.0]]),
                  agent(center=[9.0, 5.05], goals=[[1.0, 5.0]]), start=(5.0, 1.0))

    def closest(params: Params) -> float:
        sim = Simulation(sc, params)
        while sim.outcome is None:
            sim.step(0.0, 0.0)
        a, b = (p.rows for p in sim.result().agents)
        return float((np.hypot(a[:, 1] - b[:, 1], a[:, 2] - b[:, 2]) - 0.6).min())

    assert closest(Params(scenario="agents.yaml")) > 0.0
    assert closest(Params(scenario="agents.yaml", crowd_neighbor_dist=0.5)) < 0.0


def test_a_scenario_dumped_by_pydantic_reads_back():
    """model_dump writes every field, defaults included (goals: None, sees_robot: False on
    a plain obstacle; velocity (0, 0) on an agent): that is no error."""
    sc = scenario(agent(), {"shape": "disc", "center": [3.0, 3.0], "radius": 0.2})
    assert parse_scenario(sc.model_dump(), "agents.yaml") == sc
