"""The six production services on one in-memory bus (the in-process engine): a paper
scenario runs to its outcome with every message through the codec, and no service
refuses, drops or fails on anything."""

from __future__ import annotations

from zenav.engine import run_services
from zenav.services.config import SERVICE_ORDER
from zenav.services.mission import stack_params
from zenav.sim import SCENARIO_DIR
from zenav.sim.scenario import load_scenario


def test_a_paper_scenario_runs_through_the_six_services() -> None:
    path = SCENARIO_DIR / "b-static-obstacle.yaml"
    ran = run_services(stack_params(load_scenario(path), path, "paper"))
    assert ran.result.outcome == "reached"
    scans = round(ran.result.time * 10)  # the scenario's laser runs at 10 Hz
    for name in SERVICE_ORDER:
        counters = ran.counters[name]
        assert counters["rejected"] == {}, name
        assert counters["handler_errors"] == 0, name
        assert sum(counters["received"].values()) >= scans, name
    # the simulator got one base command per scan: nothing was retransmitted or lost
    assert ran.counters["simulator"]["received"]["device/base_cmd"] == scans
    assert {e.action for e in ran.events} >= {"morphin"}
