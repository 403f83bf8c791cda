"""Simulator service: stands in for the robot's hardware.

Each tick it publishes odometry and ground truth, and on scan ticks a raw laser frame
for the laser driver. It drives the simulated base with the latest base command from
the motor bridge, detects contact on exact geometry, and publishes a
:class:`RunResult` when the run ends.

Two clocks:

- ``lockstep``: after each raw frame the simulator waits for the base command that
  answers it (stamped with the frame's time) before time moves on. Runs are
  deterministic and as fast as the services answer. A frame that gets no answer is sent
  again (the services answer a repeated stamp by repeating their output), so a message
  lost while the stack connects costs a little time, not the run.
- ``realtime``: ticks follow the wall clock; the latest base command is in force.
"""

from __future__ import annotations

import asyncio
import logging
import math
import time
from collections import deque
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from zenav.schemas import keys
from zenav.schemas.messages import (
    BaseCommand,
    GroundTruth,
    ObstacleTruth,
    Odometry,
    Pose2D,
    RawLaserFrame,
    RunResult,
)
from zenav.services.node import Node
from zenav.sim.contact import clearance, first_contact
from zenav.sim.kinematics import RobotState, step_robot
from zenav.sim.raycast import simulate_scan
from zenav.sim.scenario import Scenario, load_scenario
from zenav.sim.world import World, WorldSnapshot

log = logging.getLogger(__name__)

MAX_TICK = 0.1
"""Longest simulator tick, s (the run record promises rows at most 0.1 s apart)."""


class Params(BaseModel):
    model_config = ConfigDict(extra="forbid")

    scenario: Path | None = Field(None, description="scenario YAML file (required)")
    clock: Literal["lockstep", "realtime"] = "lockstep"
    realtime_factor: float = Field(1.0, gt=0, description="sim s per wall s in realtime mode")
    accel: float = Field(1.0, gt=0, description="base acceleration limit, m/s^2")
    decel: float = Field(2.0, gt=0, description="base deceleration limit, m/s^2")
    max_omega: float = Field(2.0, gt=0, description="base turn rate limit, rad/s")
    angular_accel: float = Field(8.0, gt=0, description="base turn rate change limit, rad/s^2")
    wait_for: list[str] = Field(
        default_factory=lambda: ["laser_driver", "perception", "tracking", "planner",
                                 "motor_bridge"],
        description="services whose liveliness is awaited before the clock starts",
    )
    startup_timeout: float = Field(60.0, gt=0, description="wall s to wait for them")
    retransmit_after: float = Field(0.5, gt=0, description="wall s before a frame is resent")
    answer_timeout: float = Field(30.0, gt=0, description="wall s without an answer: fail")
    result_repeat: float = Field(0.5, gt=0, description="wall s between result repeats")
    realtime_history: float = Field(
        60.0, gt=0, description="realtime: s of trajectory kept for the run result (a live "
        "stack runs for hours; lockstep runs keep every tick)"
    )
    base_timeout: float = Field(
        1.0, gt=0, description="realtime: the simulated base holds its last command at most "
        "this many wall s, then stops (a base's own watchdog, for when the bridge is gone)"
    )


class StackSilentError(RuntimeError):
    """The stack stopped answering in lockstep mode."""


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
            accel=self.params.accel,
            decel=self.params.decel,
            omega_max=self.params.max_omega,
            alpha_accel=self.params.angular_accel,
            alpha_decel=self.params.angular_accel,
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


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        if params.scenario is None:
            raise ValueError("the simulator needs a scenario: --set scenario=FILE")
        self.node = node
        self.params = params
        self.sim = Simulation(load_scenario(params.scenario), params)
        self.raw = node.publisher(keys.RAW_LASER, RawLaserFrame)
        self.odom = node.publisher(keys.ODOM, Odometry)
        self.truth = node.publisher(keys.TRUTH, GroundTruth)
        self.result = node.publisher(keys.RESULT, RunResult, reliable=True)
        self.command = BaseCommand(stamp=0.0, seq=0, v=0.0, omega=0.0, reason="idle")
        self.command_wall = time.monotonic()
        self._answered = asyncio.Event()
        self._alive: set[str] = set()
        self._alive_changed = asyncio.Event()
        node.subscribe(keys.BASE_CMD, BaseCommand, self.on_base_command, depth=4)
        node.bus.watch_liveliness(node.keys.alive_any, self.on_liveliness)

    def on_base_command(self, command: BaseCommand) -> None:
        if command.stamp >= self.command.stamp:
            self.command = command
            self.command_wall = time.monotonic()
        if command.stamp >= self.sim.t - 1e-9:
            self._answered.set()

    def on_liveliness(self, key: str, alive: bool) -> None:
        service = key.rsplit("/", 1)[-1]
        if alive:
            self._alive.add(service)
        else:
            self._alive.discard(service)
            if service in self.params.wait_for:
                log.warning("service %s went away at t=%.2f", service, self.sim.t)
        self._alive_changed.set()

    async def wait_for_stack(self) -> None:
        deadline = time.monotonic() + self.params.startup_timeout
        while missing := set(self.params.wait_for) - self._alive:
            left = deadline - time.monotonic()
            if left <= 0:
                raise StackSilentError(
                    f"services not up after {self.params.startup_timeout:.0f} s: "
                    f"{', '.join(sorted(missing))}"
                )
            self._alive_changed.clear()
            try:
                await asyncio.wait_for(self._alive_changed.wait(), timeout=left)
            except TimeoutError:
                continue
        log.info("all services alive: %s", ", ".join(sorted(self._alive)))

    def publish_tick(self, with_scan: bool) -> None:
        seq = self.odom.next_seq()
        self.odom.publish(self.sim.odometry(seq))
        self.truth.publish(self.sim.truth(self.truth.next_seq()))
        if with_scan:
            ranges = self.sim.scan()
            self.raw.publish(RawLaserFrame(stamp=self.sim.t, seq=self.raw.next_seq(),
                                           ranges=ranges))

    async def await_answer(self) -> None:
        """Lockstep: wait for the base command stamped with this tick, resending if needed."""
        waited = 0.0
        while not self._answered.is_set():
            try:
                await asyncio.wait_for(self._answered.wait(), self.params.retransmit_after)
            except TimeoutError:
                waited += self.params.retransmit_after
                if waited >= self.params.answer_timeout:
                    raise StackSilentError(
                        f"no base command for t={self.sim.t:.2f} s within "
                        f"{self.params.answer_timeout:.0f} s"
                    ) from None
                log.debug("no answer for t=%.2f yet; resending", self.sim.t)
                self.odom.republish()
                self.raw.republish()

    async def run(self) -> None:
        await self.wait_for_stack()
        sim = self.sim
        lockstep = self.params.clock == "lockstep"
        started = time.monotonic()
        log.info("run %s starts (%s clock, tick %.3f s)", sim.scenario.name,
                 self.params.clock, sim.dt)
        while sim.outcome is None:
            scan_due = sim.scan_due()
            self._answered.clear()
            self.publish_tick(scan_due)
            if lockstep and scan_due:
                await self.await_answer()
            elif not lockstep:
                wake = started + sim.t / self.params.realtime_factor
                await asyncio.sleep(max(0.0, wake - time.monotonic()))
            v, omega = self.command.v, self.command.omega
            if not lockstep and time.monotonic() - self.command_wall > self.params.base_timeout:
                v = omega = 0.0  # nothing from the bridge for too long: the base stops
            sim.step(v, omega)
        self.publish_tick(with_scan=False)
        result = sim.result()
        log.info("run %s ended: %s at t=%.2f s", sim.scenario.name, result.outcome, result.time)
        while True:  # latched: repeated until the process is stopped
            self.result.publish(result)
            await asyncio.sleep(self.params.result_repeat)


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("simulator"))
