"""A planner written without zenav: only zenoh, msgpack and PyYAML.

It shows that a service is replaceable by any process that speaks the same keys and
schemas (deploy/graph.yaml): it reads ``tracks`` (TrackList), writes ``cmd_vel``
(VelocityCommand) and ``planner/state`` (PlannerState), holds the liveliness token
``alive/planner``, and answers a repeated stamp by repeating its command. It steers
straight at the goal. The planner swap test runs it under supervisord in place of the
real planner.

    python replacement_planner.py --transport T.yaml --robot-id robot0 --goal 8 3
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
import threading
from pathlib import Path
from types import FrameType
from typing import Any

import msgpack
import yaml
import zenoh

SCHEMA_VERSION = 1


def open_session(transport: Path) -> Any:
    settings = yaml.safe_load(transport.read_text()) or {}
    conf = zenoh.Config()
    conf.insert_json5("mode", json.dumps(settings.get("mode", "client")))
    conf.insert_json5("connect/endpoints", json.dumps(settings.get("connect", [])))
    conf.insert_json5("listen/endpoints", json.dumps(settings.get("listen", [])))
    conf.insert_json5("scouting/multicast/enabled", "false")
    conf.insert_json5("transport/link/tx/lease", json.dumps(settings.get("lease_ms", 1000)))
    for path, value in (settings.get("extra") or {}).items():
        conf.insert_json5(path, json.dumps(value))
    return zenoh.open(conf)


def pack(type_name: str, fields: dict[str, Any]) -> bytes:
    packed: bytes = msgpack.packb({**fields, "_v": SCHEMA_VERSION, "_t": type_name},
                                  use_bin_type=True)
    return packed


class StraightPlanner:
    def __init__(self, goal: tuple[float, float], speed: float, tolerance: float) -> None:
        self.goal = goal
        self.speed = speed
        self.tolerance = tolerance
        self.seq = 0
        self.last_stamp: float | None = None
        self.last: tuple[bytes, bytes] | None = None

    def on_tracks(self, payload: bytes) -> tuple[bytes, bytes] | None:
        """The (cmd_vel, planner/state) payloads answering one TrackList, or None."""
        try:
            fields = msgpack.unpackb(payload, raw=False)
        except Exception:
            return None
        if not isinstance(fields, dict) or fields.get("_t") != "track_list" \
                or fields.get("_v") != SCHEMA_VERSION:
            return None
        stamp = float(fields["stamp"])
        if self.last_stamp is not None and stamp <= self.last_stamp:
            return self.last if stamp == self.last_stamp else None
        pose = fields["pose"]
        dx, dy = self.goal[0] - pose["x"], self.goal[1] - pose["y"]
        error = math.atan2(dy, dx) - pose["heading"]
        error = math.atan2(math.sin(error), math.cos(error))
        at_goal = math.hypot(dx, dy) <= self.tolerance / 2
        v = 0.0 if at_goal else self.speed * max(0.0, math.cos(error))
        omega = 0.0 if at_goal else max(-1.0, min(1.0, 1.5 * error))
        command = pack("velocity_command", {"stamp": stamp, "seq": self.seq, "v": v,
                                            "omega": omega})
        state = pack("planner_state", {"stamp": stamp, "seq": self.seq, "scenario": "a",
                                       "action": "goal" if at_goal else "keep",
                                       "target": list(self.goal), "speed": v})
        self.seq += 1
        self.last_stamp, self.last = stamp, (command, state)
        return self.last


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--transport", type=Path, required=True)
    parser.add_argument("--robot-id", default="robot0")
    parser.add_argument("--goal", type=float, nargs=2, required=True)
    parser.add_argument("--speed", type=float, default=0.1)
    parser.add_argument("--tolerance", type=float, default=0.25)
    args = parser.parse_args()
    prefix = f"zenav/{args.robot_id}"
    planner = StraightPlanner((args.goal[0], args.goal[1]), args.speed, args.tolerance)
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, on_signal)
    session = open_session(args.transport)
    commands = session.declare_publisher(f"{prefix}/cmd_vel", express=True,
                                         priority=zenoh.Priority.REAL_TIME)
    states = session.declare_publisher(f"{prefix}/planner/state", express=True)

    def on_sample(sample: Any) -> None:
        # A few microseconds of arithmetic: done in Zenoh's callback, nothing blocks.
        try:
            answer = planner.on_tracks(sample.payload.to_bytes())
            if answer is not None:
                commands.put(answer[0])
                states.put(answer[1])
        except Exception as exc:  # never let an exception reach Zenoh's thread
            print(f"replacement planner: {exc}", file=sys.stderr, flush=True)

    subscriber = session.declare_subscriber(f"{prefix}/tracks", on_sample)
    token = session.liveliness().declare_token(f"{prefix}/alive/planner")
    print(f"replacement planner up, goal {args.goal}", flush=True)
    while not stop.wait(0.5):
        pass
    token.undeclare()
    subscriber.undeclare()
    commands.undeclare()
    states.undeclare()
    session.close()
    print(f"replacement planner stopped after {planner.seq} commands", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
