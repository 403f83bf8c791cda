"""The world, the robot and the run record, advanced one tick at a time (pure, no I/O)."""

from __future__ import annotations

import math
from collections import deque
from typing import Literal

import numpy as np

from zenav.schemas.messages import GroundTruth, ObstacleTruth, Odometry, Pose2D, RunResult
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
        self._record(0.0)

    @property
    def t(self) -> float:
        return round(self.tick * self.dt, 9)

    def scan_due(self) -> bool:
        return self.tick % self.ticks_per_scan == 0

    def snapshot(self) -> WorldSnapshot:
        return self.world.snapshot(self.t)

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

    def _record(self, t: float) -> None:
        s = self.state
        self.rows.append((t, s.x, s.y, s.heading, s.v))
        gap = clearance((s.x, s.y), self.scenario.robot.radius, self.world.snapshot(t))
        self.min_clearance = min(self.min_clearance, gap)

    def step(self, v: float, omega: float) -> None:
        """Drive for one tick with the commanded velocities; set ``outcome`` if the run ends."""
        robot = self.scenario.robot
        t0 = self.t
        before = self.state
        after = step_robot(
            before,
            v,
            omega,
            self.dt,
            v_max=robot.effective_max_speed,
            accel=self.params.base_accel,
            decel=self.params.base_decel,
            omega_max=self.params.max_omega,
            alpha_accel=self.params.base_angular_accel,
            alpha_decel=self.params.base_angular_accel,
        )
        t1 = round((self.tick + 1) * self.dt, 9)
        p0, p1 = (before.x, before.y), (after.x, after.y)
        contact = first_contact(p0, p1, robot.radius, self.world, t0, t1)
        if contact is not None:
            t_hit, index = contact
            frac = (t_hit - t0) / (t1 - t0) if t1 > t0 else 0.0
            self.state = RobotState(
                before.x + frac * (after.x - before.x),
                before.y + frac * (after.y - before.y),
                after.heading,
                after.v,
                after.omega,
            )
            self.path_length += frac * math.dist(p0, p1)
            self.tick += 1
            self._record(t_hit)
            self.min_clearance = min(self.min_clearance, 0.0)
            self.outcome, self.collided_with = "collision", index
            return
        self.state = after
        self.path_length += math.dist(p0, p1)
        self.tick += 1
        self._record(self.t)
        if math.dist(p1, tuple(self.goal)) <= robot.goal_tolerance:
            self.outcome = "reached"
        elif self.t >= self.scenario.duration - 1e-9:
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
        )
