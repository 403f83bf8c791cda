"""A real-time stack with the bench listening to it, for the latency, memory and rate
benchmarks of ``zenav bench perf``."""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from zenav.launch import Stack
from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys, Topic
from zenav.schemas.messages import BaseCommand, ServiceStatus
from zenav.services.mission import stack_params
from zenav.sim.scenario import load_scenario
from zenav.tooling import StampedSubscriber, ThreadedBus

log = logging.getLogger(__name__)


class Listener:
    """The bench's own tool on the stack's bus: the wall receive time (taken in Zenoh's
    callback) of every scan, velocity command and base command by stamp (with ``hops``,
    of every message of the scan's path: also the raw frame, the obstacle chain and the
    track list), and the latest status per service. Its liveliness token ``bench`` is up
    once it listens.

    The samples of the path are only stamped and kept as they come, on Zenoh's thread;
    :meth:`settle` decodes them and files them by stamp. The listener's loop is not woken
    for each of them: the observer takes no CPU from the stack it measures while the
    stack works (it has two cores to share with it)."""

    def __init__(self, stack: Stack, hops: bool = False) -> None:
        self.k = Keys(stack.robot_id)
        self.hops = hops
        self.lock = threading.Lock()
        self.frames: dict[float, float] = {}
        self.scans: dict[float, float] = {}
        self.chains: dict[float, float] = {}
        self.tracks: dict[float, float] = {}
        self.commands: dict[float, float] = {}
        self.base: dict[float, float] = {}
        self.status: dict[str, ServiceStatus] = {}
        self._heard: list[tuple[Topic, dict[float, float], str, bytes, int]] = []
        self._heard_lock = threading.Lock()  # held only to append or to take the list
        self._handles: list[Any] = []
        self._bus = ThreadedBus(stack.transport(driver=True))
        self._subscribers = self._bus.call(self._listen)

    def _listen(self) -> list[StampedSubscriber]:
        bus = self._bus.bus
        for topic, into in self.path():
            if self.hops or topic in (keys.SCAN, keys.CMD_VEL, keys.BASE_CMD):
                self._handles.append(bus.session.declare_subscriber(
                    self.k.of(topic), self._stamper(topic, into)))
        subscribers = [StampedSubscriber(bus, self.k.status_any, self._status)]
        bus.declare_token(self.k.alive("bench"))
        return subscribers

    def path(self) -> tuple[tuple[Topic, dict[float, float]], ...]:
        """The topics of the scan's path through the stack, in order, each with the
        receive times by stamp (of the samples settled so far)."""
        return ((keys.RAW_LASER, self.frames), (keys.SCAN, self.scans),
                (keys.OBSTACLES, self.chains), (keys.TRACKS, self.tracks),
                (keys.CMD_VEL, self.commands), (keys.BASE_CMD, self.base))

    def clear(self) -> None:
        """Forget every receive time so far (the start of a measured window)."""
        with self._heard_lock:
            self._heard = []
        with self.lock:
            for _, into in self.path():
                into.clear()

    def _stamper(self, topic: Topic, into: dict[float, float]) -> Callable[[Any], None]:
        def on_sample(sample: Any) -> None:  # on Zenoh's thread
            try:
                now = time.time_ns()
                heard = (topic, into, str(sample.key_expr), sample.payload.to_bytes(), now)
                with self._heard_lock:
                    self._heard.append(heard)
            except Exception:  # never let an exception reach Zenoh's thread
                log.exception("bench listener failed on %s", topic.name)

        return on_sample

    def settle(self) -> None:
        """Decode the samples heard since the last call and file their receive times by
        stamp (a base command counts only when it passes on a command)."""
        with self._heard_lock:
            heard, self._heard = self._heard, []
        with self.lock:
            for topic, into, key, payload, received_ns in heard:
                with contextlib.suppress(DecodeError):
                    message = decode(payload, topic.message, key, topic.max_bytes)
                    if isinstance(message, BaseCommand) and message.reason != "command":
                        continue
                    into.setdefault(float(message.stamp), received_ns / 1e9)

    def _status(self, key: str, payload: bytes, received_ns: int) -> None:
        with contextlib.suppress(DecodeError):
            status = decode(payload, ServiceStatus, key, keys.STATUS.max_bytes)
            with self.lock:
                self.status[status.service] = status

    def drops(self) -> dict[str, int]:
        with self.lock:
            return {s: int(sum(d.dropped.values())) for s, d in self.status.items()}

    def close(self) -> None:
        def unsubscribe() -> None:
            for subscriber in self._subscribers:
                subscriber.close()
            for handle in self._handles:
                with contextlib.suppress(Exception):  # already undeclared with the session
                    handle.undeclare()

        with contextlib.suppress(Exception):
            self._bus.call(unsubscribe)
        self._bus.close()


@contextlib.contextmanager
def live_stack(scenario_path: Path, out_dir: Path, overrides: dict[str, dict[str, Any]],
               hops: bool = False) -> Iterator[tuple[Stack, Listener]]:
    """A real-time stack on ``scenario_path`` with the bench listening (``hops``: to
    every message of the scan's path); the simulator's clock starts once the bench's
    liveliness token is up."""
    scenario = load_scenario(scenario_path)
    params = stack_params(scenario, scenario_path, "paper")
    params["simulator"].update(clock="realtime",
                               wait_for=["laser_driver", "perception", "tracking", "planner",
                                         "motor_bridge", "bench"])
    params["motor_bridge"]["clock"] = "realtime"
    for service, values in overrides.items():
        params.setdefault(service, {}).update(values)
    stack = Stack(out_dir=out_dir, params=params, log_level="WARNING")
    listener: Listener | None = None
    try:  # a start that fails half-way leaves no service running
        stack.start()
        listener = Listener(stack, hops)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            failure = stack.failure()
            if failure:
                raise RuntimeError(failure)
            listener.settle()
            with listener.lock:
                if listener.scans:
                    break
            time.sleep(0.05)
        else:
            raise RuntimeError(f"no scan within 60 s; see {out_dir / 'logs'}")
        yield stack, listener
    finally:
        if listener is not None:
            listener.close()
        stack.stop()

