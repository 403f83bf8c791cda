"""``zenav params NAME [--scenario FILE] [--params FILE] [--set NAME=VALUE ...]``.

Every parameter of a service with its value and where the value came from: ``default``
(the code), ``scenario`` (what the scenario sets, as ``zenav run`` would), ``file`` or
``--set``. The layering is :func:`zenav.services.config.resolve`; this is the argparse.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from zenav.services.config import SERVICE_ORDER


def add_command(sub: Any) -> None:
    params = sub.add_parser(
        "params", help="print a service's parameters, their values and where they came from",
        description="Print every parameter of a service as YAML, each value followed by its "
                    "origin: default, profile, scenario, file or --set.")
    params.add_argument("name", help=f"service: {', '.join(SERVICE_ORDER)}")
    params.add_argument("--planner",
                        help="planner implementation, for NAME planner only (default paper)")
    params.add_argument("--profile", default="zenav", metavar="NAME",
                        help="parameter profile laid over the defaults: zenav or paper")
    params.add_argument("--scenario", type=Path, metavar="FILE",
                        help="the values zenav run derives from this scenario")
    params.add_argument("--params", type=Path, action="append", default=[], metavar="FILE",
                        help="YAML parameter file, as the service's --config (repeatable)")
    params.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override one parameter (dotted names for nested ones)")
    params.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from zenav.services.config import (
        ConfigError,
        Layer,
        assignment_layer,
        file_layer,
        resolve,
        show_settings,
    )
    from zenav.services.mission import scenario_layer
    from zenav.services.profiles import profile_layer
    from zenav.services.runner import check_params, service_params
    from zenav.sim.scenario import ScenarioError, load_scenario
    from zenav.stackcmd import say_each

    try:
        if args.planner is not None and args.name != "planner":
            raise ConfigError(f"--planner {args.planner}: only the planner service has "
                              f"implementations to choose from, not {args.name}")
        planner = args.planner or "paper"
        model = service_params(args.name, planner)
        layers: list[Layer] = [profile_layer(args.profile, args.name, planner)]
        if args.scenario is not None:
            scenario = load_scenario(args.scenario)
            layers.append(scenario_layer(scenario, args.scenario, args.name, planner))
        layers += [file_layer(path) for path in args.params]
        layers += [assignment_layer(text) for text in args.set]
        values, settings = resolve(model, layers)
        # What the service would refuse at start; a simulator not yet given its scenario
        # is shown as it is (its scenario: null), not refused.
        if getattr(values, "scenario", "") is not None:
            check_params(args.name, values, planner)
    except (ConfigError, ScenarioError, ValueError) as exc:
        say_each("zenav params", exc)  # one line per problem
        return 2
    title = f"{args.name}: every parameter, its value and its origin (zenav params {args.name})"
    print(show_settings(title, settings))
    return 0
