"""Real processes over Zenoh on loopback: zenav run end to end, failures, shutdown."""

from __future__ import annotations

import itertools
import json
import math
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import psutil
import pytest
import yaml

from zenav.launch import Stack
from zenav.services.config import SERVICE_ORDER

pytestmark = pytest.mark.integration

SCENARIOS = Path(__file__).resolve().parents[2] / "sim" / "scenarios"


def zenav(*args: str, timeout: float = 180) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "zenav", *args], capture_output=True,
                          text=True, timeout=timeout, check=False)


def write_scenario(path: Path, **changes: object) -> Path:
    data = yaml.safe_load((SCENARIOS / "a-no-obstacle.yaml").read_text())
    for dotted, value in changes.items():
        target = data
        parts = dotted.split("__")
        for part in parts[:-1]:
            target = target[part]
        target[parts[-1]] = value
    path.write_text(yaml.safe_dump(data))
    return path


def check_record(record: dict[str, Any], scenario: dict[str, Any]) -> None:
    """The run record as the spec promises it, recomputed from the trajectory."""
    assert set(record) >= {"scenario", "planner", "outcome", "time", "path_length",
                           "min_clearance", "trajectory", "events"}
    assert record["scenario"] == scenario["name"]
    traj = record["trajectory"]
    assert all(len(row) == 5 for row in traj)
    times = [row[0] for row in traj]
    assert times[0] == 0.0 and times[-1] == pytest.approx(record["time"])
    steps = [b - a for a, b in itertools.pairwise(times)]
    assert min(steps) > 0 and max(steps) <= 0.1 + 1e-9
    start = scenario["robot"]["start"]
    assert traj[0][1:3] == pytest.approx(start)
    length = sum(math.dist(a[1:3], b[1:3]) for a, b in itertools.pairwise(traj))
    assert record["path_length"] == pytest.approx(length, abs=1e-3)


def test_no_obstacle_scenario_reaches_its_goal_through_all_six_processes(tmp_path):
    done = zenav("run", str(SCENARIOS / "a-no-obstacle.yaml"), "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    record = json.loads((tmp_path / "run.json").read_text())
    scenario = yaml.safe_load((SCENARIOS / "a-no-obstacle.yaml").read_text())
    check_record(record, scenario)
    assert record["outcome"] == "reached"
    last = record["trajectory"][-1]
    assert math.dist(last[1:3], scenario["robot"]["goal"]) <= 0.25
    assert abs(last[2] - 3.0) < 0.01  # straight along the global path
    assert (tmp_path / "run.png").stat().st_size > 10_000
    logs = sorted(p.stem for p in (tmp_path / "logs").glob("*.log"))
    assert logs == sorted(SERVICE_ORDER)
    assert "unclean_exits" not in record  # every service stopped on SIGTERM with status 0


def test_two_runs_at_once_do_not_hear_each_other_and_are_deterministic(tmp_path):
    east = write_scenario(tmp_path / "east.yaml", name="east")
    north = write_scenario(tmp_path / "north.yaml", name="north", robot__start=[5.0, 0.5],
                           robot__goal=[5.0, 5.0], robot__heading_deg=90.0, duration=80)
    runs = [(east, tmp_path / "e1"), (north, tmp_path / "n1"), (east, tmp_path / "e2")]
    with ThreadPoolExecutor(3) as pool:
        done = list(pool.map(lambda r: zenav("run", str(r[0]), "--out", str(r[1])), runs))
    for result in done:
        assert result.returncode == 0, result.stderr
    records = [json.loads((out / "run.json").read_text()) for _, out in runs]
    assert [r["outcome"] for r in records] == ["reached"] * 3
    assert records[1]["trajectory"][-1][2] > 4.7  # the north robot went north
    assert records[0]["trajectory"] == records[2]["trajectory"]  # same seed, same run


def test_bad_scenario_fails_with_one_line_naming_file_and_field(tmp_path):
    bad = write_scenario(tmp_path / "bad.yaml", robot__radius=-0.2)
    done = zenav("run", str(bad), "--out", str(tmp_path / "out"))
    assert done.returncode == 2
    assert "bad.yaml" in done.stderr and "robot.radius" in done.stderr
    assert not (tmp_path / "out" / "run.json").exists()


def test_a_parameter_a_service_would_refuse_ends_the_run_before_it_starts(tmp_path):
    """Once a service that failed at start (exit 1, its log's reason); now the --set is
    checked against the service's parameters before any process starts."""
    done = zenav("run", str(SCENARIOS / "a-no-obstacle.yaml"), "--out", str(tmp_path),
                 "--set", "perception.window_radius=-1", timeout=60)
    assert done.returncode == 2
    assert done.stderr.splitlines() == [
        "zenav run: --set perception.window_radius=-1: window_radius: Input should be "
        "greater than 0 (got -1)"]
    assert not (tmp_path / "logs").exists()  # nothing was started


def test_a_service_that_dies_mid_run_ends_the_run_without_a_hang(tmp_path):
    long_run = write_scenario(tmp_path / "long.yaml", name="long", duration=600,
                              robot__goal=[9.5, 3.0], robot__speed=0.01)
    proc = subprocess.Popen([sys.executable, "-m", "zenav", "run", str(long_run), "--out",
                             str(tmp_path / "out")], stderr=subprocess.PIPE, text=True)
    try:
        sim_log = tmp_path / "out" / "logs" / "simulator.log"
        deadline = time.monotonic() + 60
        while "starts" not in (sim_log.read_text() if sim_log.exists() else ""):
            assert time.monotonic() < deadline, "the run never started"
            time.sleep(0.1)
        planner = next(p for p in psutil.Process(proc.pid).children()
                       if "planner" in p.cmdline())
        planner.kill()
        _, stderr = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 1
    assert "service planner was killed by signal 9 (SIGKILL)" in stderr


def test_every_service_stops_within_one_second_of_sigterm_or_sigint(tmp_path):
    scenario = write_scenario(tmp_path / "s.yaml", duration=600)
    stack = Stack(out_dir=tmp_path, params={"simulator": {"scenario": str(scenario),
                                                          "clock": "realtime"}})
    stack.start()
    try:
        sim_log = stack.log_path("simulator")
        deadline = time.monotonic() + 60
        while "starts" not in (sim_log.read_text() if sim_log.exists() else ""):
            assert time.monotonic() < deadline, "the stack never came up"
            time.sleep(0.1)
        time.sleep(1.0)  # let data flow through every service
        elapsed = {}
        for i, (name, proc) in enumerate(stack.processes.items()):
            sent = time.monotonic()
            proc.send_signal(signal.SIGINT if i % 2 else signal.SIGTERM)
            code = proc.wait(timeout=5)
            elapsed[name] = time.monotonic() - sent
            assert code == 0, f"{name} exited with {code}"
    finally:
        stack.stop()
    slow = {name: round(t, 2) for name, t in elapsed.items() if t > 1.0}
    assert not slow, f"slower than 1 s to stop: {slow}"
