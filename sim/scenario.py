"""Scenario files: pydantic models and a loader with readable errors.

The format is the contract in ``scenario-and-run-record.md``: metres, seconds and
degrees in the file; x right, y up, origin at the lower-left corner of the world;
headings from +x, counter-clockwise positive. Every error names the file, the
field path and the problem, e.g. ``bad.yaml: robot.radius: must be > 0 (got -0.2)``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import yaml
from numpy.typing import NDArray
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from zenav.services.inputs import AliasError, BoundedLoader, not_valid_yaml, safe_load, shown
from zenav.services.mission import WINDOW_CELLS, WINDOW_FLOOR, window_radius

__all__ = [
    "LaserSpec",
    "ObstacleSpec",
    "RobotSpec",
    "Scenario",
    "ScenarioError",
    "WorldSpec",
    "load_scenario",
    "parse_scenario",
]

MAGNITUDE = 1e6
"""The largest number a scenario may hold (m, s, m/s, degrees): beyond it the simulator's
arithmetic overflows long before a run could mean anything."""

# Numbers must be numbers in the file (no "1.0" strings, no booleans), finite, and within
# +-MAGNITUDE.
Number = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=-MAGNITUDE, le=MAGNITUDE)]
Positive = Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0, le=MAGNITUDE)]
NonNegative = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=0, le=MAGNITUDE)]
Point = tuple[Number, Number]

NAME_PATTERN = r"^[a-z0-9-]+$"

Loc = tuple[str | int, ...]


class ScenarioError(ValueError):
    """A scenario file that cannot be used; the message says where and why.

    One line per problem, each ``<file>: <field.path>: <problem>``.
    """


class _ProblemsError(ValueError):
    """Raised inside validators: problems keyed by a field path below the model."""

    def __init__(self, problems: list[tuple[Loc, str]]) -> None:
        super().__init__("; ".join(f"{_format_loc(loc)}: {msg}" for loc, msg in problems))
        self.problems = problems


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class WorldSpec(_Model):
    """The world rectangle [0, width] x [0, height], m, and the grid cell size, m."""

    size: tuple[Positive, Positive]
    cell: Positive


class RobotSpec(_Model):
    """The robot: a disc of ``radius`` m driving from ``start`` to ``goal`` (m)."""

    start: Point
    heading_deg: Number = 0.0
    goal: Point
    goal_tolerance: Positive = 0.25
    speed: Positive  # cruise speed V_R, m/s
    max_speed: Positive | None = None  # m/s; None means 2 x speed
    radius: Positive

    @property
    def effective_max_speed(self) -> float:
        """Top speed, m/s: ``max_speed`` if given, else twice the cruise speed."""
        return self.max_speed if self.max_speed is not None else 2.0 * self.speed

    @property
    def heading_rad(self) -> float:
        """Initial heading, rad, from +x counter-clockwise."""
        return math.radians(self.heading_deg)


class LaserSpec(_Model):
    """A planar laser scanner centred on the robot heading (ROS LaserScan layout)."""

    fov_deg: Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0, le=360)] = 180.0
    resolution_deg: Positive = 0.5
    max_range: Positive = 8.0  # m
    rate_hz: Positive = 10.0  # scans per second
    noise_std: NonNegative = 0.0  # Gaussian range noise, m

    @model_validator(mode="after")
    def _whole_number_of_beams(self) -> LaserSpec:
        steps = self.fov_deg / self.resolution_deg
        if abs(steps - round(steps)) > 1e-6 * max(1.0, steps) or round(steps) < 1:
            raise _ProblemsError(
                [
                    (
                        ("resolution_deg",),
                        "fov_deg / resolution_deg must be a whole number of steps "
                        f"(got {self.fov_deg:g} / {self.resolution_deg:g} = {steps:.6g})",
                    )
                ]
            )
        return self

    @property
    def beam_count(self) -> int:
        """Number of beams: fov / resolution + 1 (361 for 180 degrees at 0.5)."""
        return round(self.fov_deg / self.resolution_deg) + 1

    @property
    def angle_min_rad(self) -> float:
        """Angle of beam 0 relative to the heading, rad (negative: on the right)."""
        return -math.radians(self.fov_deg) / 2.0

    @property
    def angle_increment_rad(self) -> float:
        """Angle between neighbouring beams, rad (counter-clockwise)."""
        return math.radians(self.resolution_deg)

    @property
    def period(self) -> float:
        """Time between scans, s."""
        return 1.0 / self.rate_hz

    def angles_rad(self) -> NDArray[np.float64]:
        """Beam angles relative to the heading, rad, from -fov/2 (right) to +fov/2 (left)."""
        return self.angle_min_rad + self.angle_increment_rad * np.arange(
            self.beam_count, dtype=np.float64
        )


class ObstacleSpec(_Model):
    """An axis-aligned box (``size``, m) or a disc (``radius``, m), maybe moving.

    The centre at time t is ``center + velocity * (t - appear)`` while
    ``appear <= t < vanish``; outside that interval the obstacle does not exist.

    With ``behavior: orca`` the disc is an agent: it starts at ``center``, walks to its
    ``goals`` in order at up to ``preferred_speed`` (m/s) and avoids the other agents (and
    the robot when ``sees_robot``) with ORCA; its path is made by the run (``sim/agents.py``).
    """

    shape: Literal["box", "disc"]
    center: Point  # m
    size: tuple[Positive, Positive] | None = None  # box width, height, m
    radius: Positive | None = None  # disc radius, m
    velocity: Point = (0.0, 0.0)  # m/s
    appear: Number = 0.0  # s
    vanish: Number | None = None  # s; None means never
    behavior: Literal["orca"] | None = None  # "orca": an agent (the fields below)
    goals: list[Point] | None = None  # m, visited in order; it stays at the last one
    preferred_speed: Positive | None = None  # m/s, also its top speed
    sees_robot: Annotated[bool, Field(strict=True)] = False  # False: CrowdNav's "invisible"

    @field_validator("velocity", mode="before")
    @classmethod
    def _null_velocity_is_static(cls, value: object) -> object:
        return (0.0, 0.0) if value is None else value

    @model_validator(mode="after")
    def _shape_fields(self) -> ObstacleSpec:
        problems: list[tuple[Loc, str]] = []
        if self.shape == "box":
            if self.size is None:
                problems.append((("size",), "required for a box"))
            if self.radius is not None:
                problems.append((("radius",), "not allowed for a box (use size)"))
        else:
            if self.radius is None:
                problems.append((("radius",), "required for a disc"))
            if self.size is not None:
                problems.append((("size",), "not allowed for a disc (use radius)"))
        if self.vanish is not None and self.vanish <= self.appear:
            problems.append(
                (("vanish",), f"must be > appear ({self.appear:g}) (got {self.vanish:g})")
            )
        problems += self._agent_problems()
        if problems:
            raise _ProblemsError(problems)
        return self

    def _agent_problems(self) -> list[tuple[Loc, str]]:
        problems: list[tuple[Loc, str]] = []
        if self.behavior == "orca":
            if self.shape != "disc":
                problems.append((("shape",), f"behavior orca needs shape disc (got {self.shape})"))
            if not self.goals:
                problems.append((("goals",), "behavior orca needs a non-empty list of goals"))
            if self.preferred_speed is None:
                problems.append((("preferred_speed",), "required for behavior orca"))
            if self.velocity != (0.0, 0.0):
                problems.append((("velocity",), "not allowed with behavior orca (an agent's "
                                 "velocity comes from ORCA)"))
        else:
            # Defaults (as model_dump writes them) are fine; a value means an agent was meant.
            given = {"goals": self.goals is not None,
                     "preferred_speed": self.preferred_speed is not None,
                     "sees_robot": self.sees_robot}
            problems += [((name,), "only for behavior: orca") for name, set_ in given.items()
                         if set_]
        return problems

    @property
    def is_agent(self) -> bool:
        """True for an ORCA agent (``behavior: orca``)."""
        return self.behavior == "orca"

    @property
    def is_static(self) -> bool:
        """True when the obstacle does not move (an agent always may)."""
        return not self.is_agent and self.velocity[0] == 0.0 and self.velocity[1] == 0.0

    @property
    def vanish_time(self) -> float:
        """Time the obstacle is gone from, s (inf for never)."""
        return math.inf if self.vanish is None else self.vanish

    def exists_at(self, t: float) -> bool:
        """Whether the obstacle exists at time ``t``, s."""
        return self.appear <= t < self.vanish_time

    def center_at(self, t: float) -> tuple[float, float]:
        """Centre at time ``t``, s (meaningful while the obstacle exists), m."""
        dt = t - self.appear
        return (self.center[0] + self.velocity[0] * dt, self.center[1] + self.velocity[1] * dt)

    def signed_distance(self, point: tuple[float, float], t: float) -> float:
        """Signed distance from ``point`` (m) to the surface at time ``t``, m; < 0 inside."""
        cx, cy = self.center_at(t)
        dx, dy = point[0] - cx, point[1] - cy
        if self.shape == "disc":
            assert self.radius is not None
            return math.hypot(dx, dy) - self.radius
        assert self.size is not None
        qx = abs(dx) - self.size[0] / 2.0
        qy = abs(dy) - self.size[1] / 2.0
        outside = math.hypot(max(qx, 0.0), max(qy, 0.0))
        return outside + min(max(qx, qy), 0.0)


class Scenario(_Model):
    """One scenario file: the world, the robot, the laser, the obstacles."""

    name: Annotated[str, Field(strict=True, pattern=NAME_PATTERN)]
    description: Annotated[str, Field(strict=True)] = ""
    world: WorldSpec
    robot: RobotSpec
    laser: LaserSpec = LaserSpec()
    obstacles: list[ObstacleSpec] = []
    duration: Positive = 300.0  # s
    seed: Annotated[int, Field(strict=True, ge=0)] = 0

    @field_validator("description", "laser", "obstacles", mode="before")
    @classmethod
    def _null_is_default(cls, value: object, info: ValidationInfo) -> object:
        # A key written with nothing after it (``obstacles:``) means "the default".
        defaults: dict[str | None, object] = {"description": "", "laser": {}, "obstacles": []}
        return defaults[info.field_name] if value is None else value

    @model_validator(mode="after")
    def _placement(self) -> Scenario:
        problems: list[tuple[Loc, str]] = []
        width, height = self.world.size
        robot = self.robot
        for field in ("start", "goal"):
            x, y = getattr(robot, field)
            if not (0.0 <= x <= width and 0.0 <= y <= height):
                problems.append(
                    (
                        ("robot", field),
                        f"outside the world [0, {width:g}] x [0, {height:g}] (got [{x:g}, {y:g}])",
                    )
                )
        for i, obstacle in enumerate(self.obstacles):
            if obstacle.exists_at(0.0):
                gap = obstacle.signed_distance(robot.start, 0.0) - robot.radius
                if gap <= 0.0:
                    problems.append(
                        (
                            ("robot", "start"),
                            f"robot disc overlaps obstacles[{i}] ({obstacle.shape}) at t=0 "
                            f"(gap {gap:.3g} m)",
                        )
                    )
            forever = obstacle.appear <= 0.0 and obstacle.vanish is None
            if obstacle.is_static and forever and obstacle.signed_distance(robot.goal, 0.0) < 0.0:
                problems.append(
                    (("robot", "goal"), f"inside static obstacles[{i}] ({obstacle.shape})")
                )
        if problems:
            raise _ProblemsError(problems)
        return self

    @model_validator(mode="after")
    def _within_limits(self) -> Scenario:
        problems = limit_problems(self)
        if problems:
            raise _ProblemsError(problems)
        return self


# --- limits --------------------------------------------------------------------------
# What the stack can carry, checked when the file is loaded: a scenario beyond them would
# start six processes and then fail on a message that cannot be sent.

MAX_OBSTACLES = 1000
"""Obstacles in one scenario: the simulator's ground truth carries at most this many."""

MAX_BEAMS = 4000
"""Beams per scan: a frame of float32 ranges must fit the laser keys' 32 KB."""

MAX_GRID_CELLS = 4_000_000
"""Cells of the world grid (width / cell x height / cell): the planner's map is one array."""

MAX_TICKS = 200_000
"""Simulator ticks in a run (duration x max(rate_hz, 10)): the run's result carries one
trajectory row per tick within its 16 MB."""


def limit_problems(scenario: Scenario) -> list[tuple[Loc, str]]:
    """Every way ``scenario`` exceeds what the stack can carry, or cannot succeed (a goal
    no robot disc can reach), as (field, problem) pairs; empty when it is within limits."""
    problems: list[tuple[Loc, str]] = []
    count = len(scenario.obstacles)
    if count > MAX_OBSTACLES:
        problems.append((("obstacles",), f"at most {MAX_OBSTACLES} obstacles (got {count})"))
    beams = scenario.laser.beam_count
    if beams > MAX_BEAMS:
        problems.append((("laser", "resolution_deg"), f"at most {MAX_BEAMS} beams per scan "
                         f"(got {beams}: fov_deg / resolution_deg + 1)"))
    width, height = scenario.world.size
    cells = math.ceil(width / scenario.world.cell) * math.ceil(height / scenario.world.cell)
    if cells > MAX_GRID_CELLS:
        problems.append((("world", "cell"), f"at most {MAX_GRID_CELLS} grid cells "
                         f"(got {cells}: a larger cell or a smaller world)"))
    ticks = scenario.duration * max(scenario.laser.rate_hz, 10.0)
    if ticks > MAX_TICKS:
        problems.append((("duration",), f"at most {MAX_TICKS} simulator ticks (got "
                         f"{ticks:.0f}: duration x max(laser.rate_hz, 10))"))
    if window_radius(scenario.world.cell, scenario.laser.max_range) < scenario.world.cell:
        problems.append((("laser", "max_range"), f"must be at least world.cell "
                         f"({scenario.world.cell:g} m): the perception window reaches "
                         f"{WINDOW_CELLS} cells (at least {WINDOW_FLOOR:g} m) but no farther "
                         f"than the laser, and must hold a cell "
                         f"(got {scenario.laser.max_range:g} m)"))
    robot = scenario.robot
    if robot.effective_max_speed < robot.speed:
        problems.append((("robot", "max_speed"), f"must be at least robot.speed "
                         f"({robot.speed:g} m/s, the cruise speed; got "
                         f"{robot.effective_max_speed:g} m/s)"))
    for i, obstacle in enumerate(scenario.obstacles):
        if count > MAX_OBSTACLES:
            break  # the count is the problem; one line, not a thousand
        forever = obstacle.appear <= 0.0 and obstacle.vanish is None
        if not (obstacle.is_static and forever):
            continue
        to_goal = obstacle.signed_distance(robot.goal, 0.0)
        # The point itself inside is _placement's problem. Free but so close that the
        # robot's centre cannot come within goal_tolerance of it without its disc
        # overlapping the obstacle: no run could reach it.
        if to_goal >= 0.0 and to_goal + robot.goal_tolerance <= robot.radius:
            problems.append((("robot", "goal"), f"unreachable: static obstacles[{i}] "
                             f"({obstacle.shape}) is {to_goal:.3g} m from the goal, and the "
                             f"robot disc (radius {robot.radius:g} m) cannot come within "
                             f"goal_tolerance ({robot.goal_tolerance:g} m) of it"))
    return problems


# --- loading -------------------------------------------------------------------------


class _Loader(BoundedLoader):
    """:class:`BoundedLoader` (no runaway aliases, no duplicate keys) that also reads
    ``1e-3`` as a float (YAML 1.2)."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."),
)


def load_scenario(path: str | Path) -> Scenario:
    """Read and check a scenario YAML file; raise ScenarioError naming what is wrong."""
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"{source}: file not found") from None
    except IsADirectoryError:
        raise ScenarioError(f"{source}: is a folder, not a scenario file") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError(f"{source}: not a text file ({exc.reason} at byte "
                            f"{exc.start})") from None
    except OSError as exc:
        raise ScenarioError(f"{source}: cannot read file ({exc.strerror or exc})") from None
    try:
        data = safe_load(text, _Loader)
    except AliasError as exc:
        raise ScenarioError(f"{source}: {exc}") from None
    except yaml.YAMLError as exc:
        raise ScenarioError(f"{source}: {not_valid_yaml(exc)}") from None
    return parse_scenario(data, source)


def parse_scenario(data: object, source: str) -> Scenario:
    """Check already-parsed YAML data; ``source`` names the file in error messages."""
    if data is None:
        raise ScenarioError(f"{source}: file is empty")
    if not isinstance(data, dict):
        raise ScenarioError(
            f"{source}: the top level must be a mapping of fields (got {type(data).__name__})"
        )
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        lines = [f"{source}: {path}: {problem}" for path, problem in _problems(exc.errors())]
        raise ScenarioError("\n".join(lines)) from None


def _format_loc(loc: Iterable[str | int]) -> str:
    text = ""
    for part in loc:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else part
    return text or "(top level)"


def _show(value: object) -> str:
    """A value as an error line quotes it: short (:func:`shown`), floats as ``%g``."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, tuple):
        value = list(value)
    return shown(value)


def _problems(errors: Iterable[Any]) -> list[tuple[str, str]]:
    """Turn pydantic error dicts into (field path, readable problem) pairs."""
    result: list[tuple[str, str]] = []
    for error in errors:
        loc: Loc = tuple(error["loc"])
        kind: str = error["type"]
        ctx: dict[str, Any] = error.get("ctx", {})
        got = _show(error.get("input"))
        exc = ctx.get("error")
        if isinstance(exc, _ProblemsError):
            result.extend((_format_loc(loc + sub), msg) for sub, msg in exc.problems)
            continue
        if kind == "missing" and loc and isinstance(loc[-1], int):
            # A pair with too few items reports the first missing index.
            result.append((_format_loc(loc[:-1]), f"must be a list of 2 numbers (got {got})"))
            continue
        messages = {
            "missing": "required field is missing",
            "extra_forbidden": "unknown field",
            "greater_than": f"must be > {_show(ctx.get('gt'))} (got {got})",
            "greater_than_equal": f"must be >= {_show(ctx.get('ge'))} (got {got})",
            "less_than_equal": f"must be <= {_show(ctx.get('le'))} (got {got})",
            "float_type": f"must be a number (got {got})",
            "finite_number": f"must be a finite number (got {got})",
            "int_type": f"must be a whole number (got {got})",
            "string_type": f"must be a string (got {got})",
            "string_pattern_mismatch": f"must match [a-z0-9-]+ (got {got})",
            "literal_error": f"must be one of {ctx.get('expected')} (got {got})",
            "tuple_type": f"must be a list of 2 numbers (got {got})",
            "too_long": f"must be a list of 2 numbers (got {got})",
            "too_short": f"must be a list of 2 numbers (got {got})",
            "list_type": f"must be a list (got {got})",
            "model_type": f"must be a mapping of fields (got {got})",
            "model_attributes_type": f"must be a mapping of fields (got {got})",
        }
        message = messages.get(kind)
        if message is None:
            message = str(error["msg"]).removeprefix("Value error, ")
        result.append((_format_loc(loc), message))
    return result


def dump_scenario(scenario: Scenario, path: str | Path) -> Path:
    """Write ``scenario`` as a scenario YAML file that :func:`load_scenario` reads back."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    for obstacle in data.get("obstacles", []):
        if obstacle.get("behavior") == "orca":
            obstacle.pop("velocity", None)  # an agent's velocity comes from ORCA
        else:
            obstacle.pop("sees_robot", None)
    target = Path(path)
    target.write_text(yaml.safe_dump(data, sort_keys=False))
    return target
