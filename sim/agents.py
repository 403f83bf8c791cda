"""Agents that react: disc obstacles with ``behavior: orca`` walk their goals by ORCA.

ORCA (van den Berg, Guy, Lin & Manocha, "Reciprocal n-body collision avoidance", 2011)
comes from the ``pyrvo`` package (bindings of the RVO2 library), with CrowdNav's settings
as defaults (:class:`CrowdParams`). Every ``time_step`` (0.25 s) one ORCA step gives each
agent a new velocity; between ORCA steps an agent moves in a straight line at constant
velocity, so the simulator's finer tick and its exact contact check apply to agents as to
the constant-velocity movers: :meth:`Crowd.advance` returns the motion of a tick as
pieces, each a :class:`~zenav.sim.world.World` of discs on straight lines.

- An agent heads for its current goal; within its radius of a goal that is not its last
  it takes the next one. Its preferred velocity points at the goal at the preferred
  speed, slowing within ``preferred_speed x 1 s`` of it (CrowdNav's rule: the preferred
  velocity is the vector to the goal, capped at the preferred speed), so it settles on the
  last goal. Its top speed is its preferred speed.
- Agents always see each other. Agents with ``sees_robot`` also see the robot: an agent in
  the ORCA simulation whose position and velocity are set from the robot's state at every
  ORCA step (CrowdNav's "visible" setting); the others ignore it ("invisible"). With both
  kinds in one scenario, two RVO2 simulations run side by side (with and without the
  robot), each agent taking its velocity from the one that matches it.
- Before ``appear`` an agent stands at its ``center``, absent; from its ``vanish`` on it is
  gone. An absent agent is parked far outside every neighbour distance.
- Deterministic: RVO2 has no random draw, so the same scenario gives the same paths.

Positions in m, velocities in m/s, times in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pyrvo
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from zenav.sim.scenario import Scenario
from zenav.sim.world import World

__all__ = ["Crowd", "CrowdParams", "RobotMotion"]

FloatArray = NDArray[np.float64]

PARK = -1.0e5
"""Absent agents stand at (PARK - 1000 i, PARK), m: far beyond any neighbour distance."""


class CrowdParams(BaseModel):
    """ORCA settings of the agents (CrowdNav's values as defaults)."""

    model_config = ConfigDict(extra="forbid")

    time_step: float = Field(0.25, gt=0, description="time between ORCA steps, s "
                             "(CrowdNav: 0.25)")
    neighbor_dist: float = Field(10.0, gt=0, description="agents farther than this are "
                                 "ignored, m (CrowdNav: 10)")
    max_neighbors: int = Field(10, gt=0, description="most neighbours considered "
                               "(CrowdNav: 10)")
    time_horizon: float = Field(5.0, gt=0, description="ORCA's time horizon for other "
                                "agents, s (CrowdNav: 5)")
    time_horizon_obst: float = Field(5.0, gt=0, description="ORCA's time horizon for "
                                     "obstacles, s (CrowdNav: 5)")
    radius_margin: float = Field(0.01, ge=0, description="added to every radius in ORCA, m "
                                 "(CrowdNav adds 0.01)")
    slow_within: float = Field(1.0, gt=0, description="the preferred velocity is the vector "
                               "to the goal divided by this, capped at the preferred speed, "
                               "s (CrowdNav: 1)")


@dataclass(frozen=True)
class RobotMotion:
    """The robot during a tick: at ``position`` (m) at ``t0`` (s), moving at ``velocity``
    (m/s) in a straight line; ``radius`` m, ``max_speed`` m/s."""

    t0: float
    position: tuple[float, float]
    velocity: tuple[float, float]
    radius: float
    max_speed: float

    def at(self, t: float) -> tuple[float, float]:
        dt = t - self.t0
        return (self.position[0] + self.velocity[0] * dt,
                self.position[1] + self.velocity[1] * dt)


class Crowd:
    """The agents of a scenario, moved by ORCA; positions kept at time :attr:`t`."""

    def __init__(self, scenario: Scenario, params: CrowdParams | None = None) -> None:
        self.params = params or CrowdParams()
        agents = [(i, o) for i, o in enumerate(scenario.obstacles) if o.is_agent]
        self.ids = np.array([i for i, _ in agents], dtype=np.int64)
        n = len(agents)
        self.radii = np.array([o.radius for _, o in agents], dtype=np.float64).reshape(n)
        self.speeds = np.array([o.preferred_speed for _, o in agents],
                               dtype=np.float64).reshape(n)
        self.appear = np.array([o.appear for _, o in agents], dtype=np.float64).reshape(n)
        self.vanish = np.array([o.vanish_time for _, o in agents], dtype=np.float64).reshape(n)
        self.sees_robot = np.array([o.sees_robot for _, o in agents], dtype=bool).reshape(n)
        self.goals = [np.array(o.goals, dtype=np.float64).reshape(-1, 2) for _, o in agents]
        self.goal_index = np.zeros(n, dtype=np.int64)
        self.positions = np.array([o.center for _, o in agents],
                                  dtype=np.float64).reshape(n, 2)
        self.velocities = np.zeros((n, 2))
        self.t = 0.0
        self.steps = 0  # ORCA steps done; the next one is at steps * time_step
        robot = scenario.robot
        self._robot_radius = robot.radius
        self._robot_speed = robot.effective_max_speed
        # One RVO2 simulation per kind of agent present: blind to the robot, seeing it.
        self._sims: dict[bool, pyrvo.RVOSimulator] = {}
        for sees in (False, True):
            if n and bool((self.sees_robot == sees).any()):
                self._sims[sees] = self._make_sim(with_robot=sees)

    @property
    def count(self) -> int:
        return len(self.ids)

    def _make_sim(self, with_robot: bool) -> pyrvo.RVOSimulator:
        p = self.params
        sim = pyrvo.RVOSimulator(p.time_step, p.neighbor_dist, p.max_neighbors, p.time_horizon,
                                 p.time_horizon_obst, 0.3, 1.0, pyrvo.Vector2(0.0, 0.0))
        for k in range(self.count):
            sim.add_agent(self._park(k), p.neighbor_dist, p.max_neighbors, p.time_horizon,
                          p.time_horizon_obst, float(self.radii[k]) + p.radius_margin,
                          float(self.speeds[k]), (0.0, 0.0))
        if with_robot:
            sim.add_agent(self._park(self.count), p.neighbor_dist, p.max_neighbors,
                          p.time_horizon, p.time_horizon_obst,
                          self._robot_radius + p.radius_margin, self._robot_speed, (0.0, 0.0))
        return sim

    @staticmethod
    def _park(k: int) -> tuple[float, float]:
        return (PARK - 1000.0 * k, PARK)

    def exists(self, t: float) -> NDArray[np.bool_]:
        """Which agents exist at ``t`` (s): ``appear <= t < vanish``."""
        return (self.appear <= t) & (t < self.vanish)

    def positions_at(self, t: float) -> FloatArray:
        """Centres at ``t`` (s), m, for ``t`` between :attr:`t` and the next ORCA step."""
        moved: FloatArray = self.positions + self.velocities * (t - self.t)
        return moved

    def next_step_time(self) -> float:
        return round(self.steps * self.params.time_step, 9)

    def preferred_velocities(self) -> FloatArray:
        """Toward the current goal, capped at the preferred speed (switching goals first)."""
        p = self.params
        prefs = np.zeros((self.count, 2))
        for k in range(self.count):
            goals = self.goals[k]
            while (self.goal_index[k] < len(goals) - 1 and
                   math.dist(self.positions[k], goals[self.goal_index[k]]) < self.radii[k]):
                self.goal_index[k] += 1
            d = goals[self.goal_index[k]] - self.positions[k]
            distance = math.hypot(d[0], d[1])
            speed = min(float(self.speeds[k]), distance / p.slow_within)
            if distance > 0.0:
                prefs[k] = d / distance * speed
        return prefs

    def _orca_step(self, robot: RobotMotion | None) -> None:
        """New velocities for every agent at time :attr:`t` (positions already there)."""
        on = self.exists(self.t)
        prefs = self.preferred_velocities()
        new = np.zeros((self.count, 2))
        for sees, sim in self._sims.items():
            for k in range(self.count):
                if on[k]:
                    sim.set_agent_position(k, (float(self.positions[k, 0]),
                                               float(self.positions[k, 1])))
                    sim.set_agent_velocity(k, (float(self.velocities[k, 0]),
                                               float(self.velocities[k, 1])))
                    sim.set_agent_pref_velocity(k, (float(prefs[k, 0]), float(prefs[k, 1])))
                else:
                    sim.set_agent_position(k, self._park(k))
                    sim.set_agent_velocity(k, (0.0, 0.0))
                    sim.set_agent_pref_velocity(k, (0.0, 0.0))
            if sees:
                r = self.count
                if robot is None:
                    sim.set_agent_position(r, self._park(r))
                    sim.set_agent_velocity(r, (0.0, 0.0))
                else:
                    sim.set_agent_position(r, robot.at(self.t))
                    sim.set_agent_velocity(r, robot.velocity)
                sim.set_agent_pref_velocity(r, robot.velocity if robot else (0.0, 0.0))
            sim.do_step()
            for k in range(self.count):
                if on[k] and bool(self.sees_robot[k]) == sees:
                    v = sim.get_agent_velocity(k)
                    new[k] = (v.x, v.y)
        self.velocities = new

    def start(self, robot: RobotMotion | None) -> None:
        """The ORCA step at t = 0 (call once before the first :meth:`advance`)."""
        if self.steps == 0:
            self._orca_step(robot)
            self.steps = 1

    def advance(self, t1: float, robot: RobotMotion | None) -> list[tuple[float, float, World]]:
        """Move the agents from :attr:`t` to ``t1`` (s), taking every ORCA step on the way.

        Returns the pieces of the motion, ``(ta, tb, world)``: within ``[ta, tb]`` each
        agent moves on a straight line, as ``world``'s discs (its obstacle indices are the
        scenario's) do; the contact check runs on each piece.
        """
        self.start(robot)
        pieces: list[tuple[float, float, World]] = []
        while self.t < t1 - 1e-12:
            tb = min(t1, self.next_step_time())
            pieces.append((self.t, tb, self._piece(self.t, tb)))
            self.positions = self.positions_at(tb)
            self.t = tb
            if abs(tb - self.next_step_time()) <= 1e-9:
                self._orca_step(robot)
                self.steps += 1
        return pieces

    def _piece(self, ta: float, tb: float) -> World:
        """The agents during [ta, tb] as discs on straight lines (World semantics: centre
        ``center + velocity * (t - appear)`` while ``appear <= t < vanish``). An agent that
        appears inside the piece stands at its centre (its velocity is 0 until its first
        ORCA step)."""
        none = np.zeros((0, 2))
        return World(
            size=(0.0, 0.0), disc_centers=self.positions.copy(), disc_radii=self.radii,
            disc_velocities=self.velocities.copy(), disc_appear=np.maximum(self.appear, ta),
            disc_vanish=self.vanish, disc_ids=self.ids, box_centers=none,
            box_half_sizes=none, box_velocities=none, box_appear=np.zeros(0),
            box_vanish=np.zeros(0), box_ids=np.zeros(0, dtype=np.int64),
        )
