"""Scenario files: the spec example loads with its defaults; every bad file is named."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from zenav.sim.scenario import LaserSpec, ScenarioError, load_scenario, parse_scenario

SPEC_EXAMPLE = """\
name: head-on                 # required, [a-z0-9-]+
description: free text        # optional
world:
  size: [10.0, 10.0]          # width, height; the border is NOT a wall unless listed
  cell: 0.5                   # grid resolution r of Eq. (2) (the paper: 500 mm)
robot:
  start: [2.0, 5.0]
  heading_deg: 0.0
  goal: [8.0, 5.0]
  goal_tolerance: 0.25        # optional, default 0.25: reached when centre is this close
  speed: 0.1                  # cruise speed V_R, m/s
  max_speed: 0.2              # optional, default 2 x speed
  radius: 0.2                 # disc footprint
laser:                        # optional; defaults are the paper's SICK scanner
  fov_deg: 180                # centred on the heading
  resolution_deg: 0.5         # 361 beams over 180 degrees
  max_range: 8.0
  rate_hz: 10
  noise_std: 0.0              # Gaussian range noise, metres
obstacles:                    # optional, default none
  - shape: box                # axis-aligned rectangle
    center: [5.0, 5.0]
    size: [0.5, 0.5]
  - shape: disc
    center: [9.0, 5.0]
    radius: 0.2
    velocity: [-0.5, 0.0]     # optional, m/s, constant; absent = static
    appear: 0.0               # optional, s: present from this time on (default 0)
    vanish: 40.0              # optional, s: gone from this time on (default never)
duration: 300                 # optional, s, default 300: the run ends as a timeout
seed: 0                       # optional: fixes every random draw (noise)
"""

MINIMAL: dict[str, Any] = {
    "name": "minimal",
    "world": {"size": [10.0, 10.0], "cell": 0.5},
    "robot": {"start": [2.0, 5.0], "goal": [8.0, 5.0], "speed": 0.1, "radius": 0.2},
    "obstacles": [
        {"shape": "box", "center": [5.0, 5.0], "size": [0.5, 0.5]},
        {"shape": "disc", "center": [9.0, 2.0], "radius": 0.2},
    ],
}


@pytest.fixture(autouse=True)
def _in_tmp_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # Files are loaded by relative name, so messages start with just "bad.yaml: ".
    monkeypatch.chdir(tmp_path)


def write(tmp_path: Path, data: object, name: str = "bad.yaml") -> Path:
    """Write ``data`` (YAML text or plain data) to ``tmp_path / name``; return the relative name."""
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data), encoding="utf-8")
    return Path(name)


def load_error(path: Path) -> str:
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    return str(info.value)


def test_spec_example_loads_exactly(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, SPEC_EXAMPLE, "head-on.yaml"))
    assert scenario.name == "head-on"
    assert scenario.world.size == (10.0, 10.0)
    assert scenario.robot.start == (2.0, 5.0)
    assert scenario.robot.max_speed == 0.2
    assert scenario.robot.effective_max_speed == 0.2
    assert scenario.laser.beam_count == 361
    box, disc = scenario.obstacles
    assert (box.shape, box.size, box.velocity, box.vanish) == ("box", (0.5, 0.5), (0, 0), None)
    assert (disc.radius, disc.velocity, disc.vanish) == (0.2, (-0.5, 0.0), 40.0)
    assert (scenario.duration, scenario.seed) == (300.0, 0)


def test_minimal_file_gets_the_documented_defaults(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, MINIMAL, "minimal.yaml"))
    assert scenario.description == ""
    assert scenario.robot.heading_deg == 0.0
    assert scenario.robot.goal_tolerance == 0.25
    assert scenario.robot.max_speed is None
    assert scenario.robot.effective_max_speed == pytest.approx(0.2)  # 2 x speed
    assert scenario.laser == LaserSpec(
        fov_deg=180, resolution_deg=0.5, max_range=8.0, rate_hz=10, noise_std=0.0
    )
    assert scenario.obstacles[1].velocity == (0.0, 0.0)
    assert scenario.obstacles[1].appear == 0.0
    assert scenario.obstacles[1].vanish is None
    assert scenario.duration == 300.0
    assert scenario.seed == 0


def test_optional_sections_may_be_left_empty(tmp_path: Path) -> None:
    text = "name: empty\nworld: {size: [4, 3], cell: 0.5}\n"
    text += "robot: {start: [1, 1], goal: [3, 2], speed: 0.5, radius: 0.2}\nlaser:\nobstacles:\n"
    scenario = load_scenario(write(tmp_path, text, "empty.yaml"))
    assert scenario.obstacles == []
    assert scenario.laser.beam_count == 361


def test_exponent_without_dot_reads_as_number(tmp_path: Path) -> None:
    # PyYAML (YAML 1.1) would read ``1e-2`` as a string; the spec says metres.
    text = SPEC_EXAMPLE.replace("noise_std: 0.0", "noise_std: 1e-2")
    assert load_scenario(write(tmp_path, text, "noisy.yaml")).laser.noise_std == 0.01


def test_laser_beam_angles_follow_laserscan_convention() -> None:
    laser = LaserSpec()
    angles = laser.angles_rad()
    assert angles.shape == (361,)
    assert angles[0] == pytest.approx(-math.pi / 2)  # beam 0 on the right
    assert angles[180] == pytest.approx(0.0, abs=1e-12)  # straight ahead
    assert angles[-1] == pytest.approx(math.pi / 2)
    np.testing.assert_allclose(np.diff(angles), math.radians(0.5))
    assert LaserSpec(fov_deg=270, resolution_deg=0.25).beam_count == 1081
    assert LaserSpec(fov_deg=180, resolution_deg=0.1).beam_count == 1801


def test_robot_start_near_box_corner_is_fine_with_exact_geometry() -> None:
    # The disc is inside the box's inflated bounding square but clear of the corner.
    data = copy.deepcopy(MINIMAL)
    data["obstacles"] = [{"shape": "box", "center": [3.0, 3.0], "size": [2.0, 2.0]}]
    data["robot"]["start"] = [4.15, 4.15]  # 0.212 m from the corner (4, 4), radius 0.2
    assert parse_scenario(data, "corner.yaml").robot.start == (4.15, 4.15)


def test_goal_inside_obstacle_that_moves_or_goes_is_allowed() -> None:
    data = copy.deepcopy(MINIMAL)
    data["obstacles"] = [
        {"shape": "box", "center": [8.0, 5.0], "size": [1, 1], "vanish": 10.0},
        {"shape": "disc", "center": [8.0, 5.0], "radius": 0.5, "velocity": [0.0, 0.1]},
        {"shape": "box", "center": [8.0, 5.0], "size": [1, 1], "appear": 5.0},
    ]
    assert len(parse_scenario(data, "ok.yaml").obstacles) == 3


Edit = Callable[[dict[str, Any]], None]


def _parent(data: dict[str, Any], path: str) -> tuple[Any, Any]:
    """The container holding ``a.b.0.c``-style ``path``, and the last key."""
    keys: list[Any] = [int(k) if k.isdigit() else k for k in path.split(".")]
    node: Any = data
    for key in keys[:-1]:
        node = node[key]
    return node, keys[-1]


def set_at(path: str, value: object) -> Edit:
    """An edit that sets ``path`` in the scenario data."""

    def edit(data: dict[str, Any]) -> None:
        node, key = _parent(data, path)
        node[key] = value

    return edit


def delete(path: str) -> Edit:
    """An edit that removes ``path`` from the scenario data."""

    def edit(data: dict[str, Any]) -> None:
        node, key = _parent(data, path)
        del node[key]

    return edit


BAD_CASES: list[tuple[str, Edit, str]] = [
    ("negative-radius", set_at("robot.radius", -0.2), "robot.radius: must be > 0 (got -0.2)"),
    ("missing-field", delete("robot.speed"), "robot.speed: required field is missing"),
    ("missing-section", delete("world"), "world: required field is missing"),
    ("string-for-number", set_at("robot.speed", "fast"), "robot.speed: must be a number"),
    ("bool-for-number", set_at("world.cell", True), "world.cell: must be a number (got True)"),
    ("list-for-mapping", set_at("robot", [1, 2]), "robot: must be a mapping"),
    ("unknown-top-key", set_at("colour", "red"), "colour: unknown field"),
    ("unknown-nested-key", set_at("robot.wheels", 2), "robot.wheels: unknown field"),
    ("unknown-obstacle-key", set_at("obstacles.1.mass", 3), "obstacles[1].mass: unknown field"),
    ("negative-world-size", set_at("world.size", [-10, 10]), "world.size[0]: must be > 0"),
    ("zero-cell", set_at("world.cell", 0), "world.cell: must be > 0 (got 0)"),
    ("negative-speed", set_at("robot.speed", -0.1), "robot.speed: must be > 0 (got -0.1)"),
    ("negative-max-speed", set_at("robot.max_speed", -1), "robot.max_speed: must be > 0"),
    ("negative-tolerance", set_at("robot.goal_tolerance", -0.1), "robot.goal_tolerance: must be"),
    ("negative-noise", set_at("laser", {"noise_std": -0.01}), "laser.noise_std: must be >= 0"),
    ("negative-range", set_at("laser", {"max_range": -8}), "laser.max_range: must be > 0"),
    ("zero-rate", set_at("laser", {"rate_hz": 0}), "laser.rate_hz: must be > 0 (got 0)"),
    ("negative-rate", set_at("laser", {"rate_hz": -10}), "laser.rate_hz: must be > 0"),
    (
        "fractional-beams",
        set_at("laser", {"resolution_deg": 0.7}),
        "laser.resolution_deg: fov_deg / resolution_deg must be a whole number",
    ),
    ("fov-too-wide", set_at("laser", {"fov_deg": 400}), "laser.fov_deg: must be <= 360"),
    ("bad-name", set_at("name", "Head On"), "name: must match [a-z0-9-]+ (got 'Head On')"),
    ("numeric-name", set_at("name", 12), "name: must be a string"),
    ("box-without-size", delete("obstacles.0.size"), "obstacles[0].size: required for a box"),
    ("disc-without-radius", delete("obstacles.1.radius"), "obstacles[1].radius: required for a"),
    ("unknown-shape", set_at("obstacles.1.shape", "circle"), "obstacles[1].shape: must be one of"),
    ("negative-disc-radius", set_at("obstacles.1.radius", -0.2), "obstacles[1].radius: must be >"),
    ("negative-box-size", set_at("obstacles.0.size", [0.5, -1]), "obstacles[0].size[1]: must be"),
    ("short-center", set_at("obstacles.0.center", [5.0]), "obstacles[0].center: must be a list"),
    (
        "vanish-before-appear",
        set_at(
            "obstacles.1",
            {"shape": "disc", "center": [9, 2], "radius": 0.2, "appear": 5.0, "vanish": 5.0},
        ),
        "obstacles[1].vanish: must be > appear (5) (got 5)",
    ),
    ("start-outside", set_at("robot.start", [-1.0, 5.0]), "robot.start: outside the world"),
    ("goal-outside", set_at("robot.goal", [8.0, 10.5]), "robot.goal: outside the world"),
    (
        "start-on-static-box",
        set_at("obstacles.0.center", [2.3, 5.0]),  # box from x=2.05, robot disc to x=2.2
        "robot.start: robot disc overlaps obstacles[0] (box) at t=0",
    ),
    (
        "start-on-moving-disc",
        set_at(
            "obstacles.1",
            {
                "shape": "disc",
                "center": [0.0, 5.0],
                "radius": 0.3,
                "velocity": [1.0, 0.0],
                "appear": -1.8,
            },
        ),  # at t=0: (1.8, 5)
        "robot.start: robot disc overlaps obstacles[1] (disc) at t=0",
    ),
    ("goal-in-static-box", set_at("obstacles.0.center", [8.2, 5.1]), "robot.goal: inside static"),
    ("negative-seed", set_at("seed", -1), "seed: must be >= 0"),
    ("zero-duration", set_at("duration", 0), "duration: must be > 0"),
    ("huge-velocity", set_at("obstacles.1.velocity", [1e308, 0.0]),
     "obstacles[1].velocity[0]: must be <= 1e+06 (got 1e+308)"),
    ("huge-speed", set_at("robot.speed", 1e300), "robot.speed: must be <= 1e+06 (got 1e+300)"),
    ("far-centre", set_at("obstacles.1.center", [-1e308, 3.0]),
     "obstacles[1].center[0]: must be >= -1e+06 (got -1e+308)"),
    ("cell-beyond-the-laser", set_at("laser", {"max_range": 0.1}),
     "laser.max_range: must be at least world.cell (0.5 m)"),
    ("top-speed-below-cruise", set_at("robot.max_speed", 0.05),
     "robot.max_speed: must be at least robot.speed"),
]


@pytest.mark.parametrize(
    ("edit", "expected"), [c[1:] for c in BAD_CASES], ids=[c[0] for c in BAD_CASES]
)
def test_bad_field_is_named_with_file_path_and_problem(
    tmp_path: Path, edit: Edit, expected: str
) -> None:
    data = copy.deepcopy(MINIMAL)
    edit(data)
    message = load_error(write(tmp_path, data))
    lines = message.splitlines()
    assert all(line.startswith("bad.yaml: ") for line in lines), message
    assert any(line.startswith(f"bad.yaml: {expected}") for line in lines), message


def test_start_box_overlap_uses_exact_geometry_at_the_corner() -> None:
    data = copy.deepcopy(MINIMAL)
    data["obstacles"] = [{"shape": "box", "center": [3.0, 3.0], "size": [2.0, 2.0]}]
    data["robot"]["start"] = [4.1, 4.1]  # 0.141 m from the corner, radius 0.2: overlap
    with pytest.raises(ScenarioError, match=r"robot\.start: robot disc overlaps obstacles\[0\]"):
        parse_scenario(data, "corner.yaml")


def test_every_problem_is_reported_on_its_own_line(tmp_path: Path) -> None:
    data = copy.deepcopy(MINIMAL)
    data["robot"]["radius"] = -0.2
    data["robot"]["speed"] = "slow"
    data["extra"] = 1
    lines = load_error(write(tmp_path, data)).splitlines()
    assert sorted(lines) == [
        "bad.yaml: extra: unknown field",
        "bad.yaml: robot.radius: must be > 0 (got -0.2)",
        "bad.yaml: robot.speed: must be a number (got 'slow')",
    ]


def test_yaml_syntax_error_names_file_and_line(tmp_path: Path) -> None:
    message = load_error(write(tmp_path, "name: x\nworld: [1, 2\nrobot: {}\n"))
    assert message.startswith("bad.yaml: not valid YAML (")
    assert "line 3" in message


def test_duplicate_key_is_an_error(tmp_path: Path) -> None:
    message = load_error(write(tmp_path, SPEC_EXAMPLE + "seed: 3\n"))
    assert message.startswith("bad.yaml: not valid YAML (duplicate key 'seed'")


def test_missing_file_is_named(tmp_path: Path) -> None:
    assert load_error(Path("nowhere.yaml")) == "nowhere.yaml: file not found"
    assert load_error(tmp_path / "gone.yaml") == f"{tmp_path / 'gone.yaml'}: file not found"


def test_a_folder_or_a_binary_file_is_named_as_such(tmp_path: Path) -> None:
    assert load_error(tmp_path) == f"{tmp_path}: is a folder, not a scenario file"
    binary = tmp_path / "bin.yaml"
    binary.write_bytes(b"name: x\n\xff\xfe\x00")
    assert load_error(binary) == f"{binary}: not a text file (invalid start byte at byte 8)"


@pytest.mark.parametrize(
    ("text", "expected"),
    [("", "bad.yaml: file is empty"), ("- 1\n- 2\n", "bad.yaml: the top level must be a mapping")],
    ids=["empty", "list"],
)
def test_top_level_that_is_not_a_mapping_is_rejected(
    tmp_path: Path, text: str, expected: str
) -> None:
    assert load_error(write(tmp_path, text)).startswith(expected)


def test_scenario_error_is_a_value_error() -> None:
    with pytest.raises(ValueError, match=r"mine\.yaml: name: required field is missing"):
        parse_scenario({k: v for k, v in MINIMAL.items() if k != "name"}, "mine.yaml")
