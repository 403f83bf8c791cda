"""Sessions that try the secured router, run inside a network namespace by the tests.

``probe ENDPOINT [--cert DIR NAME] [--ca FILE]``: open a client session; exit 0 when it
connects (and the router's liveliness token is visible), 3 when it cannot.

``drive ENDPOINT --certs DIR --as NAME --seconds S``: put velocity commands (0.2 m/s,
stamped with the robot's latest odometry stamp, as a planner would) at 20 Hz with NAME's
certificate, while a separate observer session (the monitor's certificate) watches the
robot's odometry and the motor bridge's counters. Prints one JSON line: the robot's
travel during the attempt and how many commands the motor bridge accepted.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import zenoh

from zenav.deploy.secure import tls_settings
from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode, encode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import Odometry, ServiceStatus, VelocityCommand
from zenav.services.transport import TransportConfig


def client(endpoint: str, settings: dict[str, Any], timeout_ms: int = 3000) -> Any:
    config = TransportConfig(mode="client", connect=[endpoint],
                             extra={**settings, "connect/timeout_ms": timeout_ms,
                                    "transport/shared_memory/enabled": False})
    return zenoh.open(config.to_zenoh())


def probe(args: argparse.Namespace) -> int:
    settings: dict[str, Any] = {}
    if args.cert:
        settings = tls_settings(Path(args.cert[0]), args.cert[1], listen=False)
    if args.ca:
        settings["transport/link/tls/root_ca_certificate"] = str(Path(args.ca).resolve())
    try:
        session = client(args.endpoint, settings)
    except Exception as exc:
        print(f"refused: {exc}")
        return 3
    try:
        replies = list(session.liveliness().get(Keys("robot0").alive("router"), timeout=2.0))
        seen = [r for r in replies if r.ok is not None]
        print(f"connected; router token {'seen' if seen else 'not seen'}")
        return 0 if seen else 4
    finally:
        session.close()


def drive(args: argparse.Namespace) -> int:
    k = Keys("robot0")
    certs = Path(args.certs)
    observer = client(args.endpoint, tls_settings(certs, "monitor", listen=False))
    driver = client(args.endpoint, tls_settings(certs, args.as_, listen=False))
    poses: list[tuple[float, float, float]] = []
    accepted: list[int] = []

    def on_odom(sample: Any) -> None:
        try:
            o = decode(sample.payload.to_bytes(), Odometry)
        except DecodeError:
            return
        poses.append((o.stamp, o.pose.x, o.pose.y))

    def on_status(sample: Any) -> None:
        try:
            s = decode(sample.payload.to_bytes(), ServiceStatus)
        except DecodeError:
            return
        if s.service == "motor_bridge":
            accepted.append(s.received.get(keys.CMD_VEL.name, 0))

    subs = [observer.declare_subscriber(k.of(keys.ODOM), on_odom),
            observer.declare_subscriber(k.status("motor_bridge"), on_status)]
    deadline = time.monotonic() + 10
    while (not poses or not accepted) and time.monotonic() < deadline:
        time.sleep(0.05)
    if not poses or not accepted:
        print(json.dumps({"error": "no odometry or motor bridge status seen"}))
        return 1
    start, accepted_before = poses[-1], accepted[-1]
    pub = driver.declare_publisher(k.of(keys.CMD_VEL))
    seq = 0
    end = time.monotonic() + args.seconds
    while time.monotonic() < end:
        pub.put(encode(VelocityCommand(stamp=poses[-1][0], seq=seq, v=0.2, omega=0.0)))
        seq += 1
        time.sleep(0.05)
    time.sleep(1.2)  # the next status message, and the base settling
    last = poses[-1]
    print(json.dumps({"as": args.as_, "sent": seq,
                      "travel": math.hypot(last[1] - start[1], last[2] - start[2]),
                      "accepted": accepted[-1] - accepted_before,
                      "odometry_seen": len(poses)}))
    for sub in subs:
        sub.undeclare()
    pub.undeclare()
    driver.close()
    observer.close()
    return 0


def main() -> int:
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("probe")
    p.add_argument("endpoint")
    p.add_argument("--cert", nargs=2, metavar=("DIR", "NAME"))
    p.add_argument("--ca")
    d = sub.add_parser("drive")
    d.add_argument("endpoint")
    d.add_argument("--certs", required=True)
    d.add_argument("--as", dest="as_", required=True)
    d.add_argument("--seconds", type=float, default=3.0)
    args = parser.parse_args()
    return probe(args) if args.command == "probe" else drive(args)


if __name__ == "__main__":
    sys.exit(main())
