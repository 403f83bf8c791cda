"""The obstacle chain's message (``wire.to_message``) holds each cluster's values as the
element-by-element conversion of its arrays gives them, and tracking's side
(``from_message``) rebuilds the chain perception sent."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from tests.perception.test_clustering_compiled import HALF_DEG, PARAMS, random_ranges, same
from zenav.schemas.codec import decode, encode
from zenav.schemas.messages import ObstacleChain
from zenav.services.perception.clustering import Clusters, cluster_scan
from zenav.services.perception.wire import from_message, to_message


def chain_of(seed: int) -> Clusters:
    rng = np.random.default_rng(seed)
    c = cluster_scan(random_ranges(rng, 361), -math.pi / 2, HALF_DEG, 0.05, 8.0,
                     (1.0, 2.0, 0.3), PARAMS[seed % len(PARAMS)])
    each = rng.uniform(0.0, 1.0, (len(c), 3))
    each[rng.random(each.shape) < 0.2] = 0.0
    refs = np.array([np.nan, 0.2, 0.4]) if seed % 2 else np.array([0.1, 0.2, 0.4])
    return c.with_motion(each, refs)


def one_by_one(c: Clusters, k: int) -> dict[str, object]:
    """Obstacle k's fields converted one numpy element at a time."""
    assert c.moved is not None and c.moved_each is not None and c.moved_refs is not None
    return {
        "x": float(c.centre[k, 0]), "y": float(c.centre[k, 1]),
        "rho": float(c.mean_rho[k]), "alpha": float(c.mean_alpha[k]),
        "cells": tuple(int(v) for v in c.box[k]), "area": int(c.area[k]),
        "beams": (int(c.beams[k, 0]), int(c.beams[k, 1])), "n_beams": int(c.n_beams[k]),
        "first": (float(c.first_point[k, 0]), float(c.first_point[k, 1])),
        "last": (float(c.last_point[k, 0]), float(c.last_point[k, 1])),
        "chord": (float(c.chord_centre[k, 0]), float(c.chord_centre[k, 1])),
        "radius": float(c.radius[k]),
        "edges": (int(c.edge_start[k]), int(c.edge_end[k])),
        "moved": float(c.moved[k]),
        "moved_each": [(float(s), float(min(max(v, 0.0), 1.0)))
                       for s, v in zip(c.moved_refs, c.moved_each[k], strict=True)
                       if np.isfinite(s)],
    }  # fmt: skip


@pytest.mark.parametrize("seed", range(12))
def test_the_message_holds_each_clusters_values(seed: int) -> None:
    c = chain_of(seed)
    message = to_message(c, 1.5, 7, 4.0)
    assert len(message.obstacles) == len(c) > 0
    for k, obstacle in enumerate(message.obstacles):
        got = obstacle.model_dump()
        want = one_by_one(c, k)
        assert repr(got) == repr(want)  # the same values and Python types
    assert (message.stamp, message.seq, message.window_radius, message.cell) == (1.5, 7, 4.0,
                                                                               c.cell)


@pytest.mark.parametrize("seed", range(6))
def test_tracking_rebuilds_the_chain_perception_sent(seed: int) -> None:
    c = chain_of(seed)
    message = decode(encode(to_message(c, 1.5, 7, 4.0)), ObstacleChain)
    back = from_message(message)
    assert c.moved_each is not None and c.moved_refs is not None
    finite = np.isfinite(c.moved_refs)  # earlier scans not remembered are not sent
    same(back, dataclasses.replace(c, moved_each=c.moved_each[:, finite],
                                   moved_refs=c.moved_refs[finite]))


def test_an_empty_chain_is_an_empty_message() -> None:
    message = to_message(Clusters.empty((1.0, 2.0, 0.5)), 0.0, 0, 4.0)
    assert message.obstacles == []
    assert len(from_message(message)) == 0
