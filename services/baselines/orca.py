"""ORCA driving the robot: CrowdNav's own baseline (pure, no I/O).

J. van den Berg, S. J. Guy, M. Lin and D. Manocha, "Reciprocal n-Body Collision
Avoidance", Robotics Research (ISRR 2009), Springer, 2011; used as the robot's policy by
CrowdNav (Chen et al., ICRA 2019, ``crowd_sim/envs/policy/orca.py``).

Each cycle builds an RVO2 query (the ``pyrvo`` package) from what the robot knows: itself
(pose, current velocity, radius, top speed) and every tracked obstacle (its track's
position, velocity and radius: what the laser saw, not ground truth). The robot's
preferred velocity points at the goal at the cruise speed, slowing within
``cruise_speed x slow_within`` of it (CrowdNav: the vector to the goal, capped at the
preferred speed); the obstacles' preferred velocities are zero (their goals are unknown),
and every radius gets CrowdNav's 0.01 m. One ORCA step gives the holonomic velocity that
is collision-free for ``time_horizon`` seconds under ORCA's reciprocity assumption.

The robot is a unicycle, not holonomic: it turns toward that velocity (turn rate
``heading_gain`` per rad of heading error, at most ``max_omega``) and drives at its
magnitude times ``cos(error)`` (zero when the error exceeds ``max_drive_error``), so it
slows in a turn and turns in place when the velocity points away.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pyrvo

from zenav.services.baselines.common import Cycle
from zenav.services.baselines.params import ORCAParams
from zenav.services.geometry import wrap_angle

__all__ = ["ORCA", "Decision", "Params", "orca_velocity", "preferred_velocity",
           "unicycle_command"]

Params = ORCAParams
"""The parameters, as ``orca.Params`` like the other baselines' modules."""


@dataclass(frozen=True)
class Decision:
    v: float  # m/s
    omega: float  # rad/s
    velocity: tuple[float, float]  # ORCA's holonomic velocity, m/s


def preferred_velocity(position: tuple[float, float], goal: tuple[float, float], speed: float,
                       slow_within: float) -> tuple[float, float]:
    """Toward ``goal`` at ``speed`` (m/s), slower within ``speed * slow_within`` m of it."""
    dx, dy = goal[0] - position[0], goal[1] - position[1]
    distance = math.hypot(dx, dy)
    if distance == 0.0:
        return (0.0, 0.0)
    scale = min(speed, distance / slow_within) / distance
    return (dx * scale, dy * scale)


def orca_velocity(cycle: Cycle, params: ORCAParams) -> tuple[float, float]:
    """ORCA's velocity for the robot (m/s, world frame) among the tracked obstacles."""
    p = params
    x, y, heading = cycle.pose
    v, _ = cycle.velocity
    sim = pyrvo.RVOSimulator(p.time_step, p.neighbor_dist, p.max_neighbors, p.time_horizon,
                             p.time_horizon, p.robot_radius + p.radius_margin, p.max_speed,
                             pyrvo.Vector2(0.0, 0.0))
    robot = sim.add_agent((x, y), p.neighbor_dist, p.max_neighbors, p.time_horizon,
                          p.time_horizon, p.robot_radius + p.radius_margin, p.max_speed,
                          (v * math.cos(heading), v * math.sin(heading)))
    sim.set_agent_pref_velocity(robot, preferred_velocity((x, y), cycle.goal, p.cruise_speed,
                                                          p.slow_within))
    obstacles = cycle.tracked
    for position, velocity, radius in zip(obstacles.positions, obstacles.velocities,
                                          obstacles.radii, strict=True):
        speed = float(np.hypot(*velocity))
        k = sim.add_agent((float(position[0]), float(position[1])), p.neighbor_dist,
                          p.max_neighbors, p.time_horizon, p.time_horizon,
                          float(radius) + p.radius_margin, max(speed, p.max_speed),
                          (float(velocity[0]), float(velocity[1])))
        sim.set_agent_pref_velocity(k, (0.0, 0.0))
    sim.do_step()
    out = sim.get_agent_velocity(robot)
    return (float(out.x), float(out.y))


def unicycle_command(velocity: tuple[float, float], heading: float, fallback_heading: float,
                     params: ORCAParams) -> tuple[float, float]:
    """(v m/s, omega rad/s) for a unicycle at ``heading`` (rad) asked for a holonomic
    ``velocity`` (m/s); a standstill turns toward ``fallback_heading`` (rad)."""
    speed = math.hypot(*velocity)
    target = math.atan2(velocity[1], velocity[0]) if speed > 1e-3 else fallback_heading
    error = wrap_angle(target - heading)
    omega = max(-params.max_omega, min(params.max_omega, params.heading_gain * error))
    v = speed * math.cos(error) if abs(error) < params.max_drive_error else 0.0
    return (max(0.0, min(v, params.max_speed)), omega)


class ORCA:
    """The policy: one ORCA query per cycle, turned into a unicycle command."""

    def __init__(self, params: ORCAParams) -> None:
        self.params = params

    def step(self, cycle: Cycle) -> Decision:
        x, y, heading = cycle.pose
        velocity = orca_velocity(cycle, self.params)
        to_goal = math.atan2(cycle.goal[1] - y, cycle.goal[0] - x)
        v, omega = unicycle_command(velocity, heading, to_goal, self.params)
        return Decision(v=v, omega=omega, velocity=velocity)
