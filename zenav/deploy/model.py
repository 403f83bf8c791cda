"""A deployment file (``deploy/stack.yaml``, ...) as a pydantic model, and reading one."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from zenav.deploy.secure import PARTIES
from zenav.schemas.keys import check_robot_id
from zenav.services.config import (
    SERVICE_ORDER,
    ConfigError,
    Layer,
    assignment_layer,
    file_layer,
    parse_assignment,
    read_yaml,
    resolve,
)
from zenav.services.transport import NO_ROUTER, Endpoint, TransportConfig, check_endpoint
from zenav.tooling import with_client_defaults

DEFAULT_CONFIG = Path("deploy/stack.yaml")
"""``zenav up`` and ``zenav down`` without ``--config``: the one-host stack (run from the
repository root)."""




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

    listen: list[Endpoint] = Field(default_factory=lambda: ["tcp/0.0.0.0:7447"])
    connect: list[Endpoint] = Field(default_factory=list, description="other routers")


class SupervisorSpec(BaseModel):
    model_config = ConfigDict(extra="forbid")

    autorestart: Literal["true", "false", "unexpected"] = Field(
        "unexpected", description="restart a program that exits with a status other than 0 "
        "or is killed")
    startsecs: int = Field(1, ge=0, description="s a program must stay up to count as started")
    startretries: int = Field(3, ge=0, description="failed starts in a row before FATAL")
    stopwaitsecs: int = Field(5, ge=1, description="s after SIGTERM before SIGKILL")
    nice: int = Field(-5, ge=-20, le=19, description="scheduling niceness of every program "
                      "(`nice -n`): below 0 the robot's processes, and above all a restarted "
                      "one's start-up, go before other work on the host; needs root or "
                      "CAP_SYS_NICE, else `nice` says so in the program's log and it runs at 0")
    standby: bool = Field(False, description="beside the router and every zenav service, a "
                          "warm spare (program NAME_standby) that has loaded everything and "
                          "takes over the moment the serving process ends, kill -9 included; "
                          "the process killed is restarted as the new spare")
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


def check_program_params(deployment: Deployment, path: Path, overrides: list[str]) -> None:
    """Validate the parameters of every zenav service program (its files, its ``set`` and
    the command line's ``--set``) before anything starts: a bad one is a ConfigError with
    one line per problem naming the flag or file, not a program restarting in a loop."""
    from zenav.services.runner import service_params

    problems = []
    for program, spec in deployment.services.items():
        if spec.command is not None:
            continue
        from_flags = {text.partition(".")[2] for text in overrides
                      if text.partition(".")[0] == program}
        layers = [file_layer(config) for config in spec.config]
        for text in spec.set:
            layer = assignment_layer(text)
            source = (f"--set {program}.{text}" if text in from_flags
                      else f"{path}: services.{program}.set: {text}")
            layers.append(Layer(layer.origin, source, layer.values))
        try:
            resolve(service_params(deployment.service_of(program)), layers)
        except ConfigError as exc:
            problems.append(str(exc))
    if problems:
        raise ConfigError("\n".join(problems))


def load_deployment(path: Path, overrides: Iterable[str] = (),
                    connect: list[str] | None = None,
                    scenario: Path | None = None) -> Deployment:
    """Read a deployment file; relative paths in it are relative to the file.

    ``overrides`` are ``PROGRAM.NAME=VALUE`` parameter overrides appended to a program's
    ``set``; ``connect`` replaces the transport's endpoints (the server side's router);
    ``scenario`` (relative to the working directory) replaces the file's scenario.
    """
    for endpoint in connect or []:  # before anything else: no session would open
        try:
            check_endpoint(endpoint)
        except ValueError as exc:
            raise ConfigError(f"--connect: {exc}") from None
    data = read_yaml(path)
    if scenario is not None:
        data["scenario"] = str(scenario.resolve())
    try:
        deployment = Deployment.model_validate(data)
    except ValidationError as exc:
        lines = []
        for error in exc.errors(include_url=False):
            where = ".".join(str(p) for p in error["loc"]) or "(top level)"
            lines.append(f"{path}: {where}: {error['msg'].removeprefix('Value error, ')}")
        raise ConfigError("\n".join(lines)) from None
    base = path.resolve().parent
    if deployment.scenario is not None:
        deployment.scenario = (base / deployment.scenario).resolve()
        from zenav.sim.scenario import ScenarioError, load_scenario

        try:
            load_scenario(deployment.scenario)
        except ScenarioError as exc:  # named where it was given: --scenario, or the file
            where = "--scenario" if scenario is not None else f"{path}: scenario"
            raise ConfigError(f"{where}: {exc}") from None
    for spec in deployment.services.values():
        spec.config = [(base / p).resolve() for p in spec.config]
    if deployment.security is not None:
        deployment.security.certs = (base / deployment.security.certs).resolve()
        missing = [f"{name}.pem" for name in ("ca", "router", *PARTIES)
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
    check_program_params(deployment, path, list(overrides))
    if connect:
        deployment.transport = deployment.transport.model_copy(update={"connect": connect})
    if deployment.transport.finds_no_router():
        raise ConfigError(f"{path}: transport: {NO_ROUTER}")
    deployment.transport = with_client_defaults(deployment.transport)
    return deployment

