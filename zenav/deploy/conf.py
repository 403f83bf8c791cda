"""The run directory of a deployment and the supervisord configuration in it."""

from __future__ import annotations

import hashlib
import os
import shlex
import sys
from pathlib import Path
from typing import Any

import yaml

from zenav.deploy.model import Deployment
from zenav.deploy.secure import access_control, tls_settings
from zenav.services.transport import TransportConfig

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
    from zenav.services.mission import stack_params
    from zenav.sim.scenario import load_scenario

    params = stack_params(load_scenario(deployment.scenario), deployment.scenario, "paper")
    for key in ("clock", "wait_for"):
        params["simulator"].pop(key, None)
    return params


STANDBY_SUFFIX = "_standby"


def standby_twins(deployment: Deployment) -> dict[str, str]:
    """Program -> the program name of its warm spare, when the deployment has standbys: the
    router and every zenav service that starts with the deployment (a custom command is
    not told about the lock)."""
    if not deployment.supervisor.standby:
        return {}
    names = ["router"] if deployment.router is not None else []
    names += [p for p, s in deployment.services.items() if s.command is None and s.autostart]
    return {name: name + STANDBY_SUFFIX for name in names}


def standby_lock(run_dir: Path, program: str) -> Path:
    """The lock a program and its spare share: whoever holds it serves (its pid is in it)."""
    return run_dir.resolve() / "standby" / f"{program}.lock"


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
        extra = tls_settings(certs, "router", listen=True)
        if deployment.router.connect:
            extra |= tls_settings(certs, "router", listen=False)
        if deployment.security.access_control:
            extra["access_control"] = access_control(deployment.robot_id)
        return TransportConfig(mode="router", listen=deployment.router.listen,
                               connect=deployment.router.connect, extra=extra)
    base = deployment.transport
    return base.model_copy(update={"extra": {**base.extra, **tls_settings(
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
    twins = standby_twins(deployment)
    for i, (program, argv, autostart, priority) in enumerate(list(programs)):
        if program in twins:
            paired = [*argv, "--standby-lock", str(standby_lock(run_dir, program))]
            programs[i] = (program, paired, autostart, priority)
            programs.append((twins[program], paired, autostart, priority))
    programs.sort(key=lambda program: program[3])  # stable: the file's order within a rank
    for program, argv, autostart, priority in programs:
        log = run_dir / "logs" / f"{program}.log"
        # nice execs the program: supervisord's pid is still the program's
        command = ["nice", "-n", str(sup.nice), *argv] if sup.nice != 0 else argv
        lines += [
            "",
            f"[program:{program}]",
            f"command={_conf_value(shlex.join(command))}",
            f"directory={_conf_value(str(workdir))}",
            f"priority={priority}",
            f"autostart={str(autostart).lower()}",
            f"autorestart={sup.autorestart}",
            # 2 is a service's "bad parameter or input": restarting cannot help, so
            # supervisord leaves it EXITED and `zenav up` reports the service's own line.
            "exitcodes=0,2",
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

