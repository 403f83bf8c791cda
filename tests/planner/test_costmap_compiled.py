"""The map's compiled scan tracing (``_loops.trace_scan``, what ``Costmap.update`` calls)
gives, to the bit, the grids of the numpy update it replaced: the marks (Eq. 1 returns,
those on a mover left out), the clearing and the marking with its confirmation. The
cells the compiled update walks along each beam are checked against the geometry
(``beam_cells``), then given to the numpy update, which sampled points every half cell
and so missed some of the cells a beam crosses at a corner."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt

from tests.planner.beam_cells import beam_cells as cells_of_beams
from zenav.services.perception.clustering import to_global
from zenav.services.planner._loops import floor_quotients
from zenav.services.planner.costmap import Costmap, ScanData
from zenav.services.planner.prediction import path_count, path_points

Mover = tuple[float, float, float]


def numpy_update(cm: Costmap, scan: ScanData, stamp: float, movers: list[Mover] | None,
                 seen_now: np.ndarray) -> None:
    """The update as numpy array operations (the code ``trace_scan`` replaced), with the
    cells the beams clear taken from ``seen_now`` (a grid's cells seen at ``stamp``,
    as (i, j) rows, after the same update), once checked to lie between the cells the
    beams surely cross and those they may touch, except the returns' cells."""
    cm.now = max(cm.now, stamp)
    x, y = scan.pose[0], scan.pose[1]
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    alpha = scan.angle_min + scan.angle_increment * np.arange(ranges.size)
    hit = (ranges < scan.range_max) & (ranges >= scan.range_min)
    ends = np.column_stack(to_global(scan.pose, ranges, alpha))
    cm.grow_to(np.vstack([[x, y], ends[hit]]) if hit.any() else np.array([[x, y]]),
               cm.padding / 2)
    marks = ends[hit]
    if movers and len(marks):
        discs = np.asarray(movers, dtype=np.float64).reshape(-1, 3)
        gap = np.hypot(marks[:, None, 0] - discs[None, :, 0],
                       marks[:, None, 1] - discs[None, :, 1]) - discs[None, :, 2]
        marks = marks[(gap > cm.resolution).all(axis=1)]
    hits = cm.cell_of(marks)
    hits = hits[cm.inside(hits)]
    returned = np.zeros(cm.shape, dtype=bool)
    returned[hits[:, 0], hits[:, 1]] = True
    marked = {(int(i), int(j)) for i, j in hits}
    crossed, touched = beam_cells(cm, scan)
    cleared = {(int(i), int(j)) for i, j in seen_now} - marked
    assert crossed - marked <= cleared <= touched - marked
    cells = np.array(sorted(cleared), dtype=np.intp).reshape(-1, 2)
    cm.seen[cells[:, 0], cells[:, 1]] = stamp
    cm.occupied[cells[:, 0], cells[:, 1]] = False
    cm.walls[cells[:, 0], cells[:, 1]] = False
    newly = ~cm.occupied[hits[:, 0], hits[:, 1]]
    cm.hit_since[hits[newly, 0], hits[newly, 1]] = stamp
    cm.seen[hits[:, 0], hits[:, 1]] = stamp
    cm.occupied[hits[:, 0], hits[:, 1]] = True
    confirmed = cm.hit_since[hits[:, 0], hits[:, 1]] <= stamp - cm.confirm
    cm.walls[hits[confirmed, 0], hits[confirmed, 1]] = True
    cm.version += 1


def update_both(compiled: Costmap, reference: Costmap, scan: ScanData, stamp: float,
                movers: list[Mover] | None = None) -> None:
    compiled.update(scan, stamp, movers)
    numpy_update(reference, scan, stamp, movers, np.argwhere(compiled.seen == stamp))


_beam_cells: dict[tuple[object, ...], tuple[set[tuple[int, int]], set[tuple[int, int]]]] = {}


def beam_cells(cm: Costmap, scan: ScanData) -> tuple[set[tuple[int, int]], set[tuple[int, int]]]:
    """``beam_cells.beam_cells``, worked out once for a scan repeated on the same grid."""
    key = (scan.pose, np.asarray(scan.ranges).tobytes(), cm.origin.tobytes(), cm.shape)
    if key not in _beam_cells:
        _beam_cells[key] = cells_of_beams(cm, scan)
    return _beam_cells[key]


def same_grids(a: Costmap, b: Costmap) -> bool:
    return (a.origin.tobytes() == b.origin.tobytes() and a.version == b.version
            and all(getattr(a, g).tobytes() == getattr(b, g).tobytes()
                    for g in ("seen", "occupied", "hit_since", "walls")))


def scans(rng: np.random.Generator, aligned: bool) -> list[tuple[ScanData, list[Mover]]]:
    """A robot wandering among returns near and far, some beams with none, some ranges
    below range_min; ``aligned`` puts it on cell corners and the beams along the axes
    (quotients that are whole numbers: the exact edges of the floor)."""
    out = []
    for _ in range(8):
        if aligned:
            pose = (float(rng.integers(20, 90)) / 10, float(rng.integers(20, 90)) / 10,
                    float(rng.integers(-4, 4)) * math.pi / 2)
            beams, start, inc = 361, -math.pi, math.pi / 180
        else:
            pose = (float(rng.uniform(2, 9)), float(rng.uniform(2, 9)),
                    float(rng.uniform(-3, 3)))
            beams, start, inc = 181, -math.pi / 2, math.pi / 180
        ranges = np.round(rng.uniform(0.0, 9.0, beams), 1 if aligned else 8)
        ranges[rng.random(beams) < 0.3] = 8.0  # no return
        ranges = np.minimum(ranges, 8.0)
        movers = [(pose[0] + float(rng.uniform(-3, 3)), pose[1] + float(rng.uniform(-3, 3)),
                   float(rng.uniform(0.1, 0.6))) for _ in range(int(rng.integers(0, 4)))]
        out.append((ScanData(pose, ranges, start, inc, 8.0, range_min=0.1), movers))
    return out


@pytest.mark.parametrize("aligned", [False, True])
@pytest.mark.parametrize("seed", range(4))
def test_the_compiled_update_gives_the_grids_of_the_numpy_one(seed: int,
                                                              aligned: bool) -> None:
    rng = np.random.default_rng(seed)
    compiled = Costmap((4.0, 4.0), (6.0, 6.0), resolution=0.1, decay=60.0, inflation=0.3,
                       confirm=0.25, padding=1.0, max_size=30.0)
    reference = copy.deepcopy(compiled)
    marked_on_movers = 0
    unconfirmed = False
    # each scan three times over (0.3 s > confirm: its returns become walls)
    for k, (scan, movers) in enumerate(s for s in scans(rng, aligned) for _ in range(3)):
        stamp = 0.15 * k
        update_both(compiled, reference, scan, stamp, movers)
        assert same_grids(compiled, reference)
        marked_on_movers += len(movers)
        unconfirmed |= bool((compiled.occupied & ~compiled.walls).any())
    assert marked_on_movers  # the mover test ran
    assert unconfirmed and compiled.walls.any()  # marks before and after confirmation


@pytest.mark.parametrize("seed", range(4))
def test_beams_that_leave_the_grid_or_start_outside_it_trace_alike(seed: int) -> None:
    """A grid held small by ``max_size``: most beams run out of it (the compiled loop
    ends a beam at its first point out after one in), and the robot itself is at times
    outside it (no point of a beam in, or the beam entering it from outside)."""
    rng = np.random.default_rng(100 + seed)
    compiled = Costmap((4.0, 4.0), (5.0, 5.0), resolution=0.1, decay=60.0, inflation=0.3,
                       confirm=0.0, padding=0.5, max_size=2.5)
    reference = copy.deepcopy(compiled)
    outside = 0
    for k in range(12):
        pose = (float(rng.uniform(1.0, 8.0)), float(rng.uniform(1.0, 8.0)),
                float(rng.uniform(-3.0, 3.0)))
        ranges = np.minimum(rng.uniform(0.2, 9.0, 181), 8.0)
        scan = ScanData(pose, ranges, -math.pi / 2, math.pi / 180, 8.0)
        update_both(compiled, reference, scan, 0.1 * k)
        assert same_grids(compiled, reference)
        outside += not compiled.inside(compiled.cell_of(np.array([pose[:2]])))[0]
    assert outside  # the robot was beyond the grid at least once


def test_a_scan_with_no_return_and_one_with_nan_ranges_trace_alike() -> None:
    compiled = Costmap((0.0, 0.0), (3.0, 0.0), resolution=0.1, decay=60.0, inflation=0.3,
                       confirm=0.0, padding=1.0, max_size=30.0)
    reference = copy.deepcopy(compiled)
    ranges = np.full(91, 8.0)
    ranges[10:20] = np.nan  # no return, and no point along the beam either
    ranges[40:50] = 1.5
    for stamp, r in ((0.0, np.full(91, 8.0)), (0.1, ranges)):
        scan = ScanData((0.0, 0.0, 0.3), r, -0.5, 0.01, 8.0)
        update_both(compiled, reference, scan, stamp, [(1.0, 0.0, 0.2)])
        assert same_grids(compiled, reference)


def test_the_cell_index_is_the_floor_of_the_quotient() -> None:
    """``cell_index`` (truncation, one less below zero with a fraction) against
    ``np.floor(offset / resolution)``: whole quotients, their neighbours a unit of the
    last place away, signed zeros, and random offsets."""
    resolution = 0.1
    whole = np.arange(-300, 300) * resolution
    offsets = np.concatenate([
        whole, np.nextafter(whole, -np.inf), np.nextafter(whole, np.inf),
        [0.0, -0.0, 1e-300, -1e-300, 5e-324, -5e-324, 1e12, -1e12],
        np.random.default_rng(0).uniform(-50.0, 50.0, 5000)])
    out = np.empty(offsets.size, dtype=np.int_)
    floor_quotients(offsets, resolution, out)
    assert np.array_equal(out, np.floor(offsets / resolution).astype(np.int64))


def scanned_map(rng: np.random.Generator) -> Costmap:
    """A 4 x 3 m map at 0.1 m, seen once from (1, 1) by a 181-beam scan of random ranges."""
    cm = Costmap((0.0, 0.0), (4.0, 3.0), resolution=0.1, decay=60.0, inflation=0.3,
                 confirm=0.0, padding=1.0, max_size=30.0)
    cm.update(ScanData((1.0, 1.0, 0.2), rng.uniform(0.5, 4.0, 181), -math.pi / 2,
                       math.pi / 180, 8.0), 0.0)
    return cm


def test_the_map_looks_points_up_as_cell_of_and_inside_do() -> None:
    """``blocked_at`` and ``lethal_at`` (compiled ``look_up``) against the numpy look-up
    they replaced: points inside and beyond the grid, on cell edges, and nan."""
    rng = np.random.default_rng(5)
    cm = scanned_map(rng)
    edges = np.column_stack([np.arange(-12, 52) * 0.1, np.arange(-12, 52)[::-1] * 0.1])
    points = np.vstack([rng.uniform(-3.0, 8.0, (2000, 2)), edges,
                        [[np.nan, 1.0], [1.0, np.nan], [np.inf, 0.0]]])

    def numpy_look_up(grid: np.ndarray, outside: bool) -> np.ndarray:
        with np.errstate(invalid="ignore"):
            cells = cm.cell_of(points)
        ok = cm.inside(cells)
        out = np.full(len(cells), outside, dtype=bool)
        out[ok] = grid[cells[ok, 0], cells[ok, 1]]
        return out

    for outside in (False, True):
        blocked = cm.blocked_at(points, outside=outside)
        assert np.array_equal(blocked, numpy_look_up(cm.blocked(), outside))
    lethal = cm.lethal_at(points)
    assert np.array_equal(lethal, numpy_look_up(cm.lethal_grid(), False))
    assert lethal.any() and blocked.any() and not blocked.all()



@pytest.mark.parametrize("seed", range(3))
def test_the_maps_distances_and_blocked_cells_are_scipys(seed: int) -> None:
    """``gap`` (asked after the stamping) and ``blocked`` on the map's own grid, against
    ``scipy.ndimage.distance_transform_edt`` of its lethal cells."""
    rng = np.random.default_rng(seed)
    cm = Costmap((0.0, 0.0), (5.0, 4.0), resolution=0.05, decay=60.0, inflation=0.3,
                 confirm=0.0, padding=1.0, max_size=30.0)
    cm.update(ScanData((1.0, 1.0, 0.4), rng.uniform(0.5, 5.0, 361), -math.pi, math.pi / 180,
                       8.0), 0.0)
    lethal = cm.lethal_grid()
    assert lethal.any()
    expected = np.asarray(distance_transform_edt(~lethal), dtype=np.float64) * cm.resolution
    assert cm.gap().tobytes() == expected.tobytes()
    assert np.array_equal(cm.blocked(), expected <= cm.inflation)


@pytest.mark.parametrize("inflation", [0.0, 0.1, 0.3, 0.35, 0.45, 1.2])
@pytest.mark.parametrize("many", [False, True])
def test_the_blocked_cells_are_those_within_the_inflation_by_the_distance_transform(
        inflation: float, many: bool) -> None:
    """The blocked cells, stamped as discs round few lethal cells or read off the
    distances when there are many, are the cells whose scipy distance times the
    resolution is within the inflation (in doubles: at 0.3 m on a 0.1 m grid the cell
    3 cells away is 0.30000000000000004 m off, not blocked)."""
    rng = np.random.default_rng(int(inflation * 100) + many)
    cm = Costmap((0.0, 0.0), (5.0, 4.0), resolution=0.1, decay=60.0, inflation=inflation,
                 confirm=0.0, padding=1.0, max_size=30.0)
    ranges = rng.uniform(0.3, 1.2 if many else 5.0, 721 if many else 61)
    cm.update(ScanData((2.0, 2.0, 0.0), ranges, -math.pi, 2 * math.pi / (len(ranges) - 1),
                       8.0), 0.0)
    lethal = cm.lethal_grid()
    di, _ = cm._disc
    by_distances = np.count_nonzero(lethal) * len(di) > 4 * lethal.size
    if not many or inflation > 1:
        assert by_distances == many  # each way is taken
    expected = np.asarray(distance_transform_edt(~lethal), dtype=np.float64) * 0.1
    assert np.array_equal(cm.blocked(), expected <= inflation)
    assert cm.gap().tobytes() == expected.tobytes()


@pytest.mark.parametrize("seed", range(40))
def test_blocked_along_looks_up_the_points_of_path_points(seed: int) -> None:
    """``blocked_along`` (compiled ``line_any``, making the points itself) is
    ``blocked_at`` of ``path_points``' points, ``any``: lines across a map with walls,
    into and beyond the grid, and of length 0."""
    rng = np.random.default_rng(seed)
    cm = scanned_map(rng)
    hits = 0
    for _ in range(50):
        start = rng.uniform(-2.0, 6.0, 2)
        heading = rng.uniform(-math.pi, math.pi)
        direction = np.array([math.cos(heading), math.sin(heading)])
        length = 0.0 if rng.random() < 0.1 else float(rng.uniform(0.05, 6.0))
        step = float(rng.choice([0.05, 0.025]))
        want = bool(cm.blocked_at(path_points(start, direction, length, step)).any())
        got = cm.blocked_along((float(start[0]), float(start[1])),
                               (float(direction[0]), float(direction[1])), length,
                               path_count(length, step))
        assert got == want
        hits += want
    assert 0 < hits < 50


@pytest.mark.parametrize("seed", range(10))
def test_blocked_along_from_far_away_looks_only_at_the_points_on_the_grid(seed: int) -> None:
    """A way that starts tens to hundreds of metres off the grid, toward it or past it, is
    ``blocked_at`` of all its points (those off the grid are free); one that starts 1e15 m
    away (a pose a bad message may carry) is answered without walking its 4e16 points."""
    rng = np.random.default_rng(1000 + seed)
    cm = scanned_map(rng)
    hits = 0
    for _ in range(40):
        bearing = rng.uniform(-math.pi, math.pi)
        start = np.array([2.0, 1.5]) + rng.uniform(20.0, 300.0) * np.array(
            [math.cos(bearing), math.sin(bearing)])
        aim = rng.uniform(-1.0, 5.0, 2)  # a point on or near the grid
        offset = aim - start
        direction = offset / np.hypot(*offset)
        length = float(np.hypot(*offset) + rng.uniform(-5.0, 10.0))
        want = bool(cm.blocked_at(path_points(start, direction, length, 0.05)).any())
        got = cm.blocked_along((float(start[0]), float(start[1])),
                               (float(direction[0]), float(direction[1])), length,
                               path_count(length, 0.05))
        assert got == want
        hits += want
    assert 0 < hits < 40
    far = 1e15
    assert not cm.blocked_along((far, far), (1.0, 0.0), far, path_count(far, 0.025))
    toward = (-math.sqrt(0.5), -math.sqrt(0.5))
    assert isinstance(cm.blocked_along((far, far), toward, far * math.sqrt(2.0),
                                       path_count(far * math.sqrt(2.0), 0.025)), bool)


@pytest.mark.parametrize("seed", range(5))
def test_blocked_rows_is_any_of_blocked_at_per_row(seed: int) -> None:
    """``blocked_rows`` (compiled ``look_up_rows``) is ``blocked_at`` of every point, any
    per row: rows of points inside and beyond the grid."""
    rng = np.random.default_rng(seed)
    cm = scanned_map(rng)
    xs, ys = rng.uniform(-3.0, 8.0, (300, 12)), rng.uniform(-3.0, 8.0, (300, 12))
    want = cm.blocked_at(np.column_stack([xs.ravel(), ys.ravel()])).reshape(xs.shape)
    got = cm.blocked_rows(xs, ys)
    assert np.array_equal(got, want.any(axis=1))
    assert got.any() and not got.all()


@pytest.mark.parametrize("seed", range(6))
def test_the_compiled_lethal_cells_are_lethals(seed: int) -> None:
    """The lethal grid ``_refresh`` makes in one compiled pass (``_loops.lethal_cells``,
    what ``lethal_grid`` and the inflation read) against ``lethal()``, the numpy test:
    cells seen and hit at random times, walls among them, on the decay, wall decay and
    confirmation edges exactly, never seen (-inf), nan, on grids dense and sparse (the
    pass skips eight empty cells at a time); and the cache kept only while the set
    stays the same."""
    rng = np.random.default_rng(seed)
    # 60 x 50 cells, or 63 x 49: a last run shorter than eight
    goal = (4.0, 3.0) if seed % 2 else (4.3, 2.9)
    cm = Costmap((0.0, 0.0), goal, resolution=0.1, decay=2.0, inflation=0.3,
                 confirm=0.5, wall_decay=5.0, wall_confirm=1.0, padding=1.0,
                 max_size=30.0)
    kept = renewed = 0
    old = (cm.occupied.copy(), cm.seen.copy(), cm.hit_since.copy(), cm.walls.copy())
    for k in range(30):
        cm.now = 10.0 + 0.1 * k
        if rng.random() < 0.7:  # else the grids stay and only the time moves on
            # dense, or sparse enough that most runs of eight cells hold neither
            density = 0.3 if k % 2 else 0.01
            cm.occupied = rng.random(cm.shape) < density
            cm.walls = rng.random(cm.shape) < density
            cm.seen = rng.choice([cm.now - 2.0, cm.now - 1.0, cm.now - 3.0, cm.now - 5.0,
                                  cm.now - 6.0, -math.inf, math.nan, cm.now], size=cm.shape)
            cm.hit_since = rng.choice([cm.now - 0.5, cm.now - 0.4, cm.now, math.inf,
                                       math.nan, cm.now - 9.0, cm.now - 4.0, cm.now - 7.0],
                                      size=cm.shape)
            if rng.random() < 0.3 and k:  # the same cells again, new arrays
                cm.occupied, cm.seen, cm.hit_since, cm.walls = old
            cm.version += 1
        old = (cm.occupied.copy(), cm.seen.copy(), cm.hit_since.copy(), cm.walls.copy())
        before = cm._inflated
        got = cm.lethal_grid()
        with np.errstate(invalid="ignore"):
            want = cm.lethal()
        assert np.array_equal(got, want) and got.dtype == want.dtype
        if before is not None and before[0] is got:
            kept += 1
            assert np.array_equal(before[0], want)
        else:
            renewed += 1
    assert kept and renewed


def numpy_returns_near(cm: Costmap, a: np.ndarray, b: np.ndarray, distance: float,
                       lo: np.ndarray, hi: np.ndarray) -> tuple[bool, float]:
    """``returns_near_segment`` as numpy array operations (the code the compiled loop
    replaced), and the smallest gap's distance from ``distance`` (how close the answer
    came to the other one)."""
    first = np.maximum(cm.cell_of(lo[None, :])[0], 0)
    last = np.maximum(np.minimum(cm.cell_of(hi[None, :])[0] + 1, cm.shape), first)
    part = (slice(int(first[0]), int(last[0])), slice(int(first[1]), int(last[1])))
    cells = np.argwhere(cm.occupied[part] & (cm.seen[part] >= cm.now - cm.decay))
    if len(cells) == 0:
        return False, math.inf
    rel = cm.centre_of(cells + first) - a
    offset = b - a
    length2 = float(offset @ offset)
    t = np.clip(rel @ offset / length2, 0.0, 1.0) if length2 > 0 else np.zeros(len(rel))
    gaps = np.hypot(*(rel - t[:, None] * offset[None, :]).T)
    return bool((gaps <= distance).any()), float(np.abs(gaps - distance).min())


@pytest.mark.parametrize("seed", range(6))
def test_returns_near_a_segment_are_the_numpy_ones(seed: int) -> None:
    """On random maps (returns old and recent), random segments and boxes: the same
    answer as the numpy code, wherever no gap lies within 1e-9 m of the distance (there
    the two may round the last bit of a dot product differently: numpy's BLAS fuses its
    multiply-adds)."""
    rng = np.random.default_rng(40 + seed)
    cm = Costmap((0.0, 0.0), (6.0, 4.0), resolution=0.1, decay=2.0, inflation=0.3,
                 padding=2.0, max_size=40.0)
    nx, ny = cm.shape
    cm.occupied[:] = rng.random((nx, ny)) < 0.02
    cm.seen[:] = rng.uniform(0.0, 10.0, (nx, ny))
    cm.now = 10.0
    answers = set()
    for _ in range(300):
        a, b = rng.uniform(cm.origin, cm.origin + np.array([nx, ny]) * 0.1, (2, 2))
        if rng.random() < 0.05:
            b = a.copy()
        distance = float(rng.uniform(0.05, 0.8))
        box = None if rng.random() < 0.5 else np.sort(rng.uniform(-2.0, 8.0, (2, 2)), axis=0)
        lo, hi = ((np.minimum(a, b) - distance, np.maximum(a, b) + distance) if box is None
                  else (box[0], box[1]))
        want, margin = numpy_returns_near(cm, a, b, distance, lo, hi)
        got = (cm.returns_near_segment(a, b, distance) if box is None
               else cm.returns_near_segment(a, b, distance, box[0], box[1]))
        if margin > 1e-9:
            assert got == want
            answers.add(want)
        assert cm.has_returns_in(lo, hi) == numpy_returns_near(cm, a, b, math.inf, lo, hi)[0]
    assert answers == {True, False}
