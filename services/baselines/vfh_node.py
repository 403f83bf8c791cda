"""The VFH baseline as the planner service: ``zenav run --planner vfh``,
``zenav service planner --planner vfh`` (algorithm and parameters: ``vfh.py``)."""

from __future__ import annotations

from zenav.services.baselines.node import BaselineService
from zenav.services.baselines.vfh import VFH, Params
from zenav.services.node import Node

__all__ = ["Params", "Service"]


class Service(BaselineService):
    def __init__(self, node: Node, params: Params) -> None:
        super().__init__(node, params, VFH(params))


if __name__ == "__main__":
    import sys

    from zenav.services.runner import main

    raise SystemExit(main("planner", ["--planner", "vfh", *sys.argv[1:]]))
