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

With ``robot: ros2`` the simulated robot shows a ROS 2 face instead of zenav's device
keys (:mod:`zenav.sim.ros2_face`): LaserScan and Odometry out, velocity commands in.
"""

from __future__ import annotations

import asyncio
import logging
import time

from zenav.schemas import keys
from zenav.schemas.messages import BaseCommand, GroundTruth, Odometry, RawLaserFrame, RunResult
from zenav.services.node import Node
from zenav.sim.params import Params
from zenav.sim.ros2_face import Ros2Face
from zenav.sim.scenario import load_scenario
from zenav.sim.simulation import Simulation

__all__ = ["Params", "Service", "Simulation", "StackSilentError"]
# Params and Simulation are also read from here by zenav/inprocess.py and bench_perf.py.

log = logging.getLogger(__name__)


class StackSilentError(RuntimeError):
    """The stack stopped answering in lockstep mode."""


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
        self.face: Ros2Face | None = None
        if params.robot == "ros2":
            self.face = Ros2Face(node, params.ros2, self.sim.scenario.laser,
                                 self.on_base_command, lambda: self.sim.t)
        else:
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
                # After the run's end the stack is being stopped: a departure is expected.
                level = logging.WARNING if self.sim.outcome is None else logging.INFO
                log.log(level, "service %s went away at t=%.2f", service, self.sim.t)
        self._alive_changed.set()

    async def wait_for_stack(self) -> None:
        """Until every service of ``wait_for`` is alive. The timeout is a wait for the
        *next* one: it starts again each time another arrives, so a loaded machine that
        starts services slowly but steadily is waited for, and a stuck one is named."""
        timeout = self.params.startup_timeout
        deadline = time.monotonic() + timeout
        waiting = set(self.params.wait_for)
        while missing := set(self.params.wait_for) - self._alive:
            if missing < waiting:  # progress: another one is up
                waiting, deadline = missing, time.monotonic() + timeout
            left = deadline - time.monotonic()
            if left <= 0:
                raise StackSilentError(
                    f"services not up after {timeout:.0f} s without another arriving; still "
                    f"waiting on {', '.join(sorted(missing))}"
                )
            self._alive_changed.clear()
            try:
                await asyncio.wait_for(self._alive_changed.wait(), timeout=left)
            except TimeoutError:
                continue
        log.info("all services alive: %s", ", ".join(sorted(self._alive)))

    def close(self) -> None:
        if self.face is not None:
            self.face.close()

    def publish_tick(self, with_scan: bool) -> None:
        """Odometry, then the raw frame (the stack's answer starts from these two), then
        the ground truth, which no service waits for."""
        odometry = self.sim.odometry(self.odom.next_seq())
        if self.face is not None:
            self.face.publish_odometry(odometry)
            if with_scan:
                self.face.publish_scan(self.sim.t, self.sim.scan())
        else:
            self.odom.publish(odometry)
            if with_scan:
                ranges = self.sim.scan()
                self.raw.publish(RawLaserFrame(stamp=self.sim.t, seq=self.raw.next_seq(),
                                               ranges=ranges))
        self.truth.publish(self.sim.truth(self.truth.next_seq()))

    async def await_answer(self) -> None:
        """Lockstep: wait for the base command stamped with this tick, resending if needed."""
        waited = 0.0
        while not self._answered.is_set():
            try:  # a timer on this task, not a task of its own per tick as wait_for makes
                async with asyncio.timeout(self.params.retransmit_after):
                    await self._answered.wait()
            except TimeoutError:
                waited += self.params.retransmit_after
                if waited >= self.params.answer_timeout:
                    raise StackSilentError(
                        f"no base command for t={self.sim.t:.2f} s within "
                        f"{self.params.answer_timeout:.0f} s"
                    ) from None
                log.debug("no answer for t=%.2f yet; resending", self.sim.t)
                if self.face is not None:
                    self.face.republish()
                else:
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
