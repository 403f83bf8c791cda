"""Tracking service: obstacle chains in, tracks (type, speed, heading) out."""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence

from pydantic import TypeAdapter

from zenav.schemas import keys
from zenav.schemas.messages import MAX_TRACKS, ObstacleChain, Track, TrackList
from zenav.services.node import Node, StampGate
from zenav.services.perception.wire import from_message
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Track as TrackState
from zenav.services.tracking.tracker import Tracker

log = logging.getLogger(__name__)

WARN_EVERY = 10.0
"""s between two warnings that tracks were left out of a track list."""

# The messages of one frame's tracks validated together: one call into the validator for
# the whole list costs less a track than a model built at a time (the same checks).
_TRACK_LIST = TypeAdapter(list[Track])


def track_messages(tracks: Sequence[TrackState]) -> list[Track]:
    """The bus messages of a frame's tracks (the paper quantities clamped to their ranges)."""
    if not tracks:
        return []  # (the validator's call costs more than the empty list)
    return _TRACK_LIST.validate_python(
        [
            {
                "id": track.id,
                "kind": track.kind,
                "x": track.x,
                "y": track.y,
                "vx": track.vx,
                "vy": track.vy,
                "speed": track.speed,
                "heading": track.heading,
                "radius": track.radius,
                "xi": min(max(track.xi, 0.0), 1.0),
                "varsigma": min(max(track.varsigma, 0.0), 1.0),
                "alpha_o_deg": (
                    track.alpha_o_deg % 360.0 if math.isfinite(track.alpha_o_deg) else 0.0
                ),
                "age": track.age,
                "cells": track.box,
                "area": track.area,
                "visible": track.visible,
            }
            for track in tracks
        ]
    )


def nearest_tracks(states: Sequence[TrackState], x: float, y: float) -> list[TrackState]:
    """The :data:`MAX_TRACKS` tracks nearest the robot at (x, y), in their order: all of
    them when there are no more (a track list holds no more)."""
    if len(states) <= MAX_TRACKS:
        return list(states)
    order = sorted(range(len(states)), key=lambda i: math.hypot(states[i].x - x, states[i].y - y))
    kept = set(order[:MAX_TRACKS])
    return [state for i, state in enumerate(states) if i in kept]


class Service:
    def __init__(self, node: Node, params: TrackingParams) -> None:
        self.node = node
        self.tracker = Tracker(params)
        self._warned = -math.inf  # stamp of the last warning that tracks were left out
        self.tracks = node.publisher(keys.TRACKS, TrackList)
        self.gate = StampGate(node, keys.OBSTACLES)
        node.subscribe(keys.OBSTACLES, ObstacleChain, self.on_chain, depth=2)

    def on_chain(self, chain: ObstacleChain) -> None:
        if not self.gate.admit(chain.stamp, self.tracks):
            return
        clusters = from_message(chain)
        states = self.tracker.update(chain.stamp, clusters.pose, clusters)
        if len(states) > MAX_TRACKS:
            self._warn_left_out(len(states), chain.stamp)
            states = nearest_tracks(states, chain.pose.x, chain.pose.y)
        self.tracks.publish(
            TrackList(
                stamp=chain.stamp,
                seq=self.tracks.next_seq(),
                pose=chain.pose,
                tracks=track_messages(states),
            )
        )

    def _warn_left_out(self, count: int, stamp: float) -> None:
        """A warning, at most every :data:`WARN_EVERY` s, that ``count`` tracks are more
        than a track list holds."""
        if stamp >= self._warned + WARN_EVERY or stamp < self._warned:
            self._warned = stamp
            log.warning("%d tracks at t=%.1f; the %d farthest from the robot are left out of "
                        "the track list (at most %d)", count, stamp, count - MAX_TRACKS,
                        MAX_TRACKS)


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("tracking"))
