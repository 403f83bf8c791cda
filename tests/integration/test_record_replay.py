"""``zenav record`` a live run to MCAP, then ``zenav replay`` its scans and odometry into
fresh perception and tracking processes: they produce what they produced live."""

from __future__ import annotations

import signal
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from tests.integration.livestack import (
    OFFBOARD_SCENARIO,
    REPO,
    Deployed,
    copy_deployment,
    run,
    zenav,
)
from zenav.bag.mcapfile import MsgpackDecoderFactory, read_bag, recorded_robot
from zenav.launch import free_port_block
from zenav.schemas.codec import decode
from zenav.schemas.messages import (
    LaserScan,
    Message,
    ObstacleChain,
    TrackList,
    VelocityCommand,
)
from zenav.services.perception.params import PerceptionParams

pytestmark = pytest.mark.integration

SERVICES = ["laser_driver", "perception", "tracking", "planner", "motor_bridge"]
OUTPUTS: dict[str, type[Message]] = {
    "obstacles": ObstacleChain, "tracks": TrackList, "cmd_vel": VelocityCommand}


def wait_for_line(path: Path, text: str, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while text not in (path.read_text() if path.exists() else ""):
        assert time.monotonic() < deadline, f"no {text!r} in {path} after {timeout:.0f} s"
        time.sleep(0.1)


def recorder(path: Path, endpoint: str) -> subprocess.Popen[str]:
    return subprocess.Popen(zenav("record", str(path), "--connect", endpoint),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def stop(proc: subprocess.Popen[str]) -> str:
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=15)
    assert proc.returncode == 130, out  # stopped by SIGINT, the file complete all the same
    return out


def by_stamp(path: Path, topic: str, message_type: type[Message]) -> dict[float, dict[str, Any]]:
    """The file's messages on one topic, by stamp, without their seq."""
    messages = [decode(r.payload, message_type) for r in read_bag(path, {topic})]
    return {m.stamp: m.model_dump(exclude={"seq"}) for m in messages}


Outputs = dict[str, dict[float, Any]]
"""One run's recorded outputs: topic -> stamp -> message."""


@dataclass(frozen=True)
class Comparison:
    compared: int
    """Outputs found equal in both runs."""
    differs: float | None
    """The stamp of an output that differs although nothing before it leaves a doubt that
    both runs fed the stage the same chains."""
    stopped: str
    """Why the comparison ended."""


def compare_stateful(live: Outputs, replayed: Outputs, stage: str,
                     evidence: tuple[str, ...]) -> Comparison:
    """Compare a stage that carries state from input to input (tracking, the planner).

    A loaded host may lose a message in two places: the stage's newest-wins buffer drops
    an input (its state then differs from there on, rightly), or the recorder misses a
    sample the stage did answer (nothing differs). A stamp on any of the ``evidence``
    topics (the stage's input, its output, or an output downstream of it) shows the stage
    was fed that input. Outputs are compared in stamp order, from the first both runs
    recorded (before it, a subscriber may not be heard yet in one run):
    - an input fed in one run only ends the comparison;
    - an output recorded in one run only leaves a doubt (dropped, or missed);
    - an output that differs is a failure when no doubt came before it, else the end."""
    answered = live[stage].keys() & replayed[stage].keys()
    if not answered:
        return Comparison(0, None, f"no {stage} stamp recorded in both runs")
    seen = set().union(*(run[topic].keys() for run in (live, replayed) for topic in evidence))
    doubt: float | None = None
    compared = 0
    for stamp in sorted(s for s in seen if s >= min(answered)):
        fed = [any(stamp in run[topic] for topic in evidence) for run in (live, replayed)]
        if fed[0] != fed[1]:
            return Comparison(compared, None, f"the input at {stamp} reached one run only")
        a, b = live[stage].get(stamp), replayed[stage].get(stamp)
        if a is None or b is None:
            doubt = stamp if doubt is None else doubt
        elif a != b:
            if doubt is None:
                return Comparison(compared, stamp, f"the {stage} at {stamp} differ")
            return Comparison(compared, None, f"they differ at {stamp}, after one run lacked "
                              f"the {stage} at {doubt}")
        else:
            compared += 1
    return Comparison(compared, None, "the runs ended")


def on_router(source: str, target: Path, **changes: object) -> tuple[Deployed, str]:
    endpoint = f"tcp/127.0.0.1:{free_port_block(1)}"
    config = copy_deployment(REPO / "deploy" / source, target, scenario=str(OFFBOARD_SCENARIO),
                             router={"listen": [endpoint]},
                             transport={"mode": "client", "connect": [endpoint]}, **changes)
    return Deployed(config, target.with_suffix(".run")), endpoint


def record_and_replay(tmp_path: Path) -> str | None:
    """One attempt: a live run recorded, then replayed. Every check of the recording, of
    perception's chains and of the outputs' equality is asserted; returns why the
    stateful stages could not be compared (None when they were)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    # A live run at 4x real time, recorded; the simulator waits for the recorder.
    live, endpoint = on_router("stack.yaml", tmp_path / "live.yaml")
    live.up_args = ["--set", "simulator.realtime_factor=4",
                    "--set", f"simulator.wait_for=[{','.join(SERVICES)},record]"]
    recording = tmp_path / "run.mcap"
    proc = None
    try:
        live.up()
        proc = recorder(recording, endpoint)
        wait_for_line(live.run_dir / "logs" / "simulator.log", "ended", timeout=60)
        summary = stop(proc)
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
        live.cleanup()
    assert "recording zenav/robot0/**" in summary and "messages" in summary

    # A standard MCAP file: one channel per key, msgpack payloads, JSON Schemas, stamps.
    with recording.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[MsgpackDecoderFactory()])
        summary_section = reader.get_summary()
        assert summary_section is not None
        topics = {c.topic: c for c in summary_section.channels.values()}
        assert {"zenav/robot0/scan", "zenav/robot0/odom", "zenav/robot0/obstacles",
                "zenav/robot0/tracks", "zenav/robot0/cmd_vel",
                "zenav/robot0/alive/planner"} <= set(topics)
        scan_channel = topics["zenav/robot0/scan"]
        assert scan_channel.message_encoding == "msgpack"
        schema = summary_section.schemas[scan_channel.schema_id]
        assert (schema.name, schema.encoding) == ("zenav.LaserScan", "jsonschema")
        decoded = [(m.publish_time, d) for _, _, m, d in
                   reader.iter_decoded_messages(topics=["zenav/robot0/scan"])]
    assert decoded and all(isinstance(d, LaserScan) for _, d in decoded)
    assert all(t == round(d.stamp * 1e9) for t, d in decoded)
    assert recorded_robot(recording) == "robot0"

    recorded = {topic: by_stamp(recording, topic, kind) for topic, kind in OUTPUTS.items()}
    scans = list(read_bag(recording, {"scan"}))
    assert len(scans) > 100
    assert len(recorded["obstacles"]) >= 0.95 * len(scans)  # a loaded host may drop a few
    assert any(chain["obstacles"] for chain in recorded["obstacles"].values())

    # Replay scan + odom at twice the recorded pace into fresh perception, tracking and
    # planner (deploy/replay.yaml), recording what they publish.
    bench, endpoint = on_router("replay.yaml", tmp_path / "bench.yaml")
    replayed = tmp_path / "replayed.mcap"
    proc = None
    try:
        bench.up()
        proc = recorder(replayed, endpoint)
        span = (scans[-1].log_time - scans[0].log_time) / 1e9
        started = time.monotonic()
        done = run(zenav("replay", str(recording), "--topics", "scan,odom", "--rate", "2",
                         "--wait-for", "perception,tracking,planner,record",
                         "--connect", endpoint), timeout=120)
        took = time.monotonic() - started
        assert done.returncode == 0, done.stderr
        stop(proc)
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
        stopped = bench.down()
        bench.cleanup()
    assert stopped.returncode == 0 and "stopped cleanly" in stopped.stdout, stopped.stderr
    assert span / 2 * 0.9 < took < span / 2 + 10, (span, took)  # at twice the pace
    again = {topic: by_stamp(replayed, topic, kind) for topic, kind in OUTPUTS.items()}
    # Perception answers each scan from that scan, the odometry and the scans it answered
    # in the motion cue's memory before it (its longest baseline and a second more): the
    # same chain for every stamp both runs answered after the same recent scans. A loaded
    # host may drop a scan in one run and not the other; the chains just after it may
    # then differ, and are not compared.
    # At twice the pace on a loaded host (load 6-9 on two cores) perception dropped up to
    # a third of the scans; a replay that fed it nothing, or only the first few, fails here.
    common = recorded["obstacles"].keys() & again["obstacles"].keys()
    assert len(common) >= 0.5 * len(scans), (len(common), len(scans))
    memory = max(PerceptionParams().motion_baselines) + 1.0 + 0.05

    def recent(answered: list[float], stamp: float) -> list[float]:
        return [t for t in answered if stamp - memory < t <= stamp]

    live_answered, replay_answered = sorted(recorded["obstacles"]), sorted(again["obstacles"])
    comparable = [s for s in common
                  if recent(live_answered, s) == recent(replay_answered, s)]
    # Quiet, every one of them is comparable (215 of 215); under load 6 about two thirds.
    assert len(comparable) >= 20, (len(comparable), len(common))
    assert all(again["obstacles"][s] == recorded["obstacles"][s] for s in comparable)
    # Tracking and the planner carry state from chain to chain: the same outputs as long as
    # each was fed the same chains (see `compare_stateful`).
    compared = len(scans)
    for stage, evidence in (("tracks", ("obstacles", "tracks", "cmd_vel")),
                            ("cmd_vel", ("tracks", "cmd_vel"))):
        outcome = compare_stateful(recorded, again, stage, evidence)
        assert outcome.differs is None, (
            f"the {stage} differ at {outcome.differs} though both runs fed the same chains "
            f"and answered each of them alike before it")
        if outcome.compared < 10:
            return (f"the {stage} were compared over {outcome.compared} chains only, "
                    f"{outcome.stopped}: obstacles live {sorted(recorded['obstacles'])[:12]}, "
                    f"replayed {sorted(again['obstacles'])[:12]}; {stage} live "
                    f"{sorted(recorded[stage])[:12]}, replayed {sorted(again[stage])[:12]}")
        compared = min(compared, outcome.compared)
    print(f"replay: {len(comparable)} of {len(scans)} scans answered after the same recent "
          f"scans gave the same chain ({len(common)} answered in both runs); tracks and "
          f"commands identical over {compared} chains")
    return None


def test_a_recorded_run_replayed_into_perception_tracking_and_planner_gives_the_same_outputs(
        tmp_path):
    # A loaded host may drop a scan in the first second of either run (a stage still
    # warming up); tracking and the planner then differ from there on, rightly, and too
    # few chains are left to compare. That attempt proves nothing either way: the test
    # tries again, up to three times. Outputs that differ on the same inputs fail at once.
    reasons: list[str] = []
    for attempt in range(3):
        reason = record_and_replay(tmp_path / f"attempt-{attempt}")
        if reason is None:
            return
        reasons.append(reason)
    pytest.fail("no attempt could compare tracking and the planner over 10 chains:\n"
                + "\n".join(reasons))
