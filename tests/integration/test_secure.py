"""The secured two-host layout (deploy/secure/): mutual TLS and default-deny access control.

Robot and server in two network namespaces, as in test_offboard.py. A denied put is
dropped silently by Zenoh, so the access control is judged on the receiver: the robot's
odometry and the motor bridge's count of accepted commands. Needs root; skipped
otherwise.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.integration.livestack import (
    REPO,
    Deployed,
    Monitor,
    NetnsPair,
    copy_deployment,
    netns_pair,
    reached,
    run,
    zenav,
)

pytestmark = pytest.mark.integration

PORT = 7447
STATIC = REPO / "sim" / "scenarios" / "b-static-obstacle.yaml"
# h-mixed collided in real time through this stack on a quiet machine (an open fault of
# the planner at 2-4x real time); this test checks the security setup end to end.
STILL = REPO / "sim" / "scenarios" / "a-no-obstacle.yaml"


@pytest.fixture
def net() -> Iterator[NetnsPair]:
    with netns_pair() as pair:
        yield pair


def make_certs(directory: Path, *hosts: str) -> Path:
    done = run(["sh", str(REPO / "deploy" / "secure" / "make-certs.sh"), str(directory),
                *hosts])
    assert done.returncode == 0, done.stderr
    return directory


def secured(net: NetnsPair, tmp_path: Path, scenario: Path, factor: float,
            server: bool = True) -> tuple[Deployed, Deployed | None, Path]:
    certs = make_certs(tmp_path / "certs", net.robot_ip)
    security = {"certs": str(certs), "access_control": True}
    robot = Deployed(
        copy_deployment(REPO / "deploy" / "secure" / "robot.yaml", tmp_path / "robot.yaml",
                        scenario=str(scenario), security=security),
        tmp_path / "run-robot", prefix=net.exec(net.robot),
        up_args=["--set", f"simulator.realtime_factor={factor}",
                 *([] if server else ["--set", "simulator.wait_for=[laser_driver,motor_bridge]"])])
    far = None
    if server:
        far = Deployed(
            copy_deployment(REPO / "deploy" / "secure" / "server.yaml",
                            tmp_path / "server.yaml", scenario=str(scenario),
                            security={"certs": str(certs)}),
            tmp_path / "run-server", prefix=net.exec(net.server),
            up_args=["--connect", f"tls/{net.robot_ip}:{PORT}"])
    return robot, far, certs


def client(net: NetnsPair, *args: str, timeout: float = 40) -> subprocess.CompletedProcess[str]:
    return run([*net.exec(net.server), sys.executable, "-m",
                "tests.integration.secure_client", *args], timeout=timeout)


def test_only_the_planner_moves_the_robot(net: NetnsPair, tmp_path: Path) -> None:
    """Sessions with valid certificates that are not the planner's put velocity commands:
    nothing reaches the motor bridge and the robot stays put. The planner's certificate,
    with the very same commands, moves it (so the observation can see motion)."""
    robot, _, certs = secured(net, tmp_path, STILL, factor=1.0, server=False)
    endpoint = f"tls/{net.robot_ip}:{PORT}"
    try:
        robot.up()
        outcomes = {}
        for party in ("monitor", "tracking", "perception", "planner"):
            done = client(net, "drive", endpoint, "--certs", str(certs), "--as", party,
                          "--seconds", "2.5")
            assert done.returncode == 0, done.stdout + done.stderr
            outcomes[party] = json.loads(done.stdout.strip().splitlines()[-1])
        print(outcomes)
        for rogue in ("monitor", "tracking", "perception"):
            assert outcomes[rogue]["sent"] > 30
            assert outcomes[rogue]["odometry_seen"] > 20, outcomes[rogue]
            assert outcomes[rogue]["accepted"] == 0, outcomes[rogue]
            assert outcomes[rogue]["travel"] < 0.005, outcomes[rogue]
        assert outcomes["planner"]["accepted"] > 20, outcomes["planner"]
        assert outcomes["planner"]["travel"] > 0.1, outcomes["planner"]
    finally:
        robot.cleanup()


def test_a_client_without_a_valid_certificate_cannot_connect(net: NetnsPair,
                                                             tmp_path: Path) -> None:
    robot, _, certs = secured(net, tmp_path, STILL, factor=1.0, server=False)
    # A certificate named like the planner, but from another authority.
    other = make_certs(tmp_path / "other-ca", net.robot_ip)
    tls, tcp = f"tls/{net.robot_ip}:{PORT}", f"tcp/{net.robot_ip}:{PORT}"
    try:
        robot.up()
        attempts = {
            "no certificate": client(net, "probe", tls, "--ca", str(certs / "ca.pem")),
            "another authority's planner": client(
                net, "probe", tls, "--cert", str(other), "planner", "--ca",
                str(certs / "ca.pem")),
            "plain tcp": client(net, "probe", tcp),
        }
        for what, done in attempts.items():
            assert done.returncode == 3, f"{what}: {done.stdout}{done.stderr}"
        ok = client(net, "probe", tls, "--cert", str(certs), "monitor")
        assert ok.returncode == 0, ok.stdout + ok.stderr
    finally:
        robot.cleanup()


def test_secured_stack_completes_a_scenario(net: NetnsPair, tmp_path: Path) -> None:
    # 2x real time: at 4x a loaded machine delays the off-board planner's commands by
    # whole ticks and the run stops being a test of the security setup.
    robot, server, _ = secured(net, tmp_path, STATIC, factor=2.0)
    assert server is not None
    monitor = None
    started = time.monotonic()
    try:
        robot.up()
        monitor = Monitor([*net.exec(net.robot), *zenav(
            "monitor", "--transport", str(tmp_path / "run-robot" / "transport-monitor.yaml"),
            "--jsonl", "--period", "0.2")],
            tmp_path / "monitor.log")
        server.up()
        final = monitor.state("the run's result", reached, timeout=150)
        assert final["result"]["outcome"] == "reached", final["result"]
        assert final["result"]["collided_with"] is None
        assert set(server.pids()) == {"perception", "tracking", "planner"}
    finally:
        if monitor is not None:
            monitor.stop()
        for side in (server, robot):
            side.cleanup()
    print(f"secured run: {time.monotonic() - started:.1f} s wall")
