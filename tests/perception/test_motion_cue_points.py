"""The motion cue (``MotionCue``, as perception runs it): a mover scores while a standing
post does not, each baseline's column is what a cue with that baseline alone gives, and
the window clustering hands it gives the cue's own scores."""

from __future__ import annotations

import numpy as np
import pytest

from zenav.services.perception.clustering import scan_window
from zenav.services.perception.motion_cue import MotionCue, ScanSnapshot

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


def test_the_mover_scores_and_the_post_does_not() -> None:
    past = scan(0.0, (0.0, 0.0, 0.0), [(3.0, 1.5), (3.0, -1.0)])
    now = scan(0.5, (0.1, 0.0, 0.0), [(3.0, 1.5), (3.0, -0.4)])
    cue = MotionCue((0.5,), margin=0.1, reach=0.5, window_radius=8.0)
    cue.score_each(past, 0.0, clusters_of(past))
    scores, stamps = cue.score_each(now, 0.0, clusters_of(now))  # the mover, then the post
    assert stamps.tolist() == [0.0]
    assert scores.shape == (2, 1)
    assert scores[0, 0] > 0.5 and scores[1, 0] == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_each_baseline_scores_as_a_cue_with_that_baseline_alone(seed: int) -> None:
    """MotionCue builds the clusters' points once for all its baselines; each column of
    score_each is what a cue with that one baseline gives on the same scans, to the bit."""
    rng = np.random.default_rng(seed)
    standing = [(float(rng.uniform(2, 4)), float(rng.uniform(-2, 2))) for _ in range(3)]
    baselines = (0.2, 0.5)
    cue = MotionCue(baselines, margin=0.1, reach=0.5, window_radius=4.0)
    alone = [MotionCue((b,), margin=0.1, reach=0.5, window_radius=4.0) for b in baselines]
    for k in range(8):
        mover = (3.0, -1.5 + 0.12 * k)
        s = scan(0.1 * k, (0.05 * k, 0.0, 0.01 * k), [*standing, mover])
        each, stamps = cue.score_each(s, 0.0, clusters_of(s))
        singles = [c.score_each(s, 0.0, clusters_of(s)) for c in alone]
        for j, (one, one_stamps) in enumerate(singles):
            assert np.array_equal(each[:, j], one[:, 0])
            assert np.array_equal(stamps[j:j + 1], one_stamps, equal_nan=True)
    assert np.all(np.isfinite(stamps)) and each.any()


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
