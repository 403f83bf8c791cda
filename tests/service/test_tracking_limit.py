"""Tracking on the in-memory bus when it holds more tracks than a track list carries: it
sends the nearest ones and warns, instead of failing on every scan."""

from __future__ import annotations

import logging

import pytest

from tests.service.harness import running
from zenav.schemas import keys
from zenav.schemas.messages import Obstacle, ObstacleChain, Pose2D, TrackList
from zenav.services.tracking import node as tracking_node
from zenav.services.tracking.params import TrackingParams


def chain(t: float, seq: int, xs: list[float]) -> ObstacleChain:
    """Small obstacles on the line y = 0 at ``xs``, seen from the robot at the origin."""
    obstacles = [
        Obstacle(x=x, y=0.0, rho=x, alpha=0.0, cells=(k * 4, k * 4, 0, 0), area=1,
                 beams=(k * 4, k * 4 + 1), n_beams=2, first=(x, -0.05), last=(x, 0.05),
                 chord=(x, 0.0), radius=0.05, edges=(0, 0))
        for k, x in enumerate(xs)]
    return ObstacleChain(stamp=t, seq=seq, pose=Pose2D(x=0.0, y=0.0, heading=0.0),
                         window_radius=8.0, cell=0.5, obstacles=obstacles)


async def test_more_tracks_than_a_list_holds_sends_the_nearest_and_warns_once(
        monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    monkeypatch.setattr(tracking_node, "MAX_TRACKS", 3)
    xs = [7.0, 1.0, 5.0, 2.0, 6.0, 3.0]
    with caplog.at_level(logging.WARNING, logger=tracking_node.__name__):
        async with running("tracking", TrackingParams()) as h:
            for k in range(3):
                h.send(keys.OBSTACLES, chain(round(0.1 * k, 6), k, xs))
                await h.settle()
            lists = h.received(keys.TRACKS, TrackList)
    assert [m.stamp for m in lists] == [0.0, 0.1, 0.2]  # none lost
    for message in lists:
        assert sorted(round(t.x, 3) for t in message.tracks) == [1.0, 2.0, 3.0]
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == ["6 tracks at t=0.0; the 3 farthest from the robot are left out of the "
                        "track list (at most 3)"]


def test_nearest_tracks_keeps_all_when_there_are_few() -> None:
    from types import SimpleNamespace

    states = [SimpleNamespace(x=float(x), y=0.0) for x in range(5)]
    assert tracking_node.nearest_tracks(states, 0.0, 0.0) == states  # type: ignore[arg-type]
