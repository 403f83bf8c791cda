"""A walker seen in part is measured as the disc of its last whole view (``hidden_fit``).

As a walker leaves the field of view across its edge, or passes behind something nearer,
the visible sliver shrinks and slides along the walker. Measured as it is, the track's
radius shrinks to a few centimetres and its position and velocity lag the walker; fitted,
they keep to the walker. Each test runs the same scans with the fit off to show that the
scene really cuts the view and that the assertions fail without the fit.
"""

from __future__ import annotations

import math

from tests.tracking.test_tracker import Box, Disc, drive, nearest, still
from zenav.services.tracking.params import TrackingParams

R = 0.3  # the walker's radius, m
SPEED = 0.5


def leaving_the_view(t: float) -> tuple[list[Disc], list[Box]]:
    """Crosses in front of the robot (at the origin, facing +x, laser +-90 degrees) and
    leaves the view across its left edge: the centre is on the edge at t = 3 s."""
    return [(1.5 - SPEED * t, 1.5, R)], []


def behind_a_post(t: float) -> tuple[list[Disc], list[Box]]:
    """Walks up the y axis behind a post of radius 0.2 m, fully hidden about t = 3 s."""
    return [(2.0, 0.0, 0.2), (3.5, -1.5 + SPEED * t, R)], []


def test_a_walker_leaving_the_view_keeps_its_size_and_velocity() -> None:
    def cut_frames(fit: bool) -> list[tuple[float, float]]:
        """(radius, velocity error) of the walker's track while the edge cuts it."""
        out = []
        for t, tracks in drive(leaving_the_view, still, 4.0, TrackingParams(hidden_fit=fit),
                               noise=0.01):
            x, y, _ = leaving_the_view(t)[0][0]
            if not -0.25 <= x <= 0.25:
                continue
            tr = nearest(tracks, x, y, reach=0.8)
            assert tr is not None and tr.visible and tr.kind == "dynamic"
            out.append((tr.radius, math.hypot(tr.vx + SPEED, tr.vy)))
        assert len(out) >= 8
        return out

    fitted = cut_frames(True)
    assert min(r for r, _ in fitted) >= 0.25
    assert max(e for _, e in fitted) <= 0.15
    plain = cut_frames(False)
    assert min(r for r, _ in plain) < 0.1  # the sliver: the scene does cut the view
    assert max(e for _, e in plain) > 0.15


def test_a_walker_passing_behind_a_post_keeps_its_size_and_place() -> None:
    def cut_frames(fit: bool) -> list[tuple[float, float]]:
        """(radius, lag along its way) of the walker's track while it is seen in part."""
        out = []
        for t, tracks in drive(behind_a_post, still, 6.0, TrackingParams(hidden_fit=fit),
                               noise=0.01):
            x, y, _ = behind_a_post(t)[0][1]
            if not -0.6 <= y <= 0.7:
                continue
            tr = nearest(tracks, x, y, reach=0.8)
            assert tr is not None and tr.kind == "dynamic"
            if tr.visible:
                out.append((tr.radius, abs(tr.y - y)))
        assert len(out) >= 8
        return out

    fitted = cut_frames(True)
    assert min(r for r, _ in fitted) >= 0.25
    assert max(lag for _, lag in fitted) <= 0.1
    plain = cut_frames(False)
    assert min(r for r, _ in plain) < 0.1
    assert max(lag for _, lag in plain) > 0.1


def test_the_fit_leaves_a_walker_seen_whole_alone() -> None:
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        return [(2.5, -1.0 + SPEED * t, R)], []

    on = drive(world, still, 4.0, TrackingParams(hidden_fit=True), noise=0.01)
    off = drive(world, still, 4.0, TrackingParams(hidden_fit=False), noise=0.01)
    assert on == off
