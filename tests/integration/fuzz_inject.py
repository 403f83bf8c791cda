"""Send malformed messages on every subscribed key of a running stack.

Run as its own process (``python -m tests.integration.fuzz_inject ...``) so that its
work does not share a GIL with the test that watches the stack. It draws every payload
first; with ``--wait-go`` it then prints ``ready`` and waits for a line on stdin, so a
test can start the stack only once the fuzz is armed (a lockstep scenario runs several
times faster than real time, faster than a loaded machine imports and draws). It then
waits until the simulation is under way (an odometry stamp of at least ``--after`` s),
then sends
``--per-key`` payloads on each key, paced at ``--rate`` payloads per second in all, and
writes how many it sent per key and per kind as JSON.

Every payload is malformed by construction, so every one must be refused: random bytes,
truncated msgpack, valid msgpack of the wrong message type or schema version, an
envelope missing, NaN / Inf / negative numbers, a wrong beam count, an oversized
payload, and well-formed messages stamped from the past or far in the future. The
payload shapes are drawn with hypothesis strategies (``hypothesis`` generates them up
front, seeded, so runs are repeatable).
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
import time
from collections import Counter
from typing import Any

import msgpack
import numpy as np
import zenoh

from zenav.schemas import keys
from zenav.schemas.codec import SCHEMA_VERSION, decode, encode
from zenav.schemas.keys import Keys, Topic
from zenav.schemas.messages import (
    BaseCommand,
    LaserScan,
    Message,
    Obstacle,
    ObstacleChain,
    Odometry,
    Pose2D,
    RawLaserFrame,
    Track,
    TrackList,
    VelocityCommand,
)
from zenav.services.config import loopback_mesh

FUZZED: tuple[Topic, ...] = (keys.RAW_LASER, keys.BASE_CMD, keys.SCAN, keys.ODOM,
                             keys.OBSTACLES, keys.TRACKS, keys.CMD_VEL)
"""Every key a service subscribes to."""

def _subscribers() -> dict[str, tuple[str, ...]]:
    """Which services read each fuzzed key, from the services' own code (the graph that
    deploy/graph.yaml is checked against), so a new subscription is counted here too."""
    from zenav.graph import derive_graph

    services = derive_graph()["services"]
    return {topic.name: tuple(name for name, entry in services.items()
                              if topic.name in entry.get("subscribes", {}))
            for topic in FUZZED}


SUBSCRIBERS: dict[str, tuple[str, ...]] = _subscribers()

FUTURE = 1.0e6
"""Stamp of the "future" messages: far beyond any run."""


def sample(topic: Topic, stamp: float) -> Message:
    """A valid message for ``topic`` (the base the malformed ones are made from)."""
    pose = Pose2D(x=1.0, y=1.0, heading=0.0)
    ranges = np.full(361, 5.0, np.float32)
    if topic is keys.RAW_LASER:
        return RawLaserFrame(stamp=stamp, seq=0, ranges=ranges)
    if topic is keys.SCAN:
        return LaserScan(stamp=stamp, seq=0, frame="laser", angle_min=-math.pi / 2,
                         angle_max=math.pi / 2, angle_increment=math.radians(0.5),
                         range_min=0.0, range_max=8.0, ranges=ranges)
    if topic is keys.ODOM:
        return Odometry(stamp=stamp, seq=0, pose=pose, v=0.0, omega=0.0)
    if topic is keys.OBSTACLES:
        ob = Obstacle(x=3.0, y=2.0, rho=2.0, alpha=0.1, cells=(5, 7, 3, 4), area=6,
                      beams=(170, 190), n_beams=21, first=(3.0, 1.8), last=(3.0, 2.2),
                      chord=(3.0, 2.0), radius=0.2, edges=(0, 1))
        return ObstacleChain(stamp=stamp, seq=0, pose=pose, window_radius=4.0, cell=0.5,
                             obstacles=[ob])
    if topic is keys.TRACKS:
        tr = Track(id=1, kind="dynamic", x=3.0, y=1.0, vx=-1.0, vy=0.0, speed=1.0,
                   heading=math.pi, radius=0.2, xi=0.5, varsigma=0.5, alpha_o_deg=270.0,
                   age=5, cells=(1, 2, 3, 4), area=4)
        return TrackList(stamp=stamp, seq=0, pose=pose, tracks=[tr])
    if topic is keys.CMD_VEL:
        return VelocityCommand(stamp=stamp, seq=0, v=0.2, omega=0.0)
    if topic is keys.BASE_CMD:
        return BaseCommand(stamp=stamp, seq=0, v=0.2, omega=0.0)
    raise ValueError(topic.name)


def _pack(fields: Any) -> bytes:
    packed: bytes = msgpack.packb(fields, use_bin_type=True)
    return packed


class Generator:
    """Malformed payloads of every kind, from a seeded pool drawn with hypothesis."""

    KINDS = ("random", "truncated", "wrong_type", "version", "envelope", "nan", "inf",
             "negative", "beam_count", "oversized", "past", "future", "bad_field")

    def __init__(self, seed: int) -> None:
        self.rng = random.Random(seed)
        self.blobs = _hypothesis_pool(seed)

    def make(self, topic: Topic, kind: str) -> bytes:
        rng = self.rng
        good = sample(topic, 0.0)
        fields: dict[str, Any] = good.model_dump(mode="python")
        fields.update(_v=SCHEMA_VERSION, _t=good.TYPE)
        has_ranges = "ranges" in fields
        number = "v" if "v" in fields else ("window_radius" if "window_radius" in fields
                                            else None)
        if kind == "random":
            return rng.choice(self.blobs) or b"\xc1"
        if kind == "truncated":
            full = encode(good)
            return full[: rng.randrange(1, len(full))]
        if kind == "wrong_type":
            other = keys.ODOM if topic is not keys.ODOM else keys.CMD_VEL
            return encode(sample(other, 0.0))
        if kind == "version":
            fields["_v"] = rng.choice([0, SCHEMA_VERSION + 1, 99, "1", None, -1])
            if fields["_v"] is None:
                fields["_v"] = 2
            return _pack(fields)
        if kind == "envelope":
            del fields[rng.choice(["_v", "_t"])]
            return _pack(fields)
        if kind in ("nan", "inf", "negative"):
            bad = {"nan": math.nan, "inf": rng.choice([math.inf, -math.inf]), "negative": -1.0}
            value = bad[kind]
            if has_ranges:
                ranges = np.full(361, 5.0, "<f4")
                ranges[rng.randrange(361)] = value
                fields["ranges"] = ranges.tobytes()
            elif kind == "negative":
                fields["stamp"] = -rng.uniform(0.001, 1e6)
            elif number is not None:
                fields[number] = value
            else:
                fields["pose"] = {"x": value, "y": 1.0, "heading": 0.0}
            return _pack(fields)
        if kind == "beam_count":
            if has_ranges:
                n = rng.choice([0, 1, 360, 362, 720])
                fields["ranges"] = np.full(n, 5.0, "<f4").tobytes()
            else:
                fields["seq"] = -rng.randrange(1, 1000)
            return _pack(fields)
        if kind == "oversized":
            return encode(good) + b"\x00" * (topic.max_bytes + rng.randrange(1, 4096))
        if kind == "past":
            return encode(sample(topic, 0.0))  # every key is well past t=0 by now
        if kind == "future":
            return encode(sample(topic, FUTURE + rng.uniform(0.0, 1e6)))
        if kind == "bad_field":
            fields[rng.choice(["extra", "seq", "stamp"])] = rng.choice(["x", [1, 2], {"a": 1}])
            return _pack(fields)
        raise ValueError(kind)


def _hypothesis_pool(seed: int, size: int = 400) -> list[bytes]:
    """Random byte strings and random msgpack documents, drawn with hypothesis."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    pool: list[bytes] = []
    leaves = st.none() | st.booleans() | st.integers(-(2**63), 2**63 - 1) | st.floats() | \
        st.text(max_size=20) | st.binary(max_size=64)
    documents = st.recursive(leaves, lambda children: st.lists(children, max_size=5) |
                             st.dictionaries(st.text(max_size=8), children, max_size=5),
                             max_leaves=20)

    @settings(max_examples=size, database=None, derandomize=True, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(st.binary(min_size=1, max_size=3000) | documents.map(_pack))
    def draw(blob: bytes) -> None:
        pool.append(blob)

    draw()
    random.Random(seed).shuffle(pool)
    return pool


def must_be_refused(topic: Topic, payload: bytes) -> bool:
    """Whether the codec alone refuses ``payload`` (past/future and beam-count ones are
    refused by the stamp order and the laser driver instead)."""
    try:
        decode(payload, topic.message, "k", topic.max_bytes)
    except Exception:
        return True
    return False


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--base-port", type=int, required=True)
    parser.add_argument("--robot-id", default="robot0")
    parser.add_argument("--per-key", type=int, default=10_000)
    parser.add_argument("--rate", type=float, default=4000.0, help="payloads per second")
    parser.add_argument("--after", type=float, default=2.0, help="start at this sim time, s")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", required=True)
    parser.add_argument("--wait-go", action="store_true",
                        help="print 'ready' once armed, then wait for a line on stdin")
    args = parser.parse_args(argv)

    k = Keys(args.robot_id)
    generator = Generator(args.seed)
    plan: list[tuple[Topic, str]] = []
    for topic in FUZZED:
        kinds = [kind for kind in Generator.KINDS
                 if not (kind == "beam_count" and topic is keys.SCAN)]  # covered by nan etc.
        plan += [(topic, kinds[i % len(kinds)]) for i in range(args.per_key)]
    random.Random(args.seed).shuffle(plan)
    payloads = [generator.make(topic, kind) for topic, kind in plan]
    if args.wait_go:
        print("ready", flush=True)
        if not sys.stdin.readline():
            print("fuzz: stdin closed before the go", file=sys.stderr)
            return 1

    sent: Counter[str] = Counter()
    kinds_sent: Counter[str] = Counter()
    latest = [-1.0]

    def on_odom(sample_: Any) -> None:
        try:
            stamp = decode(sample_.payload.to_bytes(), Odometry).stamp
            if stamp < FUTURE:  # our own "future" messages come back to us
                latest[0] = max(latest[0], stamp)
        except Exception:  # our own fuzz, or anything else: not a clock reading
            pass

    # Every service that reads a fuzzed key must be linked to this session before the
    # fuzz is armed. This session opens before the stack and connects to each service's
    # port on Zenoh's retries, which back off to seconds apart; peers relay nothing, so
    # a put made before the link to a service is up never reaches it, uncounted.
    readers = {name for names in SUBSCRIBERS.values() for name in names}
    linked: set[str] = set()

    def on_alive(sample_: Any) -> None:
        if sample_.kind == zenoh.SampleKind.PUT:
            linked.add(str(sample_.key_expr).rsplit("/", 1)[-1])

    conf = loopback_mesh(None, args.base_port).to_zenoh()
    with zenoh.open(conf) as session:
        sub = session.declare_subscriber(k.of(keys.ODOM), on_odom)
        alive = session.liveliness().declare_subscriber(k.alive_any, on_alive, history=True)
        pubs = {t.name: session.declare_publisher(  # BLOCK: delivered, never lost on the way
            k.of(t), congestion_control=zenoh.CongestionControl.BLOCK) for t in FUZZED}
        deadline = time.monotonic() + 120
        # Zenoh's type stub says matching_status is a bool. At runtime it is a
        # MatchingStatus object, always truthy, and its .matching field holds the answer.
        while not (readers <= linked and all(
                pub.matching_status.matching for pub in pubs.values())):  # type: ignore[attr-defined]
            if time.monotonic() > deadline:
                print(f"fuzz: no link to {', '.join(sorted(readers - linked)) or 'a reader'} "
                      "in 120 s", file=sys.stderr)
                return 1
            time.sleep(0.01)
        # The watching test holds the simulation back until this token is up.
        token = session.liveliness().declare_token(k.alive("fuzz"))
        while latest[0] < args.after:
            if time.monotonic() > deadline:
                print("fuzz: the simulation never started", file=sys.stderr)
                return 1
            time.sleep(0.01)
        started = time.monotonic()
        stamp_at_start = latest[0]
        for i, ((topic, kind), payload) in enumerate(zip(plan, payloads, strict=True)):
            pubs[topic.name].put(payload)
            sent[topic.name] += 1
            kinds_sent[kind] += 1
            ahead = started + (i + 1) / args.rate - time.monotonic()
            if ahead > 0:
                time.sleep(ahead)
        elapsed = time.monotonic() - started
        stamp_at_end = latest[0]
        sub.undeclare()  # type: ignore[no-untyped-call]
        alive.undeclare()  # type: ignore[no-untyped-call]
        token.undeclare()  # type: ignore[no-untyped-call]
        for pub in pubs.values():
            pub.undeclare()  # type: ignore[no-untyped-call]
    with open(args.out, "w") as f:
        json.dump({"sent": dict(sent), "kinds": dict(kinds_sent), "seconds": elapsed,
                   "sim_started": stamp_at_start, "sim_ended": stamp_at_end}, f)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
