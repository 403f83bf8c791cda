"""The scenario as each service's parameters, one default per quantity, and where each
value of ``zenav params`` comes from."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from pydantic import BaseModel

from zenav.cli import main
from zenav.services.config import (
    SERVICE_ORDER,
    ConfigError,
    Layer,
    assignment_layer,
    file_layer,
    resolve,
)
from zenav.services.mission import MAX_OMEGA, scenario_layer, stack_params, window_radius
from zenav.services.runner import PLANNERS, service_params
from zenav.sim import SCENARIO_DIR
from zenav.sim.scenario import load_scenario

SCENARIO = SCENARIO_DIR / "a-no-obstacle.yaml"


def models() -> dict[str, type[BaseModel]]:
    found = {name: service_params(name) for name in SERVICE_ORDER}
    found.update({f"planner/{p}": service_params("planner", p) for p in PLANNERS})
    return found


def test_stack_params_derive_the_robot_laser_and_window_from_the_scenario() -> None:
    scenario = load_scenario(SCENARIO)
    params = stack_params(scenario, SCENARIO)
    window = min(max(8 * scenario.world.cell, 4.0), scenario.laser.max_range)
    assert window_radius(scenario.world.cell, scenario.laser.max_range) == window
    for service in ("perception", "tracking", "planner"):
        assert params[service]["window_radius"] == window
    assert params["planner"]["cruise_speed"] == scenario.robot.speed
    assert params["planner"]["max_speed"] == params["motor_bridge"]["max_speed"]
    assert params["laser_driver"]["range_max"] == scenario.laser.max_range
    assert params["simulator"]["scenario"] == str(SCENARIO.resolve())
    assert params["simulator"]["wait_for"][-1] == "run"


@pytest.mark.parametrize(("cell", "range_max", "window"), [
    (0.5, 8.0, 4.0),    # the paper's: 8 cells of 0.5 m
    (1.0, 8.0, 8.0),    # a coarser grid: still 8 cells
    (0.25, 8.0, 4.0),   # a finer one: never below the paper's 4 m
    (0.1, 8.0, 4.0),
    (0.1, 3.0, 3.0),    # and never beyond the laser
    (1.0, 6.0, 6.0),
])
def test_the_window_is_eight_cells_but_never_less_than_four_metres(
        cell: float, range_max: float, window: float) -> None:
    assert window_radius(cell, range_max) == window


@pytest.mark.parametrize("model", sorted(models()))
def test_every_derived_parameter_is_one_the_service_has(model: str) -> None:
    service = model.split("/", maxsplit=1)[0]
    derived = stack_params(load_scenario(SCENARIO), SCENARIO)[service]
    service_params_model = models()[model]
    assert set(derived) <= set(service_params_model.model_fields)
    resolve(service_params_model, [scenario_layer(load_scenario(SCENARIO), SCENARIO, service)])


def test_one_default_per_name_across_services() -> None:
    """A name two services share means one quantity with one default (the planner
    implementations are alternatives of one service: their own tuning may differ)."""
    defaults: dict[str, dict[str, object]] = {}
    for model_name, model in models().items():
        for name, info in model.model_fields.items():
            defaults.setdefault(name, {})[model_name.split("/")[0]] = repr(
                info.get_default(call_default_factory=True))
    # clock: the simulator's says how time advances, the bridge's which watchdog runs.
    differing = {name: by for name, by in defaults.items()
                 if len(set(by.values())) > 1 and name != "clock"}
    assert differing == {}
    assert {s for s, m in models().items() if "max_omega" in m.model_fields} >= {
        "simulator", "motor_bridge", "planner/paper", "planner/vfh", "planner/dwa"}
    assert service_params("simulator").model_fields["max_omega"].default == MAX_OMEGA


def test_each_value_comes_from_the_last_layer_that_sets_it(tmp_path: Path) -> None:
    model = service_params("planner")
    file = tmp_path / "planner.yaml"
    file.write_text("cruise_speed: 0.15\nheading_gain: 2.0\n")
    layers = [scenario_layer(load_scenario(SCENARIO), SCENARIO, "planner"),
              file_layer(file), assignment_layer("heading_gain=3")]
    params, settings = resolve(model, layers)
    origin = {s.name: (s.origin, s.source) for s in settings}
    assert origin["goal"] == ("scenario", f"scenario {SCENARIO}")
    assert origin["cruise_speed"] == ("file", str(file))
    assert origin["heading_gain"] == ("--set", "--set heading_gain=3")
    assert origin["kappa"] == ("default", "code")
    assert params.model_dump()["heading_gain"] == 3.0
    assert [s.name for s in settings] == list(model.model_fields)


def test_a_problem_is_named_with_the_layer_it_came_from(tmp_path: Path) -> None:
    model = service_params("perception")
    layers = [Layer("file", "deploy.yaml", {"cell": 0.5}), assignment_layer("window_radius=-1")]
    with pytest.raises(ConfigError, match=r"^--set window_radius=-1: window_radius: Input"):
        resolve(model, layers)
    with pytest.raises(ConfigError, match=r"deploy\.yaml: nope: Extra inputs"):
        resolve(model, [Layer("file", "deploy.yaml", {"nope": 1})])


def test_zenav_params_prints_yaml_with_each_origin(capsys: pytest.CaptureFixture[str],
                                                   tmp_path: Path) -> None:
    assert main(["params", "tracking"]) == 0
    out = capsys.readouterr().out
    values = [line for line in out.splitlines() if not line.startswith("#")]
    assert values and all(line.endswith("  # default") for line in values)
    assert yaml.safe_load(out)["window_radius"] == 4.0  # the comments are YAML comments

    file = tmp_path / "t.yaml"
    file.write_text("memory: 10.0\n")
    assert main(["params", "tracking", "--scenario", str(SCENARIO), "--params", str(file),
                 "--set", "gate=0.4"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert f"window_radius: 4.0  # scenario {SCENARIO}" in lines
    assert f"memory: 10.0  # file {file}" in lines
    assert "gate: 0.4  # --set" in lines


@pytest.mark.parametrize("argv, problem", [
    (["params", "nope"], "no service named 'nope'"),
    (["params", "planner", "--set", "nope=1"], "--set nope=1: nope: Extra inputs"),
    (["params", "planner", "--set", "cruise_speed=-1"], "cruise_speed: Input should be greater"),
    (["params", "planner", "--params", "/no/such.yaml"], "/no/such.yaml: cannot read"),
    (["params", "planner", "--scenario", "/no/such.yaml"], "/no/such.yaml"),
])
def test_zenav_params_refuses_bad_input_in_one_line(
        capsys: pytest.CaptureFixture[str], argv: list[str], problem: str) -> None:
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("zenav params: ") and problem in lines[0]
