"""Exact 2D ray casting against discs and axis-aligned boxes, vectorised over rays.

Angles are radians from +x, counter-clockwise. Distances are metres. A ray that
only grazes a surface (tangent) counts as a hit. The two ``*_entry_time`` helpers
are shared with the contact checker, so the laser and the collision test agree on
the geometry.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from zenav.sim.world import WorldSnapshot

__all__ = ["box_entry_time", "cast_rays", "circle_entry_time", "simulate_scan"]

FloatArray = NDArray[np.float64]
Pair = tuple[ArrayLike, ArrayLike]  # x and y components, broadcastable


def circle_entry_time(f: Pair, d: Pair, r: ArrayLike) -> FloatArray:
    """First s >= 0 at which the point ``f + s * d`` is within distance ``r`` of the origin.

    ``f = (fx, fy)`` is the start relative to the circle centre (m), ``d = (dx, dy)``
    the direction or velocity (any length, so s is in units of 1/|d|: m for unit
    vectors, s for a velocity in m/s), ``r`` the radius (m). Returns 0 when ``f`` is
    already inside or on the circle and inf when the point never gets there. All
    components broadcast together.
    """
    fx, fy, dx, dy, r = (np.asarray(v, dtype=np.float64) for v in (*f, *d, r))
    a = dx * dx + dy * dy
    b = fx * dx + fy * dy
    c = fx * fx + fy * fy - r * r
    disc = b * b - a * c
    inside = c <= 0.0
    approaching = (b < 0.0) & (disc >= 0.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # Nearer root of a s^2 + 2 b s + c = 0, written without cancellation.
        s = c / (-b + np.sqrt(np.maximum(disc, 0.0)))
    return np.where(inside, 0.0, np.where(approaching, s, np.inf))


def _slab(
    o: FloatArray, d: FloatArray, lo: FloatArray, hi: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Parameter interval in which ``o + s * d`` lies within [lo, hi] on one axis."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s1 = (lo - o) / d
        s2 = (hi - o) / d
    parallel = d == 0.0
    within = (lo <= o) & (o <= hi)
    s_near = np.where(parallel, np.where(within, -np.inf, np.inf), np.minimum(s1, s2))
    s_far = np.where(parallel, np.where(within, np.inf, -np.inf), np.maximum(s1, s2))
    return s_near, s_far


def box_entry_time(o: Pair, d: Pair, lo: Pair, hi: Pair) -> FloatArray:
    """First s >= 0 at which ``o + s * d`` is inside the closed box [lo, hi] (slab method).

    Each argument is an (x, y) pair of broadcastable arrays: start ``o`` (m),
    direction ``d`` of any length (see ``circle_entry_time``), lower-left corner
    ``lo`` and upper-right corner ``hi`` (m). Returns 0 when ``o`` is inside or on
    the box and inf when the point never enters it.
    """
    ox, oy, dx, dy, xmin, ymin, xmax, ymax = (
        np.asarray(v, dtype=np.float64) for v in (*o, *d, *lo, *hi)
    )
    near_x, far_x = _slab(ox, dx, xmin, xmax)
    near_y, far_y = _slab(oy, dy, ymin, ymax)
    s_in = np.maximum(near_x, near_y)
    s_out = np.minimum(far_x, far_y)
    hit = (s_in <= s_out) & (s_out >= 0.0)
    return np.where(hit, np.maximum(s_in, 0.0), np.inf)


def cast_rays(
    origin: ArrayLike,
    angles: ArrayLike,
    disc_centers: ArrayLike,
    disc_radii: ArrayLike,
    box_mins: ArrayLike,
    box_maxs: ArrayLike,
    max_range: float,
) -> FloatArray:
    """Distance (m) from ``origin`` (2,) to the first surface along each ray.

    ``angles`` (m,) are global, rad. Discs: ``disc_centers`` (n, 2), ``disc_radii``
    (n,), m. Boxes: ``box_mins`` / ``box_maxs`` (k, 2) corners, m. Returns (m,)
    float64, ``np.inf`` where nothing is hit within ``max_range`` (m); all zeros
    when the origin is inside or on an obstacle.
    """
    o = np.asarray(origin, dtype=np.float64).reshape(2)
    theta = np.asarray(angles, dtype=np.float64).reshape(-1)
    centers = np.asarray(disc_centers, dtype=np.float64).reshape(-1, 2)
    radii = np.asarray(disc_radii, dtype=np.float64).reshape(-1)
    mins = np.asarray(box_mins, dtype=np.float64).reshape(-1, 2)
    maxs = np.asarray(box_maxs, dtype=np.float64).reshape(-1, 2)

    fx = o[0] - centers[:, 0]
    fy = o[1] - centers[:, 1]
    in_disc = fx * fx + fy * fy <= radii * radii
    in_box = np.all((mins <= o) & (o <= maxs), axis=1)
    if in_disc.any() or in_box.any():
        return np.zeros(theta.shape, dtype=np.float64)

    dx = np.cos(theta)[:, None]  # (m, 1) against (n,) obstacles -> (m, n)
    dy = np.sin(theta)[:, None]
    ranges = np.full(theta.shape, np.inf, dtype=np.float64)
    if len(radii):
        s = circle_entry_time((fx, fy), (dx, dy), radii)
        ranges = np.minimum(ranges, s.min(axis=1))
    if len(mins):
        s = box_entry_time(
            (o[0], o[1]), (dx, dy), (mins[:, 0], mins[:, 1]), (maxs[:, 0], maxs[:, 1])
        )
        ranges = np.minimum(ranges, s.min(axis=1))
    ranges[ranges > max_range] = np.inf
    return ranges


def simulate_scan(
    origin: ArrayLike,
    heading: float,
    beam_angles_rel: ArrayLike,
    snapshot: WorldSnapshot,
    max_range: float,
    noise_std: float,
    rng: np.random.Generator,
) -> NDArray[np.float32]:
    """The ranges (m) a laser at ``origin`` (m) facing ``heading`` (rad) reports.

    ``beam_angles_rel`` (m,) are relative to the heading, rad (beam 0 on the right
    in the ROS convention). Hits get Gaussian noise of ``noise_std`` m and are
    clipped to [0, max_range]; beams with no hit report exactly ``max_range``, which
    is also what a hit pushed past ``max_range`` by noise reports. When
    ``noise_std > 0`` exactly one normal draw per beam is taken from ``rng`` (hit
    or not), so the random stream does not depend on the geometry.
    """
    rel = np.asarray(beam_angles_rel, dtype=np.float64).reshape(-1)
    ranges = cast_rays(
        origin,
        heading + rel,
        snapshot.disc_centers,
        snapshot.disc_radii,
        snapshot.box_mins,
        snapshot.box_maxs,
        max_range,
    )
    hit = np.isfinite(ranges)
    if noise_std > 0.0:
        noise = rng.normal(0.0, noise_std, size=rel.shape)
        ranges = np.where(hit, ranges + noise, ranges)
    reported = np.where(hit, np.clip(ranges, 0.0, max_range), max_range)
    return reported.astype(np.float32)
