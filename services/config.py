"""Parameters: code defaults, overridden by YAML files, overridden by ``--set``.

Each value's origin is kept (:func:`resolve`): ``default`` (the code), ``profile`` (a named
set of overrides, :mod:`zenav.services.profiles`), ``scenario`` (what
:func:`zenav.services.mission.stack_params` derives), ``file`` or ``--set``.

Every service keeps all its parameters, with defaults and units, in one pydantic model.
``deploy/params/<service>.yaml`` and any ``--config FILE`` override them; an error names
the file, the field and the problem.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, TypeVar

import yaml
from pydantic import BaseModel, ValidationError
from pydantic_core import ErrorDetails

from zenav.services.inputs import AliasError, clipped, not_valid_yaml, safe_load, shown
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
"""First loopback port of the embedded default mesh (7450..7455, one per service; 7456 for
the tools)."""


class ConfigError(ValueError):
    """A parameter or configuration file that cannot be used; the text says why."""


def read_yaml(path: Path, mapping: str = "parameter names to values") -> dict[str, Any]:
    """A YAML file whose top level is a mapping (of ``mapping``, as the error says); an
    empty file is an empty mapping. ConfigError naming the file and the problem."""
    try:
        text = path.read_text()
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except UnicodeDecodeError:
        raise ConfigError(f"{path}: not a text file") from None
    try:
        data = safe_load(text)
    except AliasError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: {not_valid_yaml(exc)}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: expected a mapping of {mapping}")
    return data


def read_transport(path: Path) -> TransportConfig:
    """A transport file (``--transport``); ConfigError with one line per problem, each
    naming the file (and the field, when one is wrong)."""
    data = read_yaml(path, f"transport settings ({', '.join(TransportConfig.model_fields)})")
    try:
        return TransportConfig.model_validate(data)
    except ValidationError as exc:
        raise ConfigError("\n".join(dict.fromkeys(  # one line for a list short by two
            format_error(str(path), error) for error in exc.errors(include_url=False)))) from None


def parse_assignment(text: str) -> tuple[list[str], Any]:
    """``a.b=1.5`` -> (["a", "b"], 1.5); the value is read as YAML."""
    name, sep, raw = text.partition("=")
    if not sep or not name.strip():
        raise ConfigError(f"--set {shown(text)}: expected NAME=VALUE")
    try:
        value = safe_load(raw)
    except AliasError as exc:
        raise ConfigError(f"--set {shown(text)}: {exc}") from None
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


FINITE = "must be a finite number"
"""What a parameter given as inf, -inf, nan or a number beyond a float (1e400) is told, as
the scenario loader says it."""


def non_finite(value: object) -> bool:
    """Whether ``value`` is, or is text read as, a float that is not finite."""
    if isinstance(value, float):
        return not math.isfinite(value)
    if isinstance(value, str):
        try:
            return not math.isfinite(float(value))
        except ValueError:
            return False
    return False


def _non_finite_leaves(value: object, loc: tuple[str | int, ...]
                       ) -> list[tuple[tuple[str | int, ...], float]]:
    if isinstance(value, float) and not math.isfinite(value):
        return [(loc, value)]
    if isinstance(value, dict):
        return [leaf for key, item in value.items()
                for leaf in _non_finite_leaves(item, (*loc, str(key)))]
    if isinstance(value, list | tuple):
        return [leaf for i, item in enumerate(value)
                for leaf in _non_finite_leaves(item, (*loc, i))]
    return []


def format_error(source: str, error: ErrorDetails) -> str:
    loc = error["loc"]
    if (error["type"] == "missing" and loc and isinstance(loc[-1], int)
            and isinstance(error["input"], list | tuple)):
        # A list too short: pydantic reports each absent item as a missing field.
        parent = ".".join(str(p) for p in loc[:-1])
        return f"{source}: {parent}: too few items (got {shown(error['input'])})"
    where = ".".join(str(p) for p in loc) or "(top level)"
    # A check of our own (value_error) quotes the value itself where it helps.
    got = f" (got {shown(error['input'])})" if error["type"] not in ("missing",
                                                                     "value_error") else ""
    message = error["msg"].removeprefix("Value error, ")
    if error["type"] == "too_long" and "max_length" in error.get("ctx", {}):
        message = f"too many items, at most {error['ctx']['max_length']}"
    if error["type"] not in ("missing", "extra_forbidden") and non_finite(error["input"]):
        message = FINITE  # nan is not "not greater than 0": it is no number at all
    return f"{source}: {where}: {message}{got}"


Origin = Literal["default", "profile", "scenario", "file", "--set"]
"""Where a parameter's value came from, lowest precedence first."""


@dataclass(frozen=True)
class Layer:
    """Parameter values from one source, applied over the ones before it."""

    origin: Origin
    source: str  # as error messages name it: the file, "--set NAME=VALUE", "scenario FILE"
    values: dict[str, Any]


def file_layer(path: Path) -> Layer:
    return Layer("file", str(path), read_yaml(path))


def assignment_layer(text: str) -> Layer:
    path_parts, value = parse_assignment(text)
    nested: dict[str, Any] = {path_parts[-1]: value}
    for part in reversed(path_parts[:-1]):
        nested = {part: nested}
    return Layer("--set", f"--set {clipped(text)}", nested)


@dataclass(frozen=True)
class Setting:
    """One parameter as used: its value (as YAML would show it) and where it came from."""

    name: str
    value: Any
    origin: Origin
    source: str
    description: str | None


def resolve(model: type[P], layers: list[Layer]) -> tuple[P, list[Setting]]:
    """Build ``model`` from its defaults and then each layer in order; each parameter with
    the layer that set it last. Raises ConfigError naming the layer of each problem."""
    data: dict[str, Any] = {}
    set_by: dict[str, Layer] = {}
    for layer in layers:
        data = _merge(data, layer.values)
        set_by.update(dict.fromkeys(layer.values, layer))
    try:
        params = model.model_validate(data)
    except ValidationError as exc:
        everyone = " + ".join(layer.source for layer in layers) or "defaults"
        lines = []
        for error in exc.errors(include_url=False):
            first = str(error["loc"][0]) if error["loc"] else ""
            source = set_by[first].source if first in set_by else everyone
            lines.append(format_error(source, error))
        raise ConfigError("\n".join(dict.fromkeys(lines))) from None  # a short list: once
    # pydantic reads "inf" and "1e400" as floats; no parameter of ours may be infinite
    infinite = [format_error(set_by[str(loc[0])].source if str(loc[0]) in set_by else "code",
                             {"type": "finite_number", "loc": loc, "msg": FINITE,
                              "input": value})
                for loc, value in _non_finite_leaves(params.model_dump(), ())]
    if infinite:
        raise ConfigError("\n".join(infinite))
    dumped = params.model_dump(mode="json")
    settings = [
        Setting(name, dumped[name], set_by[name].origin if name in set_by else "default",
                set_by[name].source if name in set_by else "code", info.description)
        for name, info in model.model_fields.items()
    ]
    return params, settings


def show_settings(title: str, settings: list[Setting], width: int = 88) -> str:
    """The settings as YAML a service reads back: each description as comments, each
    value with its origin (and the file or scenario it came from) after it."""
    lines = [f"# {title}"]
    for setting in settings:
        if setting.description:
            lines += [f"# {line}" for line in textwrap.wrap(setting.description, width)]
        value = yaml.safe_dump(setting.value, default_flow_style=True).strip()
        value = value.removesuffix("...").strip()
        where = setting.origin if setting.origin in ("default", "--set") else (
            setting.source if setting.origin == "profile" else
            f"{setting.origin} {setting.source.removeprefix('scenario ')}")
        lines.append(f"{setting.name}: {value}  # {where}")
    return "\n".join(lines)


def load_params(model: type[P], files: list[Path], assignments: list[str]) -> P:
    """Build ``model`` from its defaults, then each file in order, then the assignments."""
    layers = [file_layer(path) for path in files]
    layers += [assignment_layer(text) for text in assignments]
    return resolve(model, layers)[0]


def loopback_port(service: str, base_port: int = DEFAULT_BASE_PORT) -> int:
    return base_port + SERVICE_ORDER.index(service)


def tool_port(base_port: int = DEFAULT_BASE_PORT) -> int:
    """The loopback mesh's port for a tool, after the services' own: every service
    connects to it, and the first tool to come listens on it."""
    return base_port + len(SERVICE_ORDER)


def loopback_mesh(
    service: str | None, base_port: int = DEFAULT_BASE_PORT, *, tool_listens: bool = False
) -> TransportConfig:
    """The embedded default: every service a peer on its own loopback port, connected to
    all the others and to the tool port after them (``base_port + 6``).

    ``service=None`` is a tool (zenav run, a monitor): it connects to every service. The
    tool that drives a run, and any tool that finds the tool port free, also listens on
    it (``tool_listens``), so the links to it are made from both ends and come up as
    soon as either side starts.
    """
    endpoints = {name: f"tcp/127.0.0.1:{loopback_port(name, base_port)}" for name in SERVICE_ORDER}
    tool = f"tcp/127.0.0.1:{tool_port(base_port)}"
    if service is None:
        return TransportConfig(mode="peer", listen=[tool] if tool_listens else [],
                               connect=list(endpoints.values()))
    connect = [ep for name, ep in endpoints.items() if name != service] + [tool]
    return TransportConfig(mode="peer", listen=[endpoints[service]], connect=connect)
