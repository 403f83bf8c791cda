"""Tracking service: obstacle chains in, tracks (type, speed, heading) out."""

from __future__ import annotations

import math
from collections.abc import Sequence

from pydantic import TypeAdapter

from zenav.schemas import keys
from zenav.schemas.messages import ObstacleChain, Track, TrackList
from zenav.services.node import Node, StampGate
from zenav.services.perception.wire import from_message
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Track as TrackState
from zenav.services.tracking.tracker import Tracker

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


class Service:
    def __init__(self, node: Node, params: TrackingParams) -> None:
        self.node = node
        self.tracker = Tracker(params)
        self.tracks = node.publisher(keys.TRACKS, TrackList)
        self.gate = StampGate(node, keys.OBSTACLES)
        node.subscribe(keys.OBSTACLES, ObstacleChain, self.on_chain, depth=2)

    def on_chain(self, chain: ObstacleChain) -> None:
        if not self.gate.admit(chain.stamp, self.tracks):
            return
        clusters = from_message(chain)
        states = self.tracker.update(chain.stamp, clusters.pose, clusters)
        self.tracks.publish(
            TrackList(
                stamp=chain.stamp,
                seq=self.tracks.next_seq(),
                pose=chain.pose,
                tracks=track_messages(states),
            )
        )


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("tracking"))
