"""Deployment files and the supervisord configuration ``zenav up`` writes from them."""

from __future__ import annotations

import configparser
import shlex
from pathlib import Path

import pytest
import yaml

from zenav.deploy.conf import prepare, socket_path
from zenav.deploy.model import load_deployment
from zenav.services.config import SERVICE_ORDER, ConfigError
from zenav.tooling import CLIENT_EXTRA

DEPLOY = Path(__file__).resolve().parents[2] / "deploy"


def conf_of(path: Path) -> configparser.RawConfigParser:
    parser = configparser.RawConfigParser()
    parser.read(path)
    return parser


def test_the_shipped_deployments_split_the_services_between_robot_and_server():
    stack = load_deployment(DEPLOY / "stack.yaml")
    robot = load_deployment(DEPLOY / "robot.yaml")
    server = load_deployment(DEPLOY / "server.yaml")
    assert set(stack.services) == set(SERVICE_ORDER)
    assert set(robot.services) | set(server.services) == set(SERVICE_ORDER)
    assert not set(robot.services) & set(server.services)
    assert "motor_bridge" in robot.services  # a cut link must stop the wheels
    assert robot.router is not None and server.router is None
    for deployment in (stack, robot, server):
        assert deployment.transport.mode == "client"
        assert deployment.transport.extra["connect/timeout_ms"] == -1
        for spec in deployment.services.values():
            assert all(p.is_file() for p in spec.config)
        assert deployment.scenario is not None and deployment.scenario.is_file()
    assert server.transport.extra["transport/shared_memory/enabled"] is False
    motor = yaml.safe_load((DEPLOY / "params" / "motor_bridge.yaml").read_text())
    simulator = yaml.safe_load((DEPLOY / "params" / "simulator.yaml").read_text())
    assert motor["clock"] == simulator["clock"] == "realtime"


def test_supervisord_conf_restarts_on_failure_logs_per_program_and_stops_cleanly(tmp_path):
    deployment = load_deployment(DEPLOY / "robot.yaml", ["simulator.realtime_factor=4"],
                                 connect=["tcp/127.0.0.1:9999"])
    conf = conf_of(prepare(deployment, tmp_path / "run", python="/py", workdir=tmp_path))
    programs = [s.removeprefix("program:") for s in conf.sections() if s.startswith("program:")]
    assert programs == ["router", "motor_bridge", "simulator", "laser_driver"]  # start order
    for name in programs:
        section = conf[f"program:{name}"]
        assert section["autorestart"] == "unexpected" and section["exitcodes"] == "0,2"
        assert section["stopsignal"] == "TERM" and section["redirect_stderr"] == "true"
        assert section["stdout_logfile"] == str(tmp_path / "run" / "logs" / f"{name}.log")
        assert section["directory"] == str(tmp_path)
    priorities = [int(conf[f"program:{p}"]["priority"]) for p in programs]
    assert priorities == sorted(priorities) and priorities[0] == 10  # router first
    simulator = shlex.split(conf["program:simulator"]["command"])
    # every program at the deployment's niceness (default -5): ahead of other work
    assert simulator[:8] == ["nice", "-n", "-5", "/py", "-m", "zenav", "service", "simulator"]
    assert all(shlex.split(conf[f"program:{p}"]["command"])[:3] == ["nice", "-n", "-5"]
               for p in programs)
    assert "realtime_factor=4" in simulator
    assert f"scenario={deployment.scenario}" in simulator
    assert simulator[simulator.index("--transport") + 1] == str(tmp_path / "run" /
                                                                  "transport.yaml")
    router = shlex.split(conf["program:router"]["command"])
    assert router[router.index("--listen") + 1] == "tcp/0.0.0.0:7447"
    transport = yaml.safe_load((tmp_path / "run" / "transport.yaml").read_text())
    assert transport["mode"] == "client" and transport["connect"] == ["tcp/127.0.0.1:9999"]
    assert transport["extra"]["connect/retry"] == CLIENT_EXTRA["connect/retry"]
    assert conf["supervisord"]["pidfile"] == str(tmp_path / "run" / "supervisord.pid")


def test_scenario_dependent_parameters_are_derived_and_the_clock_left_to_the_files(tmp_path):
    deployment = load_deployment(DEPLOY / "stack.yaml")
    conf = conf_of(prepare(deployment, tmp_path / "run", python="/py", workdir=tmp_path))
    planner = shlex.split(conf["program:planner"]["command"])
    configs = [planner[i + 1] for i, a in enumerate(planner) if a == "--config"]
    assert configs == [str(tmp_path / "run" / "params" / "planner.scenario.yaml"),
                       str(DEPLOY / "params" / "planner.yaml")]  # the file wins
    derived = yaml.safe_load(Path(configs[0]).read_text())
    assert derived["goal"] == [8.0, 3.0] and derived["cruise_speed"] == 0.1
    simulator = yaml.safe_load((tmp_path / "run" / "params" / "simulator.scenario.yaml")
                               .read_text())
    assert "clock" not in simulator and "wait_for" not in simulator


def test_a_program_may_be_any_command_standing_in_for_a_service(tmp_path):
    base = yaml.safe_load((DEPLOY / "stack.yaml").read_text())
    base["scenario"] = str(DEPLOY / base["scenario"])
    for spec in base["services"].values():
        spec["config"] = [str(DEPLOY / p) for p in spec["config"]]
    base["supervisor"]["nice"] = -5
    base["services"]["planner_b"] = {
        "service": "planner", "autostart": False,
        "command": ["{python}", "my_planner.py", "--transport", "{transport}",
                    "--robot-id", "{robot_id}", "--value", "100%"]}
    path = tmp_path / "d.yaml"
    path.write_text(yaml.safe_dump(base))
    deployment = load_deployment(path)
    conf_text = prepare(deployment, tmp_path / "run", python="/py").read_text()
    conf = conf_of(tmp_path / "run" / "supervisord.conf")
    section = conf["program:planner_b"]
    assert section["autostart"] == "false" and section["priority"] == "70"
    assert shlex.split(section["command"].replace("%%", "%")) == [
        "nice", "-n", "-5", "/py", "my_planner.py", "--transport",
        str(tmp_path / "run" / "transport.yaml"),
        "--robot-id", "robot0", "--value", "100%"]
    assert "100%%" in conf_text  # supervisord's expansion character is escaped


@pytest.mark.parametrize(("change", "message"), [
    ({"services": {"planer": {}}}, "no service named 'planer'"),
    ({"services": {"router": {}}}, "use the router section"),
    ({"services": {"x": {"command": ["a"], "set": ["b=1"]}}}, "not to a command"),
    ({"name": "Bad Name"}, "name"),
    ({"robot_id": "a/b"}, "robot id"),
    ({"transport": {"mode": "clinet"}}, "transport.mode"),
])
def test_a_bad_deployment_file_is_refused_naming_file_and_field(tmp_path, change, message):
    data = {"name": "t", "transport": {"mode": "client", "connect": ["tcp/127.0.0.1:1"]},
            "services": {"planner": {}}}
    data.update(change)
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ConfigError) as info:
        load_deployment(path)
    assert str(path) in str(info.value) and message in str(info.value)


def test_another_scenario_replaces_the_deployments_and_sets_the_derived_parameters(tmp_path):
    other = Path(__file__).resolve().parents[1] / "integration" / "data" / "offpath.yaml"
    deployment = load_deployment(DEPLOY / "stack.yaml", ["simulator.realtime_factor=4"],
                                 scenario=other)
    assert deployment.scenario == other
    conf = conf_of(prepare(deployment, tmp_path / "run", python="/py", workdir=tmp_path))
    simulator = shlex.split(conf["program:simulator"]["command"])
    sets = [simulator[i + 1] for i, a in enumerate(simulator) if a == "--set"]
    assert sets == [f"scenario={other}", "realtime_factor=4"]  # an explicit --set comes last
    planner = yaml.safe_load((tmp_path / "run" / "params" / "planner.scenario.yaml").read_text())
    assert planner["goal"] == [6.0, 4.0]


def test_a_missing_scenario_is_refused_when_the_file_is_read(tmp_path):
    path = tmp_path / "d.yaml"
    path.write_text(yaml.safe_dump({"name": "t", "scenario": "nowhere.yaml",
                                    "transport": {"mode": "client"}, "services": {}}))
    with pytest.raises(ConfigError, match=r"d.yaml: scenario: .*nowhere.yaml: file not found"):
        load_deployment(path)


def test_zenav_down_reads_from_supervisords_log_which_stops_were_clean(tmp_path):
    from zenav.deploy.rpc import unclean_stops

    log = tmp_path / "supervisord.log"
    log.write_text("... INFO stopped: old (terminated by SIGKILL)\n")
    offset = log.stat().st_size
    with log.open("a") as stream:
        stream.write("2026-11-22 00:20:55,459 INFO stopped: planner (exit status 0)\n"
                     "2026-11-22 00:20:55,460 WARN stopped: tracking (terminated by SIGTERM)\n"
                     "2026-11-22 00:20:55,461 INFO waiting for perception to stop\n"
                     "2026-11-22 00:21:00,461 WARN stopped: perception (terminated by SIGKILL)\n"
                     "2026-11-22 00:21:00,462 INFO stopped: router (exit status 1)\n")
    assert unclean_stops(log, offset) == ["perception (terminated by SIGKILL)",
                                          "router (exit status 1)"]
    assert unclean_stops(tmp_path / "missing.log", 0) == []


def test_overrides_must_name_a_program_of_the_deployment():
    with pytest.raises(ConfigError, match=r"PROGRAM\.NAME=VALUE"):
        load_deployment(DEPLOY / "server.yaml", ["simulator.realtime_factor=2"])


def test_the_control_socket_moves_to_tmp_when_the_run_directory_is_too_deep(tmp_path):
    short = tmp_path / "r"
    assert socket_path(short) == short.resolve() / "supervisor.sock"
    deep = tmp_path / ("d" * 120)
    moved = socket_path(deep)
    assert moved.parent == Path("/tmp") and moved == socket_path(deep)
    assert len(str(moved)) < 100


def test_niceness_zero_runs_the_programs_as_they_are(tmp_path):
    base = yaml.safe_load((DEPLOY / "stack.yaml").read_text())
    base["scenario"] = str(DEPLOY / base["scenario"])
    for spec in base["services"].values():
        spec["config"] = [str(DEPLOY / p) for p in spec["config"]]
    base["supervisor"]["nice"] = 0
    path = tmp_path / "d.yaml"
    path.write_text(yaml.safe_dump(base))
    conf = conf_of(prepare(load_deployment(path), tmp_path / "run", python="/py"))
    commands = [shlex.split(conf[s]["command"]) for s in conf.sections()
                if s.startswith("program:")]
    assert len(commands) == 7 and all(c[0] == "/py" for c in commands)


def test_standby_pairs_every_service_and_the_router_with_a_warm_spare(tmp_path):
    base = yaml.safe_load((DEPLOY / "stack.yaml").read_text())
    base["scenario"] = str(DEPLOY / base["scenario"])
    for spec in base["services"].values():
        spec["config"] = [str(DEPLOY / p) for p in spec["config"]]
    base["supervisor"]["standby"] = True
    base["services"]["planner_b"] = {"service": "planner", "autostart": False,
                                     "command": ["{python}", "my_planner.py"]}
    path = tmp_path / "d.yaml"
    path.write_text(yaml.safe_dump(base))
    deployment = load_deployment(path)
    conf = conf_of(prepare(deployment, tmp_path / "run", python="/py"))
    programs = [s.removeprefix("program:") for s in conf.sections() if s.startswith("program:")]
    served = ["router", "motor_bridge", "simulator", "laser_driver", "perception", "tracking",
              "planner"]
    assert [p for p in programs if p != "planner_b"] == [
        p for name in served for p in (name, f"{name}_standby")]  # in start order
    for name in served:
        command = shlex.split(conf[f"program:{name}"]["command"])
        assert command == shlex.split(conf[f"program:{name}_standby"]["command"])
        assert command[-2:] == ["--standby-lock",
                                str(tmp_path / "run" / "standby" / f"{name}.lock")]
        assert conf[f"program:{name}"]["priority"] == conf[f"program:{name}_standby"]["priority"]
    assert "--standby-lock" not in conf["program:planner_b"]["command"]


def test_a_programs_reason_is_its_last_error_without_the_log_records_time_and_level(tmp_path):
    from zenav.deploy.wait import _reason

    log = tmp_path / "router.log"
    log.write_text("2026-12-05 18:03:26,100 router INFO starting\n"
                   "2026-12-05 18:03:26,960 router ERROR cannot open the router on "
                   "tcp/0.0.0.0:7447: Address already in use (os error 98)\n"
                   "2026-12-05 18:03:27,000 router INFO bye\n")
    assert _reason(log) == ("cannot open the router on tcp/0.0.0.0:7447: Address already in "
                            "use (os error 98)")
    log.write_text("zenav laser: cannot open /dev/ttyUSB9\n")
    assert _reason(log) == "zenav laser: cannot open /dev/ttyUSB9"
    assert _reason(tmp_path / "none.log") == "(no log)"
