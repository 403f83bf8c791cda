"""The obstacle chain between its numpy form (:class:`Clusters`) and its message form.

Perception sends a :class:`Clusters`; tracking rebuilds the same arrays on arrival.
"""

from __future__ import annotations

import numpy as np

from zenav.schemas.messages import Obstacle, ObstacleChain, Pose2D
from zenav.services.perception.clustering import Clusters


def _pair(row: np.ndarray) -> tuple[float, float]:
    return float(row[0]), float(row[1])


def to_message(clusters: Clusters, stamp: float, seq: int, window_radius: float) -> ObstacleChain:
    x, y, heading = clusters.pose
    obstacles = [
        Obstacle(
            x=float(clusters.centre[k, 0]),
            y=float(clusters.centre[k, 1]),
            rho=float(clusters.mean_rho[k]),
            alpha=float(clusters.mean_alpha[k]),
            cells=(
                int(clusters.box[k, 0]),
                int(clusters.box[k, 1]),
                int(clusters.box[k, 2]),
                int(clusters.box[k, 3]),
            ),
            area=int(clusters.area[k]),
            beams=(int(clusters.beams[k, 0]), int(clusters.beams[k, 1])),
            n_beams=int(clusters.n_beams[k]),
            first=_pair(clusters.first_point[k]),
            last=_pair(clusters.last_point[k]),
            chord=_pair(clusters.chord_centre[k]),
            radius=float(clusters.radius[k]),
            edges=(int(clusters.edge_start[k]), int(clusters.edge_end[k])),
            moved=float(clusters.moved[k]) if clusters.moved is not None else 0.0,
            moved_each=_each(clusters, k),
        )
        for k in range(len(clusters))
    ]
    return ObstacleChain(
        stamp=stamp,
        seq=seq,
        pose=Pose2D(x=x, y=y, heading=heading),
        window_radius=window_radius,
        cell=clusters.cell,
        obstacles=obstacles,
    )


def _each(clusters: Clusters, k: int) -> list[tuple[float, float]]:
    if clusters.moved_each is None or clusters.moved_refs is None:
        return []
    return [(float(stamp), float(min(max(score, 0.0), 1.0)))
            for stamp, score in zip(clusters.moved_refs, clusters.moved_each[k], strict=True)
            if np.isfinite(stamp)]


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

    def floats(rows: list[tuple[float, float]]) -> np.ndarray:
        return np.asarray(rows, dtype=np.float64).reshape(-1, 2)

    each, refs = _each_arrays(obs)
    return Clusters(
        centre=floats([(o.x, o.y) for o in obs]),
        mean_rho=np.asarray([o.rho for o in obs], dtype=np.float64),
        mean_alpha=np.asarray([o.alpha for o in obs], dtype=np.float64),
        box=np.asarray([o.cells for o in obs], dtype=np.int64).reshape(-1, 4),
        area=np.asarray([o.area for o in obs], dtype=np.int64),
        beams=np.asarray([o.beams for o in obs], dtype=np.int64).reshape(-1, 2),
        n_beams=np.asarray([o.n_beams for o in obs], dtype=np.int64),
        first_point=floats([o.first for o in obs]),
        last_point=floats([o.last for o in obs]),
        chord_centre=floats([o.chord for o in obs]),
        radius=np.asarray([o.radius for o in obs], dtype=np.float64),
        edge_start=np.asarray([o.edges[0] for o in obs], dtype=np.int64),
        edge_end=np.asarray([o.edges[1] for o in obs], dtype=np.int64),
        moved=np.asarray([o.moved for o in obs], dtype=np.float64),
        moved_each=each,
        moved_refs=refs,
        pose=pose,
        cell=chain.cell,
    )
