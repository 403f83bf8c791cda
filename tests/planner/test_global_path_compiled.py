"""The global path's line tests in compiled code (``visible`` over ``_loops.line_any``,
``_cost_along`` over ``_loops.max_along``) give, to the bit, what the numpy sampling they
replaced gives: on random grids, for segments inside the grid, leaving it, starting
outside it, and of zero length; and the shortcut, which asks them hundreds of times a
plan, keeps the same vertices."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from zenav.services.planner import global_path
from zenav.services.planner.costmap import Costmap
from zenav.services.planner.global_path import _cost_along, shortcut, visible

Vec = np.ndarray


def numpy_points(costmap: Costmap, a: Vec, b: Vec) -> np.ndarray:
    """The cells of the quarter-cell samples of a-b (the numpy code both replaced)."""
    count = max(2, math.ceil(float(np.hypot(*(b - a))) / (costmap.resolution / 4)) + 1)
    t = np.linspace(0.0, 1.0, count)[:, None]
    return costmap.cell_of(a[None, :] + t * (b - a)[None, :])


def numpy_visible(free: np.ndarray, costmap: Costmap, a: Vec, b: Vec) -> bool:
    cells = numpy_points(costmap, a, b)
    ok = costmap.inside(cells)
    return bool(ok.all() and free[cells[:, 0], cells[:, 1]].all())


def numpy_cost_along(cost: np.ndarray, costmap: Costmap, points: Vec) -> float:
    worst = 0.0
    for a, b in itertools.pairwise(points):
        cells = numpy_points(costmap, a, b)
        ok = costmap.inside(cells)
        if ok.any():
            worst = max(worst, float(cost[cells[ok, 0], cells[ok, 1]].max()))
    return worst


def random_map(rng: np.random.Generator) -> tuple[Costmap, np.ndarray, np.ndarray]:
    costmap = Costmap((0.0, 0.0), (float(rng.uniform(3, 8)), float(rng.uniform(-4, 4))),
                      resolution=float(rng.choice([0.05, 0.1, 0.25])), decay=60.0,
                      inflation=0.3, padding=2.0, max_size=40.0)
    nx, ny = costmap.shape
    free = rng.random((nx, ny)) > rng.uniform(0.0, 0.2)
    cost = np.where(rng.random((nx, ny)) < 0.3, rng.uniform(0.0, 2.0, (nx, ny)), 0.0)
    return costmap, free, cost


def segment_ends(costmap: Costmap, rng: np.random.Generator) -> tuple[Vec, Vec]:
    """Two points mostly on the grid, some beyond it, some on cell edges exactly."""
    nx, ny = costmap.shape
    lo = costmap.origin - 1.0
    hi = costmap.origin + np.array([nx, ny]) * costmap.resolution + 1.0
    a, b = rng.uniform(lo, hi), rng.uniform(lo, hi)
    if rng.random() < 0.2:  # on cell edges
        a = costmap.origin + rng.integers(0, min(nx, ny), 2) * costmap.resolution
    if rng.random() < 0.05:
        b = a.copy()
    return a, b


@pytest.mark.parametrize("seed", range(12))
def test_visible_and_the_cost_along_a_line_are_the_numpy_samplings(seed: int) -> None:
    rng = np.random.default_rng(seed)
    costmap, free, cost = random_map(rng)
    seen = {True: 0, False: 0}
    for _ in range(200):
        a, b = segment_ends(costmap, rng)
        expected = numpy_visible(free, costmap, a, b)
        assert visible(free, costmap, a, b) == expected
        seen[expected] += 1
        points = np.vstack([a, b] + [segment_ends(costmap, rng)[0]
                                     for _ in range(int(rng.integers(0, 4)))])
        assert _cost_along(cost, costmap, points) == numpy_cost_along(cost, costmap, points)
    assert seen[True] and seen[False]  # both answers were exercised


@pytest.mark.parametrize("seed", range(4))
def test_the_shortcut_keeps_the_vertices_of_the_numpy_tests(
        seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """A grid path of cell centres round random walls, shortcut with the compiled tests
    and again with the numpy ones put in their place."""
    rng = np.random.default_rng(100 + seed)
    costmap, free, cost = random_map(rng)
    free[:] = True
    nx, ny = costmap.shape
    for _ in range(6):  # a few walls
        i, j = int(rng.integers(0, nx)), int(rng.integers(0, ny))
        free[i:i + int(rng.integers(1, 8)), j:j + 2] = False
    walk = [(int(rng.integers(0, nx)), int(rng.integers(0, ny)))]
    while len(walk) < 60:
        i, j = walk[-1]
        step = (i + int(rng.integers(-1, 2)), j + int(rng.integers(-1, 2)))
        if 0 <= step[0] < nx and 0 <= step[1] < ny and free[step]:
            walk.append(step)
    points = costmap.centre_of(np.array(walk))

    compiled = shortcut(free, costmap, points, cost)
    monkeypatch.setattr(global_path, "visible", numpy_visible)
    monkeypatch.setattr(global_path, "_cost_along", numpy_cost_along)
    expected = shortcut(free, costmap, points, cost)
    assert len(expected) < len(points)  # it did cut something
    np.testing.assert_array_equal(compiled, expected)


def numpy_straight_ahead(points: Vec, p: Vec, direction: Vec) -> float:
    """How far the path runs on straight from ``p``, as the numpy loop ``straight_ahead``
    replaced computed it, vertex by vertex."""
    lengths = global_path.arc_lengths(points)
    s0 = global_path.project(points, p, lengths)[0]
    end = 0.0
    for vertex in points[int(np.searchsorted(lengths, s0 + 1e-6, side="right")):]:
        leg = vertex - p
        d = float(np.hypot(*leg))
        if d > 1e-9 and float(leg @ direction) / d < 0.999:
            break
        end = d
    return end


def test_straight_ahead_stops_at_the_bend() -> None:
    """An L: along its first leg the way runs straight to the corner; past the corner,
    to the end; heading off the leg, not at all."""
    path = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 3.0]])
    lengths = global_path.arc_lengths(path)
    east, north = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    assert global_path.straight_ahead(path, np.array([1.0, 0.0]), east, lengths) == 3.0
    assert global_path.straight_ahead(path, np.array([4.0, 1.0]), north, lengths) == 2.0
    assert global_path.straight_ahead(path, np.array([1.0, 0.0]), north, lengths) == 0.0


@pytest.mark.parametrize("seed", range(8))
def test_straight_ahead_is_the_numpy_loop(seed: int) -> None:
    rng = np.random.default_rng(300 + seed)
    seen = set()
    for _ in range(300):
        # paths that run nearly straight for a while, then bend
        turns = rng.choice([0.0, 0.0005, 0.01, 0.5], size=int(rng.integers(1, 7)))
        angles = np.cumsum(turns * rng.choice([-1.0, 1.0], size=turns.size))
        legs = rng.uniform(0.2, 2.0, turns.size)[:, None] * np.column_stack(
            [np.cos(angles), np.sin(angles)])
        path = np.vstack([[0.0, 0.0], np.cumsum(legs, axis=0)])
        p = path[0] + rng.normal(0.0, 0.05, 2) + rng.uniform(0.0, 1.0) * (path[1] - path[0])
        direction = path[-1] - p if rng.random() < 0.5 else path[1] - p
        direction = direction / np.hypot(*direction)
        got = global_path.straight_ahead(path, p, direction, global_path.arc_lengths(path))
        want = numpy_straight_ahead(path, p, direction)
        assert got == want
        seen.add(want == 0.0)
    assert seen == {True, False}


def numpy_first_blocked(costmap: Costmap, points: Vec, from_s: float, step: float
                        ) -> float | None:
    """``first_blocked`` as numpy operations (the code the compiled walk replaced)."""
    lengths = global_path.arc_lengths(points)
    total = float(lengths[-1])
    if from_s >= total:
        return None
    s = np.arange(from_s, total + step / 2, step)
    samples = np.column_stack([np.interp(s, lengths, points[:, 0]),
                               np.interp(s, lengths, points[:, 1])])
    hit = costmap.blocked_at(samples, outside=True)
    return float(s[int(np.argmax(hit))]) if hit.any() else None


@pytest.mark.parametrize("seed", range(8))
def test_first_blocked_is_the_numpy_sampling(seed: int) -> None:
    """Random paths (some with a repeated vertex, some leaving the grid) on random maps,
    from random arc lengths (some before the start): the same arc length, or None."""
    rng = np.random.default_rng(700 + seed)
    costmap = Costmap((0.0, 0.0), (6.0, 3.0), resolution=0.1, decay=60.0, inflation=0.3,
                      padding=2.0, max_size=40.0)
    nx, ny = costmap.shape
    costmap.now = 10.0
    seen = {"blocked": 0, "beyond": 0, "none": 0}
    for _ in range(200):
        costmap.occupied[:] = rng.random((nx, ny)) < float(rng.choice([0.0, 0.002, 0.01]))
        costmap.seen[:] = 10.0
        costmap.hit_since[:] = 0.0
        costmap.version += 1
        points = rng.uniform(costmap.origin - 1.0,
                             costmap.origin + np.array([nx, ny]) * 0.1 + 1.0,
                             (int(rng.integers(2, 7)), 2))
        if rng.random() < 0.3:  # a repeated vertex: a segment of length 0
            k = int(rng.integers(0, len(points)))
            points = np.insert(points, k, points[k], axis=0)
        from_s = float(rng.uniform(-1.0, 4.0))
        step = float(rng.choice([0.05, 0.1, 0.13]))
        want = numpy_first_blocked(costmap, points, from_s, step)
        assert global_path.first_blocked(costmap, points, from_s, step) == want
        if want is None:
            seen["none"] += 1
        else:
            at = np.array([[np.interp(want, global_path.arc_lengths(points), points[:, k])
                            for k in range(2)]])
            seen["beyond" if not costmap.inside(costmap.cell_of(at))[0] else "blocked"] += 1
    assert all(seen.values())  # blocked cells, the grid's edge, and clear paths all occur
