"""A walker seen in part is measured as the disc of its last whole view (``hidden_fit``).

As a walker leaves the field of view across its edge, or passes behind something nearer,
the visible sliver shrinks and slides along the walker. Measured as it is, the track's
radius shrinks to a few centimetres and its position and velocity lag the walker; fitted,
they keep to the walker. Each test runs the same scans with the fit off to show that the
scene really cuts the view and that the assertions fail without the fit.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from tests.tracking.test_tracker import Box, Disc, World, drive, nearest, still
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Track

R = 0.3  # the walker's radius, m
SPEED = 0.5


def leaving_the_view(t: float) -> tuple[list[Disc], list[Box]]:
    """Crosses in front of the robot (at the origin, facing +x, laser +-90 degrees) and
    leaves the view across its left edge: the centre is on the edge at t = 3 s."""
    return [(1.5 - SPEED * t, 1.5, R)], []


def behind_a_post(t: float) -> tuple[list[Disc], list[Box]]:
    """Walks up the y axis behind a post of radius 0.2 m, fully hidden about t = 3 s."""
    return [(2.0, 0.0, 0.2), (3.5, -1.5 + SPEED * t, R)], []


def cut_view(
    world: World, walker: int, seconds: float, cut: Callable[[float, float], bool], fit: bool
) -> list[tuple[Track, float, float]]:
    """(track, true x, true y) of the walker on each scan that sees it while ``cut(x, y)``
    holds for its true centre (the view of it is cut there)."""
    out = []
    for t, tracks in drive(world, still, seconds, TrackingParams(hidden_fit=fit), noise=0.01):
        x, y, _ = world(t)[0][walker]
        if not cut(x, y):
            continue
        tr = nearest(tracks, x, y, reach=0.8)
        assert tr is not None and tr.kind == "dynamic"
        if tr.visible:
            out.append((tr, x, y))
    assert len(out) >= 8
    return out


def test_a_walker_leaving_the_view_keeps_its_size_and_velocity() -> None:
    def radius_and_velocity_error(fit: bool) -> tuple[float, float]:
        seen = cut_view(leaving_the_view, 0, 4.0, lambda x, y: -0.25 <= x <= 0.25, fit)
        return (min(tr.radius for tr, _, _ in seen),
                max(math.hypot(tr.vx + SPEED, tr.vy) for tr, _, _ in seen))

    radius, error = radius_and_velocity_error(True)
    assert radius >= 0.25
    assert error <= 0.15
    radius, error = radius_and_velocity_error(False)
    assert radius < 0.1  # the sliver: the scene does cut the view
    assert error > 0.15


def test_a_walker_passing_behind_a_post_keeps_its_size_and_place() -> None:
    def radius_and_lag(fit: bool) -> tuple[float, float]:
        seen = cut_view(behind_a_post, 1, 6.0, lambda x, y: -0.6 <= y <= 0.7, fit)
        return (min(tr.radius for tr, _, _ in seen),
                max(abs(tr.y - y) for tr, _, y in seen))

    radius, lag = radius_and_lag(True)
    assert radius >= 0.25
    assert lag <= 0.1
    radius, lag = radius_and_lag(False)
    assert radius < 0.1
    assert lag > 0.1


def test_the_fit_leaves_a_walker_seen_whole_alone() -> None:
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        return [(2.5, -1.0 + SPEED * t, R)], []

    on = drive(world, still, 4.0, TrackingParams(hidden_fit=True), noise=0.01)
    off = drive(world, still, 4.0, TrackingParams(hidden_fit=False), noise=0.01)
    assert on == off
