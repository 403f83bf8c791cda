"""The APF baseline as the planner service: ``zenav run --planner apf``,
``zenav service planner --planner apf`` (algorithm and parameters: ``apf.py``)."""

from __future__ import annotations

from zenav.services.baselines.apf import APF, Params
from zenav.services.baselines.node import BaselineService
from zenav.services.node import Node

__all__ = ["Params", "Service"]


class Service(BaselineService):
    def __init__(self, node: Node, params: Params) -> None:
        super().__init__(node, params, APF(params))


if __name__ == "__main__":
    import sys

    from zenav.services.runner import main

    raise SystemExit(main("planner", ["--planner", "apf", *sys.argv[1:]]))
