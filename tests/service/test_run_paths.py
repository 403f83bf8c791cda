"""What ``zenav run`` keeps of the planner's global paths: each distinct path once, in
order, however many times the planner sends an unchanged one again (every
``path_period``), in both engines; the record's ``path`` is the last of them."""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from zenav.run import Heard, _take_paths_and_map, run_scenario
from zenav.schemas import keys
from zenav.schemas.codec import encode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import GlobalPath
from zenav.services.planner.params import Params
from zenav.services.transport import InMemoryBus
from zenav.sim import SCENARIO_DIR


def path(stamp: float, seq: int, planned: float, reason: str,
         points: list[list[float]]) -> GlobalPath:
    return GlobalPath(stamp=stamp, seq=seq, points=np.array(points, dtype=np.float64).reshape(
        -1, 2), reason=reason, planned=planned)


async def test_the_stack_collector_keeps_each_distinct_path_once():
    """The planner's sends as the stack's collector hears them: a path and its repeats, a
    new path and its repeats, no way and its repeat."""
    k = Keys("r1")
    bus = InMemoryBus(keep_published=False)
    paths = bus.subscribe(k.of(keys.PATH), depth=100)
    maps = bus.latest(k.of(keys.MAP))
    start = [[2.0, 3.0], [8.0, 3.0]]
    detour = [[3.0, 3.0], [5.0, 4.5], [8.0, 3.0]]
    sent = [path(0.0, 0, 0.0, "start", start), path(1.0, 1, 0.0, "start", start),
            path(2.0, 2, 0.0, "start", start), path(2.4, 3, 2.4, "off the path", detour),
            path(3.4, 4, 2.4, "off the path", detour),
            path(3.9, 5, 3.9, "no way to the goal", []),
            path(4.9, 6, 3.9, "no way to the goal", []),
            # the same vertices and reason planned anew: a distinct path
            path(5.5, 7, 5.5, "off the path", detour)]
    heard = Heard()
    for i, message in enumerate(sent):
        bus.deliver(k.of(keys.PATH), encode(message))
        if i % 3 == 2:  # looked at between arrivals, as the collector's loop does
            await _take_paths_and_map(k, paths, maps, heard)
    await _take_paths_and_map(k, paths, maps, heard)
    assert [(p.seq, p.planned) for p in heard.paths] == [(0, 0.0), (3, 2.4), (5, 3.9), (7, 5.5)]
    assert heard.path is not None and heard.path.seq == 7


def test_a_run_keeps_each_path_once_however_long_it_lasts(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch):
    """A minute of simulated time (in-process engine) sends the unchanged path some sixty
    times; the picture gets each distinct path once and run.json holds the last one."""
    drawn: dict[str, Any] = {}

    def plot_run(scenario: Any, record: Any, out: Path, occupancy: Any = None,
                 paths: Any = ()) -> None:
        drawn["paths"] = list(paths)

    monkeypatch.setattr("zenav.plot.plot_run", plot_run)
    record = run_scenario(SCENARIO_DIR / "b-static-obstacle.yaml", tmp_path,
                          engine="inprocess")
    paths: list[GlobalPath] = drawn["paths"]
    period = Params().path_period
    assert record["time"] > 30 * period  # the premise: many repeats were sent
    assert 1 <= len(paths) <= 5, [(p.stamp, p.reason) for p in paths]
    assert not any(b.repeats(a) for a, b in itertools.pairwise(paths))
    planned = [p.planned_at for p in paths]
    assert planned == sorted(set(planned))
    assert all(p.stamp == p.planned_at for p in paths)  # each as first sent
    written = json.loads((tmp_path / "run.json").read_text())
    assert written["path"] == [[round(float(x), 4), round(float(y), 4)]
                               for x, y in paths[-1].points]
    assert written == record
