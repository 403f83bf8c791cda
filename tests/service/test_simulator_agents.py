"""The simulator service with an ORCA agent, on the in-memory bus: ground truth carries the
agent as it walks, and the run result its path at the trajectory's ticks."""

from __future__ import annotations

import asyncio

import numpy as np

from tests.service.harness import running
from zenav.schemas import keys
from zenav.schemas.messages import GroundTruth, RunResult
from zenav.sim.params import Params

SCENARIO = """\
name: one-walker
world: {size: [10.0, 10.0], cell: 0.5}
robot: {start: [5.0, 5.0], goal: [9.0, 9.0], speed: 1.0, radius: 0.3}
obstacles:
  - {shape: box, center: [8.0, 2.0], size: [0.5, 0.5]}
  - {shape: disc, behavior: orca, center: [1.0, 5.1], radius: 0.3, goals: [[9.0, 5.0]],
     preferred_speed: 1.0}
duration: 10
"""


async def test_truth_and_result_carry_the_agent(tmp_path):
    path = tmp_path / "walker.yaml"
    path.write_text(SCENARIO)
    params = Params(scenario=path, clock="realtime", realtime_factor=50.0, wait_for=[])
    async with running("simulator", params) as h:
        for _ in range(400):  # at most 4 s wall: the run lasts 3.4 simulated s
            await asyncio.sleep(0.01)
            if h.received(keys.RESULT, RunResult):
                break
        results = h.received(keys.RESULT, RunResult)
        truths = h.received(keys.TRUTH, GroundTruth)
    assert results, "no run result within 4 s"
    result = results[0]
    assert result.outcome == "collision" and result.collided_with == 1  # it walks into us
    (path_1,) = result.agents
    assert path_1.index == 1
    assert np.array_equal(path_1.rows[:, 0], result.trajectory[:, 0])
    walker = [next(o for o in t.obstacles if o.index == 1) for t in truths]
    assert walker[0].x == 1.0 and walker[-1].x > 4.0  # it moved, and truth followed it
    assert all(o.shape == "disc" and o.size == (0.6, 0.6) for o in walker)
    assert max(o.vx for o in walker) > 0.9
