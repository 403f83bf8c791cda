"""Scenario and parameter files with errors are refused, naming the file, the field and
the problem, through the commands a user types (``zenav run``, ``zenav service``), exit
status 2 and nothing started."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from zenav.cli import main as zenav_main
from zenav.services.runner import main as service_main

GOOD_SCENARIO = """\
name: t
world: {size: [10.0, 10.0], cell: 0.5}
robot: {start: [2.0, 5.0], heading_deg: 0.0, goal: [8.0, 5.0], speed: 0.1, radius: 0.2}
obstacles:
  - {shape: box, center: [5.0, 5.0], size: [0.5, 0.5]}
"""

SCENARIO_CASES = [
    ("wrong-type", ("speed: 0.1", "speed: fast"), "robot.speed: must be a number (got 'fast')"),
    ("missing-field", (", speed: 0.1", ""), "robot.speed: required field is missing"),
    ("unknown-key", ("name: t", "name: t\nbogus: 1"), "bogus: unknown field"),
    ("negative-world-size", ("size: [10.0, 10.0]", "size: [-10.0, 10.0]"),
     "world.size[0]: must be > 0 (got -10)"),
    ("negative-obstacle-size", ("size: [0.5, 0.5]", "size: [-0.5, 0.5]"),
     "obstacles[0].size[0]: must be > 0 (got -0.5)"),
    ("start-inside-obstacle", ("start: [2.0, 5.0]", "start: [5.0, 5.0]"),
     "robot.start: robot disc overlaps obstacles[0] (box)"),
    ("goal-outside-world", ("goal: [8.0, 5.0]", "goal: [18.0, 5.0]"),
     "robot.goal: outside the world [0, 10] x [0, 10] (got [18, 5])"),
]


@pytest.mark.parametrize(("edit", "expected"), [c[1:] for c in SCENARIO_CASES],
                         ids=[c[0] for c in SCENARIO_CASES])
def test_zenav_run_refuses_a_bad_scenario_naming_file_field_and_problem(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: tuple[str, str], expected: str
) -> None:
    old, new = edit
    assert old in GOOD_SCENARIO
    path = tmp_path / "bad.yaml"
    path.write_text(GOOD_SCENARIO.replace(old, new, 1))
    code = zenav_main(["run", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert f"zenav run: {path}: {expected}" in err, err
    assert not (tmp_path / "out" / "run.json").exists()


PARAM_CASES = [
    ("perception", "wrong-type", {"lambda_": "abc"}, "lambda_: Input should be a valid number"),
    ("perception", "unknown-key", {"bogus": 1}, "bogus: Extra inputs are not permitted"),
    ("perception", "negative-size", {"cell": -0.5}, "cell: Input should be greater than 0"),
    ("perception", "negative-window", {"window_radius": -3},
     "window_radius: Input should be greater than 0"),
    ("laser_driver", "negative-range", {"range_max": -8.0},
     "range_max: Input should be greater than 0"),
    ("motor_bridge", "wrong-type", {"max_speed": [1, 2]},
     "max_speed: Input should be a valid number"),
]


@pytest.mark.parametrize(("service", "content", "expected"),
                         [(c[0], c[2], c[3]) for c in PARAM_CASES],
                         ids=[f"{c[0]}-{c[1]}" for c in PARAM_CASES])
def test_a_bad_parameter_file_is_refused_naming_file_field_and_problem(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], service: str, content: dict[str, object],
    expected: str,
) -> None:
    path = tmp_path / f"{service}.yaml"
    path.write_text(yaml.safe_dump(content))
    code = service_main(service, ["--config", str(path), "--log-level", "ERROR"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert f"{path}: {expected}" in err, err


def test_a_parameter_file_that_is_not_a_mapping_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "tracking.yaml"
    path.write_text("- 1\n- 2\n")
    assert service_main("tracking", ["--config", str(path)]) == 2
    assert str(path) in capsys.readouterr().err
