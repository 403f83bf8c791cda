"""``zenav bench nav``: ``--fov`` gives the same worlds another laser and nothing else;
a run that ends standing still while a way existed is counted against the planner, and
the goal line names every family short of the target."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from zenav.bench.nav import (
    appeared_at_contact,
    expand_families,
    goal_lines,
    never_in_view,
    no_warning,
    still_at_end,
    summarise,
    write_worlds,
)
from zenav.sim.scenario import Scenario, load_scenario


def test_fov_changes_only_the_laser(tmp_path: Path) -> None:
    own = write_worlds(["crossing", "crowd"], 2, 7, tmp_path / "own")
    wide = write_worlds(["crossing", "crowd"], 2, 7, tmp_path / "wide", fov_deg=360.0)
    assert [p.name for p in own] == [p.name for p in wide]
    for a, b in zip(own, wide, strict=True):
        before, after = load_scenario(a), load_scenario(b)
        assert before.laser.fov_deg == 180.0
        assert after.laser.fov_deg == 360.0
        assert after.laser.beam_count == 721
        assert after.model_dump(exclude={"laser"}) == before.model_dump(exclude={"laser"})
        assert (after.laser.model_dump(exclude={"fov_deg"})
                == before.laser.model_dump(exclude={"fov_deg"}))


def record(name: str, outcome: str, trajectory: list[list[float]]) -> dict[str, Any]:
    return {"scenario": name, "planner": "paper", "outcome": outcome, "time": 60.0,
            "path_length": 3.0, "min_clearance": 0.3, "events": [], "trajectory": trajectory}


def standing_from(t_stop: float, t_end: float) -> list[list[float]]:
    """Driving along x at 1 m/s until ``t_stop``, then standing (0.01 m of jitter)."""
    rows = []
    for k in range(round(t_end * 10) + 1):
        t = k / 10
        x = min(t, t_stop) + (0.01 if t > t_stop and k % 2 else 0.0)
        rows.append([t, x, 0.0, 0.0, 0.0])
    return rows


def test_still_at_end_is_the_time_since_the_robot_last_moved() -> None:
    assert still_at_end(standing_from(40.0, 60.0)) == 20.0
    assert still_at_end(standing_from(60.0, 60.0)) == 0.0
    assert still_at_end([]) == 0.0


def test_a_timeout_standing_where_a_way_existed_is_stuck_and_fails_the_goal() -> None:
    records = [record("crowd-1", "timeout", standing_from(30.0, 60.0)),  # stuck
               record("crowd-2", "timeout", standing_from(55.0, 60.0)),  # still driving
               record("static-1", "timeout", standing_from(30.0, 60.0)),  # no way there
               record("static-2", "reached", standing_from(30.0, 60.0)),
               record("mixed-1", "collision", standing_from(30.0, 60.0))]
    (paper,), families = summarise(records, ["paper"], lambda name: name != "static-1")
    assert paper.stuck == ["crowd-1"]
    line = goal_lines([paper], families)
    assert "stood still: 1 (crowd-1) (NOT met)." in line
    assert "short: crowd 0 %, static 50 %, mixed 0 %) (NOT met);" in line


def test_each_half_of_the_goal_has_its_own_verdict() -> None:
    # One family short, nobody stuck: the success half fails, the standing half holds.
    records = [record("crowd-1", "reached", standing_from(30.0, 31.0)),
               record("crowd-2", "collision", standing_from(30.0, 31.0))]
    (paper,), families = summarise(records, ["paper"])
    line = goal_lines([paper], families)
    assert "(short: crowd 50 %) (NOT met); stood still: 0 (met)." in line


def test_the_goal_is_met_when_every_family_reaches_the_target() -> None:
    records = [record(f"{f}-{k}", "reached", standing_from(30.0, 31.0))
               for f in ("static", "crowd") for k in range(3)]
    (paper,), families = summarise(records, ["paper"])
    assert paper.stuck == []
    line = goal_lines([paper], families)
    assert "lowest family static 100 % (met);" in line
    assert line.endswith("stood still: 0 (met).")


def walker_world(velocity: tuple[float, float], start: float = -3.0) -> Scenario:
    """The robot drives east along y = 0 at 1 m/s from x = 0 (180-degree laser, 8 m); one
    walker starts at (``start``, 0)."""
    return Scenario.model_validate({
        "name": "walker", "world": {"size": [20.0, 10.0], "cell": 0.5},
        "robot": {"start": [0.0, 0.0], "goal": [15.0, 0.0], "speed": 1.0, "max_speed": 1.0,
                  "radius": 0.3},
        "obstacles": [{"shape": "box", "center": [18.0, 8.0], "size": [0.5, 0.5]},
                      {"shape": "disc", "center": [start, 0.0], "radius": 0.3,
                       "velocity": list(velocity)}],
        "duration": 30.0})


def test_a_hit_from_behind_by_a_walker_never_in_the_field_of_view_is_told_apart() -> None:
    driving = [[k / 10, k / 10, 0.0, 0.0, 1.0] for k in range(25)]  # 0-2.4 s, east
    hit = {**record("crowd-1", "collision", driving), "collided_with": 1}
    # Overtaking at 2 m/s from behind: always behind the robot, never in its field.
    assert never_in_view(walker_world((2.0, 0.0)), hit)
    # The same collision index, but the walker came from ahead (head-on): it was seen.
    assert not never_in_view(walker_world((-2.0, 0.0), start=8.0), hit)
    # Not a collision: nothing to tell.
    assert not never_in_view(walker_world((2.0, 0.0)), {**hit, "outcome": "timeout"})
    # An ORCA agent is placed by the record's rows: these put it ahead of the robot once.
    rows = [[t, x - 3.0, 0.0] for t, x, *_ in driving]
    rows[5] = [0.5, 2.0, 0.0]
    assert not never_in_view(walker_world((2.0, 0.0)), {**hit, "agents": {"1": rows}})
    assert never_in_view(walker_world((0.0, 0.0)), {**hit, "agents": {
        "1": [[t, x - 1.0, 0.0] for t, x, *_ in driving]}})
    (paper,), families = summarise([hit, record("crowd-2", "reached", driving)], ["paper"],
                            unwarned_hit=lambda r: no_warning(walker_world((2.0, 0.0)), r))
    assert paper.hit_unwarned == ["crowd-1"] and paper.collisions == 1
    assert ("Collisions no scan could have warned of (never in the laser's field of view, "
            "or appeared at the contact): 1 of 1 (crowd-1).") in goal_lines([paper], families)


def test_a_mover_that_appears_on_the_robot_is_told_apart_from_one_seen_in_time() -> None:
    driving = [[k / 10, k / 10, 0.0, 0.0, 1.0] for k in range(25)]  # 0-2.4 s, east
    ahead = walker_world((0.0, 0.0), start=2.6)  # standing 0.2 m ahead of the robot at 2.4 s
    hit = {**record("crowd-1", "collision", driving), "collided_with": 1, "time": 2.4}
    at = ahead.model_dump(mode="json", exclude_none=True)
    at["obstacles"][1]["appear"] = 2.4  # it appears at the contact: no scan showed it
    assert appeared_at_contact(Scenario.model_validate(at), hit)
    assert no_warning(Scenario.model_validate(at), hit)
    at["obstacles"][1]["appear"] = 2.2  # two laser periods (10 Hz) before: scans showed it
    assert not appeared_at_contact(Scenario.model_validate(at), hit)
    # There from the start, in view ahead all along: the planner's to avoid.
    assert not appeared_at_contact(ahead, hit)
    assert not no_warning(ahead, hit)
    # Not a collision: nothing to tell.
    at["obstacles"][1]["appear"] = 2.4
    assert not appeared_at_contact(Scenario.model_validate(at),
                                   {**hit, "outcome": "timeout"})


@pytest.mark.parametrize("reuse", [False, True])
def test_a_sweep_makes_every_run_again_unless_told_to_reuse(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, reuse: bool) -> None:
    """A run.json left in --out by an earlier sweep is that run's record only with
    ``reuse``; otherwise the run is made again and its record replaces it."""
    from zenav import batch
    from zenav.bench.nav import run_nav

    made: list[str] = []

    def fake_run(scenario: Path, out: Path, **options: Any) -> dict[str, Any]:
        made.append(scenario.stem)
        fresh = record(scenario.stem, "reached", standing_from(60.0, 60.0))
        out.mkdir(parents=True, exist_ok=True)
        (out / "run.json").write_text(json.dumps(fresh))
        return fresh

    monkeypatch.setattr(batch, "run_scenario", fake_run)
    kept = tmp_path / "runs" / "paper" / "static-0"
    kept.mkdir(parents=True)
    (kept / "run.json").write_text(json.dumps(record("static-0", "collision", [])))

    report = run_nav(["paper"], 2, 0, tmp_path, families=["static"], jobs=1, engine="stack",
                     progress=False, echo=lambda text: None, reuse=reuse)

    assert sorted(made) == (["static-1"] if reuse else ["static-0", "static-1"])
    outcomes = {r["scenario"]: r["outcome"]
                for r in json.loads((tmp_path / "nav.json").read_text())}
    assert outcomes == {"static-0": "collision" if reuse else "reached",
                        "static-1": "reached"}
    assert ("--reuse" in report) == reuse


def test_family_groups_stand_for_their_classes_and_unknown_names_are_refused() -> None:
    assert expand_families(["crowd", "walkers"]) == [
        "crowd", "unseen-walkers-corridor", "unseen-walkers-doorway", "unseen-walkers-across"]
    assert len(expand_families(["unseen"])) == 7
    assert "unseen-walkers-corridor" not in expand_families(["unseen"])
    with pytest.raises(ValueError, match="unknown family walkers-corridor"):
        expand_families(["walkers-corridor"])
    with pytest.raises(ValueError, match="none given"):
        expand_families([])
