"""The bad-input table: each mistake a user can make on the command line, the exit status
and the one line that names it, before any process starts or any work is done.

Every row runs the real ``zenav`` entry point in this process (nothing here opens a Zenoh
session or starts a service). ``BAD_INPUT`` is the table itself; the report quotes it.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import yaml

from tests.unit.clirun import status_of
from zenav.bag.mcapfile import BagWriter
from zenav.cli import main as zenav_main
from zenav.schemas.codec import encode
from zenav.schemas.messages import Odometry, Pose2D
from zenav.services.runner import PLANNERS
from zenav.sim.scenario import MAX_OBSTACLES

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "sim" / "scenarios" / "a-no-obstacle.yaml"


def scenario_with(tmp: Path, name: str, **changes: object) -> Path:
    data = yaml.safe_load(SCENARIO.read_text())
    for dotted, value in changes.items():
        target = data
        *parents, last = dotted.split("__")
        for part in parents:
            target = target[part]
        target[last] = value
    path = tmp / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def a_file(tmp: Path) -> Path:
    path = tmp / "a-file"
    path.write_text("not a folder\n")
    return path


def a_text(tmp: Path, name: str, text: str) -> Path:
    path = tmp / name
    path.write_text(text)
    return path


def a_bag(tmp: Path) -> Path:
    path = tmp / "run.mcap"
    with path.open("wb") as stream:
        writer = BagWriter(stream, "robot0")
        odom = Odometry(stamp=0.1, seq=0, pose=Pose2D(x=1.0, y=2.0, heading=0.0), v=0.0,
                        omega=0.0)
        writer.add("zenav/robot0/odom", encode(odom), 1)
        writer.close()
    return path


Args = Callable[[Path], list[str]]

NO_ROUTER = "mode client needs a router to connect to: give connect: [ENDPOINT] (or --connect "\
    "ENDPOINT)"
PAST_LAST_CASE = "beyond the last, 4294966295 (a case's seed, 1000 + case, must fit in 32 bits)"

BAD_INPUT: list[tuple[str, Args, int, str]] = [
    # (case, argv from a scratch folder, exit status, the first line of stderr)
    ("run --out an existing file",
     lambda t: ["run", str(SCENARIO), "--out", str(a_file(t))], 2,
     "zenav run: {t}/a-file: exists and is not a folder"),
    ("run --out a folder under a file",
     lambda t: ["run", str(SCENARIO), "--out", str(a_file(t) / "out")], 2,
     "zenav run: {t}/a-file/out: {t}/a-file is a file, not a folder"),
    ("run --out in /proc", lambda t: ["run", str(SCENARIO), "--out", "/proc/zenav"], 2,
     "zenav run: /proc/zenav: under /proc, which is not a place for output"),
    ("paper --out an existing file", lambda t: ["paper", "--out", str(a_file(t))], 2,
     "zenav paper: {t}/a-file: exists and is not a folder"),
    ("bench nav --out in /sys", lambda t: ["bench", "nav", "--out", "/sys/zenav"], 2,
     "zenav bench nav: /sys/zenav: under /sys, which is not a place for output"),
    ("bench nav --fov beyond a full turn",
     lambda t: ["bench", "nav", "--fov", "400", "--out", str(t / "out")], 2,
     "zenav bench nav: --fov must be in (0, 360] in half degrees (got 400)"),
    ("bench nav with no worlds",
     lambda t: ["bench", "nav", "--worlds", "0", "--out", str(t / "out")], 2,
     "zenav bench nav: --worlds must be >= 1 (got 0)"),
    ("bench nav with no jobs",
     lambda t: ["bench", "nav", "--jobs", "0", "--out", str(t / "out")], 2,
     "zenav bench nav: --jobs must be >= 1 (got 0)"),
    ("bench nav with no planner",
     lambda t: ["bench", "nav", "--planners", ",", "--out", str(t / "out")], 2,
     "zenav bench nav: unknown planner (none given); choose from " + ", ".join(PLANNERS)),
    ("paper with no jobs", lambda t: ["paper", "--jobs", "0", "--out", str(t / "out")], 2,
     "zenav paper: --jobs must be >= 1 (got 0)"),
    ("paper --verify below zero",
     lambda t: ["paper", "--verify", "-1", "--out", str(t / "out")], 2,
     "zenav paper: --verify must be >= 0 (got -1)"),
    ("paper --verify with the stack engine",
     lambda t: ["paper", "--verify", "5", "--out", str(t / "out")], 2,
     "zenav paper: --verify checks --engine inprocess against the stack; with --engine stack "
     "every run is a stack run already"),
    ("bench crowd --verify with the stack engine",
     lambda t: ["bench", "crowd", "--engine", "stack", "--verify", "2", "--out", str(t / "o")], 2,
     "zenav bench crowd: --verify checks --engine inprocess against the stack; with --engine "
     "stack every run is a stack run already"),
    ("bench nav --verify below zero",
     lambda t: ["bench", "nav", "--verify", "-1", "--out", str(t / "o")], 2,
     "zenav bench nav: --verify must be >= 0 (got -1)"),
    ("bench perf --out a folder under a file",
     lambda t: ["bench", "perf", "--out", str(a_file(t) / "x")], 2,
     "zenav bench perf: {t}/a-file/x: {t}/a-file is a file, not a folder"),
    ("schemas --out an existing file", lambda t: ["schemas", "--out", str(a_file(t))], 2,
     "zenav schemas: {t}/a-file: exists and is not a folder"),
    ("record into a folder under a file",
     lambda t: ["record", str(a_file(t) / "x.mcap"), "--connect", "tcp/127.0.0.1:9"], 2,
     "zenav record: {t}/a-file/x.mcap: {t}/a-file is a file, not a folder"),
    ("record onto a folder", lambda t: ["record", str(t), "--connect", "tcp/127.0.0.1:9"], 2,
     "zenav record: {t}: is a folder, not a file"),
    ("replay a file that is not MCAP",
     lambda t: ["replay", str(a_file(t)), "--connect", "tcp/127.0.0.1:9"], 2,
     "zenav replay: {t}/a-file: not an MCAP file (or cut short)"),
    ("replay a missing file",
     lambda t: ["replay", str(t / "none.mcap"), "--connect", "tcp/127.0.0.1:9"], 2,
     "zenav replay: {t}/none.mcap: cannot read (No such file or directory)"),
    ("replay --topics bogus",
     lambda t: ["replay", str(a_bag(t)), "--topics", "odom,bogus",
                "--connect", "tcp/127.0.0.1:9"], 2,
     "zenav replay: --topics: bogus not in {t}/run.mcap (it has odom)"),
    ("replay --wait-for a name no process has",
     lambda t: ["replay", str(a_bag(t)), "--wait-for", "planer", "--connect", "tcp/127.0.0.1:9"],
     2, "zenav replay: --wait-for: no process is called planer (the names are simulator, "
     "laser_driver, perception, tracking, planner, motor_bridge, router, record, run)"),
    ("monitor --connect something not an endpoint",
     lambda t: ["monitor", "--connect", "garbage"], 2,
     "zenav monitor: argument --connect: 'garbage' is not a Zenoh endpoint: expected "
     "PROTOCOL/ADDRESS, e.g. tcp/127.0.0.1:7447"),
    ("up --connect something not an endpoint",
     lambda t: ["up", "--run-dir", str(t / "run"), "--config",
                str(REPO / "deploy" / "server.yaml"), "--connect", "garbage"], 2,
     "zenav up: --connect: 'garbage' is not a Zenoh endpoint: expected PROTOCOL/ADDRESS, "
     "e.g. tcp/127.0.0.1:7447"),
    ("run --planner foo",
     lambda t: ["run", str(SCENARIO), "--out", str(t / "o"), "--planner", "foo"], 2,
     f"zenav run: --planner 'foo': no such planner; choose from {', '.join(PLANNERS)}"),
    ("run --set an unknown parameter",
     lambda t: ["run", str(SCENARIO), "--out", str(t / "o"), "--set", "perception.nosuch=1"],
     2, "zenav run: --set perception.nosuch=1: nosuch: Extra inputs are not permitted (got 1)"),
    ("run --set a bad value",
     lambda t: ["run", str(SCENARIO), "--out", str(t / "o"), "--set", "planner.cruise_speed=-1"],
     2, "zenav run: --set planner.cruise_speed=-1: cruise_speed: Input should be greater "
     "than 0 (got -1)"),
    ("run --set an unknown service",
     lambda t: ["run", str(SCENARIO), "--out", str(t / "o"), "--set", "nosuch.x=1"], 2,
     "zenav run: --set 'nosuch.x=1': expected SERVICE.NAME=VALUE with SERVICE one of "
     "simulator, laser_driver, perception, tracking, planner, motor_bridge"),
    ("run a scenario with 10,000 obstacles",
     lambda t: ["run", str(scenario_with(t, "many", obstacles=[
         {"shape": "disc", "center": [1.0, 1.0 + 1e-4 * i], "radius": 0.05}
         for i in range(10_000)])), "--out", str(t / "o")], 2,
     f"zenav run: {{t}}/many.yaml: obstacles: at most {MAX_OBSTACLES} obstacles (got 10000)"),
    ("run an obstacle faster than any number a scenario may hold",
     lambda t: ["run", str(scenario_with(t, "fast", obstacles=[
         {"shape": "disc", "center": [5.0, 1.0], "radius": 0.2, "velocity": [1e308, 0.0]}])),
                "--out", str(t / "o")], 2,
     "zenav run: {t}/fast.yaml: obstacles[0].velocity[0]: must be <= 1e+06 (got 1e+308)"),
    ("run a grid cell larger than the laser reaches",
     lambda t: ["run", str(scenario_with(t, "big", world__cell=10.0)), "--out", str(t / "o")],
     2, "zenav run: {t}/big.yaml: laser.max_range: must be at least world.cell (10 m): the "
     "perception window reaches 8 cells (at least 4 m) but no farther than the laser, and "
     "must hold a cell (got 8 m)"),
    ("run a top speed below the cruise speed",
     lambda t: ["run", str(scenario_with(t, "slow", robot__max_speed=0.05)),
                "--out", str(t / "o")], 2,
     "zenav run: {t}/slow.yaml: robot.max_speed: must be at least robot.speed (0.1 m/s, the "
     "cruise speed; got 0.05 m/s)"),
    ("bench perf with no sections",
     lambda t: ["bench", "perf", "--sections", "", "--out", str(t / "o")], 2,
     "zenav bench perf: --sections is empty; choose from compute, latency, lockstep, engine, "
     "rate, floor"),
    ("bench perf --rates beyond what the simulator's tick limit lets it measure",
     lambda t: ["bench", "perf", "--sections", "rate", "--rates", "10,20000",
                "--out", str(t / "o")], 2,
     "zenav bench perf: --rates 20000 Hz: at most 7143 Hz, so that a run of 6 s measured "
     "(--rate-seconds) fits the simulator's 200000 ticks"),
    ("bench crowd --seed below zero",
     lambda t: ["bench", "crowd", "--seed", "-1", "--out", str(t / "o")], 2,
     "zenav bench crowd: argument --seed: must be >= 0 (got -1)"),
    ("run a goal the robot disc cannot come within the tolerance of",
     lambda t: ["run", str(scenario_with(t, "goal", robot__goal_tolerance=0.05, obstacles=[
         {"shape": "box", "center": [8.35, 3.0], "size": [0.5, 0.5]}])), "--out", str(t / "o")],
     2, "zenav run: {t}/goal.yaml: robot.goal: unreachable: static obstacles[0] (box) is "
     "0.1 m from the goal, and the robot disc (radius 0.2 m) cannot come within "
     "goal_tolerance (0.05 m) of it"),
    ("up --set an unknown parameter",
     lambda t: ["up", "--print", "--run-dir", str(t / "run"), "--config",
                str(REPO / "deploy" / "stack.yaml"), "--set", "planner.nosuch=1"], 2,
     "zenav up: --set planner.nosuch=1: nosuch: Extra inputs are not permitted (got 1)"),
    ("ctl status with nothing up",
     lambda t: ["ctl", "--run-dir", str(t / "run"), "status"], 1,
     "zenav ctl: run is not up ({t}/run); start it with `zenav up`"),
    ("ctl status --run-dir X, the option after the action",
     lambda t: ["ctl", "status", "--run-dir", str(t / "run")], 1,
     "zenav ctl: run is not up ({t}/run); start it with `zenav up`"),
    ("ctl status --run-dir without its path", lambda t: ["ctl", "status", "--run-dir"], 2,
     "zenav ctl: --run-dir: expected a path after it"),
    ("service --set an unknown parameter",
     lambda t: ["service", "perception", "--set", "nosuch=1"], 2,
     "zenav service perception: --set nosuch=1: nosuch: Extra inputs are not permitted (got 1)"),
    ("bench bound --offsets not numbers", lambda t: ["bench", "bound", "--offsets", "left"], 2,
     "zenav bench bound: argument --offsets: offsets must be numbers in m, got 'left'"),
    ("bench bound --cases 0", lambda t: ["bench", "bound", "--cases", "0"], 2,
     "zenav bench bound: --cases must be >= 1 (got 0)"),
    ("bench bound --margin nan", lambda t: ["bench", "bound", "--margin", "nan"], 2,
     "zenav bench bound: --margin must be >= 0 (got nan)"),
    ("params of an unknown planner", lambda t: ["params", "planner", "--planner", "foo"], 2,
     f"zenav params: no planner named 'foo'; the planners are {', '.join(PLANNERS)}"),
    ("an unknown flag of a command", lambda t: ["run", str(SCENARIO), "--out", str(t / "o"),
                                                "--bogus"], 2,
     "zenav run: unrecognized arguments: --bogus"),
    ("an unknown flag of a bench", lambda t: ["bench", "crowd", "--bogus"], 2,
     "zenav bench crowd: unrecognized arguments: --bogus"),
    ("replay a file shorter than MCAP's magic",
     lambda t: ["replay", str(a_text(t, "short.mcap", "hello")), "--connect", "tcp/127.0.0.1:9"],
     2, "zenav replay: {t}/short.mcap: not an MCAP file (or cut short)"),
    ("replay an empty file",
     lambda t: ["replay", str(a_text(t, "empty.mcap", "")), "--connect", "tcp/127.0.0.1:9"], 2,
     "zenav replay: {t}/empty.mcap: not an MCAP file (or cut short)"),
    ("replay --robot-id, which the recorded id decides",
     lambda t: ["replay", str(a_bag(t)), "--robot-id", "robot1", "--connect", "tcp/127.0.0.1:9"],
     2, "zenav replay: --robot-id: replay publishes under the robot id recorded in the file; "
     "give --as-robot ID to publish under another"),
    ("monitor as a client with no router to connect to",
     lambda t: ["monitor", "--transport", str(a_text(t, "client.yaml", "mode: client\n"))], 2,
     "zenav monitor: {t}/client.yaml: " + NO_ROUTER),
    ("a service as a client with no router to connect to",
     lambda t: ["service", "tracking", "--transport",
                str(a_text(t, "client.yaml", "mode: client\n"))], 2,
     "zenav service tracking: {t}/client.yaml: " + NO_ROUTER),
    ("up a deployment whose clients have no router to connect to",
     lambda t: ["up", "--print", "--run-dir", str(t / "run"), "--config",
                str(a_text(t, "d.yaml", "name: d\ntransport: {mode: client}\nservices: {}\n"))],
     2,
     "zenav up: {t}/d.yaml: transport: " + NO_ROUTER),
    ("bench bound past CrowdNav's last test case",
     lambda t: ["bench", "bound", "--cases", "2", "--seed", "4294966295"], 2,
     "zenav bench bound: --seed 4294966295 with --cases 2 runs to case 4294966296, "
     + PAST_LAST_CASE),
    ("bench crowd past CrowdNav's last test case",
     lambda t: ["bench", "crowd", "--seed", "4294967294", "--out", str(t / "o")], 2,
     "zenav bench crowd: --seed 4294967294 with --cases 500 runs to case 4294967793, "
     + PAST_LAST_CASE),
    ("up --scenario a file that is not there",
     lambda t: ["up", "--print", "--run-dir", str(t / "run"), "--config",
                str(REPO / "deploy" / "stack.yaml"), "--scenario", str(t / "none.yaml")], 2,
     "zenav up: --scenario: {t}/none.yaml: file not found"),
    ("params of a simulator whose scenario is not there",
     lambda t: ["params", "simulator", "--set", f"scenario={t / 'none.yaml'}"], 2,
     "zenav params: {t}/none.yaml: file not found"),
    ("params --planner for a service that is not the planner",
     lambda t: ["params", "perception", "--planner", "vfh"], 2,
     "zenav params: --planner vfh: only the planner service has implementations to choose "
     "from, not perception"),
    ("params from a file that sets one twice",
     lambda t: ["params", "planner", "--params",
                str(a_text(t, "twice.yaml", "cruise_speed: 0.2\ncruise_speed: 0.3\n"))], 2,
     "zenav params: {t}/twice.yaml: not valid YAML (duplicate key 'cruise_speed' (line 2, "
     "column 1))"),
    ("a transport file that sets one twice",
     lambda t: ["record", str(t / "x.mcap"), "--transport",
                str(a_text(t, "twice.yaml", "mode: peer\nmode: client\n"))], 2,
     "zenav record: {t}/twice.yaml: not valid YAML (duplicate key 'mode' (line 2, column 1))"),
]


@pytest.mark.parametrize(("argv", "code", "message"), [row[1:] for row in BAD_INPUT],
                         ids=[row[0] for row in BAD_INPUT])
def test_bad_input_is_one_line_and_a_status(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                            argv: Args, code: int, message: str) -> None:
    tmp = tmp_path.resolve()
    status = status_of(argv(tmp))
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert status == code, captured.err
    assert lines == [message.format(t=tmp)], captured.err
    assert "Traceback" not in captured.err + captured.out
    assert not (tmp / "o" / "run.json").exists()


def test_several_problems_in_one_scenario_are_one_line_each(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = scenario_with(tmp_path, "three", world__cell=0, robot__speed=0, robot__radius=-0.2)
    assert zenav_main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"zenav run: {path}: world.cell: must be > 0 (got 0)",
        f"zenav run: {path}: robot.speed: must be > 0 (got 0)",
        f"zenav run: {path}: robot.radius: must be > 0 (got -0.2)",
    ]


def test_schemas_without_out_prints_every_schema_and_writes_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import json

    from zenav.schemas.messages import ALL_MESSAGES

    monkeypatch.chdir(tmp_path)
    assert zenav_main(["schemas"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert set(printed) == {m.TYPE for m in ALL_MESSAGES}
    assert list(tmp_path.iterdir()) == []


def test_ctl_outside_the_repository_looks_in_the_default_stacks_run_directory(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """No deploy/stack.yaml in the current folder (an installed wheel): the default
    deployment's run directory, not a complaint about the missing file."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("ZENAV_STATE_DIR", str(tmp_path / "state"))
    assert zenav_main(["ctl", "status"]) == 1
    assert capsys.readouterr().err.splitlines() == [
        f"zenav ctl: stack is not up ({tmp_path / 'state' / 'stack'}); start it with "
        "`zenav up`"]


def test_several_limits_exceeded_are_one_line_each(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = scenario_with(tmp_path, "limits", laser={"resolution_deg": 0.025}, duration=30000,
                         obstacles=[{"shape": "disc", "center": [1.0, 1.0], "radius": 0.05}]
                         * (MAX_OBSTACLES + 1))
    assert zenav_main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"zenav run: {path}: obstacles: at most {MAX_OBSTACLES} obstacles "
        f"(got {MAX_OBSTACLES + 1})",
        f"zenav run: {path}: laser.resolution_deg: at most 4000 beams per scan (got 7201: "
        "fov_deg / resolution_deg + 1)",
        f"zenav run: {path}: duration: at most 200000 simulator ticks (got 300000: duration "
        "x max(laser.rate_hz, 10))",
    ]


PARAMS_PROBLEMS: list[tuple[str, Callable[[Path], list[str]], list[str]]] = [
    # (case, argv, the lines on stderr)
    ("a scenario with two mistakes",
     lambda t: ["params", "planner", "--scenario",
                str(scenario_with(t, "two", robot__speed=0, robot__radius=-0.2))],
     ["zenav params: {t}/two.yaml: robot.speed: must be > 0 (got 0)",
      "zenav params: {t}/two.yaml: robot.radius: must be > 0 (got -0.2)"]),
    ("two bad --set", lambda t: ["params", "planner", "--set", "nosuch=1",
                                 "--set", "cruise_speed=-1"],
     ["zenav params: --set cruise_speed=-1: cruise_speed: Input should be greater than 0 "
      "(got -1)",
      "zenav params: --set nosuch=1: nosuch: Extra inputs are not permitted (got 1)"]),
    ("a parameter file with two mistakes",
     lambda t: ["params", "perception", "--params", str(a_params_file(t))],
     ["zenav params: {t}/perception.yaml: lambda_: Input should be greater than 0 (got -1)",
      "zenav params: {t}/perception.yaml: nosuch: Extra inputs are not permitted (got 1)"]),
    ("an empty list for three weights (one line, not one per missing item)",
     lambda t: ["params", "planner", "--set", "kappa=[]"],
     ["zenav params: --set kappa=[]: kappa: too few items (got [])"]),
    ("four weights for three",
     lambda t: ["params", "planner", "--set", "kappa=[1,2,3,4]"],
     ["zenav params: --set kappa=[1,2,3,4]: kappa: too many items, at most 3 "
      "(got [1, 2, 3, 4])"]),
]


def a_params_file(tmp: Path) -> Path:
    path = tmp / "perception.yaml"
    path.write_text("lambda_: -1\nnosuch: 1\n")
    return path


@pytest.mark.parametrize(("argv", "lines"), [row[1:] for row in PARAMS_PROBLEMS],
                         ids=[row[0] for row in PARAMS_PROBLEMS])
def test_params_names_each_problem_on_its_own_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: Args, lines: list[str]
) -> None:
    tmp = tmp_path.resolve()
    assert zenav_main(argv(tmp)) == 2
    assert capsys.readouterr().err.splitlines() == [line.format(t=tmp) for line in lines]


def test_service_and_up_name_each_bad_set_on_its_own_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert zenav_main(["service", "perception", "--set", "nosuch=1", "--set", "lambda_=-1"]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "zenav service perception: --set lambda_=-1: lambda_: Input should be greater than 0 "
        "(got -1)",
        "zenav service perception: --set nosuch=1: nosuch: Extra inputs are not permitted (got 1)"]
    assert zenav_main(["up", "--print", "--run-dir", str(tmp_path / "run"), "--config",
                       str(REPO / "deploy" / "stack.yaml"), "--set", "planner.nosuch=1",
                       "--set", "tracking.nosuch=2"]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "zenav up: --set tracking.nosuch=2: nosuch: Extra inputs are not permitted (got 2)",
        "zenav up: --set planner.nosuch=1: nosuch: Extra inputs are not permitted (got 1)"]
