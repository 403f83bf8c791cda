"""The ``zenav`` command: registration only. Each command lives in its own module, whose
``add_command(sub)`` (or ``add_commands(sub)``) adds its parser and sets ``func``, the
function ``main`` calls with the parsed arguments."""

from __future__ import annotations

import argparse
import logging
import os
import sys

LIGHT = ("service", "router", "run", "schemas")
"""Commands whose parser is built alone, without importing every other command (the
benchmarks pull in scipy and matplotlib: about 1 s of a 2-core machine). A supervisor
restarts ``service`` and ``router`` after a crash, and a restarted service's start-up time
is the robot's outage (15-25 s against 4.5 s on a loaded 2-core machine); ``run`` (with
``schemas``, its neighbour in :mod:`zenav.stackcmd`) is the command people and the
benchmarks repeat, and that second was a fifth of a whole run."""


def _top_parser() -> argparse.ArgumentParser:
    from importlib.metadata import version

    from zenav.services.inputs import OneLineParser

    parser = OneLineParser(prog="zenav", description="Mobile-robot navigation as Zenoh services.")
    parser.add_argument("--version", action="version", version=f"zenav {version('zenav')}")
    return parser


def _describe(parser: argparse.ArgumentParser) -> None:
    """Give every subcommand without a description its one-line help as one, so that
    ``zenav CMD --help`` says what CMD is for (recursively: ``zenav bench nav``)."""
    for action in parser._actions:
        if not isinstance(action, argparse._SubParsersAction):
            continue
        helps = {choice.dest: choice.help for choice in action._choices_actions}
        for name, child in action.choices.items():
            if child.description is None and helps.get(name):
                child.description = helps[name]
            _describe(child)


def build_light_parser(command: str) -> argparse.ArgumentParser:
    """The parser of one of the :data:`LIGHT` commands only."""
    parser = _top_parser()
    sub = parser.add_subparsers(dest="command", required=True)
    if command == "router":
        from zenav.deploy import router

        router.add_command(sub)
    else:
        from zenav import stackcmd

        stackcmd.add_commands(sub)  # run, service, schemas
    _describe(parser)
    return parser


def build_parser() -> argparse.ArgumentParser:
    from zenav import graph, paper, paramscmd, rviz, stackcmd
    from zenav.bag import record, replay
    from zenav.bench import cli as bench
    from zenav.deploy import commands as deploy
    from zenav.deploy import router
    from zenav.foxglove import live as foxglove_live
    from zenav.monitor import command as monitor

    parser = _top_parser()
    sub = parser.add_subparsers(dest="command", required=True)
    stackcmd.add_commands(sub)  # run, service, schemas

    paramscmd.add_command(sub)
    paper.add_command(sub)
    deploy.add_commands(sub)  # up, down, ctl
    router.add_command(sub)
    monitor.add_command(sub)
    record.add_command(sub)
    replay.add_command(sub)
    graph.add_command(sub)
    rviz.add_command(sub)
    foxglove_live.add_command(sub)
    bench.add_commands(sub)  # bench perf|nav|accuracy, soak
    _describe(parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    """The command's exit status; SIGINT at any point (even while the modules load) ends it
    quietly with 130, as a shell expects."""
    try:
        code = _main(argv)
    except KeyboardInterrupt:
        code = 130
    # Stopped while connecting, the interpreter's teardown stalls for seconds in Zenoh's;
    # after a service's clean stop it has nothing left to do but free memory.
    if _nothing_left_but_teardown():
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code


def _nothing_left_but_teardown() -> bool:
    """Whether a session is still being opened by a thread no one waits for, or this
    process's service closed everything cleanly: then ``os._exit`` ends it. Only modules
    the command loaded are asked (importing one now would be time for a Ctrl-C to land
    in, outside any handler)."""
    runner = sys.modules.get("zenav.services.runner")
    tooling = sys.modules.get("zenav.tooling")
    return bool((tooling is not None and tooling.still_opening())
                or (runner is not None and (runner.still_opening() or runner.closed_cleanly())))


def _main(argv: list[str] | None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = build_light_parser(argv[0]) if argv[:1] and argv[0] in LIGHT else build_parser()
    args, rest = parser.parse_known_args(argv)
    if rest and not getattr(args, "passes_rest", False):  # only `zenav service` passes them on
        _chosen(parser, args).error(f"unrecognized arguments: {' '.join(rest)}")
    args.rest = rest
    if (problem := _out_problem(args)) is not None:
        print(f"{_chosen(parser, args).prog}: {problem}", file=sys.stderr)
        return 2
    return int(args.func(args))


def _chosen(parser: argparse.ArgumentParser,
            args: argparse.Namespace) -> argparse.ArgumentParser:
    """The (sub)command parser ``args`` came through, the deepest one: its errors carry
    the command's own name (``zenav bench crowd: ...``), as argparse's own do."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            child = action.choices.get(getattr(args, action.dest, None) or "")
            if child is not None:
                return _chosen(child, args)
    return parser


def _out_problem(args: argparse.Namespace) -> str | None:
    """Every command's ``--out`` folder is checked before it starts work: a bad one (an
    existing file, a folder under a file, /proc or /sys) is one line, not a traceback.
    Nothing is created here: each command makes its folder once the rest of its input
    is known good (a refused scenario leaves no empty folder behind)."""
    from pathlib import Path

    from zenav.services.writable import PathError, check_output_dir

    out = getattr(args, "out", None)
    if not isinstance(out, Path):
        return None
    try:
        check_output_dir(out, create=False)
    except PathError as exc:
        return str(exc)
    return None
