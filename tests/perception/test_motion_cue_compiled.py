"""The motion cue's compiled grouping and scoring (``_loops.group_points`` and
``_loops.free_scores``, what ``cluster_points`` and ``scores_against`` call) give, to the
bit, what the numpy code they replaced gave: the same points, boxes and scores."""

from __future__ import annotations

import numpy as np
import pytest

from zenav.services.perception.motion_cue import (
    ClusterPoints,
    ScanSnapshot,
    cluster_points,
    scores_against,
    seen_free,
)

BEAMS = 181
ANGLE_MIN, STEP = -np.pi / 2, np.pi / 180


def numpy_cluster_points(current: ScanSnapshot, cluster_beams: np.ndarray,
                         window_beams: np.ndarray, reach: float,
                         window_points: np.ndarray) -> ClusterPoints | None:
    """The grouping as numpy array operations (the code ``group_points`` replaced)."""
    n = len(cluster_beams)
    owner = np.full(current.ranges.shape[0], -1, dtype=np.int64)
    for k, (first, last) in enumerate(cluster_beams):
        owner[first: last + 1] = k
    owned = owner[window_beams] >= 0
    beams = window_beams[owned]
    if len(beams) == 0:
        return None
    member = owner[beams]
    points = window_points[owned]
    counts = np.bincount(member, minlength=n)
    lo = np.full((n, 2), np.inf)
    hi = np.full((n, 2), -np.inf)
    order = np.argsort(member, kind="stable")
    grouped, ordered = member[order], points[order]
    starts = np.flatnonzero(np.r_[True, grouped[1:] != grouped[:-1]])
    lo[grouped[starts]] = np.minimum.reduceat(ordered, starts, axis=0)
    hi[grouped[starts]] = np.maximum.reduceat(ordered, starts, axis=0)
    return ClusterPoints(n, member, points, counts, lo - reach, hi + reach)


def numpy_scores(clustered: ClusterPoints, current: ScanSnapshot, past: ScanSnapshot,
                 past_points: np.ndarray, margin: float) -> np.ndarray:
    """The scores as numpy array operations (the code ``free_scores`` replaced)."""
    n, member, counts = clustered.n, clustered.member, clustered.counts
    entered = np.bincount(member, weights=seen_free(past, clustered.points, margin),
                          minlength=n)
    scores = np.divide(entered, counts, out=np.zeros(n), where=counts > 0)
    if len(past_points) >= 2:
        vacated = seen_free(current, past_points, margin)
        inside = ((past_points[:, None, :] >= clustered.lo[None])
                  & (past_points[:, None, :] <= clustered.hi[None])).all(axis=2)
        n_near = inside.sum(axis=0)
        gone = (inside & vacated[:, None]).sum(axis=0)
        share = np.divide(gone, n_near, out=np.zeros(n), where=n_near >= 2)
        scores = np.maximum(scores, share)
    result: np.ndarray = scores
    return result


def random_scan(rng: np.random.Generator, stamp: float) -> ScanSnapshot:
    """Posts at random ranges in runs of beams, the rest no return (8 m)."""
    ranges = np.full(BEAMS, 8.0)
    first = 0
    while first < BEAMS:
        width = int(rng.integers(1, 12))
        if rng.random() < 0.6:
            ranges[first: first + width] = rng.uniform(0.5, 4.0) + rng.normal(0, 0.05, width)[
                : BEAMS - first]
        first += width + int(rng.integers(0, 6))
    pose = (float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-3, 3)))
    return ScanSnapshot(stamp, pose, ranges, ANGLE_MIN, STEP, 8.0)


def runs(scan: ScanSnapshot) -> np.ndarray:
    hit = scan.ranges < 8.0
    edges = np.flatnonzero(np.diff(np.r_[0, hit.astype(int), 0]))
    beams: np.ndarray = edges.reshape(-1, 2) - np.array([0, 1])
    return beams


@pytest.mark.parametrize("seed", range(20))
def test_grouping_and_scores_are_the_numpy_ones_to_the_bit(seed: int) -> None:
    rng = np.random.default_rng(seed)
    past, now = random_scan(rng, 0.0), random_scan(rng, 0.5)
    # The past scan nearly the same as now, seen from nearby, so that boxes hold points.
    if seed % 2:
        past = ScanSnapshot(0.0, (now.pose[0] - 0.1, now.pose[1], now.pose[2] + 0.02),
                            np.where(rng.random(BEAMS) < 0.8, now.ranges, 8.0), ANGLE_MIN,
                            STEP, 8.0)
    window = np.flatnonzero(now.ranges < 4.0)
    past_window = np.flatnonzero(past.ranges < 4.0)
    beams = runs(now)
    if seed % 3 == 0 and len(beams) > 1:
        beams = beams[::2].copy()  # some window beams in no cluster
    window_points = now.points(window)
    got = cluster_points(now, beams, window, 0.3, window_points)
    want = numpy_cluster_points(now, beams, window, 0.3, window_points)
    assert (got is None) == (want is None)
    if got is None or want is None:
        return
    assert got.n == want.n
    for name in ("member", "points", "counts", "lo", "hi"):
        a, b = getattr(got, name), getattr(want, name)
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), name
    for past_points in (past.points(past_window), past.points(past_window[:1])):
        scores = scores_against(got, now, past, past_points, 0.1)
        expected = numpy_scores(want, now, past, past_points, 0.1)
        assert scores.tobytes() == expected.tobytes()


def test_the_cases_are_not_all_trivial() -> None:
    """Across the seeds above some clusters score in between 0 and 1, and some 0."""
    seen = []
    for seed in range(20):
        rng = np.random.default_rng(seed)
        past, now = random_scan(rng, 0.0), random_scan(rng, 0.5)
        if seed % 2:
            past = ScanSnapshot(0.0, (now.pose[0] - 0.1, now.pose[1], now.pose[2] + 0.02),
                                np.where(rng.random(BEAMS) < 0.8, now.ranges, 8.0),
                                ANGLE_MIN, STEP, 8.0)
        window = np.flatnonzero(now.ranges < 4.0)
        clustered = cluster_points(now, runs(now), window, 0.3, now.points(window))
        if clustered is not None:
            past_points = past.points(np.flatnonzero(past.ranges < 4.0))
            seen += scores_against(clustered, now, past, past_points, 0.1).tolist()
    assert any(0.0 < s < 1.0 for s in seen) and any(s == 0.0 for s in seen)
