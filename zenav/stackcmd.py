"""The commands that run or describe the stack itself: ``zenav run`` (one scenario
through the six processes), ``zenav service`` (one service process) and ``zenav schemas``
(the JSON Schema of every message)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from zenav import argtypes
from zenav.services.config import SERVICE_ORDER
from zenav.services.runner import add_log_level_argument


def _run(args: argparse.Namespace) -> int:
    from zenav.run import RunError, run_scenario
    from zenav.services.config import ConfigError
    from zenav.services.writable import PathError
    from zenav.sim.scenario import ScenarioError

    try:  # the folder is made once the input is known good (zenav.cli checked it could be)
        record = run_scenario(args.scenario, args.out, planner=args.planner,
                              overrides=args.set, log_level=args.log_level,
                              robot_face=args.robot, mcap=args.record,
                              profile=args.profile, engine=args.engine)
    except (ScenarioError, ConfigError, PathError) as exc:
        say_each("zenav run", exc)
        return 2
    except RunError as exc:
        print(f"zenav run: {exc}", file=sys.stderr)
        return 1
    clearance = record["min_clearance"]
    print(f"{record['scenario']}: {record['outcome']} at t={record['time']:.2f} s, "
          f"path {record['path_length']:.2f} m, min clearance "
          f"{'-' if clearance is None else f'{clearance:.3f} m'}, "
          f"{len(record['events'])} events, {record['wall_time']:.1f} s wall -> {args.out}")
    return 0


def say_each(command: str, exc: BaseException) -> None:
    """One line on stderr per problem the exception names (a file with three mistakes is
    three lines: "zenav run: file: field: problem")."""
    for line in str(exc).splitlines() or [type(exc).__name__]:
        print(f"{command}: {line}", file=sys.stderr)


class _ServiceHelp(argparse.Action):
    """``zenav service --help`` is this parser's help; ``zenav service NAME --help`` is
    the service's own (its parameters' options), so it is passed on with the rest."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: Any, option_string: str | None = None) -> None:
        if getattr(namespace, "name", None) is None:
            parser.print_help()
            parser.exit()
        namespace.service_help = True


def _service(args: argparse.Namespace) -> int:
    from zenav.services.runner import main as service_main

    return service_main(args.name, ["--help", *args.rest] if args.service_help else args.rest)


def _schemas(args: argparse.Namespace) -> int:
    from zenav.schemas.messages import ALL_MESSAGES
    from zenav.services.writable import PathError, check_output_dir

    schemas = {m.TYPE: m.model_json_schema(mode="serialization") for m in ALL_MESSAGES}
    if args.out is None:  # no folder given: one JSON document on stdout, nothing written
        print(json.dumps(schemas, indent=2))
        return 0
    try:
        check_output_dir(args.out)
        for name, schema in schemas.items():
            path = args.out / f"{name}.schema.json"
            path.write_text(json.dumps(schema, indent=2) + "\n")
            print(path)
    except PathError as exc:
        print(f"zenav schemas: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"zenav schemas: {args.out}: cannot write ({exc.strerror or exc})",
              file=sys.stderr)
        return 2
    return 0


def add_commands(sub: Any) -> None:
    run = sub.add_parser("run", help="run a scenario through the whole stack")
    run.add_argument("scenario", type=argtypes.path, help="scenario YAML file")
    run.add_argument("--out", type=argtypes.path, required=True,
                     help="directory for run.json, run.png")
    run.add_argument("--planner", default="paper", help="planner service (default paper)")
    run.add_argument("--profile", default="zenav", metavar="NAME",
                     help="parameter profile: zenav (the defaults) or paper (Section 3 as "
                          "written); --set still overrides it")
    run.add_argument("--set", action="append", default=[], metavar="SERVICE.NAME=VALUE",
                     help="override a service parameter, e.g. perception.lambda_=1.5")
    add_log_level_argument(run, "the services' log level")
    run.add_argument("--robot", choices=["native", "ros2"], default="native",
                     help="how the simulated robot talks to the stack: zenav's device keys "
                          "(native, the default) or ROS 2 over rmw_zenoh (/scan, /odom, /cmd_vel)")
    run.add_argument("--record", action="store_true",
                     help="also write DIR/run.mcap: every message of the run, with Foxglove "
                          "channels (opens in Foxglove)")
    run.add_argument("--engine", choices=("stack", "inprocess"), default="stack",
                     help="stack: six processes over Zenoh (default, the acceptance path); "
                          "inprocess: the same services in one process on an in-memory bus")
    run.set_defaults(func=_run)

    service = sub.add_parser("service", help="run one service process", add_help=False,
                             description="Run one service; options after NAME go to it "
                                         "(zenav service NAME --help).")
    service.add_argument("-h", "--help", action=_ServiceHelp, nargs=0,
                         help="this help; after NAME, the service's own options")
    service.add_argument("name", choices=SERVICE_ORDER, help="the service to run")
    # the arguments zenav.cli.main does not know go to the service (args.rest)
    service.set_defaults(func=_service, passes_rest=True, service_help=False)

    schemas = sub.add_parser("schemas", help="write the JSON Schema of every message")
    schemas.add_argument("--out", type=argtypes.path, metavar="DIR",
                         help="write TYPE.schema.json files into DIR (default: print one "
                         "JSON object of every schema, by message type, on stdout)")
    schemas.set_defaults(func=_schemas)
