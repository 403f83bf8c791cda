"""A long-running stack on one host under supervisord (``zenav up``, deploy/stack.yaml):
crashed services restarted and rejoining, the planner replaced mid-run, clean stop.

Each stack gets its own router port on loopback; a ``zenav monitor --jsonl`` process
reports what happens on the bus, with the wall time of each change.
"""

from __future__ import annotations

import itertools
import os
import signal
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from tests.integration.livestack import (
    LONG_SCENARIO,
    REPO,
    Deployed,
    Event,
    Monitor,
    copy_deployment,
    monitor_command,
    moving_at,
    reached,
    run,
    zenav,
)
from zenav.launch import free_port_block
from zenav.sim.scenario import load_scenario

pytestmark = pytest.mark.integration

OUTPUT = {
    "laser_driver": "scan",
    "perception": "obstacles",
    "tracking": "tracks",
    "planner": "cmd_vel",
    "motor_bridge": "device/base_cmd",
    "router": "odom",
}
"""What each killed program's comeback is measured on: its output, or for the router the
robot side's odometry reaching the monitor again."""


LONGER_SCENARIO = LONG_SCENARIO.with_name("longer.yaml")

OUTAGE_WAIT = 20.0
"""s the kill test waits for the monitor to report the killed program's output stopped; a
restart faster than the monitor's outage threshold shows no outage at all."""
LOADED_WAIT = 90.0
"""s any one step of the loaded kill -9 test may take: with two busy loops beside a
shared 2-core machine, a Python service's restart alone can take tens of seconds."""


def outage(monitor: Monitor, topic: str, since: float) -> Callable[[], Event | None]:
    """Finds the monitor's report of ``topic`` stopping, noticed after ``since``."""
    def find() -> Event | None:
        return next((e for e in monitor.events if e["event"] == "flow" and e["topic"] == topic
                     and not e["flowing"] and e["noticed"] >= since), None)
    return find


def has_tracks_after(since: float) -> Callable[[Event], bool]:
    def check(snap: Event) -> bool:
        return bool(snap["wall"] > since and snap["obstacles"])
    return check


def one_host(tmp_path: Path, timeout: float = 30, speed: float = 2.0,
             scenario: Path = LONG_SCENARIO, **changes: object) -> tuple[Deployed, str]:
    """deploy/stack.yaml on a free loopback port, on ``scenario``, at ``speed`` x real
    time; ``timeout`` is zenav up's wait for each next program."""
    endpoint = f"tcp/127.0.0.1:{free_port_block(1)}"
    config = copy_deployment(
        REPO / "deploy" / "stack.yaml", tmp_path / "stack.yaml", scenario=str(scenario),
        router={"listen": [endpoint]}, transport={"mode": "client", "connect": [endpoint]},
        **changes)
    return Deployed(config, tmp_path / "run",
                    up_args=["--set", f"simulator.realtime_factor={speed:g}", "--timeout",
                             str(timeout)]), endpoint


def test_up_ctl_down_give_a_realtime_stack_with_one_log_per_program(tmp_path):
    stack, _ = one_host(tmp_path)
    programs = ["laser_driver", "motor_bridge", "perception", "planner", "router",
                "simulator", "tracking"]
    try:
        done = stack.up()
        assert "alive on the bus" in done.stdout
        status = stack.ctl("status")
        assert status.returncode == 0, status.stderr
        assert sorted(line.split()[0] for line in status.stdout.splitlines()) == programs
        assert all(" RUNNING " in line for line in status.stdout.splitlines())
        again = run(zenav("up", "--config", str(stack.config), "--run-dir", str(stack.run_dir)))
        assert again.returncode == 2 and "already up" in again.stderr, again
    finally:
        stopped = stack.down()
        stack.cleanup()
    assert stopped.returncode == 0 and "stopped cleanly" in stopped.stdout, stopped.stderr
    logs = {p.stem for p in (stack.run_dir / "logs").glob("*.log")}
    assert logs == {*programs, "supervisord"}
    assert "all services alive" in (stack.run_dir / "logs" / "simulator.log").read_text()
    # Stopped in reverse start order: planner first (the bridge stops the wheels), router last.
    lines = (stack.run_dir / "logs" / "supervisord.log").read_text().splitlines()
    order = [line.split("stopped: ")[1].split()[0] for line in lines if "stopped: " in line]
    assert order == ["planner", "tracking", "perception", "laser_driver", "simulator",
                     "motor_bridge", "router"]
    assert all("(exit status 0)" in line for line in lines if "stopped: " in line)
    assert Deployed(stack.config, stack.run_dir).supervisor.pid() is None


def test_a_program_killed_with_sigkill_is_restarted_and_rejoins_without_the_others(
        tmp_path, measure, busy_machine):
    """Measured with two busy loops running (``busy_machine``): recovery must not depend
    on a quiet machine."""
    # Real time on the 28 m run: while an upstream service restarts (seconds, on a busy
    # machine) the robot goes on with the last tracks, and it must still be under way
    # for the last kill.
    stack, endpoint = one_host(tmp_path, timeout=LOADED_WAIT, speed=1.0,
                               scenario=LONGER_SCENARIO)
    monitor = None
    start_x = load_scenario(LONGER_SCENARIO).robot.start[0]
    times: dict[str, dict[str, float]] = {}
    try:
        stack.up()
        monitor = Monitor(monitor_command(endpoint), tmp_path / "monitor.log")
        monitor.state("steady data on every output (so that an outage shows)",
                      lambda s: all(s["rates"].get(o, 0) > 5 for o in OUTPUT.values()),
                      LOADED_WAIT)
        x = start_x + 0.2
        for program, output in OUTPUT.items():
            snap = monitor.state(f"the robot under way before killing {program}",
                                 moving_at(x), timeout=LOADED_WAIT)
            before = stack.pids()
            killed = time.time()
            os.kill(before[program], signal.SIGKILL)
            deadline = time.monotonic() + LOADED_WAIT
            while (pid := stack.pids()[program]) in (before[program], 0):
                assert time.monotonic() < deadline, f"{program} not restarted"
                time.sleep(0.01)
            spawned = time.time()
            back = monitor.event("alive", LOADED_WAIT, after=killed, service=program,
                                 alive=True)
            try:
                stopped = monitor.wait(f"{output} stopping after the kill",
                                       outage(monitor, output, killed), timeout=OUTAGE_WAIT)
            except AssertionError:
                # The output never paused long enough for the monitor to call it stopped:
                # the restart beat the monitor's outage threshold; it flows from liveliness.
                flowing_wall = back["wall"]
            else:
                flowing_wall = monitor.event("flow", LOADED_WAIT, after=stopped["noticed"],
                                             topic=output, flowing=True)["wall"]
            times[program] = {"spawned": spawned - killed, "alive": back["wall"] - killed,
                              "flowing": flowing_wall - killed}
            measure(f"kill -9 {program}, {len(busy_machine)} busy loops -> data flowing "
                    f"again ({output})", times[program]["flowing"],
                    f"respawned {times[program]['spawned']:.3f} s, liveliness back "
                    f"{times[program]['alive']:.3f} s")
            after = stack.pids()
            assert after[program] == pid
            assert {p: after[p] for p in after if p != program} == \
                {p: before[p] for p in before if p != program}, "another program restarted"
            if program == "tracking":  # its state is rebuilt from the next messages
                monitor.state("tracks again after the restart",
                              has_tracks_after(flowing_wall), timeout=LOADED_WAIT)
            x = snap["truth"]["x"] + 0.1
        final = monitor.state("the run's result", reached, timeout=6 * LOADED_WAIT)
        assert final["result"]["outcome"] == "reached", final["result"]
        assert final["result"]["collided_with"] is None
        rejoins = {name: s["rejoins"] for name, s in final["services"].items()}
        assert all(rejoins[p] >= 1 for p in OUTPUT), rejoins
        assert all(s["alive"] for s in final["services"].values())
    finally:
        if monitor is not None:
            monitor.stop()
        stopped = stack.down() if stack.is_up else None
        stack.cleanup()
    assert stopped is not None and stopped.returncode == 0, stopped
    # The target is 1 s; this bound only catches a recovery that does not happen (the
    # figures above are the result, and depend on how busy the machine is besides).
    assert all(t["flowing"] < LOADED_WAIT for t in times.values()), times


class Arrivals:
    """The wall time of every sample of one key, taken in the Zenoh callback of a client
    session of the test's own (which, like the stack's clients, rejoins a restarted router
    within 0.1 s)."""

    def __init__(self, endpoint: str, key: str) -> None:
        import zenoh

        from zenav.tooling import client_transport

        self.times: list[float] = []
        self.session: Any = zenoh.open(client_transport([endpoint]).to_zenoh())
        self.subscriber: Any = self.session.declare_subscriber(
            key, lambda sample: self.times.append(time.time()))

    def steady(self, count: int, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        start = len(self.times)
        while len(self.times) < start + count:
            assert time.monotonic() < deadline, "no steady output before the kill"
            time.sleep(0.05)

    def outage(self, killed: float) -> tuple[float, float]:
        """(the kill's pause: the longest between two samples that ends after ``killed`` and
        begins before ``killed`` + 2 s, so that a sample still under way from the killed
        process does not hide it; the time from ``killed`` to the sample that ends it)."""
        pauses = [(b - a, b) for a, b in itertools.pairwise(self.times)
                  if b > killed and a < killed + 2.0]
        assert pauses, "no output after the kill"
        pause, end = max(pauses)
        return pause, end - killed

    def close(self) -> None:
        self.subscriber.undeclare()
        self.session.close()


SETTLE = 8.0
"""s of output watched after each kill before its pause is measured."""


def test_with_warm_spares_a_killed_program_is_replaced_at_once_on_a_busy_machine(
        tmp_path, measure, busy_machine):
    """``supervisor.standby``: beside each program a spare that has loaded everything waits
    on a lock the kernel frees when the serving process dies; kill -9 of the serving one
    costs the time to open a Zenoh session, not a Python start-up (issue 14's 1 s, with
    two busy loops running)."""
    supervisor = {**yaml.safe_load((REPO / "deploy" / "stack.yaml").read_text())["supervisor"],
                  "standby": True}
    stack, endpoint = one_host(tmp_path, timeout=LOADED_WAIT, speed=1.0,
                               scenario=LONGER_SCENARIO, supervisor=supervisor)
    monitor = None
    start_x = load_scenario(LONGER_SCENARIO).robot.start[0]
    times: dict[str, tuple[float, float]] = {}
    try:
        stack.up()
        monitor = Monitor(monitor_command(endpoint), tmp_path / "monitor.log")
        monitor.state("steady data on every output",
                      lambda s: all(s["rates"].get(o, 0) > 5 for o in OUTPUT.values()),
                      LOADED_WAIT)
        monitor.state("the robot under way", moving_at(start_x + 0.2), timeout=LOADED_WAIT)
        for program, output in OUTPUT.items():
            twin = f"{program}_standby"
            lock = stack.run_dir / "standby" / f"{program}.lock"
            arrivals = Arrivals(endpoint, f"zenav/robot0/{output}")
            try:
                arrivals.steady(20, LOADED_WAIT)
                before = stack.pids()
                serving = int(lock.read_text())
                assert serving in (before[program], before[twin]), (serving, before)
                killed = time.time()
                os.kill(serving, signal.SIGKILL)
                time.sleep(SETTLE)
                pause, back = arrivals.outage(killed)
            finally:
                arrivals.close()
            times[program] = (pause, back)
            measure(f"kill -9 {program} with a warm spare, {len(busy_machine)} busy loops -> "
                    f"longest pause of {output}", pause, f"it ended {back:.3f} s after the kill")
            after = stack.pids()
            spare = before[twin] if serving == before[program] else before[program]
            assert int(lock.read_text()) == spare  # the spare serves now
            assert serving not in after.values()  # the killed one came back as a spare
            assert all(after[p] == before[p] for p in after
                       if p not in (program, twin)), "another program restarted"
        final = monitor.state("the run's result", reached, timeout=6 * LOADED_WAIT)
        assert final["result"]["outcome"] == "reached", final["result"]
        assert final["result"]["collided_with"] is None
    finally:
        if monitor is not None:
            monitor.stop()
        stopped = stack.down() if stack.is_up else None
        stack.cleanup()
    assert stopped is not None and stopped.returncode == 0, stopped
    # The target is 1 s; this bound only catches a takeover that does not happen (the
    # figures above are the result).
    assert all(pause < LOADED_WAIT for pause, _ in times.values()), times


def test_the_planner_replaced_mid_run_stops_the_robot_meanwhile_and_it_reaches_the_goal(
        tmp_path, measure):
    scenario = load_scenario(LONG_SCENARIO)
    goal, speed = scenario.robot.goal, scenario.robot.speed
    replacement = {"service": "planner", "autostart": False, "command": [
        "{python}", str(REPO / "tests" / "integration" / "replacement_planner.py"),
        "--transport", "{transport}", "--robot-id", "{robot_id}",
        "--goal", str(goal[0]), str(goal[1]), "--speed", str(speed)]}
    services = copy_deployment(REPO / "deploy" / "stack.yaml", tmp_path / "base.yaml")
    programs = yaml.safe_load(services.read_text())["services"]
    # Real time: 40 s of driving, so that on a loaded machine the run is still under way
    # when `zenav up` returns and the monitor joins.
    stack, endpoint = one_host(tmp_path, speed=1.0,
                               services={**programs, "planner_b": replacement})
    monitor = None
    try:
        stack.up()
        monitor = Monitor(monitor_command(endpoint), tmp_path / "monitor.log")
        monitor.state("the robot under way", moving_at(scenario.robot.start[0] + 0.5), 20)

        stopping = time.time()
        done = stack.ctl("stop", "planner")
        assert done.returncode == 0 and "stopped" in done.stdout, done.stdout + done.stderr
        gone = monitor.event("alive", 5, after=stopping, service="planner", alive=False)
        stale = monitor.event("base", 5, after=stopping, reason="stale")
        still = monitor.event("motion", 5, after=stopping, source="truth", moving=False)

        starting = time.time()
        done = stack.ctl("start", "planner_b")
        assert done.returncode == 0 and "started" in done.stdout, done.stdout + done.stderr
        assert not [e for e in monitor.events if stopping < e["wall"] < starting and
                    e["event"] == "motion" and e["source"] == "truth" and e["moving"]]
        moving = monitor.event("motion", 15, after=starting, source="truth", moving=True)
        final = monitor.state("the run's result", reached, timeout=90)
        assert final["result"]["outcome"] == "reached", final["result"]
        assert final["result"]["collided_with"] is None
        assert final["truth"]["x"] > still["x"] + 1.0  # it went on after the swap
        infos = stack.supervisor.processes()
        assert infos["planner"]["statename"] == "STOPPED"
        assert infos["planner_b"]["statename"] == "RUNNING"
    finally:
        if monitor is not None:
            monitor.stop()
        stopped = stack.down() if stack.is_up else None
        stack.cleanup()
    assert stopped is not None and stopped.returncode == 0, stopped
    log = (stack.run_dir / "logs" / "planner_b.log").read_text()
    assert "replacement planner stopped after" in log and " 0 commands" not in log
    measure("planner stopped -> zero base command (stale)", stale["wall"] - gone["wall"])
    measure("planner stopped -> robot at standstill", still["wall"] - stopping)
    measure("replacement started -> robot moving", moving["wall"] - starting)
