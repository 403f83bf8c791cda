"""The obstacle chain between its numpy form (:class:`Clusters`) and its message form.

Perception sends a :class:`Clusters`; tracking rebuilds the same arrays on arrival.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import TypeAdapter

from zenav.schemas.messages import Obstacle, ObstacleChain, Pose2D
from zenav.services.perception.clustering import Clusters

# The obstacles of one chain validated together: one call into the validator for the
# whole list costs less an obstacle than a model built at a time (the same checks).
_OBSTACLES = TypeAdapter(list[Obstacle])


def to_message(clusters: Clusters, stamp: float, seq: int, window_radius: float) -> ObstacleChain:
    x, y, heading = clusters.pose
    n = len(clusters)
    obstacles: list[Obstacle] = []
    if n:
        # Every array as Python numbers in one call each (the values ``float`` and ``int``
        # give one element at a time, for a fraction of the cost).
        centre, box = clusters.centre.tolist(), clusters.box.tolist()
        rho, alpha = clusters.mean_rho.tolist(), clusters.mean_alpha.tolist()
        area, n_beams = clusters.area.tolist(), clusters.n_beams.tolist()
        beams = clusters.beams.tolist()
        first, last = clusters.first_point.tolist(), clusters.last_point.tolist()
        chord, radius = clusters.chord_centre.tolist(), clusters.radius.tolist()
        start, end = clusters.edge_start.tolist(), clusters.edge_end.tolist()
        moved = clusters.moved.tolist() if clusters.moved is not None else [0.0] * n
        each = _each(clusters, n)
        obstacles = _OBSTACLES.validate_python([
            {
                "x": centre[k][0], "y": centre[k][1], "rho": rho[k], "alpha": alpha[k],
                "cells": tuple(box[k]), "area": area[k], "beams": tuple(beams[k]),
                "n_beams": n_beams[k], "first": tuple(first[k]), "last": tuple(last[k]),
                "chord": tuple(chord[k]), "radius": radius[k], "edges": (start[k], end[k]),
                "moved": moved[k], "moved_each": each[k],
            }
            for k in range(n)
        ])  # fmt: skip
    return ObstacleChain(
        stamp=stamp,
        seq=seq,
        pose=Pose2D(x=x, y=y, heading=heading),
        window_radius=window_radius,
        cell=clusters.cell,
        obstacles=obstacles,
    )


def _each(clusters: Clusters, n: int) -> list[list[tuple[float, float]]]:
    """Each obstacle's (stamp, score) against the earlier scans remembered (a finite
    stamp), the score clamped to [0, 1]."""
    if clusters.moved_each is None or clusters.moved_refs is None:
        return [[] for _ in range(n)]
    refs = [(k, stamp) for k, stamp in enumerate(clusters.moved_refs.tolist())
            if math.isfinite(stamp)]
    return [[(stamp, min(max(row[k], 0.0), 1.0)) for k, stamp in refs]
            for row in clusters.moved_each.tolist()]


def _each_arrays(obs: list[Obstacle]) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The per-baseline scores back as arrays; None unless every obstacle has the same
    earlier scans (as perception sends them)."""
    refs = [tuple(stamp for stamp, _ in o.moved_each) for o in obs]
    if not refs[0] or any(r != refs[0] for r in refs):
        return None, None
    each = np.asarray([[score for _, score in o.moved_each] for o in obs], dtype=np.float64)
    return each, np.asarray(refs[0], dtype=np.float64)


def from_message(chain: ObstacleChain) -> Clusters:
    pose = (chain.pose.x, chain.pose.y, chain.pose.heading)
    obs = chain.obstacles
    if not obs:
        return Clusters.empty(pose, chain.cell)

    # The float fields and the int fields of every obstacle in one array each, then each
    # field's columns as an array of its own (contiguous, as perception made them).
    f = np.array([(o.x, o.y, *o.first, *o.last, *o.chord, o.rho, o.alpha, o.radius, o.moved)
                  for o in obs], dtype=np.float64)
    i = np.array([(*o.cells, *o.beams, *o.edges, o.area, o.n_beams) for o in obs],
                 dtype=np.int64)
    each, refs = _each_arrays(obs)
    return Clusters(
        centre=f[:, 0:2].copy(),
        mean_rho=f[:, 8].copy(),
        mean_alpha=f[:, 9].copy(),
        box=i[:, 0:4].copy(),
        area=i[:, 8].copy(),
        beams=i[:, 4:6].copy(),
        n_beams=i[:, 9].copy(),
        first_point=f[:, 2:4].copy(),
        last_point=f[:, 4:6].copy(),
        chord_centre=f[:, 6:8].copy(),
        radius=f[:, 10].copy(),
        edge_start=i[:, 6].copy(),
        edge_end=i[:, 7].copy(),
        moved=f[:, 11].copy(),
        moved_each=each,
        moved_refs=refs,
        pose=pose,
        cell=chain.cell,
    )
