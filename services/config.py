"""Parameters: code defaults, overridden by YAML files, overridden by ``--set``.

Every service keeps all its parameters, with defaults and units, in one pydantic model.
``deploy/params/<service>.yaml`` and any ``--config FILE`` override them; an error names
the file, the field and the problem.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from zenav.services.transport import TransportConfig

P = TypeVar("P", bound=BaseModel)

SERVICE_ORDER: tuple[str, ...] = (
    "simulator",
    "laser_driver",
    "perception",
    "tracking",
    "planner",
    "motor_bridge",
)
"""The six processes of a stack, in the order their loopback ports are numbered."""

DEFAULT_BASE_PORT = 7450
"""First loopback port of the embedded default mesh (7450..7455, one per service)."""


class ConfigError(ValueError):
    """A parameter or configuration file that cannot be used; the text says why."""


def read_yaml(path: Path) -> dict[str, Any]:
    try:
        text = path.read_text()
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read ({exc.strerror})") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: not valid YAML ({exc})") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping of parameter names to values")
    return data


def parse_assignment(text: str) -> tuple[list[str], Any]:
    """``a.b=1.5`` -> (["a", "b"], 1.5); the value is read as YAML."""
    name, sep, raw = text.partition("=")
    if not sep or not name.strip():
        raise ConfigError(f"--set {text!r}: expected NAME=VALUE")
    try:
        value = yaml.safe_load(raw)
    except yaml.YAMLError:
        value = raw
    return name.strip().split("."), value


def _merge(base: dict[str, Any], update: dict[str, Any]) -> dict[str, Any]:
    merged = dict(base)
    for key, value in update.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = _merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def format_validation_error(source: str, exc: ValidationError) -> str:
    lines = []
    for error in exc.errors(include_url=False):
        where = ".".join(str(p) for p in error["loc"]) or "(top level)"
        got = f" (got {error['input']!r})" if error["type"] != "missing" else ""
        lines.append(f"{source}: {where}: {error['msg']}{got}")
    return "\n".join(lines)


def load_params(model: type[P], files: list[Path], assignments: list[str]) -> P:
    """Build ``model`` from its defaults, then each file in order, then the assignments."""
    data: dict[str, Any] = {}
    sources = []
    for path in files:
        data = _merge(data, read_yaml(path))
        sources.append(str(path))
    for text in assignments:
        path_parts, value = parse_assignment(text)
        nested: dict[str, Any] = {path_parts[-1]: value}
        for part in reversed(path_parts[:-1]):
            nested = {part: nested}
        data = _merge(data, nested)
        sources.append(f"--set {text}")
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        source = " + ".join(sources) or "defaults"
        raise ConfigError(format_validation_error(source, exc)) from None


def loopback_port(service: str, base_port: int = DEFAULT_BASE_PORT) -> int:
    return base_port + SERVICE_ORDER.index(service)


def loopback_mesh(
    service: str | None, base_port: int = DEFAULT_BASE_PORT, *, tool_listens: bool = False
) -> TransportConfig:
    """The embedded default: every service a peer on its own loopback port, connected to
    all the others and to the tool port after them (``base_port + 6``).

    ``service=None`` is a tool (zenav run, a monitor): it connects to every service. The
    one tool that drives a run also listens on the tool port (``tool_listens``), so the
    links to it are made from both ends and come up as soon as either side starts.
    """
    endpoints = {name: f"tcp/127.0.0.1:{loopback_port(name, base_port)}" for name in SERVICE_ORDER}
    tool = f"tcp/127.0.0.1:{base_port + len(SERVICE_ORDER)}"
    if service is None:
        return TransportConfig(mode="peer", listen=[tool] if tool_listens else [],
                               connect=list(endpoints.values()))
    connect = [ep for name, ep in endpoints.items() if name != service] + [tool]
    return TransportConfig(mode="peer", listen=[endpoints[service]], connect=connect)
