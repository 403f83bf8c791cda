"""The motion cue with the points it keeps from scan to scan gives exactly the scores it
gives computing them afresh, and a mover scores while a standing box does not."""

from __future__ import annotations

import numpy as np
import pytest

from zenav.services.perception.clustering import scan_window
from zenav.services.perception.motion_cue import MotionCue, ScanSnapshot, motion_scores

BEAMS = 181
ANGLE_MIN, STEP = -np.pi / 2, np.pi / 180


def scan(stamp: float, pose: tuple[float, float, float],
         boxes: list[tuple[float, float]]) -> ScanSnapshot:
    """Ranges to round posts of 0.2 m radius at ``boxes`` (global), else 8 m."""
    ranges = np.full(BEAMS, 8.0)
    angles = pose[2] + ANGLE_MIN + STEP * np.arange(BEAMS)
    for bx, by in boxes:
        dx, dy = bx - pose[0], by - pose[1]
        along = dx * np.cos(angles) + dy * np.sin(angles)
        off2 = dx * dx + dy * dy - along ** 2
        hit = (along > 0) & (off2 < 0.04)
        ranges = np.where(hit, np.minimum(ranges, along - np.sqrt(np.clip(0.04 - off2, 0, None))),
                          ranges)
    return ScanSnapshot(stamp, pose, ranges, ANGLE_MIN, STEP, 8.0)


def clusters_of(s: ScanSnapshot) -> np.ndarray:
    hit = s.ranges < 8.0
    edges = np.flatnonzero(np.diff(np.r_[0, hit.astype(int), 0]))
    beams: np.ndarray = edges.reshape(-1, 2) - np.array([0, 1])
    return beams


@pytest.mark.parametrize("seed", range(5))
def test_kept_points_give_the_same_scores(seed: int) -> None:
    rng = np.random.default_rng(seed)
    standing = [(float(rng.uniform(2, 4)), float(rng.uniform(-2, 2))) for _ in range(3)]
    mover = (3.0, -1.0)
    past = scan(0.0, (0.0, 0.0, 0.0), [*standing, mover])
    now = scan(0.5, (0.1, 0.0, 0.01), [*standing, (mover[0], mover[1] + 0.6)])
    window, past_window = np.flatnonzero(now.ranges < 8.0), np.flatnonzero(past.ranges < 8.0)
    clusters = clusters_of(now)
    fresh = motion_scores(now, clusters, window, past, past_window, 0.1, 0.5)
    kept = motion_scores(now, clusters, window, past, past_window, 0.1, 0.5,
                         window_points=now.points(window), past_points=past.points(past_window))
    assert np.array_equal(fresh, kept)


def test_the_mover_scores_and_the_post_does_not() -> None:
    past = scan(0.0, (0.0, 0.0, 0.0), [(3.0, 1.5), (3.0, -1.0)])
    now = scan(0.5, (0.1, 0.0, 0.0), [(3.0, 1.5), (3.0, -0.4)])
    window, past_window = np.flatnonzero(now.ranges < 8.0), np.flatnonzero(past.ranges < 8.0)
    clusters = clusters_of(now)  # right to left: the mover, then the post
    scores = motion_scores(now, clusters, window, past, past_window, 0.1, 0.5,
                           window_points=now.points(window),
                           past_points=past.points(past_window))
    assert len(scores) == 2
    assert scores[0] > 0.5 and scores[1] == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_each_baseline_scores_as_motion_scores_does_alone(seed: int) -> None:
    """MotionCue builds the clusters' points once for all its baselines; each column of
    score_each is what motion_scores gives against that baseline's scan, to the bit."""
    from zenav.services.perception.motion_cue import MotionCue

    rng = np.random.default_rng(seed)
    standing = [(float(rng.uniform(2, 4)), float(rng.uniform(-2, 2))) for _ in range(3)]
    cue = MotionCue((0.2, 0.5), margin=0.1, reach=0.5, window_radius=4.0)
    scans = []
    for k in range(8):
        mover = (3.0, -1.5 + 0.12 * k)
        s = scan(0.1 * k, (0.05 * k, 0.0, 0.01 * k), [*standing, mover])
        scans.append(s)
        clusters = clusters_of(s)
        each, stamps = cue.score_each(s, 0.0, clusters)
    assert np.all(np.isfinite(stamps)) and each.any()
    now = scans[-1]

    def window(x: ScanSnapshot) -> np.ndarray:
        beams: np.ndarray = np.flatnonzero((x.ranges < 8.0) & (x.ranges <= 4.0))
        return beams

    for j, stamp in enumerate(stamps):
        past = next(x for x in scans if abs(x.stamp - stamp) < 1e-12)
        alone = motion_scores(now, clusters_of(now), window(now), past, window(past), 0.1, 0.5)
        assert np.array_equal(each[:, j], alone)


@pytest.mark.parametrize("seed", range(3))
def test_the_window_from_clustering_gives_the_cues_own_scores(seed: int) -> None:
    """Perception hands the cue the window clustering made (scan_window); the cue's
    scores and the points it keeps are the ones it gets making the window itself."""
    rng = np.random.default_rng(seed)
    standing = [(float(rng.uniform(2, 4)), float(rng.uniform(-2, 2))) for _ in range(3)]
    handed, own = MotionCue((0.1, 0.3), 0.1, 0.5, 6.0), MotionCue((0.1, 0.3), 0.1, 0.5, 6.0)
    for i in range(5):
        t = 0.1 * i
        s = scan(t, (0.1 * t, 0.0, 0.01 * i), [*standing, (3.0, -1.0 + 0.6 * t)])
        beams = clusters_of(s)
        window = scan_window(s.ranges, ANGLE_MIN, STEP, 0.05, 8.0, s.pose, 6.0)
        got, got_refs = handed.score_each(s, 0.05, beams, window)
        want, want_refs = own.score_each(s, 0.05, beams)
        assert np.array_equal(got, want) and np.array_equal(got_refs, want_refs, equal_nan=True)
    for (_, b1, p1), (_, b2, p2) in zip(handed._scans, own._scans, strict=True):
        assert np.array_equal(b1, b2) and np.array_equal(p1, p2)
