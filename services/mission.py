"""The robot's shared defaults, and a scenario turned into each service's parameters.

One name and one default per quantity: every service's ``Params`` takes the robot's
limits and the world window from the constants here, and :func:`stack_params` is the one
place that says which parameters follow from a scenario (``zenav run``, the in-process
pipeline, deployments and ``zenav params NAME --scenario FILE`` all use it).

The scenario is read through small protocols, so this module needs nothing of the
simulator (``zenav.sim.scenario.Scenario`` fits them). Its file keeps its own names:
the scenario's ``robot.speed`` is the planner's ``cruise_speed``, ``laser.max_range`` is
the laser driver's ``range_max``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol

from zenav.services.config import Layer

# --- the robot (the paper's Pioneer-sized robot) -------------------------------------
ROBOT_RADIUS = 0.2
"""Disc footprint, m."""
MAX_SPEED = 0.2
"""Forward speed limit, m/s."""
MAX_OMEGA = 1.0
"""Turn rate limit, rad/s: the planners command no more, the motor bridge passes no more,
the simulated base turns no faster."""
ACCEL = 0.5
"""Forward acceleration limit of the commands, m/s^2 (the motor bridge's; DWA plans with it)."""
DECEL = 1.0
"""Forward deceleration limit of the commands, m/s^2 (the motor bridge's; DWA plans with it)."""
MAX_REVERSE_SPEED = 0.1
"""Reverse speed limit, m/s: the motor bridge passes no faster reverse (the laser does not
see behind), and the paper planner times a spot aside it backs to with it."""

# --- the world window ------------------------------------------------------------------
CELL = 0.5
"""Grid resolution r of Eq. 2, m (paper: 500 mm)."""
RANGE_MAX = 8.0
"""The laser's longest range, m (the paper's SICK scanner)."""
WINDOW_CELLS = 8
"""The sliding window reaches this many cells round the robot (paper: 8 x 0.5 m)."""
WINDOW_FLOOR = WINDOW_CELLS * CELL
"""The least window, m: the paper's 8 cells of 0.5 m (4 m). With a finer grid, 8 cells alone
leave a robot nearly blind to movers (0.8 m at 0.1 m cells: README, "Departures")."""


def window_radius(cell: float, range_max: float) -> float:
    """r_w, m: ``WINDOW_CELLS`` cells, never less than ``WINDOW_FLOOR``, and no farther
    than the laser sees."""
    return min(max(WINDOW_CELLS * cell, WINDOW_FLOOR), range_max)


WINDOW_RADIUS = window_radius(CELL, RANGE_MAX)
"""r_w for the default cell and laser, m (4.0)."""


class RobotLike(Protocol):
    @property
    def start(self) -> tuple[float, float]: ...
    @property
    def goal(self) -> tuple[float, float]: ...
    @property
    def goal_tolerance(self) -> float: ...
    @property
    def speed(self) -> float: ...
    @property
    def effective_max_speed(self) -> float: ...
    @property
    def radius(self) -> float: ...


class LaserLike(Protocol):
    @property
    def fov_deg(self) -> float: ...
    @property
    def resolution_deg(self) -> float: ...
    @property
    def max_range(self) -> float: ...
    @property
    def rate_hz(self) -> float: ...


class WorldLike(Protocol):
    @property
    def cell(self) -> float: ...


class ScenarioLike(Protocol):
    """What :func:`stack_params` reads of a scenario."""

    @property
    def robot(self) -> RobotLike: ...
    @property
    def laser(self) -> LaserLike: ...
    @property
    def world(self) -> WorldLike: ...


LIVE_SERVICES = ("laser_driver", "perception", "tracking", "planner", "motor_bridge")
"""The services the simulator waits for besides the run itself."""

SCAN_WAIT = 5.0
"""Wall s a service holds a message for the scan of its stamp (a planner's track list, the
motor bridge's command) before going on without it. The scan comes straight from the laser
driver, the message through other services, so under load it can come first; in lockstep
runs this bound keeps a loaded machine from changing the result (1 s let a scan come late
under CI's load and the stack part from the in-process engine)."""


def stack_params(
    scenario: ScenarioLike, scenario_path: Path, planner: str = "paper"
) -> dict[str, dict[str, Any]]:
    """Per-service parameters that follow from the scenario (robot, laser, world grid).

    Only these replace the code defaults; every other parameter keeps its default. Every
    planner implementation (``planner``) is given the same mission.
    """
    robot, laser, cell = scenario.robot, scenario.laser, scenario.world.cell
    scan_period = 1.0 / laser.rate_hz
    window = window_radius(cell, laser.max_range)
    return {
        "simulator": {"scenario": str(scenario_path.resolve()), "clock": "lockstep",
                      "wait_for": [*LIVE_SERVICES, "run"]},
        "laser_driver": {"fov_deg": laser.fov_deg, "resolution_deg": laser.resolution_deg,
                         "range_max": laser.max_range, "rate_hz": laser.rate_hz},
        "perception": {"cell": cell, "window_radius": window},
        "tracking": {"fov_deg": laser.fov_deg, "window_radius": window},
        "planner": {"goal": list(robot.goal), "start": list(robot.start),
                    "goal_tolerance": robot.goal_tolerance, "cruise_speed": robot.speed,
                    "max_speed": robot.effective_max_speed, "robot_radius": robot.radius,
                    "cell": cell, "window_radius": window},
        "motor_bridge": {"max_speed": robot.effective_max_speed, "robot_radius": robot.radius,
                         "command_period": scan_period,
                         "stale_timeout": max(0.5, 3 * scan_period),
                         # The paper planner reverses only in its bounded recovery back-up.
                         **({"allow_reverse": True} if planner == "paper" else {})},
    }


def scenario_layer(
    scenario: ScenarioLike, scenario_path: Path, service: str, planner: str = "paper"
) -> Layer:
    """What the scenario sets of one service's parameters, as a layer over the defaults."""
    values = stack_params(scenario, scenario_path, planner).get(service, {})
    return Layer("scenario", f"scenario {scenario_path}", values)
