"""The planner's rejoin point (``Planner._rejoin_point``, what ``path_target`` asks off
the path beside standing obstacles) measures its legs in the compiled loop of the (b)
test (``_loops.box_gaps``); it finds, to the bit, the point the numpy code it replaced
found (``path_points`` and ``gap_to_boxes`` leg after leg)."""

from __future__ import annotations

import numpy as np
import pytest

from zenav.services.planner.decide import Planner
from zenav.services.planner.global_path import arc_lengths, point_at, project
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import Obstacle, gap_to_boxes, path_points


def numpy_rejoin_point(planner: Planner, point: np.ndarray,
                       statics: list[Obstacle]) -> np.ndarray | None:
    """The rejoin point as numpy array operations (the code ``box_gaps`` replaced)."""
    assert planner.path is not None
    p = planner.p
    length = float(arc_lengths(planner.path)[-1])
    if length < 1e-9:
        return None
    s0 = project(planner.path, point)[0]
    lows, highs = planner._boxes(statics)
    need = p.robot_radius + p.safety_margin
    for s in np.arange(min(s0 + p.window_radius, length), s0 - p.cell, -p.cell / 2):
        on_path = point_at(planner.path, max(float(s), 0.0))
        leg = on_path - point
        leg_length = float(np.hypot(*leg))
        if leg_length > p.window_radius:
            continue
        if leg_length < 1e-9:
            return on_path
        samples = path_points(point, leg / leg_length, leg_length, p.cell / 4)
        gaps = gap_to_boxes(samples, lows, highs)
        if (gaps >= min(need, float(gaps[0]))).all():
            return on_path
    return None


@pytest.mark.parametrize("seed", range(20))
def test_the_rejoin_point_is_the_numpy_one(seed: int) -> None:
    """Random bent paths, standing obstacles (grid boxes) round them and robots off the
    path: the same point, or None, to the bit."""
    rng = np.random.default_rng(seed)
    found = 0
    for _ in range(20):
        planner = Planner(Params.model_validate({"goal": (8.0, 0.0), "start": (0.0, 0.0)}))
        bend = (float(rng.uniform(2.0, 6.0)), float(rng.uniform(-2.0, 2.0)))
        planner._set_path(np.array([[0.0, 0.0], bend, [8.0, 0.0]]), "test")
        statics = []
        for k in range(int(rng.integers(0, 6))):
            ix, iy = int(rng.integers(0, 16)), int(rng.integers(-5, 6))
            w, h = int(rng.integers(0, 3)), int(rng.integers(0, 3))
            statics.append(Obstacle(k, "static", (ix * 0.5, iy * 0.5), (0.0, 0.0), 0.3,
                                    (ix, ix + w, iy, iy + h)))
        point = np.array([rng.uniform(0.0, 8.0), rng.uniform(-3.0, 3.0)])
        got = planner._rejoin_point(point, statics)
        want = numpy_rejoin_point(planner, point, statics)
        assert (got is None) == (want is None)
        if got is not None and want is not None:
            assert got.tobytes() == want.tobytes()
            found += 1
    assert found > 0
