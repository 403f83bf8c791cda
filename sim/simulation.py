"""The world, the robot and the run record, advanced one tick at a time (pure, no I/O)."""

from __future__ import annotations

import math
from collections import deque
from typing import Literal

import numpy as np

from zenav.schemas.messages import (
    AgentPath,
    GroundTruth,
    ObstacleTruth,
    Odometry,
    Pose2D,
    RunResult,
)
from zenav.services.geometry import wrap_angle
from zenav.sim.agents import Crowd, RobotMotion
from zenav.sim.contact import clearance, first_contact
from zenav.sim.kinematics import RobotState, step_robot
from zenav.sim.params import Params
from zenav.sim.raycast import simulate_scan
from zenav.sim.scenario import Scenario
from zenav.sim.world import World, WorldSnapshot

MAX_TICK = 0.1
"""Longest simulator tick, s (the run record promises rows at most 0.1 s apart)."""


class Simulation:
    """The world, the robot and the run record, advanced one tick at a time (no I/O)."""

    def __init__(self, scenario: Scenario, params: Params) -> None:
        self.scenario = scenario
        self.params = params
        self.world = World.from_scenario(scenario)
        robot = scenario.robot
        self.state = RobotState(robot.start[0], robot.start[1], math.radians(robot.heading_deg))
        self.goal = np.asarray(robot.goal, dtype=np.float64)
        laser = scenario.laser
        scan_period = 1.0 / laser.rate_hz
        self.ticks_per_scan = max(1, math.ceil(scan_period / MAX_TICK - 1e-9))
        self.dt = scan_period / self.ticks_per_scan
        self.beam_angles = laser.angles_rad()
        self.rng = np.random.default_rng(scenario.seed)
        self.tick = 0
        keep = (None if params.clock == "lockstep"
                else max(1, math.ceil(params.realtime_history / self.dt)))
        self.rows: deque[tuple[float, float, float, float, float]] = deque(maxlen=keep)
        self.path_length = 0.0
        self.min_clearance = math.inf
        self.outcome: Literal["reached", "collision", "timeout"] | None = None
        self.collided_with: int | None = None
        self.crowd = Crowd(scenario, params.crowd())
        self.crowd.start(self._robot_motion(0.0, self.state, (0.0, 0.0)))
        self.agent_rows: list[deque[tuple[float, float, float]]] = [
            deque(maxlen=keep) for _ in self.crowd.ids]
        self._snapshot: tuple[int, WorldSnapshot] | None = None  # (tick, its obstacles)
        self._record(0.0)
        if math.dist(robot.start, robot.goal) <= robot.goal_tolerance:
            self.outcome = "reached"  # there already: the run ends at t = 0, as it starts

    @property
    def t(self) -> float:
        """Simulated time, s: ``tick`` ticks, and never past the scenario's duration (the
        last tick is cut short there when the duration is not a whole number of ticks)."""
        return min(round(self.tick * self.dt, 9), self.scenario.duration)

    def scan_due(self) -> bool:
        return self.tick % self.ticks_per_scan == 0

    def snapshot(self) -> WorldSnapshot:
        """The obstacles now. A tick asks three times (the run record's clearance, the
        scan, the ground truth), with nothing moved in between: made once per tick."""
        if self._snapshot is None or self._snapshot[0] != self.tick:
            self._snapshot = (self.tick, self.snapshot_at(self.t, self.crowd.positions_at(self.t)))
        return self._snapshot[1]

    def snapshot_at(self, t: float, agent_positions: np.ndarray) -> WorldSnapshot:
        """The obstacles at ``t`` (s), the agents at ``agent_positions`` (m) among them."""
        snap = self.world.snapshot(t)
        if not self.crowd.count:
            return snap
        on = self.crowd.exists(t)
        return WorldSnapshot(
            t=t,
            disc_centers=np.concatenate([snap.disc_centers, agent_positions[on]]),
            disc_radii=np.concatenate([snap.disc_radii, self.crowd.radii[on]]),
            disc_velocities=np.concatenate([snap.disc_velocities,
                                            self.crowd.velocities[on]]),
            disc_ids=np.concatenate([snap.disc_ids, self.crowd.ids[on]]),
            box_mins=snap.box_mins, box_maxs=snap.box_maxs,
            box_velocities=snap.box_velocities, box_ids=snap.box_ids,
        )

    def _robot_motion(self, t0: float, state: RobotState,
                      velocity: tuple[float, float]) -> RobotMotion:
        robot = self.scenario.robot
        return RobotMotion(t0=t0, position=(state.x, state.y), velocity=velocity,
                           radius=robot.radius, max_speed=robot.effective_max_speed)

    def scan(self) -> np.ndarray:
        laser = self.scenario.laser
        return simulate_scan(
            (self.state.x, self.state.y),
            self.state.heading,
            self.beam_angles,
            self.snapshot(),
            laser.max_range,
            laser.noise_std,
            self.rng,
        )

    def _record(self, t: float, agent_positions: np.ndarray | None = None) -> None:
        s = self.state
        self.rows.append((t, s.x, s.y, s.heading, s.v))
        agents = self.crowd.positions_at(t) if agent_positions is None else agent_positions
        for rows, (x, y) in zip(self.agent_rows, agents, strict=True):
            rows.append((t, float(x), float(y)))
        # The obstacles of the tick just made (cached for its scan and ground truth), or
        # at a contact, those at its time.
        snap = (self.snapshot() if agent_positions is None and t == self.t
                else self.snapshot_at(t, agents))
        gap = clearance((s.x, s.y), self.scenario.robot.radius, snap)
        self.min_clearance = min(self.min_clearance, gap)

    def step(self, v: float, omega: float) -> None:
        """Drive for one tick with the commanded velocities; set ``outcome`` if the run ends.
        A tick that would run past the scenario's duration ends at it: the run's timeout
        comes at ``duration`` exactly, as the run record says."""
        robot = self.scenario.robot
        t0 = self.t
        t1 = round((self.tick + 1) * self.dt, 9)
        dt = self.dt
        if t1 > self.scenario.duration:
            t1 = self.scenario.duration
            dt = t1 - t0
        before = self.state
        after = step_robot(
            before,
            v,
            omega,
            dt,
            v_max=robot.effective_max_speed,
            accel=self.params.base_accel,
            decel=self.params.base_decel,
            omega_max=self.params.max_omega,
            alpha_accel=self.params.base_angular_accel,
            alpha_decel=self.params.base_angular_accel,
        )
        p0, p1 = (before.x, before.y), (after.x, after.y)
        contact = first_contact(p0, p1, robot.radius, self.world, t0, t1)
        agents_at_hit: np.ndarray | None = None
        if self.crowd.count:
            # Agents move on straight lines between ORCA steps: check each piece.
            u = ((p1[0] - p0[0]) / (t1 - t0), (p1[1] - p0[1]) / (t1 - t0))
            motion = self._robot_motion(t0, before, u)
            pieces = self.crowd.advance(t1, motion)
            for ta, tb, piece in pieces:
                hit = first_contact(motion.at(ta), motion.at(tb), robot.radius, piece, ta, tb)
                if hit is not None and (contact is None or hit < contact):
                    contact = hit
            if contact is not None:  # where the agents were at the contact
                piece = next(w for ta, tb, w in pieces if ta <= contact[0] <= tb + 1e-12)
                agents_at_hit = piece.disc_centers_at(contact[0])
        if contact is not None:
            t_hit, index = contact
            # The whole state at the contact, as the record's last row says it: each
            # value between the tick's two ends in the same proportion (the heading the
            # short way round).
            frac = (t_hit - t0) / (t1 - t0) if t1 > t0 else 0.0
            turned = wrap_angle(after.heading - before.heading)
            self.state = RobotState(
                before.x + frac * (after.x - before.x),
                before.y + frac * (after.y - before.y),
                wrap_angle(before.heading + frac * turned),
                before.v + frac * (after.v - before.v),
                before.omega + frac * (after.omega - before.omega),
            )
            self.path_length += frac * math.dist(p0, p1)
            self.tick += 1
            self._record(t_hit, agents_at_hit)
            self.min_clearance = min(self.min_clearance, 0.0)
            self.outcome, self.collided_with = "collision", index
            return
        self.state = after
        self.path_length += math.dist(p0, p1)
        self.tick += 1
        self._record(self.t)
        if math.dist(p1, tuple(self.goal)) <= robot.goal_tolerance:
            self.outcome = "reached"
        elif self.t >= self.scenario.duration:
            self.outcome = "timeout"

    def odometry(self, seq: int) -> Odometry:
        s = self.state
        return Odometry(
            stamp=self.t, seq=seq, pose=Pose2D(x=s.x, y=s.y, heading=s.heading), v=s.v,
            omega=s.omega,
        )

    def truth(self, seq: int) -> GroundTruth:
        snap = self.snapshot()
        obstacles = [
            ObstacleTruth(index=int(i), shape="disc", x=float(c[0]), y=float(c[1]),
                          size=(2 * float(r), 2 * float(r)), vx=float(v[0]), vy=float(v[1]))
            for i, c, r, v in zip(snap.disc_ids, snap.disc_centers, snap.disc_radii,
                                  snap.disc_velocities, strict=True)
        ] + [
            ObstacleTruth(index=int(i), shape="box", x=float((lo[0] + hi[0]) / 2),
                          y=float((lo[1] + hi[1]) / 2), size=(float(hi[0] - lo[0]),
                                                              float(hi[1] - lo[1])),
                          vx=float(v[0]), vy=float(v[1]))
            for i, lo, hi, v in zip(snap.box_ids, snap.box_mins, snap.box_maxs,
                                    snap.box_velocities, strict=True)
        ]
        s = self.state
        return GroundTruth(stamp=self.t, seq=seq, pose=Pose2D(x=s.x, y=s.y, heading=s.heading),
                           v=s.v, obstacles=obstacles)

    def result(self) -> RunResult:
        assert self.outcome is not None
        return RunResult(
            stamp=self.rows[-1][0],
            seq=0,
            scenario=self.scenario.name,
            outcome=self.outcome,
            time=self.rows[-1][0],
            path_length=self.path_length,
            min_clearance=self.min_clearance,
            collided_with=self.collided_with,
            trajectory=np.asarray(self.rows, dtype=np.float64),
            agents=[AgentPath(index=int(i), rows=np.asarray(rows, dtype=np.float64))
                    for i, rows in zip(self.crowd.ids, self.agent_rows, strict=True)],
        )
