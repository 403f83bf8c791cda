"""The ``zenav`` command."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from zenav.services.config import SERVICE_ORDER


def _cmd_run(args: argparse.Namespace) -> int:
    from zenav.run import RunError, run_scenario
    from zenav.services.config import ConfigError
    from zenav.sim.scenario import ScenarioError

    try:
        record = run_scenario(args.scenario, args.out, planner=args.planner,
                              overrides=args.set, log_level=args.log_level)
    except (ScenarioError, ConfigError) as exc:
        # one line, every problem in it: "file: field: problem; file: field: problem"
        print(f"zenav run: {'; '.join(str(exc).splitlines())}", file=sys.stderr)
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


def _cmd_service(args: argparse.Namespace, rest: list[str]) -> int:
    from zenav.services.runner import main as service_main

    return service_main(args.name, rest)


def _cmd_schemas(args: argparse.Namespace) -> int:
    from zenav.schemas.messages import ALL_MESSAGES

    args.out.mkdir(parents=True, exist_ok=True)
    for message in ALL_MESSAGES:
        schema = message.model_json_schema(mode="serialization")
        path = args.out / f"{message.TYPE}.schema.json"
        path.write_text(json.dumps(schema, indent=2) + "\n")
        print(path)
    return 0


def _cmd_paper(args: argparse.Namespace) -> int:
    from zenav.paper import main as paper_main
    from zenav.run import RunError

    try:
        report = paper_main(args.out, quick=args.quick, parallel=args.parallel)
    except RunError as exc:
        print(f"zenav paper: {exc}", file=sys.stderr)
        return 1
    print(f"report: {report}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="zenav", description="Mobile-robot navigation as Zenoh services."
    )
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a scenario through the whole stack")
    run.add_argument("scenario", type=Path, help="scenario YAML file")
    run.add_argument("--out", type=Path, required=True, help="directory for run.json, run.png")
    run.add_argument("--planner", default="paper", help="planner service (default paper)")
    run.add_argument("--set", action="append", default=[], metavar="SERVICE.NAME=VALUE",
                     help="override a service parameter, e.g. perception.lambda_=1.5")
    run.add_argument("--log-level", default="INFO", help="services' log level")

    service = sub.add_parser("service", help="run one service process",
                             description="Run one service; options after NAME go to it "
                                         "(zenav service NAME --help).")
    service.add_argument("name", choices=SERVICE_ORDER)

    from zenav.paramscmd import add_command as add_params_command

    add_params_command(sub)

    schemas = sub.add_parser("schemas", help="write the JSON Schema of every message")
    schemas.add_argument("--out", type=Path, default=Path("schemas/json"))

    paper = sub.add_parser("paper", help="reproduce the paper's experiments as a report")
    paper.add_argument("--out", type=Path, default=Path("out/paper"), help="report directory")
    paper.add_argument("--quick", action="store_true",
                       help="scenario (a) once only (a smoke test of the report)")
    paper.add_argument("--parallel", type=int, default=2, help="runs at once (default 2)")
    paper.set_defaults(func=_cmd_paper)

    from zenav.opscli import add_commands  # deployment and tool commands (each sets func)

    add_commands(sub)
    from zenav.bench import add_commands as add_bench_commands  # zenav bench perf|nav

    add_bench_commands(sub)
    from zenav.soak import add_command as add_soak_command  # zenav soak

    add_soak_command(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser()
    if argv[:1] == ["service"]:
        args, rest = parser.parse_known_args(argv)
        return _cmd_service(args, rest)
    args = parser.parse_args(argv)
    if hasattr(args, "func"):
        return int(args.func(args))
    if args.command == "run":
        return _cmd_run(args)
    return _cmd_schemas(args)
