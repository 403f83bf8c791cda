"""The clustering's compiled passes (``_loops.window_points``, ``run_bounds``,
``run_shapes``, ``to_global_rows`` and ``edge_codes``, what ``cluster_scan`` calls) give,
to the bit, the obstacle chain of the numpy code they replaced, field by field; that code
calls the equation functions (Eqs. 1, 2, 3 and 6), so the equations inside the passes are
checked against the pinned functions here."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from zenav.services.perception import _loops
from zenav.services.perception.clustering import (
    EDGE_CLIPPED,
    EDGE_OCCLUDED,
    Clusters,
    Pose,
    box_area,
    cluster_means,
    cluster_scan,
    grid_index,
    join_threshold,
    scan_window,
    to_global,
)
from zenav.services.perception.params import PerceptionParams

HALF_DEG = math.radians(0.5)


def numpy_edge_codes(r: np.ndarray, valid: np.ndarray, beams: np.ndarray,
                     angle_increment: float, params: PerceptionParams) -> np.ndarray:
    """The edge codes as numpy array operations (the code the compiled passes replaced)."""
    nb = beams + np.array([-1, 1], dtype=np.int64)
    outside = (nb < 0) | (nb >= r.shape[0])
    nb[outside] = 0
    has = valid[nb] & ~outside
    rho_e = r[beams]
    rho_n = np.where(has, r[nb], 0.0)
    d2 = rho_e * rho_e + rho_n * rho_n - (2.0 * math.cos(angle_increment)) * rho_e * rho_n
    thr = join_threshold(np.maximum(rho_e, rho_n), angle_increment, params)
    codes = np.zeros(beams.shape, dtype=np.int64)
    nearer = rho_n < rho_e - join_threshold(rho_e, angle_increment, params)
    codes[has & nearer] = EDGE_OCCLUDED
    codes[outside | (has & (rho_n > params.window_radius) & (d2 <= thr * thr))] = EDGE_CLIPPED
    return codes


def numpy_cluster_scan(ranges: np.ndarray, angle_min: float, angle_increment: float,
                       range_min: float, range_max: float, pose: Pose,
                       params: PerceptionParams) -> Clusters:
    """``cluster_scan`` as numpy array operations (the code the compiled passes replaced)."""
    r = np.asarray(ranges, dtype=np.float64)
    cell = params.cell
    valid = (r >= range_min) & (r < range_max)
    idx = np.flatnonzero(valid & (r <= params.window_radius))
    if idx.size == 0:
        return Clusters.empty(pose, cell)
    rho = r[idx]
    alpha = angle_min + idx * angle_increment
    px, py = to_global(pose, rho, alpha)
    dx = px[1:] - px[:-1]
    dy = py[1:] - py[:-1]
    thr = join_threshold(rho[1:], angle_increment, params)
    breaks = (dx * dx + dy * dy > thr * thr).nonzero()[0] + 1
    m = idx.size
    starts = np.r_[0, breaks].astype(np.int64)
    ends = np.r_[breaks - 1, m - 1].astype(np.int64)
    counts = ends - starts + 1
    if params.min_beams > 1:
        keep = counts >= params.min_beams
        if not keep.all():
            starts, ends, counts = starts[keep], ends[keep], counts[keep]
            if starts.size == 0:
                return Clusters.empty(pose, cell)
            sel = np.concatenate([np.arange(s, e + 1) for s, e in zip(starts, ends, strict=True)])
            rho, alpha, px, py, idx = rho[sel], alpha[sel], px[sel], py[sel], idx[sel]
            ends = np.cumsum(counts) - 1
            starts = ends - counts + 1
    mean_rho, mean_alpha = cluster_means(rho, alpha, starts, counts)
    centre = np.column_stack(to_global(pose, mean_rho, mean_alpha))
    inset = params.edge_inset
    lo_x, hi_x = np.minimum.reduceat(px, starts), np.maximum.reduceat(px, starts)
    lo_y, hi_y = np.minimum.reduceat(py, starts), np.maximum.reduceat(py, starts)
    in_x = np.minimum(inset, (hi_x - lo_x) / 2)
    in_y = np.minimum(inset, (hi_y - lo_y) / 2)
    box = np.column_stack((grid_index(lo_x + in_x, cell), grid_index(hi_x - in_x, cell),
                           grid_index(lo_y + in_y, cell), grid_index(hi_y - in_y, cell)))
    first_point = np.column_stack((px[starts], py[starts]))
    last_point = np.column_stack((px[ends], py[ends]))
    chord = 0.5 * (first_point + last_point)
    ex = px - chord[:, 0].repeat(counts)
    ey = py - chord[:, 1].repeat(counts)
    radius = np.sqrt(np.maximum.reduceat(ex * ex + ey * ey, starts))
    beams = np.column_stack((idx[starts], idx[ends]))
    edges = numpy_edge_codes(r, valid, beams, angle_increment, params)
    x_r, y_r, th_r = pose
    return Clusters(centre=centre, mean_rho=mean_rho, mean_alpha=mean_alpha, box=box,
                    area=box_area(box), beams=beams, n_beams=counts, first_point=first_point,
                    last_point=last_point, chord_centre=chord, radius=radius,
                    edge_start=edges[:, 0], edge_end=edges[:, 1],
                    pose=(float(x_r), float(y_r), float(th_r)), cell=cell)


def random_ranges(rng: np.random.Generator, n: int) -> np.ndarray:
    """Surfaces of random width and slope, gaps, readings past the window, nan and inf."""
    r = np.full(n, np.inf)
    i = 0
    while i < n:
        width = int(rng.integers(1, 25))
        start = rng.uniform(0.2, 6.0)
        r[i: i + width] = (start + rng.uniform(-0.05, 0.05) * np.arange(width)
                           + rng.normal(0, 0.01, width))[: n - i]
        i += width + int(rng.integers(0, 4))
    r[rng.random(n) < 0.03] = np.nan
    r[rng.random(n) < 0.02] = 0.01  # under range_min
    return r.astype(np.float32)


def same(a: Clusters, b: Clusters) -> None:
    for f in dataclasses.fields(Clusters):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert isinstance(y, np.ndarray), f.name
            assert (x.dtype, x.shape, x.tobytes()) == (y.dtype, y.shape, y.tobytes()), f.name
        else:
            assert repr(x) == repr(y), f.name


PARAMS = [PerceptionParams(), PerceptionParams.paper(),
          PerceptionParams(min_beams=4, edge_inset=0.2, gap_floor=0.05, window_radius=3.0)]


@pytest.mark.parametrize("seed", range(10))
def test_the_equations_are_numpy_arithmetic_to_the_bit(seed: int) -> None:
    """Eqs. 1, 2, 3 and 6, compiled once (``_equations.pxi``) behind ``to_global``,
    ``grid_index``, ``join_threshold`` and ``box_area``, give what the same formulas give
    in numpy, to the bit, in any shape (the chain test below builds on them)."""
    rng = np.random.default_rng(900 + seed)
    shape = [(), (7,), (3, 5)][seed % 3]
    rho, alpha = rng.uniform(0.0, 9.0, shape), rng.uniform(-7.0, 7.0, shape)
    x, y, th = (float(v) for v in rng.uniform(-30.0, 30.0, 3))
    gx, gy = to_global((x, y, th), rho, alpha)
    want_x, want_y = x + rho * np.cos(th + alpha), y + rho * np.sin(th + alpha)
    assert (gx.shape, gx.tobytes(), gy.tobytes()) == (np.shape(want_x), np.asarray(
        want_x).tobytes(), np.asarray(want_y).tobytes())
    ux, _ = to_global((0.0, 0.0, th), 1.0, alpha)  # a scalar range broadcast, as the map does
    assert ux.tobytes() == np.asarray(0.0 + 1.0 * np.cos(th + alpha)).tobytes()
    coord = rng.uniform(-60.0, 60.0, shape)
    assert grid_index(coord, 0.5).tobytes() == np.asarray(
        np.floor(coord / 0.5 + 0.5).astype(np.int64)).tobytes()
    params = PARAMS[seed % len(PARAMS)]
    step = math.sin(abs(HALF_DEG))
    assert join_threshold(rho, HALF_DEG, params).tobytes() == np.asarray(
        params.lambda_ * rho * step + params.gap_floor).tobytes()
    boxes = np.sort(rng.integers(-40, 40, (6, 2, 2)), axis=2).reshape(6, 4)
    cells = (boxes[:, 1] - boxes[:, 0] + 1) * (boxes[:, 3] - boxes[:, 2] + 1)
    assert box_area(boxes).tolist() == cells.tolist()
    assert box_area(tuple(boxes[0].tolist())) == int(cells[0])


@pytest.mark.parametrize("seed", range(30))
def test_the_chain_is_the_numpy_one_to_the_bit(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.choice([3, 50, 361, 720]))
    ranges = random_ranges(rng, n)
    pose = (float(rng.uniform(-20, 20)), float(rng.uniform(-20, 20)), float(rng.uniform(-7, 7)))
    for params in PARAMS:
        got = cluster_scan(ranges, -math.pi / 2, HALF_DEG, 0.05, 8.0, pose, params)
        want = numpy_cluster_scan(ranges, -math.pi / 2, HALF_DEG, 0.05, 8.0, pose, params)
        same(got, want)


@pytest.mark.parametrize("seed", range(20))
def test_the_window_is_the_numpy_one_to_the_bit(seed: int) -> None:
    """``scan_window`` (``_loops.window_points``, with Eq. 1) against the numpy code it
    replaced."""
    rng = np.random.default_rng(500 + seed)
    n = int(rng.choice([1, 3, 361, 720]))
    ranges = random_ranges(rng, n)
    pose = (float(rng.uniform(-20, 20)), float(rng.uniform(-20, 20)), float(rng.uniform(-7, 7)))
    angle_min, radius = float(rng.uniform(-math.pi, 0.0)), float(rng.choice([3.0, 4.0, 9.0]))
    got = scan_window(ranges, angle_min, HALF_DEG, 0.05, 8.0, pose, radius)
    r = np.asarray(ranges, dtype=np.float64)
    valid = (r >= 0.05) & (r < 8.0)
    idx = np.flatnonzero(valid & (r <= radius))
    alpha = angle_min + idx * HALF_DEG
    px, py = to_global(pose, r[idx], alpha)
    points = np.column_stack((px, py))
    for a, b in zip((got.ranges, got.valid, got.beams, got.rho, got.alpha, got.x, got.y,
                     got.points), (r, valid, idx, r[idx], alpha, px, py, points), strict=True):
        assert (a.dtype, a.shape, a.tobytes()) == (b.dtype, b.shape, b.tobytes())


def test_every_edge_code_and_the_speck_filter_occur() -> None:
    """The random scans above reach each edge code, and the speck filter drops runs."""
    codes: set[int] = set()
    dropped = False
    for seed in range(30):
        rng = np.random.default_rng(seed)
        n = int(rng.choice([3, 50, 361, 720]))
        ranges = random_ranges(rng, n)
        for params in PARAMS:
            c = cluster_scan(ranges, -math.pi / 2, HALF_DEG, 0.05, 8.0, (0.0, 0.0, 0.0), params)
            codes |= set(c.edge_start.tolist()) | set(c.edge_end.tolist())
            if params.min_beams > 1:
                one = cluster_scan(ranges, -math.pi / 2, HALF_DEG, 0.05, 8.0,
                                   (0.0, 0.0, 0.0), params.model_copy(update={"min_beams": 1}))
                dropped |= len(one) > len(c)
    assert codes == {0, 1, 2} and dropped


def test_production_calls_the_compiled_passes(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []
    for name in ("window_points", "run_bounds", "run_shapes", "to_global_rows",
                 "edge_codes"):
        real = getattr(_loops, name)

        def counted(*args: object, _real: object = real, _name: str = name) -> object:
            calls.append(_name)
            return _real(*args)  # type: ignore[operator]

        monkeypatch.setattr(_loops, name, counted)
    cluster_scan(np.array([2.0, 2.0, 2.0, 3.0]), 0.0, HALF_DEG, 0.05, 8.0, (0.0, 0.0, 0.0),
                 PerceptionParams())
    assert sorted(calls) == ["edge_codes", "run_bounds", "run_shapes", "to_global_rows",
                            "window_points"]


@pytest.mark.parametrize("seed", range(5))
def test_with_motion_is_the_chain_with_the_scores_replaced(seed: int) -> None:
    rng = np.random.default_rng(seed)
    ranges = random_ranges(rng, 361)
    c = cluster_scan(ranges, -math.pi / 2, HALF_DEG, 0.05, 8.0, (1.0, 2.0, 0.3), PARAMS[0])
    each = rng.uniform(0.0, 1.0, (len(c), 3))
    refs = np.array([np.nan, 0.2, 0.4])
    same(c.with_motion(each, refs),
         dataclasses.replace(c, moved=each.max(axis=1, initial=0.0), moved_each=each,
                             moved_refs=refs))
