"""bench crowd's columns from run records: CrowdNav's rates, time to goal, discomfort."""

from __future__ import annotations

import math
from typing import Any

import pytest

from zenav.bench.crowd import SETTINGS, check, discomfort_steps, summarise, table


def record(planner: str, outcome: str, time: float, gaps: list[float]) -> dict[str, Any]:
    """A robot standing at the origin; one human (radius 0.3) whose surface-to-surface gap
    to the robot (radius 0.3) is ``gaps[i]`` at tick i."""
    trajectory = [[0.1 * i, 0.0, 0.0, 0.0, 0.0] for i in range(len(gaps))]
    human = [[0.1 * i, g + 0.6, 0.0] for i, g in enumerate(gaps)]
    return {"scenario": "c", "planner": planner, "outcome": outcome, "time": time,
            "trajectory": trajectory, "agents": {"0": human}}


def test_discomfort_counts_ticks_within_point_two_metres_surface_to_surface():
    assert discomfort_steps(record("p", "reached", 1.0, [1.0, 0.19, 0.05, 0.2, 0.5])) == (2, 5)


def test_discomfort_takes_the_nearest_human():
    r = record("p", "reached", 1.0, [1.0, 1.0, 1.0])
    r["agents"]["3"] = [[0.1 * i, 0.0, 0.6 + g] for i, g in enumerate([1.0, 0.1, 1.0])]
    assert discomfort_steps(r) == (1, 3)


def test_rows_not_at_the_trajectory_ticks_are_refused():
    r = record("p", "reached", 1.0, [1.0, 1.0, 1.0])
    r["agents"]["0"] = r["agents"]["0"][:2]
    with pytest.raises(ValueError, match="not at the trajectory's ticks"):
        discomfort_steps(r)


def test_summary_rates_time_of_the_successes_and_pooled_discomfort():
    records = [
        record("orca", "reached", 10.0, [1.0, 0.1, 1.0, 1.0]),
        record("orca", "reached", 12.0, [1.0, 1.0, 1.0, 1.0]),
        record("orca", "collision", 3.0, [0.1, 0.1, 0.1, 0.0]),
        record("orca", "timeout", 25.0, [1.0, 1.0, 1.0, 1.0]),
        {"scenario": "c", "planner": "orca", "outcome": "error", "error": "boom"},
        record("paper", "reached", 14.0, [1.0, 1.0]),
    ]
    orca, paper = summarise(records, ["orca", "paper"])
    assert (orca.runs, orca.errors) == (4, 1)
    assert (orca.success, orca.collision, orca.timeout) == (0.5, 0.25, 0.25)
    assert orca.time_to_goal == 11.0 and orca.discomfort == 5 / 16
    assert (paper.runs, paper.success, paper.time_to_goal, paper.discomfort) == (1, 1.0, 14.0,
                                                                                 0.0)
    text = table([orca, paper])
    assert "| orca | 4 (+1 failed) | 0.50 | 0.25 | 0.25 | 11.00 | 0.31 |" in text


def test_a_planner_with_no_runs_shows_dashes():
    (row,) = summarise([], ["dwa"])
    assert row.runs == 0 and math.isnan(row.success)
    assert "| dwa | 0 | — | — | — | — | — |" in table([row])


def test_the_eight_settings():
    assert list(SETTINGS) == [
        "circle-invisible-180", "circle-invisible-360", "circle-visible-180",
        "circle-visible-360", "square-invisible-180", "square-invisible-360",
        "square-visible-180", "square-visible-360"]


@pytest.mark.parametrize(("args", "message"), [
    ((["x"], ["circle-invisible-180"], 1, "stack", 1), "unknown planner x"),
    ((["orca"], ["ring"], 1, "stack", 1), "unknown setting ring"),
    ((["orca"], ["circle-invisible-180"], 0, "stack", 1), "--cases must be >= 1 (got 0)"),
    ((["orca"], ["circle-invisible-180"], 1, "warp", 1), "unknown engine 'warp'"),
    ((["orca"], ["circle-invisible-180"], 1, "stack", 0), "--jobs must be >= 1 (got 0)"),
])
def test_bad_arguments_are_one_line(args, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        check(*args)


@pytest.mark.parametrize("reuse", [False, True])
def test_a_sweep_makes_every_run_again_unless_told_to_reuse(tmp_path, monkeypatch, reuse):
    """A run.json left in --out by an earlier sweep (older code, say) is that run's record
    only with ``reuse``; otherwise the run is made again and its record replaces it."""
    import json

    from zenav import batch
    from zenav.bench.crowd import run_crowd

    made: list[str] = []

    def fake_run(scenario, out, **options):
        made.append(out.name)
        fresh = record(options["planner"], "reached", 10.0, [1.0])
        out.mkdir(parents=True, exist_ok=True)
        (out / "run.json").write_text(json.dumps(fresh))
        return fresh

    monkeypatch.setattr(batch, "run_scenario", fake_run)
    kept = tmp_path / "runs" / "circle-invisible-360" / "paper" / "0"
    kept.mkdir(parents=True)
    (kept / "run.json").write_text(json.dumps(record("paper", "collision", 3.0, [1.0])))

    report = run_crowd(["paper"], tmp_path, cases=2, settings=["circle-invisible-360"],
                       jobs=1, engine="stack", progress=False, reuse=reuse,
                       echo=lambda text: None)

    assert sorted(made) == (["1"] if reuse else ["0", "1"])
    rows = json.loads((tmp_path / "crowd.json").read_text())["settings"]
    assert rows["circle-invisible-360"][0]["collision"] == (0.5 if reuse else 0.0)
    assert ("--reuse" in report) == reuse
    # The kept record is a collision the report accounts for (with no obstacle named, it
    # is neither unwarned nor without a way out).
    assert ("Collisions: paper 1 (0 never in view before the contact, 0 with no way out "
            "once seen)" in report) == reuse
    assert ("No collisions." in report) != reuse


@pytest.mark.parametrize("disagree", [False, True])
def test_the_report_says_what_the_stack_said_of_the_runs_it_made_again(tmp_path, monkeypatch,
                                                                        disagree):
    """The sweep asks the engine for ``verify`` stack re-runs, and the report's header and
    crowd.json say whether they agreed, loudly when they did not."""
    import json

    from zenav import batch
    from zenav.bench import crowd

    asked: list[int] = []

    def engine(jobs, parallel, on_done, reuse, verify):
        asked.append(verify)
        records = batch.Records()
        for job in jobs:
            records[job.key] = record(job.planner, "reached", 10.0, [1.0])
            on_done(job, records[job.key])
        records.verified = [jobs[0].key]
        records.disagreements = [f"{jobs[0].key}: tick 3: x differs"] if disagree else []
        return records

    monkeypatch.setitem(crowd.ENGINES, "inprocess", engine)
    report = crowd.run_crowd(["paper"], tmp_path, cases=2, settings=["circle-invisible-360"],
                             jobs=1, progress=False, verify=5, echo=lambda text: None)

    assert asked == [5]
    assert "--verify 5" in report
    said = ("1 of 1 runs re-made through the stack DISAGREE" if disagree
            else "1 runs re-made through the stack agree tick by tick")
    assert said in report
    summary = json.loads((tmp_path / "crowd.json").read_text())
    assert summary["verified"] == ["circle-invisible-360/paper/0"]
    assert len(summary["disagreements"]) == int(disagree)


def test_a_collision_is_unwarned_without_a_way_out_or_with_one():
    """Each collision's kind, from the scenario and the record (``zenav.bench.escape`` on a
    walker blind to the robot), counted per planner and said under the setting's table."""
    from zenav.bench.crowd import collisions_line
    from zenav.bench.nav import NO_WAY_OUT, UNWARNED, WAY_OUT, collision_kind
    from zenav.sim.scenario import Scenario

    def walker(x: float, vx: float) -> Scenario:
        # A robot at the origin facing east (top speed 0.2 m/s, 180-degree laser) and an
        # ORCA walker at 1 m/s on its line, blind to it, obstacle 0.
        return Scenario.model_validate({
            "name": "w", "world": {"size": [20.0, 20.0], "cell": 0.5},
            "robot": {"start": [0.0, 0.0], "goal": [8.0, 0.0], "speed": 0.1, "radius": 0.2},
            "obstacles": [{"shape": "disc", "behavior": "orca", "center": [x, 0.0],
                           "radius": 0.3, "goals": [[x + 13.0 * vx, 0.0]],
                           "preferred_speed": 1.0}],
            "duration": 25.0})

    def hit(x: float, vx: float, until: float) -> dict[str, Any]:
        ticks = round(until * 10) + 1
        return {"scenario": "w", "planner": "paper", "outcome": "collision", "time": until,
                "collided_with": 0,
                "trajectory": [[k / 10, 0.0, 0.0, 0.0, 0.0] for k in range(ticks)],
                "agents": {"0": [[k / 10, x + vx * k / 10, 0.0] for k in range(ticks)]}}

    # Head-on from 3 m: in view at once, but too close for a robot of 0.2 m/s to leave.
    assert collision_kind(walker(3.0, -1.0), hit(3.0, -1.0, 2.5)) == NO_WAY_OUT
    # Head-on from 8 m: time enough to step aside.
    assert collision_kind(walker(8.0, -1.0), hit(8.0, -1.0, 7.5)) == WAY_OUT
    # From behind, out of the 180-degree view until it touches.
    assert collision_kind(walker(-3.0, 1.0), hit(-3.0, 1.0, 2.5)) == UNWARNED
    assert collision_kind(walker(3.0, -1.0), {**hit(3.0, -1.0, 2.5), "outcome": "reached"}) \
        is None

    kinds = [NO_WAY_OUT, WAY_OUT, UNWARNED]
    records = [{**record("paper", "collision", 1.0, [0.0]), "hit": k} for k in kinds]
    records.append(record("paper", "reached", 9.0, [1.0]))
    (paper,) = summarise(records, ["paper"])
    assert (paper.collisions, paper.unwarned, paper.no_way_out) == (3, 1, 1)
    assert collisions_line([paper], visible=False).startswith(
        "Collisions: paper 3 (1 never in view before the contact, 1 with no way out once "
        "seen).")
    seen = collisions_line([paper], visible=True)
    assert seen.startswith("Collisions: paper 3 (1 never in view before the contact).")
    assert "not judged" in seen
    (idle,) = summarise([record("paper", "reached", 9.0, [1.0])], ["paper"])
    assert collisions_line([idle], visible=False) == "No collisions."
