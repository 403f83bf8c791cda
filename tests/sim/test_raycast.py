"""Ray casting and the simulated laser against hand-computed geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from zenav.sim.contact import clearances
from zenav.sim.raycast import box_entry_time, cast_rays, circle_entry_time, simulate_scan
from zenav.sim.scenario import LaserSpec
from zenav.sim.world import WorldSnapshot

NO_BOXES = np.zeros((0, 2))
NO_DISCS = np.zeros((0, 2))
NO_RADII = np.zeros(0)


def cast(
    origin: tuple[float, float],
    angles: list[float] | np.ndarray,
    snapshot: WorldSnapshot,
    max_range: float = 8.0,
) -> np.ndarray:
    return cast_rays(
        np.array(origin),
        np.asarray(angles, dtype=float),
        snapshot.disc_centers,
        snapshot.disc_radii,
        snapshot.box_mins,
        snapshot.box_maxs,
        max_range,
    )


def test_disc_straight_ahead_gives_distance_minus_radius_on_centre_beam() -> None:
    origin, heading, d, r = np.array([1.0, 2.0]), 0.3, 4.0, 0.5
    center = origin + d * np.array([math.cos(heading), math.sin(heading)])
    snapshot = WorldSnapshot.build(discs=[(center[0], center[1], r)])
    angles = LaserSpec().angles_rad()
    ranges = cast_rays(
        origin,
        heading + angles,
        snapshot.disc_centers,
        snapshot.disc_radii,
        NO_BOXES,
        NO_BOXES,
        8.0,
    )
    assert ranges[180] == pytest.approx(d - r, abs=1e-12)
    # Beams either side are longer, and those far off the disc see nothing.
    assert ranges[179] > ranges[180] and ranges[181] > ranges[180]
    assert np.isinf(ranges[0]) and np.isinf(ranges[-1])


def test_box_faces_and_corner() -> None:
    snapshot = WorldSnapshot.build(boxes=[(3.0, -1.0, 4.0, 1.0)])
    ranges = cast((0.0, 0.0), [0.0, math.atan2(0.999, 3.0), math.pi, math.pi / 2], snapshot)
    assert ranges[0] == pytest.approx(3.0)  # near face x = 3
    assert ranges[1] == pytest.approx(math.hypot(3.0, 0.999))  # just below corner (3, 1)
    assert np.isinf(ranges[2]) and np.isinf(ranges[3])  # behind and beside
    # From above, looking down onto the top face y = 1.
    assert cast((3.5, 5.0), [-math.pi / 2], snapshot)[0] == pytest.approx(4.0)


def test_ray_parallel_to_box_face_on_its_line_hits_the_edge() -> None:
    # The ray runs along y = 1, the box's top face: it touches the box at x = 3.
    snapshot = WorldSnapshot.build(boxes=[(3.0, -1.0, 4.0, 1.0)])
    assert cast((0.0, 1.0), [0.0], snapshot)[0] == pytest.approx(3.0)
    assert np.isinf(cast((0.0, 1.0 + 1e-9), [0.0], snapshot)[0])


def test_tangent_ray_hits_and_slightly_off_ray_misses() -> None:
    snapshot = WorldSnapshot.build(discs=[(5.0, 1.0, 1.0)])
    tangent, miss, through = cast((0.0, 0.0), [0.0, -0.01, 0.01], snapshot)
    assert tangent == 5.0  # grazes the disc at (5, 0)
    assert np.isinf(miss)  # line passes 1.05 m from the centre
    assert through < 5.0


def test_disc_behind_or_beyond_range_is_not_seen() -> None:
    snapshot = WorldSnapshot.build(discs=[(-3.0, 0.0, 1.0), (10.0, 0.0, 1.0)])
    ranges = cast((0.0, 0.0), [0.0, math.pi], snapshot, max_range=8.0)
    assert np.isinf(ranges[0])  # surface at 9 m > 8 m
    assert ranges[1] == pytest.approx(2.0)
    assert cast((0.0, 0.0), [0.0], snapshot, max_range=9.0)[0] == pytest.approx(9.0)


@pytest.mark.parametrize(
    "snapshot",
    [
        WorldSnapshot.build(discs=[(0.1, 0.0, 0.5)]),
        WorldSnapshot.build(boxes=[(-1.0, -1.0, 1.0, 1.0)]),
        WorldSnapshot.build(boxes=[(0.0, -1.0, 1.0, 1.0)]),  # origin on the face
        WorldSnapshot.build(discs=[(1.0, 0.0, 1.0), (5.0, 0.0, 1.0)]),  # on a circle
    ],
    ids=["in-disc", "in-box", "on-box-face", "on-disc-surface"],
)
def test_origin_inside_obstacle_gives_zero_on_every_beam(snapshot: WorldSnapshot) -> None:
    ranges = cast((0.0, 0.0), LaserSpec().angles_rad(), snapshot)
    assert ranges.shape == (361,)
    assert np.all(ranges == 0.0)


def test_nearest_of_several_obstacles_wins() -> None:
    snapshot = WorldSnapshot.build(
        discs=[(6.0, 0.0, 2.0), (3.0, 0.0, 0.5)], boxes=[(1.5, 1.8, 2.5, 3.0), (3.0, 3.0, 4, 4)]
    )
    ranges = cast((0.0, 0.0), [0.0, math.pi / 4], snapshot)
    assert ranges[0] == pytest.approx(2.5)  # small disc in front of the big one
    assert ranges[1] == pytest.approx(1.8 * math.sqrt(2.0))  # near box's bottom face y = 1.8


def test_empty_world_sees_nothing() -> None:
    ranges = cast_rays(np.zeros(2), np.linspace(0, 1, 5), NO_DISCS, NO_RADII, NO_BOXES, NO_BOXES, 8)
    assert ranges.dtype == np.float64
    assert np.all(np.isinf(ranges))


def test_entry_time_helpers_scale_with_speed() -> None:
    # Moving at 2 m/s towards a circle 3 m away (surface 2 m away): contact after 1 s.
    assert circle_entry_time((-3.0, 0.0), (2.0, 0.0), 1.0) == pytest.approx(1.0)
    assert np.isinf(circle_entry_time((-3.0, 0.0), (0.0, 0.0), 1.0))  # not moving
    assert box_entry_time((0.0, 0.0), (0.0, -4.0), (-1.0, -9.0), (1.0, -5.0)) == pytest.approx(1.25)


def test_laser_has_361_beams_over_180_degrees_and_beam_0_is_on_the_right() -> None:
    laser = LaserSpec()
    angles = laser.angles_rad()
    assert laser.beam_count == 361 and angles.shape == (361,)
    assert angles[-1] - angles[0] == pytest.approx(math.pi)
    np.testing.assert_allclose(np.diff(angles), math.radians(0.5), rtol=1e-12)
    # Robot at the origin facing +y; a wall to its right (+x side) is seen by beam 0.
    snapshot = WorldSnapshot.build(boxes=[(2.0, -1.0, 3.0, 1.0)])
    scan = simulate_scan(np.zeros(2), math.pi / 2, angles, snapshot, 8.0, 0.0, rng(0))
    assert scan[0] == pytest.approx(2.0)
    assert scan[-1] == 8.0


def rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


WALL = WorldSnapshot.build(boxes=[(3.0, -10.0, 4.0, 10.0)])


def test_zero_noise_is_exact_and_misses_report_max_range() -> None:
    angles = LaserSpec().angles_rad()
    scan = simulate_scan(np.zeros(2), 0.0, angles, WALL, 8.0, 0.0, rng(0))
    assert scan.dtype == np.float32
    exact = cast((0.0, 0.0), angles, WALL)
    hit = np.isfinite(exact)
    assert hit.sum() > 0 and (~hit).sum() > 0
    np.testing.assert_array_equal(scan[hit], exact[hit].astype(np.float32))
    assert np.all(scan[~hit] == np.float32(8.0))
    assert scan[180] == 3.0


def test_noise_is_reproducible_with_a_seed_and_only_on_hits() -> None:
    angles = LaserSpec().angles_rad()
    a = simulate_scan(np.zeros(2), 0.0, angles, WALL, 8.0, 0.05, rng(7))
    b = simulate_scan(np.zeros(2), 0.0, angles, WALL, 8.0, 0.05, rng(7))
    c = simulate_scan(np.zeros(2), 0.0, angles, WALL, 8.0, 0.05, rng(8))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    exact = cast((0.0, 0.0), angles, WALL)
    assert np.all(a[np.isinf(exact)] == 8.0)  # no noise on "no return"
    near = np.isfinite(exact) & (exact < 7.5)  # hits that noise cannot clip to max_range
    assert np.all(a[near] != exact[near].astype(np.float32))


def test_noise_has_the_requested_spread_and_ranges_stay_in_bounds() -> None:
    generator = rng(1)
    straight_ahead = np.array([0.0])
    draws = np.array(
        [
            simulate_scan(np.zeros(2), 0.0, straight_ahead, WALL, 8.0, 0.1, generator)[0]
            for _ in range(4000)
        ]
    )
    assert draws.mean() == pytest.approx(3.0, abs=0.01)
    assert draws.std() == pytest.approx(0.1, rel=0.05)
    # A very close obstacle with large noise never reports a negative range.
    near = WorldSnapshot.build(boxes=[(0.01, -1.0, 1.0, 1.0)])
    scan = simulate_scan(np.zeros(2), 0.0, np.zeros(500), near, 8.0, 1.0, generator)
    assert scan.min() >= 0.0 and scan.max() <= 8.0


coordinate = st.floats(-5.0, 5.0, allow_nan=False)
size = st.floats(0.05, 2.0, allow_nan=False)


@settings(max_examples=150, deadline=None)
@given(
    origin=st.tuples(coordinate, coordinate),
    discs=st.lists(st.tuples(coordinate, coordinate, size), max_size=4),
    boxes=st.lists(st.tuples(coordinate, coordinate, size, size), max_size=4),
    angles=st.lists(st.floats(-math.pi, math.pi, allow_nan=False), min_size=1, max_size=20),
)
def test_ranges_never_below_clearance_and_hits_lie_on_a_surface(
    origin: tuple[float, float],
    discs: list[tuple[float, float, float]],
    boxes: list[tuple[float, float, float, float]],
    angles: list[float],
) -> None:
    snapshot = WorldSnapshot.build(discs, [(x, y, x + w, y + h) for x, y, w, h in boxes])
    ranges = cast(origin, angles, snapshot, max_range=50.0)
    gaps, _ = clearances(origin, 0.0, snapshot)
    nearest = gaps.min(initial=np.inf)
    assume(abs(nearest) > 1e-9)  # on a surface, rounding decides inside or not
    if nearest < 0.0:
        assert np.all(ranges == 0.0)
        return
    assert np.all(ranges >= nearest - 1e-9)
    for angle, r in zip(angles, ranges, strict=True):
        if np.isfinite(r):
            hit = np.array(origin) + r * np.array([math.cos(angle), math.sin(angle)])
            hit_gaps, _ = clearances(hit, 0.0, snapshot)
            assert abs(hit_gaps.min()) < 1e-6  # the hit point is on the nearest surface
