"""Clustering of one scan: Eqs. 1-6 against hand-worked numbers, and its invariants."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from zenav.schemas.messages import LaserScan
from zenav.services.perception.clustering import (
    EDGE_CLIPPED,
    EDGE_FREE,
    EDGE_OCCLUDED,
    Clusters,
    box_area,
    cluster_scan,
    cluster_window,
    full_circle,
    grid_index,
    join_threshold,
    rotate_scan,
    scan_window,
    seam_shift,
)
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver

HALF_DEG = math.radians(0.5)
PAPER = PerceptionParams.paper()  # Eq. 3 alone, single beams kept
N = 361
A_MIN = -math.pi / 2


def scan(**beams: float) -> np.ndarray:
    """361 beams with no return except those given as b<index>=range."""
    r = np.full(N, np.inf, dtype=np.float32)
    for key, value in beams.items():
        r[int(key[1:])] = value
    return r


def run(ranges: np.ndarray, pose=(0.0, 0.0, 0.0), params=PAPER) -> Clusters:
    return cluster_scan(ranges, A_MIN, HALF_DEG, 0.05, 8.0, pose, params)


# --- Eq. 2, Eq. 3, Eq. 6 ---------------------------------------------------------------


def test_eq2_grid_index_rounds_to_the_nearest_cell_centre() -> None:
    # floor(x / 0.5 + 1/2): cell k covers [(k - 1/2) r, (k + 1/2) r)
    got = grid_index([0.0, 0.24, 0.25, 0.74, 0.75, -0.25, -0.26, 1.0], 0.5)
    assert got.tolist() == [0, 0, 1, 1, 2, 0, -1, 2]


def test_eq3_threshold_by_hand() -> None:
    # 1.2 * 2 m * sin(0.5 deg) = 0.0209437 m
    assert join_threshold(2.0, HALF_DEG, PAPER) == pytest.approx(0.0209437, abs=1e-7)
    # the floor adds on top
    floored = PerceptionParams(gap_floor=0.15)
    assert join_threshold(2.0, HALF_DEG, floored) == pytest.approx(0.1709437, abs=1e-7)
    # the step comes from the scan, not a constant: 1 degree doubles it (nearly)
    assert join_threshold(2.0, math.radians(1.0), PAPER) == pytest.approx(
        1.2 * 2.0 * math.sin(math.radians(1.0))
    )


def test_eq6_area_counts_cells_inclusively() -> None:
    assert box_area([2, 4, -1, 0]).item() == 6  # 3 columns x 2 rows
    assert box_area([[0, 0, 0, 0], [1, 3, 1, 3]]).tolist() == [1, 9]


# --- Eq. 1 and Eq. 5 --------------------------------------------------------------------


def test_beam_zero_is_on_the_right_and_eq1_is_counter_clockwise() -> None:
    # Heading 0: beam 0 (alpha = -90 deg) looks down -y, beam 180 ahead, beam 360 up +y.
    c = run(scan(b0=1.0, b1=1.0, b180=2.0, b181=2.0, b359=3.0, b360=3.0))
    assert len(c) == 3
    np.testing.assert_allclose(c.first_point[0], [0.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(c.first_point[1], [2.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(c.last_point[2], [0.0, 3.0], atol=1e-6)


def test_eq5_centre_from_mean_alpha_and_mean_rho_then_eq1() -> None:
    # Robot at (1, 2) facing +y; three beams at -0.5, 0, +0.5 deg, 2 m each.
    # mean alpha = 0, mean rho = 2 -> Z = (1 + 2 cos 90deg, 2 + 2 sin 90deg) = (1, 4).
    c = run(scan(b179=2.0, b180=2.0, b181=2.0), pose=(1.0, 2.0, math.pi / 2))
    assert len(c) == 1
    assert c.mean_alpha[0] == pytest.approx(0.0, abs=1e-12)
    assert c.mean_rho[0] == pytest.approx(2.0)
    np.testing.assert_allclose(c.centre[0], [1.0, 4.0], atol=1e-9)
    # Points: x = 1 +- 2 sin(0.5 deg) = 1.01745 / 0.98255 -> column floor(2.53) = 2 both;
    # y = 2 + 2 cos(0.5 deg) = 3.99992 -> row floor(8.49985) = 8. One cell.
    assert c.box[0].tolist() == [2, 2, 8, 8]
    assert c.area[0] == 1
    assert c.n_beams[0] == 3
    assert c.beams[0].tolist() == [179, 181]


def test_eq5_mean_rho_and_alpha_by_hand() -> None:
    # Beams 180, 181, 182 at 2.0, 2.01, 2.02 m: mean rho 2.01, mean alpha +0.5 deg.
    c = run(scan(b180=2.0, b181=2.01, b182=2.02))
    assert len(c) == 1
    assert c.mean_rho[0] == pytest.approx(2.01, abs=1e-6)
    assert c.mean_alpha[0] == pytest.approx(HALF_DEG)
    expected = (2.01 * math.cos(HALF_DEG), 2.01 * math.sin(HALF_DEG))
    np.testing.assert_allclose(c.centre[0], expected, atol=1e-6)


def test_sk_is_the_box_of_every_point() -> None:
    # A wall seen obliquely: ranges grow along the scan, so the nearest point is at one end
    # and the farthest at the other. Every point's cell must be inside S_k.
    pose = (0.3, -0.2, 0.4)
    beams = {f"b{i}": 1.0 + 0.01 * (i - 150) for i in range(150, 200)}
    c = run(scan(**beams), pose=pose, params=PerceptionParams(gap_floor=0.05, min_beams=1))
    assert len(c) == 1
    idx = np.arange(150, 200)
    rho = 1.0 + 0.01 * (idx - 150)
    ang = pose[2] + A_MIN + idx * HALF_DEG
    gx = grid_index(pose[0] + rho * np.cos(ang), 0.5)
    gy = grid_index(pose[1] + rho * np.sin(ang), 0.5)
    assert c.box[0].tolist() == [gx.min(), gx.max(), gy.min(), gy.max()]
    assert c.area[0] == (gx.max() - gx.min() + 1) * (gy.max() - gy.min() + 1)


# --- window and readings ----------------------------------------------------------------


def test_beams_beyond_the_window_and_without_return_are_ignored() -> None:
    r = scan(b100=3.9, b101=3.91, b102=4.05, b103=np.nan, b104=8.0, b105=0.01)
    c = run(r)  # window 4.0 m, range_min 0.05, range_max 8.0
    assert len(c) == 1
    assert c.beams[0].tolist() == [100, 101]
    assert c.n_beams[0] == 2


def test_empty_scan_gives_an_empty_chain() -> None:
    c = run(scan(b10=5.0))
    assert len(c) == 0
    assert c.centre.shape == (0, 2)
    assert c.box.shape == (0, 4)


def test_min_beams_drops_specks_and_keeps_the_rest_intact() -> None:
    params = PerceptionParams(min_beams=3)
    c = run(scan(b50=2.0, b100=2.0, b101=2.0, b102=2.0, b200=1.0, b201=1.0), params=params)
    assert len(c) == 1
    assert c.beams[0].tolist() == [100, 102]
    assert c.mean_rho[0] == pytest.approx(2.0)


def test_a_dropped_beam_splits_with_the_paper_threshold() -> None:
    # consecutive available points two steps apart are 2 sin(0.25 deg)... > 1.2 sin(0.5 deg)
    c = run(scan(b100=2.0, b101=2.0, b103=2.0, b104=2.0))
    assert len(c) == 2


# --- edges of a cluster -----------------------------------------------------------------


def test_edge_codes() -> None:
    # A: beams 10-20 at 2 m; beam 9 has no return (free), beam 21 is a nearer object (B).
    # B: beams 21-25 at 1 m, beam 26 is farther (A continues) -> free both sides.
    # C: beams 26-30 at 2 m; beam 31 at 4.02 m continues the surface beyond the window.
    r = scan()
    r[10:21] = 2.0
    r[21:26] = 1.0
    r[26:31] = 2.0
    r[31] = 4.2  # outside the window, far from C's end: free
    r[100:111] = np.linspace(3.9, 4.0, 11)
    r[111] = 4.01  # outside, next point of the same surface: clipped
    r[350:361] = 2.0  # touches the end of the scan: clipped
    c = run(r)
    assert [tuple(b) for b in c.beams.tolist()] == [
        (10, 20), (21, 25), (26, 30), (100, 110), (350, 360),
    ]  # fmt: skip
    assert c.edge_start.tolist() == [EDGE_FREE, EDGE_FREE, EDGE_OCCLUDED, EDGE_FREE, EDGE_FREE]
    assert c.edge_end.tolist() == [EDGE_OCCLUDED, EDGE_FREE, EDGE_FREE, EDGE_CLIPPED, EDGE_CLIPPED]
    assert c.partial.tolist() == [True, False, True, True, True]


def test_chord_centre_and_radius() -> None:
    c = run(scan(b170=2.0, b180=2.0, b190=2.0), params=PerceptionParams(gap_floor=1.0))
    assert len(c) == 1
    mid = 0.5 * (c.first_point[0] + c.last_point[0])
    np.testing.assert_allclose(c.chord_centre[0], mid)
    half = 2.0 * math.sin(math.radians(5.0))  # half the chord of +-5 degrees at 2 m
    assert c.radius[0] == pytest.approx(half, rel=1e-6)


# --- properties ---------------------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(
    rho_prev=st.floats(0.3, 3.9),
    rho_cur=st.floats(0.3, 3.9),
    step_deg=st.floats(0.1, 2.0),
    x=st.floats(-10, 10),
    y=st.floats(-10, 10),
    heading=st.floats(-math.pi, math.pi),
    floor=st.sampled_from([0.0, 0.05, 0.15]),
)
def test_two_points_split_exactly_when_farther_than_the_threshold(
    rho_prev: float,
    rho_cur: float,
    step_deg: float,
    x: float,
    y: float,
    heading: float,
    floor: float,
) -> None:
    inc = math.radians(step_deg)
    params = PerceptionParams(gap_floor=floor, min_beams=1)
    ranges = np.array([rho_prev, rho_cur])
    r32 = ranges.astype(np.float32).astype(np.float64)
    dist = math.sqrt(r32[0] ** 2 + r32[1] ** 2 - 2 * r32[0] * r32[1] * math.cos(inc))
    theta = params.lambda_ * r32[1] * math.sin(inc) + floor
    assume(abs(dist - theta) > 1e-6)
    c = cluster_scan(ranges.astype(np.float32), 0.0, inc, 0.05, 8.0, (x, y, heading), params)
    assert len(c) == (2 if dist > theta else 1)


@settings(max_examples=100, deadline=None)
@given(
    rho=st.floats(0.5, 3.5),
    n1=st.integers(2, 30),
    n2=st.integers(2, 30),
    gap_beams=st.integers(0, 20),
    jump=st.floats(-0.5, 0.5),
)
def test_two_surfaces_split_on_a_range_jump_above_the_threshold(
    rho: float, n1: int, n2: int, gap_beams: int, jump: float
) -> None:
    # Two arcs at rho and rho + jump, with gap_beams beams without return between them.
    assume(0.3 <= rho + jump <= 3.9)
    params = PerceptionParams()
    r = np.full(n1 + gap_beams + n2, np.inf)
    r[:n1] = rho
    r[n1 + gap_beams :] = rho + jump
    c = cluster_scan(r, 0.0, HALF_DEG, 0.05, 8.0, (0.0, 0.0, 0.0), params)
    a, b = rho, rho + jump
    sep = HALF_DEG * (gap_beams + 1)
    dist = math.sqrt(a * a + b * b - 2 * a * b * math.cos(sep))
    theta = params.lambda_ * b * math.sin(HALF_DEG) + params.gap_floor
    assume(abs(dist - theta) > 1e-6)
    assert len(c) == (2 if dist > theta else 1)
    assert int(c.n_beams.sum()) == n1 + n2


@settings(max_examples=100, deadline=None)
@given(
    ranges=st.lists(st.floats(0.1, 9.0), min_size=1, max_size=80),
    pose=st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(-4, 4)),
)
def test_chain_invariants(ranges: list[float], pose: tuple[float, float, float]) -> None:
    c = cluster_scan(np.asarray(ranges), A_MIN, HALF_DEG, 0.05, 8.0, pose, PerceptionParams())
    n = len(c)
    assert c.box.shape == (n, 4)
    assert np.all(c.box[:, 0] <= c.box[:, 1])
    assert np.all(c.box[:, 2] <= c.box[:, 3])
    assert np.array_equal(c.area, box_area(c.box))
    assert np.all(c.n_beams >= 2)
    assert np.all(c.beams[:, 0] <= c.beams[:, 1])
    assert np.all(np.diff(c.beams[:, 0]) > 0)  # scan order
    assert np.all(c.mean_rho <= 4.0 + 1e-9)
    assert np.all(c.radius >= 0.0)
    # Eq. 5 + Eq. 1: the centre lies at mean_rho from the robot
    d = np.hypot(c.centre[:, 0] - pose[0], c.centre[:, 1] - pose[1])
    np.testing.assert_allclose(d, c.mean_rho, atol=1e-9)


# --- the seam of a full-circle scan ------------------------------------------------------


def disc_scan(centre: tuple[float, float], radius: float, pose: tuple[float, float, float],
              n: int = 721) -> np.ndarray:
    """A 360-degree scan (beam 0 and beam n - 1 both straight behind, as the simulator's)
    of one disc, 8 m (no return) elsewhere."""
    alpha = -math.pi + HALF_DEG * np.arange(n) + pose[2]
    ox, oy = centre[0] - pose[0], centre[1] - pose[1]
    b = np.cos(alpha) * ox + np.sin(alpha) * oy
    d = b * b - (ox * ox + oy * oy - radius * radius)
    near = b - np.sqrt(np.maximum(d, 0.0))
    return np.where((d >= 0) & (near > 0), near, 8.0)


def test_full_circle_counts_one_turn_and_only_full_circles() -> None:
    assert full_circle(721, HALF_DEG) == 720  # -pi..pi, the last beam repeats the first
    assert full_circle(720, HALF_DEG) == 720
    assert full_circle(720, -HALF_DEG) == 720
    assert full_circle(361, HALF_DEG) == 0  # the paper's 180 degrees
    assert full_circle(719, HALF_DEG) == 0
    assert full_circle(100, math.radians(0.7)) == 0  # 2 pi is no whole number of steps


def test_a_disc_straight_behind_is_cut_by_the_seam_of_the_scan_as_it_comes() -> None:
    pose = (0.0, 0.0, 0.0)
    c = cluster_scan(disc_scan((-2.0, 0.0), 0.3, pose), -math.pi, HALF_DEG, 0.05, 8.0, pose,
                     PerceptionParams())
    assert len(c) == 2  # what perception turns the scan for
    assert c.beams[0, 0] == 0 and c.beams[1, 1] == 720


def test_the_turned_scan_starts_in_the_widest_break_and_keeps_every_direction() -> None:
    pose = (1.0, 2.0, 0.3)
    # straight behind the robot, across the seam, and one to its left
    behind_at = (1.0 - 2.0 * math.cos(0.3), 2.0 - 2.0 * math.sin(0.3))
    r = np.minimum(disc_scan(behind_at, 0.3, pose), disc_scan((1.0, 4.0), 0.2, pose))
    params = PerceptionParams()
    window = scan_window(r, -math.pi, HALF_DEG, 0.05, 8.0, pose, params.window_radius)
    c = cluster_window(window, HALF_DEG, pose, params)
    assert len(c) == 3  # the disc behind in two, the one to the left
    shift = seam_shift(c, window, HALF_DEG, params)
    assert shift is not None
    # The widest break between clusters that follow each other, and its middle beam.
    gaps = c.beams[1:, 0] - c.beams[:-1, 1]
    i = int(np.argmax(gaps))
    assert c.beams[i, 1] < shift < c.beams[i + 1, 0]
    turned, angle_min = rotate_scan(window.ranges, -math.pi, HALF_DEG, shift)
    assert turned.shape == (720,) and angle_min == -math.pi + shift * HALF_DEG
    # Beam k of the turned scan looks where beam (k + shift) mod 720 looked.
    k = np.arange(720)
    assert np.array_equal(turned, window.ranges[(k + shift) % 720])
    again = cluster_scan(turned, angle_min, HALF_DEG, 0.05, 8.0, pose, params)
    assert len(again) == 2
    # the whole disc behind: its chord centre within radius^2 / distance of its centre
    behind = int(np.argmin(np.hypot(*(again.chord_centre - behind_at).T)))
    # (not a half: the sliver either side of the seam has its chord centre 0.14 m aside)
    assert np.hypot(*(again.chord_centre[behind] - behind_at)) < 0.1
    assert again.radius[behind] == pytest.approx(0.3, abs=0.03)
    assert again.edge_start[behind] == EDGE_FREE and again.edge_end[behind] == EDGE_FREE


def test_the_seam_is_left_where_it_lies_at_a_break() -> None:
    pose = (0.0, 0.0, 0.0)
    params = PerceptionParams()
    r = np.minimum(disc_scan((0.0, -1.5), 0.3, pose), disc_scan((0.0, 1.5), 0.3, pose))
    window = scan_window(r, -math.pi, HALF_DEG, 0.05, 8.0, pose, params.window_radius)
    assert seam_shift(cluster_window(window, HALF_DEG, pose, params), window, HALF_DEG,
                      params) is None
    # nor is a scan that is no full circle turned
    half = scan_window(disc_scan((-2.0, 0.0), 0.3, pose)[:361], -math.pi, HALF_DEG, 0.05,
                       8.0, pose, params.window_radius)
    assert seam_shift(cluster_window(half, HALF_DEG, pose, params), half, HALF_DEG,
                      params) is None


def test_perception_sees_what_stands_or_walks_straight_behind_whole() -> None:
    # The robot drives on at 1 m/s with a disc straight behind it, across the seam of
    # every scan: a post it leaves behind, then a walker that follows it 2 m back.
    for walks in (False, True):
        perceiver = Perceiver(PerceptionParams())
        moved = []
        for k in range(12):
            pose = (0.1 * k, 0.0, 0.0)
            disc = (-2.0 + (0.1 * k if walks else 0.0), 0.0)
            scan = LaserScan(seq=k, frame="laser", stamp=0.1 * k, angle_min=-math.pi,
                             angle_max=math.pi, angle_increment=HALF_DEG, range_min=0.05,
                             range_max=8.0, ranges=disc_scan(disc, 0.3, pose).tolist())
            c = perceiver.process(scan, pose)
            assert len(c) == 1
            assert c.radius[0] == pytest.approx(0.3, abs=0.05)
            assert abs(c.chord_centre[0, 1]) < 1e-6
            assert disc[0] < c.chord_centre[0, 0] < disc[0] + 0.3
            assert c.moved is not None
            moved.append(float(c.moved[0]))
        # Every scan is turned (the disc lies across its seam); the motion cue compares
        # the turned scans: the post never moved, the walker has from the first
        # comparison (0.2 s) on.
        if walks:
            assert min(moved[2:]) > 0.5
        else:
            assert max(moved) == 0.0
