"""The collision prediction's faster arithmetic gives, to the bit, the numbers of the
numpy code it replaced: the compiled gap of path points to grid boxes
(``_loops.box_gaps``, what ``prediction.assess_all`` calls for the standing obstacles,
making the points of ``path_points`` itself),
the C library's ``hypot`` for two numbers (``_loops.c_hypot``); and a mover's vectors and
dot products (``_loops.mover_numbers``), each dot product a fused multiply-add, checked
against exact rational arithmetic."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from zenav.services.planner._loops import box_gaps, c_hypot, fused_dot, mover_numbers
from zenav.services.planner.prediction import path_points


def numpy_box_gaps(points: np.ndarray, cells: np.ndarray, cell: float,
                   clearances: np.ndarray) -> tuple[list[int], list[float]]:
    """The gaps as numpy array operations (the code ``box_gaps`` replaced)."""
    boxes = cells.astype(np.float64)
    lows = np.column_stack([(boxes[:, 0] - 0.5) * cell, (boxes[:, 2] - 0.5) * cell])
    highs = np.column_stack([(boxes[:, 1] + 0.5) * cell, (boxes[:, 3] + 0.5) * cell])
    below = lows[None, :, :] - points[:, None, :]
    above = points[:, None, :] - highs[None, :, :]
    outside = np.maximum(np.maximum(below, above), 0.0)
    every = np.hypot(outside[..., 0], outside[..., 1]) - clearances[None, :]
    negative = every < 0
    first = [int(np.argmax(negative[:, j])) if negative[:, j].any() else -1
             for j in range(len(cells))]
    return first, every.min(axis=0).tolist()


Line = tuple[np.ndarray, np.ndarray, float]
Case = tuple[np.ndarray, np.ndarray, float, np.ndarray]


def random_line(seed: int) -> tuple[Line, float]:
    """A random straight path (start, unit direction, length; now and then of length 0)
    and a cell size."""
    rng = np.random.default_rng(seed)
    cell = float(rng.choice([0.05, 0.1, 0.25]))
    heading = rng.uniform(-np.pi, np.pi)
    length = 0.0 if seed % 10 == 9 else float(rng.uniform(0.1, 6.0))
    return (rng.uniform(-2.0, 2.0, 2), np.array([np.cos(heading), np.sin(heading)]),
            length), cell


def random_case(seed: int) -> Case:
    """Points along a random path, random grid boxes round it and their clearances."""
    (start, direction, length), cell = random_line(seed)
    points = path_points(start, direction, length, cell / 4)
    rng = np.random.default_rng(seed + 1000)
    count = int(rng.integers(1, 25))
    lows = np.column_stack([rng.integers(-60, 60, count), rng.integers(-60, 60, count)])
    sizes = rng.integers(0, 6, (count, 2))
    cells = np.column_stack([lows[:, 0], lows[:, 0] + sizes[:, 0],
                             lows[:, 1], lows[:, 1] + sizes[:, 1]]).astype(np.int64)
    return points, cells, cell, rng.uniform(0.2, 1.5, count)


@pytest.mark.parametrize("seed", range(30))
def test_box_gaps_is_the_numpy_arithmetic(seed: int) -> None:
    points, cells, cell, clearances = random_case(seed)
    (start, direction, length), _ = random_line(seed)
    first = np.empty(len(cells), dtype=np.int64)
    least = np.empty(len(cells), dtype=np.float64)
    (sx, sy), (dx, dy) = start.tolist(), direction.tolist()
    box_gaps(sx, sy, dx, dy, length, len(points), cells, cell, clearances, first, least)
    want_first, want_least = numpy_box_gaps(points, cells, cell, clearances)
    assert first.tolist() == want_first
    assert least.tobytes() == np.array(want_least, dtype=np.float64).tobytes()


def test_the_random_boxes_touch_and_miss() -> None:
    """The cases above have boxes on the path and boxes clear of it, for the arithmetic
    to be checked on both sides."""
    firsts = [f for seed in range(30) for f in numpy_box_gaps(*random_case(seed))[0]]
    assert sum(f >= 0 for f in firsts) > 10 and sum(f < 0 for f in firsts) > 10


def test_c_hypot_is_numpys_hypot() -> None:
    rng = np.random.default_rng(7)
    xy = rng.normal(size=(20000, 2)) * rng.choice([1e-3, 1.0, 30.0], size=(20000, 1))
    xy[:50, 1] = 0.0
    got = np.array([c_hypot(x, y) for x, y in xy.tolist()])
    assert got.tobytes() == np.hypot(xy[:, 0], xy[:, 1]).tobytes()
    assert c_hypot(*xy[0]) == float(np.hypot(*xy[0]))  # and on numpy scalars


def fused_dot_exact(a: tuple[float, float], b: tuple[float, float]) -> float:
    """a . b as ``mover_numbers`` defines it: a_x b_x rounded, plus a_y b_y, rounded once."""
    return float(Fraction(a[1]) * Fraction(b[1]) + Fraction(a[0] * b[0]))


def test_mover_numbers_are_their_definition() -> None:
    rng = np.random.default_rng(11)
    for _ in range(2000):
        p, v, r = rng.normal(size=2) * 4, rng.normal(size=2), rng.normal(size=2) * 3
        d = rng.normal(size=2)
        d /= np.hypot(*d)
        speed = float(rng.uniform(0.0, 1.2))
        rel = (float(p[0] - r[0]), float(p[1] - r[1]))
        w = (float(v[0] - d[0] * speed), float(v[1] - d[1] * speed))
        dd, vv = (float(d[0]), float(d[1])), (float(v[0]), float(v[1]))
        got = mover_numbers(float(p[0]), float(p[1]), vv[0], vv[1], float(r[0]), float(r[1]),
                            dd[0], dd[1], speed)
        assert got == (*rel, *w, fused_dot_exact(rel, dd), fused_dot_exact(vv, dd),
                       fused_dot_exact(w, w), fused_dot_exact(rel, w))


def test_fused_dot_is_its_definition() -> None:
    rng = np.random.default_rng(12)
    for a, b in zip(rng.normal(size=(3000, 2)) * 5, rng.normal(size=(3000, 2)), strict=True):
        ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
        assert fused_dot(ax, ay, bx, by) == fused_dot_exact((ax, ay), (bx, by))
