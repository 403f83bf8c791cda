"""Long-running stacks under supervisord: ``zenav up``, ``zenav down``, ``zenav ctl``.

A *deployment file* (``deploy/stack.yaml``, ``deploy/robot.yaml``, ``deploy/server.yaml``)
says which services run on this host, with which parameter files, how they join the
bus, and whether this host runs the Zenoh router. ``zenav up`` turns it into a
supervisord configuration in a run directory, starts supervisord, and returns once every
program is running and every service's liveliness token is on the bus. supervisord then
restarts any program that dies (``kill -9`` included), keeps one log per program, and
stops them all in order on ``zenav down``.

Run directory (default ``~/.local/state/zenav/<name>``, or ``--run-dir``)::

    supervisord.conf     generated; `supervisorctl -c` it, or use `zenav ctl`
    supervisord.pid      supervisord.log is in logs/
    transport.yaml       how the services join (client of the router)
    params/              parameters derived from the scenario, one file per service
    logs/<program>.log   each program's stdout and stderr
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import os
import shlex
import subprocess
import sys
import time
import xmlrpc.client
from collections.abc import Iterable
from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from zenav import secure
from zenav.schemas.keys import check_robot_id
from zenav.services.config import SERVICE_ORDER, ConfigError, parse_assignment, read_yaml
from zenav.services.transport import TransportConfig
from zenav.tooling import with_client_defaults

DEFAULT_CONFIG = Path("deploy/stack.yaml")
"""``zenav up`` and ``zenav down`` without ``--config``: the one-host stack (run from the
repository root)."""

PRIORITY: dict[str, int] = {
    "router": 10,
    "motor_bridge": 20,
    "simulator": 30,
    "laser_driver": 40,
    "perception": 50,
    "tracking": 60,
    "planner": 70,
}
"""supervisord start order (lowest first); it stops in the reverse order, so the planner
goes first and the router last."""

CUSTOM_PRIORITY = 80

PLACEHOLDERS = ("python", "transport", "robot_id", "log_level", "run_dir")
"""``{name}`` fields a custom program's command may use."""


class ProgramSpec(BaseModel):
    """One program: a zenav service, or any command that stands in for one."""

    model_config = ConfigDict(extra="forbid")

    config: list[Path] = Field(default_factory=list,
                               description="parameter files, relative to the deployment file")
    set: list[str] = Field(default_factory=list, description="NAME=VALUE overrides")
    service: str | None = Field(None, description="the service this program is (default: "
                                "its name); its liveliness token is awaited by zenav up")
    command: list[str] | None = Field(
        None, description="a replacement process instead of `zenav service`; {python}, "
        "{transport}, {robot_id}, {log_level} and {run_dir} are filled in")
    autostart: bool = True
    priority: int | None = None


class RouterSpec(BaseModel):
    model_config = ConfigDict(extra="forbid")

    listen: list[str] = Field(default_factory=lambda: ["tcp/0.0.0.0:7447"])
    connect: list[str] = Field(default_factory=list, description="other routers")


class SupervisorSpec(BaseModel):
    model_config = ConfigDict(extra="forbid")

    autorestart: Literal["true", "false", "unexpected"] = Field(
        "unexpected", description="restart a program that exits with a status other than 0 "
        "or is killed")
    startsecs: int = Field(1, ge=0, description="s a program must stay up to count as started")
    startretries: int = Field(5, ge=0, description="failed starts in a row before FATAL")
    stopwaitsecs: int = Field(5, ge=1, description="s after SIGTERM before SIGKILL")
    log_maxbytes: str = "10MB"
    log_backups: int = Field(3, ge=0)


class SecuritySpec(BaseModel):
    """Mutual TLS on every link, and access control on the router (zenav.secure)."""

    model_config = ConfigDict(extra="forbid")

    certs: Path = Field(description="directory made by deploy/secure/make-certs.sh, "
                        "relative to the deployment file")
    access_control: bool = Field(True, description="the router's default-deny policy")


class Deployment(BaseModel):
    """A deployment file."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(pattern=r"^[a-z0-9_-]{1,40}$")
    robot_id: str = "robot0"
    scenario: Path | None = Field(
        None, description="with the simulator as the robot's backend: the scenario, from "
        "which the services' scenario-dependent parameters follow (as in zenav run)")
    log_level: str = "INFO"
    router: RouterSpec | None = None
    transport: TransportConfig
    services: dict[str, ProgramSpec]
    supervisor: SupervisorSpec = Field(default_factory=SupervisorSpec)
    security: SecuritySpec | None = None

    @field_validator("robot_id")
    @classmethod
    def _robot_id(cls, value: str) -> str:
        return check_robot_id(value)

    @field_validator("services")
    @classmethod
    def _programs(cls, services: dict[str, ProgramSpec]) -> dict[str, ProgramSpec]:
        for name, spec in services.items():
            if name == "router":
                raise ValueError("'router' is the router's program; use the router section")
            if not name.replace("_", "").isalnum() or not name.islower():
                raise ValueError(f"program name {name!r}: lower-case letters, digits and '_'")
            service = spec.service or name
            if spec.command is None and service not in SERVICE_ORDER:
                raise ValueError(f"{name}: no service named {service!r} (the services are "
                                 f"{', '.join(SERVICE_ORDER)}); give a command for others")
            if spec.command is not None and (spec.config or spec.set):
                raise ValueError(f"{name}: config and set apply to zenav services, "
                                 "not to a command")
        return services

    def service_of(self, program: str) -> str:
        return self.services[program].service or program


def load_deployment(path: Path, overrides: Iterable[str] = (),
                    connect: list[str] | None = None,
                    scenario: Path | None = None) -> Deployment:
    """Read a deployment file; relative paths in it are relative to the file.

    ``overrides`` are ``PROGRAM.NAME=VALUE`` parameter overrides appended to a program's
    ``set``; ``connect`` replaces the transport's endpoints (the server side's router);
    ``scenario`` (relative to the working directory) replaces the file's scenario.
    """
    data = read_yaml(path)
    if scenario is not None:
        data["scenario"] = str(scenario.resolve())
    try:
        deployment = Deployment.model_validate(data)
    except ValidationError as exc:
        lines = []
        for error in exc.errors(include_url=False):
            where = ".".join(str(p) for p in error["loc"]) or "(top level)"
            lines.append(f"{path}: {where}: {error['msg']}")
        raise ConfigError("\n".join(lines)) from None
    base = path.resolve().parent
    if deployment.scenario is not None:
        deployment.scenario = (base / deployment.scenario).resolve()
        from zenav.sim.scenario import ScenarioError, load_scenario

        try:
            load_scenario(deployment.scenario)
        except ScenarioError as exc:
            raise ConfigError(f"{path}: scenario: {exc}") from None
    for spec in deployment.services.values():
        spec.config = [(base / p).resolve() for p in spec.config]
    if deployment.security is not None:
        deployment.security.certs = (base / deployment.security.certs).resolve()
        missing = [f"{name}.pem" for name in ("ca", "router", *secure.PARTIES)
                   if not (deployment.security.certs / f"{name}.pem").is_file()]
        if missing:
            raise ConfigError(f"{path}: security.certs: {deployment.security.certs} lacks "
                              f"{', '.join(missing)} (make them with "
                              "deploy/secure/make-certs.sh)")
    for text in overrides:
        program, _, assignment = text.partition(".")
        if program not in deployment.services or not assignment:
            raise ConfigError(f"--set {text!r}: expected PROGRAM.NAME=VALUE with PROGRAM one "
                              f"of {', '.join(deployment.services)}")
        parse_assignment(assignment)  # reject a malformed one here, not in the service
        deployment.services[program].set.append(assignment)
    if connect:
        deployment.transport = deployment.transport.model_copy(update={"connect": connect})
    deployment.transport = with_client_defaults(deployment.transport)
    return deployment


# --- the run directory and the supervisord configuration ------------------------------


def default_run_dir(name: str) -> Path:
    """``$ZENAV_STATE_DIR/NAME``, else ``$XDG_STATE_HOME/zenav/NAME`` (``~/.local/state``)."""
    if os.environ.get("ZENAV_STATE_DIR"):
        return Path(os.environ["ZENAV_STATE_DIR"]) / name
    state = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(state) / "zenav" / name


def socket_path(run_dir: Path) -> Path:
    """supervisord's control socket: in the run directory unless that path is too long
    for a Unix socket (108 bytes), then in /tmp under a name derived from it."""
    path = run_dir.resolve() / "supervisor.sock"
    if len(os.fsencode(path)) < 100:
        return path
    digest = hashlib.sha1(os.fsencode(run_dir.resolve())).hexdigest()[:16]
    return Path("/tmp") / f"zenav-{digest}.sock"


def _conf_value(text: str) -> str:
    """A value for supervisord's INI file: '%' is its expansion character."""
    return text.replace("%", "%%")


def scenario_params(deployment: Deployment) -> dict[str, dict[str, Any]]:
    """Per-service parameters that follow from the deployment's scenario, as in
    ``zenav run`` but leaving the clock to the parameter files (real time here)."""
    if deployment.scenario is None:
        return {}
    from zenav.run import stack_params
    from zenav.sim.scenario import load_scenario

    params = stack_params(load_scenario(deployment.scenario), deployment.scenario, "paper")
    for key in ("clock", "wait_for"):
        params["simulator"].pop(key, None)
    return params


def program_command(deployment: Deployment, program: str, run_dir: Path,
                    derived: dict[str, Path], python: str) -> list[str]:
    spec = deployment.services[program]
    transport = transport_path(deployment, run_dir, deployment.service_of(program))
    if spec.command is not None:
        values = {"python": python, "transport": str(transport),
                  "robot_id": deployment.robot_id, "log_level": deployment.log_level,
                  "run_dir": str(run_dir)}
        command = []
        for template in spec.command:
            arg = template
            for name in PLACEHOLDERS:
                arg = arg.replace("{" + name + "}", values[name])
            command.append(arg)
        return command
    service = deployment.service_of(program)
    command = [python, "-m", "zenav", "service", service]
    if service in derived:
        command += ["--config", str(derived[service])]
    for path in spec.config:
        command += ["--config", str(path)]
    if service == "simulator" and deployment.scenario is not None:
        command += ["--set", f"scenario={deployment.scenario}"]
    for assignment in spec.set:  # after the scenario's: an explicit one wins
        command += ["--set", assignment]
    command += ["--robot-id", deployment.robot_id, "--transport", str(transport),
                "--log-level", deployment.log_level]
    return command


def transport_path(deployment: Deployment, run_dir: Path, party: str) -> Path:
    """The transport file of one party: shared, or its own in a secured deployment (its
    certificate)."""
    if deployment.security is None:
        return run_dir / "transport.yaml"
    return run_dir / f"transport-{party}.yaml"


def secured_transport(deployment: Deployment, party: str) -> TransportConfig:
    """``party``'s transport in a secured deployment: the router listens (TLS, mutual
    authentication, access control), every other party connects with its certificate."""
    assert deployment.security is not None
    certs = deployment.security.certs
    if party == "router":
        assert deployment.router is not None
        extra = secure.tls_settings(certs, "router", listen=True)
        if deployment.router.connect:
            extra |= secure.tls_settings(certs, "router", listen=False)
        if deployment.security.access_control:
            extra["access_control"] = secure.access_control(deployment.robot_id)
        return TransportConfig(mode="router", listen=deployment.router.listen,
                               connect=deployment.router.connect, extra=extra)
    base = deployment.transport
    return base.model_copy(update={"extra": {**base.extra, **secure.tls_settings(
        certs, party, listen=bool(base.listen))}})


def router_command(deployment: Deployment, python: str,
                   run_dir: Path | None = None) -> list[str]:
    assert deployment.router is not None
    command = [python, "-m", "zenav", "router", "--robot-id", deployment.robot_id,
               "--log-level", deployment.log_level]
    if deployment.security is not None and run_dir is not None:
        return [*command, "--transport", str(transport_path(deployment, run_dir, "router"))]
    for endpoint in deployment.router.listen:
        command += ["--listen", endpoint]
    for endpoint in deployment.router.connect:
        command += ["--connect", endpoint]
    return command


def prepare(deployment: Deployment, run_dir: Path, python: str = sys.executable,
            workdir: Path | None = None) -> Path:
    """Write the run directory: transport, derived parameters, supervisord.conf."""
    run_dir = run_dir.resolve()
    workdir = (workdir or Path.cwd()).resolve()
    (run_dir / "logs").mkdir(parents=True, exist_ok=True)
    (run_dir / "params").mkdir(exist_ok=True)
    (run_dir / "transport.yaml").write_text(
        yaml.safe_dump(deployment.transport.model_dump(mode="json"), sort_keys=False))
    if deployment.security is not None:
        parties = {deployment.service_of(p) for p in deployment.services} | {"monitor", "run"}
        if deployment.router is not None:
            parties.add("router")
        for party in sorted(parties):
            transport_path(deployment, run_dir, party).write_text(yaml.safe_dump(
                secured_transport(deployment, party).model_dump(mode="json"),
                sort_keys=False))
    derived: dict[str, Path] = {}
    for service, params in scenario_params(deployment).items():
        path = run_dir / "params" / f"{service}.scenario.yaml"
        path.write_text(f"# derived from {deployment.scenario}\n"
                        + yaml.safe_dump(params, sort_keys=False))
        derived[service] = path
    sup = deployment.supervisor
    sock = socket_path(run_dir)
    lines = [
        f"; Generated by `zenav up` from the deployment {deployment.name!r}; edit the",
        "; deployment file, not this one. Control: zenav ctl, or",
        f";   supervisorctl -c {run_dir / 'supervisord.conf'} status",
        "",
        "[unix_http_server]",
        f"file={_conf_value(str(sock))}",
        "chmod=0700",
        "",
        "[supervisord]",
        f"logfile={_conf_value(str(run_dir / 'logs' / 'supervisord.log'))}",
        f"pidfile={_conf_value(str(run_dir / 'supervisord.pid'))}",
        f"childlogdir={_conf_value(str(run_dir / 'logs'))}",
        f"identifier=zenav-{deployment.name}",
        "nodaemon=false",
        "",
        "[rpcinterface:supervisor]",
        "supervisor.rpcinterface_factory = supervisor.rpcinterface:make_main_rpcinterface",
        "",
        "[supervisorctl]",
        f"serverurl=unix://{_conf_value(str(sock))}",
    ]
    programs: list[tuple[str, list[str], bool, int]] = []
    if deployment.router is not None:
        programs.append(("router", router_command(deployment, python, run_dir), True,
                         PRIORITY["router"]))
    for program, spec in deployment.services.items():
        priority = spec.priority or PRIORITY.get(deployment.service_of(program), CUSTOM_PRIORITY)
        programs.append((program, program_command(deployment, program, run_dir, derived, python),
                         spec.autostart, priority))
    programs.sort(key=lambda program: program[3])  # stable: the file's order within a rank
    for program, command, autostart, priority in programs:
        log = run_dir / "logs" / f"{program}.log"
        lines += [
            "",
            f"[program:{program}]",
            f"command={_conf_value(shlex.join(command))}",
            f"directory={_conf_value(str(workdir))}",
            f"priority={priority}",
            f"autostart={str(autostart).lower()}",
            f"autorestart={sup.autorestart}",
            "exitcodes=0",
            f"startsecs={sup.startsecs}",
            f"startretries={sup.startretries}",
            "stopsignal=TERM",
            f"stopwaitsecs={sup.stopwaitsecs}",
            "stopasgroup=true",
            "killasgroup=true",
            "redirect_stderr=true",
            f"stdout_logfile={_conf_value(str(log))}",
            f"stdout_logfile_maxbytes={sup.log_maxbytes}",
            f"stdout_logfile_backups={sup.log_backups}",
            'environment=PYTHONUNBUFFERED="1"',
        ]
    conf = run_dir / "supervisord.conf"
    conf.write_text("\n".join(lines) + "\n")
    return conf


# --- talking to supervisord -----------------------------------------------------------


class Supervisor:
    """supervisord's XML-RPC interface over the run directory's Unix socket."""

    def __init__(self, run_dir: Path) -> None:
        self.run_dir = run_dir.resolve()
        self.conf = self.run_dir / "supervisord.conf"

    def proxy(self) -> Any:
        from supervisor.xmlrpc import SupervisorTransport

        url = f"unix://{socket_path(self.run_dir)}"
        return xmlrpc.client.ServerProxy(
            "http://127.0.0.1", transport=SupervisorTransport(None, None, url))

    def pid(self) -> int | None:
        """supervisord's pid if it is running."""
        try:
            pid = int((self.run_dir / "supervisord.pid").read_text().strip())
        except (OSError, ValueError):
            return None
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return None
        except PermissionError:
            return pid
        return pid

    def ready(self) -> bool:
        try:
            return bool(self.proxy().supervisor.getState()["statename"] == "RUNNING")
        except (OSError, xmlrpc.client.Fault, xmlrpc.client.ProtocolError):
            return False

    def processes(self) -> dict[str, dict[str, Any]]:
        """Program name -> supervisord's process info (statename, pid, exitstatus, ...)."""
        return {info["name"]: info for info in self.proxy().supervisor.getAllProcessInfo()}

    def start(self, program: str) -> None:
        self.proxy().supervisor.startProcess(program, True)

    def stop(self, program: str) -> None:
        self.proxy().supervisor.stopProcess(program, True)

    def stop_in_order(self) -> list[str]:
        """Stop every program that runs, highest priority number first (the planner before
        the motor bridge, the router last), each fully before the next; their names."""
        proxy = self.proxy()
        priority = {c["name"]: c["process_prio"] for c in proxy.supervisor.getAllConfigInfo()}
        infos = self.processes()
        stopped = []
        for program in sorted(infos, key=lambda p: -priority.get(p, 0)):
            if infos[program]["statename"] in ("RUNNING", "STARTING", "BACKOFF"):
                with contextlib.suppress(xmlrpc.client.Fault):  # it stopped meanwhile
                    proxy.supervisor.stopProcess(program, True)
                stopped.append(program)
        return stopped

    def ctl(self, args: list[str]) -> int:
        return subprocess.call([sys.executable, "-m", "supervisor.supervisorctl",
                                "-c", str(self.conf), *args])


def _tail(path: Path, lines: int = 3) -> str:
    try:
        text = path.read_text(errors="replace").splitlines()
    except OSError:
        return ""
    return " | ".join(line.strip() for line in text[-lines:] if line.strip())


def wait_running(sup: Supervisor, programs: list[str], timeout: float) -> None:
    """Until every program is RUNNING; a FATAL or BACKOFF-looping one raises ConfigError."""
    deadline = time.monotonic() + timeout
    while True:
        infos = sup.processes()
        fatal = [p for p in programs if infos.get(p, {}).get("statename") == "FATAL"]
        if fatal:
            why = "; ".join(f"{p}: {_tail(sup.run_dir / 'logs' / f'{p}.log')}" for p in fatal)
            raise ConfigError(f"could not start {', '.join(fatal)}: {why}")
        waiting = [p for p in programs if infos.get(p, {}).get("statename") != "RUNNING"]
        if not waiting:
            return
        if time.monotonic() > deadline:
            states = ", ".join(f"{p} {infos.get(p, {}).get('statename', '?')}" for p in waiting)
            raise ConfigError(f"not running after {timeout:.0f} s: {states}")
        time.sleep(0.1)


def wait_alive(deployment: Deployment, services: set[str], timeout: float) -> set[str]:
    """Services among ``services`` whose liveliness token is not on the bus after
    ``timeout`` s (empty when all are)."""
    import zenoh

    from zenav.schemas.keys import Keys

    keys = Keys(deployment.robot_id)
    transport = deployment.transport
    if deployment.security is not None:  # zenav up watches with the monitor's certificate
        transport = secured_transport(deployment, "monitor")
    if transport.mode == "client":
        extra = {**transport.extra, "connect/timeout_ms": int(timeout * 1000)}
        transport = transport.model_copy(update={"extra": extra})
    deadline = time.monotonic() + timeout
    try:
        session: Any = zenoh.open(transport.to_zenoh())
    except Exception:
        return services
    missing = set(services)
    try:
        while missing and time.monotonic() < deadline:
            for reply in session.liveliness().get(keys.alive_any, timeout=1.0):
                with contextlib.suppress(Exception):
                    missing.discard(str(reply.ok.key_expr).rsplit("/", 1)[-1])
            if missing:
                time.sleep(0.1)
    finally:
        session.close()
    return missing


def _expected_alive(deployment: Deployment) -> set[str]:
    names = {deployment.service_of(p) for p, s in deployment.services.items() if s.autostart}
    if deployment.router is not None:
        names.add("router")
    return names


# --- commands ---------------------------------------------------------------------------


def _resolve(args: argparse.Namespace) -> tuple[Deployment | None, Path]:
    deployment = None
    if args.run_dir is None or args.command == "up":
        config = args.config or DEFAULT_CONFIG
        if not config.exists():
            raise ConfigError(f"{config}: no such deployment file (give --config FILE, or run "
                              "from the repository root for deploy/stack.yaml)")
        deployment = load_deployment(config, getattr(args, "set", []),
                                     getattr(args, "connect", None) or None,
                                     getattr(args, "scenario", None))
    run_dir = args.run_dir or default_run_dir(deployment.name if deployment else "stack")
    return deployment, run_dir.resolve()


def cmd_up(args: argparse.Namespace) -> int:
    try:
        deployment, run_dir = _resolve(args)
        assert deployment is not None
        sup = Supervisor(run_dir)
        if (pid := sup.pid()) is not None:
            raise ConfigError(f"{deployment.name} is already up (supervisord pid {pid}, "
                              f"{run_dir}); zenav down first")
        conf = prepare(deployment, run_dir)
        if args.print:
            print(conf.read_text(), end="")
            return 0
        started = subprocess.run([sys.executable, "-m", "supervisor.supervisord", "-c", str(conf)],
                                 capture_output=True, text=True, check=False)
        if started.returncode != 0:
            raise ConfigError(f"supervisord did not start: {started.stderr.strip()}")
        deadline = time.monotonic() + 10
        while not sup.ready():
            if time.monotonic() > deadline:
                raise ConfigError(f"supervisord not answering on {socket_path(run_dir)}; see "
                                  f"{run_dir / 'logs' / 'supervisord.log'}")
            time.sleep(0.05)
        programs = [p for p, s in deployment.services.items() if s.autostart]
        if deployment.router is not None:
            programs.insert(0, "router")
        wait_running(sup, programs, args.timeout)
        if not args.no_wait:
            missing = wait_alive(deployment, _expected_alive(deployment), args.timeout)
            if missing:
                raise ConfigError(f"running, but not on the bus after {args.timeout:.0f} s: "
                                  f"{', '.join(sorted(missing))} (is the router at "
                                  f"{', '.join(deployment.transport.connect)} reachable?). "
                                  "Left running: they join when it is; `zenav down` stops "
                                  "them")
    except ConfigError as exc:
        print(f"zenav up: {exc}", file=sys.stderr)
        return 2
    where = "" if args.run_dir is None and args.config is None else (
        f" --run-dir {run_dir}" if args.run_dir else f" --config {args.config}")
    print(f"zenav up: {deployment.name}: {', '.join(programs)} running"
          f"{'' if args.no_wait else ' and alive on the bus'}; logs in {run_dir / 'logs'}; "
          f"stop with `zenav down{where}`")
    return 0


def cmd_down(args: argparse.Namespace) -> int:
    try:
        deployment, run_dir = _resolve(args)
    except ConfigError as exc:
        print(f"zenav down: {exc}", file=sys.stderr)
        return 2
    name = deployment.name if deployment else run_dir.name
    sup = Supervisor(run_dir)
    pid = sup.pid()
    if pid is None:
        print(f"zenav down: {name} is not up ({run_dir})")
        return 0
    log = run_dir / "logs" / "supervisord.log"
    offset = log.stat().st_size if log.exists() else 0
    unclean = []
    try:
        sup.stop_in_order()
        sup.proxy().supervisor.shutdown()
    except (OSError, xmlrpc.client.Fault) as exc:
        print(f"zenav down: supervisord did not answer ({exc}); sending SIGTERM", file=sys.stderr)
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, 15)
    deadline = time.monotonic() + 30
    while sup.pid() is not None and time.monotonic() < deadline:
        time.sleep(0.05)
    if sup.pid() is not None:
        print(f"zenav down: supervisord (pid {pid}) still running after 30 s", file=sys.stderr)
        return 1
    unclean = unclean_stops(log, offset)
    if unclean:
        print(f"zenav down: {name} stopped; unclean: {', '.join(unclean)}", file=sys.stderr)
        return 1
    print(f"zenav down: {name} stopped cleanly")
    return 0


def unclean_stops(log: Path, offset: int) -> list[str]:
    """Programs whose stop, as supervisord logged it after ``offset``, was not clean: a
    clean one exited with status 0, or was ended by the SIGTERM itself (a program still
    waiting for the router has no handler yet, and nothing to clean up)."""
    try:
        with log.open("rb") as stream:
            stream.seek(offset)
            lines = stream.read().decode(errors="replace").splitlines()
    except OSError:
        return []
    unclean = []
    for line in lines:
        if "stopped: " not in line:
            continue
        program, _, how = line.split("stopped: ", 1)[1].partition(" ")
        if how.strip() not in ("(exit status 0)", "(terminated by SIGTERM)"):
            unclean.append(f"{program} {how.strip()}")
    return unclean


def cmd_ctl(args: argparse.Namespace) -> int:
    try:
        _, run_dir = _resolve(args)
    except ConfigError as exc:
        print(f"zenav ctl: {exc}", file=sys.stderr)
        return 2
    return Supervisor(run_dir).ctl(list(args.args) or ["status"])


def _add_common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", type=Path,
                        help=f"deployment file (default {DEFAULT_CONFIG})")
    parser.add_argument("--run-dir", type=Path,
                        help="run directory (default ~/.local/state/zenav/NAME)")


def add_commands(sub: Any) -> None:
    up = sub.add_parser("up", help="start a deployment under supervisord (real time)",
                        description="Start the deployment's programs under supervisord and "
                        "wait until each is running and alive on the bus.")
    _add_common(up)
    up.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                    help="the router the services join (replaces the file's endpoints)")
    up.add_argument("--set", action="append", default=[], metavar="PROGRAM.NAME=VALUE",
                    help="override a parameter of one program")
    up.add_argument("--scenario", type=Path,
                    help="the simulator's scenario (replaces the deployment's; the "
                    "parameters that follow from it are derived from this one)")
    up.add_argument("--timeout", type=float, default=30.0, help="s to wait (default 30)")
    up.add_argument("--no-wait", action="store_true",
                    help="do not wait for the liveliness tokens")
    up.add_argument("--print", action="store_true",
                    help="write the run directory and print supervisord.conf; start nothing")
    up.set_defaults(func=cmd_up)

    down = sub.add_parser("down", help="stop a deployment started by zenav up")
    _add_common(down)
    down.set_defaults(func=cmd_down)

    ctl = sub.add_parser("ctl", help="supervisorctl on a deployment (status, restart NAME, ...)")
    _add_common(ctl)
    ctl.add_argument("args", nargs=argparse.REMAINDER, help="supervisorctl arguments")
    ctl.set_defaults(func=cmd_ctl)

