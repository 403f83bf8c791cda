"""``zenav up``, ``zenav down`` and ``zenav ctl`` (see :mod:`zenav.deploy`)."""

from __future__ import annotations

import argparse
import contextlib
import os
import subprocess
import sys
import time
import xmlrpc.client
from pathlib import Path
from typing import Any

from zenav.argtypes import positive_float
from zenav.deploy.conf import default_run_dir, prepare, socket_path, standby_twins
from zenav.deploy.model import DEFAULT_CONFIG, Deployment, load_deployment
from zenav.deploy.rpc import Supervisor, unclean_stops
from zenav.deploy.wait import check_started, expected_alive, wait_alive, wait_running
from zenav.services.config import ConfigError
from zenav.services.writable import PathError, check_output_dir

DEFAULT_NAME = "stack"
"""The name of the default deployment (deploy/stack.yaml): ``zenav ctl`` and ``zenav down``
without ``--config`` or ``--run-dir`` look in its run directory even where that file is not
(outside the repository, with an installed wheel)."""


def _resolve(args: argparse.Namespace) -> tuple[Deployment | None, Path]:
    deployment = None
    if args.command != "up" and args.run_dir is None and args.config is None \
            and not DEFAULT_CONFIG.exists():
        return None, default_run_dir(DEFAULT_NAME).resolve()
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


def _resolve_or_say(args: argparse.Namespace) -> tuple[Deployment | None, Path] | None:
    """:func:`_resolve`, or None after printing why not (the command then exits with 2)."""
    try:
        return _resolve(args)
    except ConfigError as exc:
        _say_each(f"zenav {args.command}", exc)
        return None


def _say_each(command: str, exc: ConfigError) -> None:
    """One line on stderr per problem (a ConfigError holds one per line)."""
    for line in str(exc).splitlines():
        print(f"{command}: {line}", file=sys.stderr)


def cmd_up(args: argparse.Namespace) -> int:
    try:
        deployment, run_dir = _resolve(args)
        assert deployment is not None
        try:  # before anything starts, --print too: one line, not a traceback
            check_output_dir(run_dir)
        except PathError as exc:
            raise ConfigError(f"--run-dir {exc}") from None
        sup = Supervisor(run_dir)
        if (pid := sup.pid()) is not None:
            raise ConfigError(f"{deployment.name} is already up (supervisord pid {pid}, "
                              f"{run_dir}); zenav down first")
        try:
            conf = prepare(deployment, run_dir)
        except OSError as exc:
            raise ConfigError(f"--run-dir {run_dir}: cannot write "
                              f"{exc.filename or 'in it'} ({exc.strerror or exc})") from None
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
        programs += standby_twins(deployment).values()
        missing: set[str] = set()
        try:
            wait_running(sup, programs, args.timeout)
            if not args.no_wait:
                missing = wait_alive(deployment, expected_alive(deployment), args.timeout,
                                     check=lambda: check_started(sup, programs))
                if missing:
                    check_started(sup, programs)
        except ConfigError as exc:
            # A program that cannot start (a port in use, a bad device): the others would
            # run without it, and its clients join whatever bus they reach, another
            # stack's included. What this command started is stopped again.
            left = "" if _stop_supervisor(sup) is None else (
                "; supervisord did not stop: `zenav down` stops it")
            raise ConfigError(f"{exc}; stopped what it had started{left}") from None
        if missing:
            raise ConfigError(f"running, but still waiting on {', '.join(sorted(missing))} "
                                  f"on the bus after {args.timeout:.0f} s without another "
                                  f"arriving (is the router at "
                                  f"{', '.join(deployment.transport.connect)} reachable?). "
                                  "Left running: they join when it is; `zenav down` stops "
                                  "them")
    except ConfigError as exc:
        _say_each("zenav up", exc)
        return 2
    except KeyboardInterrupt:
        print("zenav up: interrupted; what started is left running (`zenav down` stops it)",
              file=sys.stderr)
        return 130
    where = "" if args.run_dir is None and args.config is None else (
        f" --run-dir {run_dir}" if args.run_dir else f" --config {args.config}")
    print(f"zenav up: {deployment.name}: {', '.join(programs)} running"
          f"{'' if args.no_wait else ' and alive on the bus'}; logs in {run_dir / 'logs'}; "
          f"stop with `zenav down{where}`")
    return 0


def cmd_down(args: argparse.Namespace) -> int:
    if (resolved := _resolve_or_say(args)) is None:
        return 2
    deployment, run_dir = resolved
    name = deployment.name if deployment else run_dir.name
    sup = Supervisor(run_dir)
    pid = sup.pid()
    if pid is None:
        print(f"zenav down: {name} is not up ({run_dir})")
        return 0
    log = run_dir / "logs" / "supervisord.log"
    offset = log.stat().st_size if log.exists() else 0
    problem = _stop_supervisor(sup, say="zenav down")
    if problem is not None:
        print(f"zenav down: {problem}", file=sys.stderr)
        return 1
    unclean = unclean_stops(log, offset)
    if unclean:
        print(f"zenav down: {name} stopped; unclean: {', '.join(unclean)}", file=sys.stderr)
        return 1
    print(f"zenav down: {name} stopped cleanly")
    return 0


def _stop_supervisor(sup: Supervisor, say: str | None = None, timeout: float = 30.0
                     ) -> str | None:
    """Stop every program of ``sup`` in order, then supervisord itself (SIGTERM when it
    does not answer, said on stderr after ``say``); None once it is gone, else the problem
    (still running after ``timeout`` s)."""
    pid = sup.pid()
    if pid is None:
        return None
    try:
        sup.stop_in_order()
        sup.proxy().supervisor.shutdown()
    except (OSError, xmlrpc.client.Fault) as exc:
        if say is not None:
            print(f"{say}: supervisord did not answer ({exc}); sending SIGTERM",
                  file=sys.stderr)
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, 15)
    deadline = time.monotonic() + timeout
    while sup.pid() is not None and time.monotonic() < deadline:
        time.sleep(0.05)
    if sup.pid() is not None:
        return f"supervisord (pid {pid}) still running after {timeout:g} s"
    return None


OWN_OPTIONS = ("--run-dir", "--config")
"""``zenav ctl``'s own options, taken from anywhere on its command line: argparse hands
everything after the first supervisorctl word (``status --run-dir X``) to supervisorctl."""


def split_ctl_args(words: list[str]) -> tuple[dict[str, Path], list[str]] | str:
    """(``zenav ctl``'s own options found among ``words``, the words for supervisorctl), or
    the one-line problem (an option without its value)."""
    own: dict[str, Path] = {}
    rest: list[str] = []
    items = iter(words)
    for word in items:
        name, equals, value = word.partition("=")
        if name not in OWN_OPTIONS:
            rest.append(word)
            continue
        if not equals:
            value = next(items, "")
        if not value or value.startswith("--"):
            return f"{name}: expected a path after it"
        own[name] = Path(value)
    return own, rest


def cmd_ctl(args: argparse.Namespace) -> int:
    split = split_ctl_args(list(args.args))
    if isinstance(split, str):
        print(f"zenav ctl: {split}", file=sys.stderr)
        return 2
    own, args.args = split
    args.run_dir = own.get("--run-dir", args.run_dir)
    args.config = own.get("--config", args.config)
    if (resolved := _resolve_or_say(args)) is None:
        return 2
    deployment, run_dir = resolved
    sup = Supervisor(run_dir)
    if sup.pid() is None:
        name = deployment.name if deployment else run_dir.name
        print(f"zenav ctl: {name} is not up ({run_dir}); start it with `zenav up`",
              file=sys.stderr)
        return 1
    if not sup.ready():  # supervisorctl would print its own socket error
        print(f"zenav ctl: supervisord (pid {sup.pid()}) is not answering on "
              f"{socket_path(run_dir)}; see {run_dir / 'logs' / 'supervisord.log'}",
              file=sys.stderr)
        return 1
    return sup.ctl(list(args.args) or ["status"])


def _add_common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", type=Path,
                        help=f"deployment file (default {DEFAULT_CONFIG})")
    parser.add_argument("--run-dir", type=Path,
                        help="run directory (default ~/.local/state/zenav/NAME)")


def add_commands(sub: Any) -> None:
    up = sub.add_parser(
        "up", help="start a deployment under supervisord (real time)",
        description="Start the deployment's programs under supervisord and wait until each "
        "is running and alive on the bus.")
    _add_common(up)
    up.add_argument("--connect", action="append", default=[], metavar="ENDPOINT",
                    help="the router the services join (replaces the file's endpoints)")
    up.add_argument("--set", action="append", default=[], metavar="PROGRAM.NAME=VALUE",
                    help="override a parameter of one program")
    up.add_argument("--scenario", type=Path,
                    help="the simulator's scenario (replaces the deployment's; the "
                    "parameters that follow from it are derived from this one)")
    up.add_argument("--timeout", type=positive_float, default=30.0,
                    help="s to wait for the next program to run and to join the bus; "
                    "starts again at each one (default 30)")
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


