"""The DWA baseline as the planner service: ``zenav run --planner dwa``,
``zenav service planner --planner dwa`` (algorithm and parameters: ``dwa.py``)."""

from __future__ import annotations

from zenav.services.baselines.dwa import DWA, Params
from zenav.services.baselines.node import BaselineService
from zenav.services.node import Node

__all__ = ["Params", "Service"]


class Service(BaselineService):
    def __init__(self, node: Node, params: Params) -> None:
        super().__init__(node, params, DWA(params))


if __name__ == "__main__":
    import sys

    from zenav.services.runner import main

    raise SystemExit(main("planner", ["--planner", "dwa", *sys.argv[1:]]))
