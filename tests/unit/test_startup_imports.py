"""What a restarted process loads before it is back on the bus: a supervisor restarts
``zenav router`` and ``zenav service NAME`` after a crash, and on a loaded 2-core machine
every module imported is outage time (issue 14: output flowing again within 1 s)."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

from zenav.deploy import router
from zenav.schemas import keys


def loaded_by(code: str) -> set[str]:
    """The modules a fresh interpreter holds after running ``code``."""
    done = subprocess.run([sys.executable, "-c", code + "\nimport json, sys\n"
                           "print(json.dumps(sorted(sys.modules)))"],
                          capture_output=True, text=True, check=True, timeout=120)
    return set(json.loads(done.stdout.splitlines()[-1]))


def test_the_router_starts_without_the_message_schemas_or_numpy() -> None:
    modules = loaded_by("from zenav.cli import build_light_parser\n"
                        "args = build_light_parser('router').parse_args(['router'])\n"
                        "router = args.func.__module__")
    assert "zenav.deploy.router" in modules
    assert not {"numpy", "zenav.schemas.messages", "zenav.schemas.keys",
                "zenav.services.node", "zenav.stackcmd"} & modules


def test_a_service_start_loads_neither_the_router_nor_the_other_tools() -> None:
    modules = loaded_by("from zenav.cli import build_light_parser\n"
                        "build_light_parser('service').parse_known_args(['service', 'planner'])")
    assert "zenav.stackcmd" in modules
    assert not {"zenav.deploy", "zenav.deploy.router", "zenav.tooling", "zenav.run",
                "matplotlib", "scipy"} & modules


def test_the_routers_own_robot_id_check_and_token_are_the_keys_module_s() -> None:
    assert router.ROBOT_ID.pattern == keys._ROBOT_ID.pattern
    for robot_id in ("robot0", "r-2_b"):
        assert router.token_key(robot_id) == keys.Keys(robot_id).alive("router")


def test_zenav_run_loads_neither_the_benchmarks_nor_the_picture_before_it_starts(
        tmp_path: Path) -> None:
    """``zenav run`` builds its own parser only: the other commands (the benchmarks pull in
    scipy and matplotlib) would cost about a second before the first process starts."""
    missing = tmp_path / "missing.yaml"
    modules = loaded_by("from zenav.cli import main\n"
                        f"assert main(['run', {str(missing)!r}, '--out', "
                        f"{str(tmp_path / 'out')!r}]) == 2")
    assert "zenav.run" in modules
    assert not {"zenav.bench", "zenav.bench.cli", "zenav.graph", "zenav.paper",
                "matplotlib", "scipy"} & modules


def _commands(parser: argparse.ArgumentParser) -> set[str]:
    found = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return set(found[0].choices)


def test_the_commands_with_a_parser_of_their_own_are_the_ones_the_full_parser_has() -> None:
    from zenav.cli import LIGHT, build_light_parser, build_parser

    full = _commands(build_parser())
    for command in LIGHT:
        light = _commands(build_light_parser(command))
        assert command in light
        assert light <= full
