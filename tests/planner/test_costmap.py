"""The occupancy map: ray-traced free space, marked returns, movers left out, decay,
confirmation, inflation and growth (pure, hand-made scans)."""

from __future__ import annotations

import math

import numpy as np

from tests.planner.scans import scan_of
from zenav.services.planner.costmap import FREE, OCCUPIED, UNKNOWN, Costmap


def fresh(confirm: float = 0.0, decay: float = 60.0) -> Costmap:
    return Costmap((0.0, 0.0), (6.0, 0.0), resolution=0.1, decay=decay, inflation=0.35,
                   confirm=confirm, padding=2.0, max_size=100.0)


def value_at(cm: Costmap, x: float, y: float) -> int:
    i, j = cm.cell_of(np.array([[x, y]]))[0]
    return int(cm.values()[i, j])


def test_a_wall_ahead_is_occupied_the_way_to_it_free_and_behind_it_unknown() -> None:
    cm = fresh()
    cm.update(scan_of((0.0, 0.0, 0.0), boxes=[(3.0, -1.0, 3.2, 1.0)]), 0.0)
    assert value_at(cm, 1.5, 0.0) == FREE
    assert value_at(cm, 2.7, 0.5) == FREE
    assert value_at(cm, 3.05, 0.0) == OCCUPIED
    assert value_at(cm, 4.0, 0.0) == UNKNOWN  # behind the wall: never seen
    assert value_at(cm, -1.0, 0.0) == UNKNOWN  # behind the robot: the laser sees 180 deg
    # Inflated by the inflation distance, not more: the robot's centre keeps 0.35 m off.
    assert cm.blocked_at(np.array([[2.75, 0.0]]))[0]
    assert not cm.blocked_at(np.array([[2.55, 0.0]]))[0]


def test_returns_on_a_mover_are_not_marked() -> None:
    cm = fresh()
    cm.update(scan_of((0.0, 0.0, 0.0), discs=[(2.0, 0.0, 0.3)]), 0.0,
              movers=[(2.0, 0.0, 0.3)])
    assert not cm.lethal().any()
    cm.update(scan_of((0.0, 0.0, 0.0), discs=[(2.0, 0.0, 0.3)]), 0.1)
    assert cm.lethal().any()  # the same returns, not on a known mover: marked


def test_a_return_counts_once_confirmed_and_a_cell_left_unseen_decays_to_unknown() -> None:
    cm = fresh(confirm=1.0, decay=5.0)
    box = [(2.0, -0.5, 2.5, 0.5)]
    cm.update(scan_of((0.0, 0.0, 0.0), boxes=box), 0.0)
    assert not cm.lethal().any()
    cm.update(scan_of((0.0, 0.0, 0.0), boxes=box), 1.0)
    assert cm.lethal().any()
    # Turned away: nothing refreshes those cells; after the decay time they are unknown.
    cm.update(scan_of((0.0, 0.0, math.pi)), 3.0)
    assert cm.lethal().any()
    cm.update(scan_of((0.0, 0.0, math.pi)), 7.0)
    assert not cm.lethal().any()
    assert value_at(cm, 2.0, 0.0) == UNKNOWN


def test_a_moving_front_beyond_any_track_leaves_no_confirmed_wake() -> None:
    cm = fresh(confirm=1.0)
    for k in range(30):  # a disc crossing at 0.5 m/s, 5 m ahead, never typed
        t = k * 0.1
        cm.update(scan_of((0.0, 0.0, 0.0), discs=[(5.0, -1.5 + 0.5 * t, 0.25)]), t)
    assert not cm.lethal().any()


def test_the_grid_grows_to_hold_what_is_seen_and_where_the_robot_goes() -> None:
    cm = fresh()
    before = cm.shape
    cm.update(scan_of((0.0, 0.0, math.pi / 2), boxes=[(-0.5, 6.0, 0.5, 6.2)]), 0.0)
    assert cm.shape[1] > before[1]
    assert value_at(cm, 0.0, 6.05) == OCCUPIED


def test_a_straight_wall_seen_side_on_from_close_by_is_confirmed_along_its_face() -> None:
    # The robot stands 0.33 m from a long wall, facing it a little askew: the beams far
    # to either side meet the wall at a grazing angle and pass through the face cells
    # that the beams nearer the normal return from. Those returns must still confirm.
    cm = fresh(confirm=1.0)
    wall = [(0.33, -3.0, 0.53, 3.0)]
    for k in range(11):  # 1 s of scans at 10 Hz, noisy as the simulated laser
        cm.update(scan_of((0.0, 0.0, 0.2), boxes=wall, noise=0.01, seed=k), 0.1 * k)
    face = np.array([[0.35, y] for y in np.arange(-1.25, 1.3, 0.1)])
    assert cm.lethal_at(face).all()
    assert cm.blocked_at(np.array([[0.05, 0.0]]))[0]  # and the robot is in its inflation


def walled(wall_confirm: float = 3.0) -> Costmap:
    return Costmap((0.0, 0.0), (6.0, 0.0), resolution=0.1, decay=5.0, inflation=0.35,
                   confirm=1.0, wall_decay=50.0, wall_confirm=wall_confirm, padding=2.0,
                   max_size=100.0)


def see(cm: Costmap, boxes: list[tuple[float, float, float, float]], start: float,
        end: float) -> None:
    """Scans from the origin facing +x every 0.5 s from ``start`` to ``end``."""
    for k in range(round((end - start) / 0.5) + 1):
        cm.update(scan_of((0.0, 0.0, 0.0), boxes=boxes), start + 0.5 * k)


def test_a_wall_seen_long_enough_outlives_the_decay_until_its_own_decay_time() -> None:
    cm = walled()
    box = [(2.0, -0.5, 2.5, 0.5)]
    see(cm, box, 0.0, 3.0)  # returns for 3 s: a wall kept past the decay
    cm.update(scan_of((0.0, 0.0, math.pi)), 9.0)  # turned away, past the decay
    assert value_at(cm, 2.05, 0.0) == OCCUPIED
    assert value_at(cm, 1.0, 0.0) == UNKNOWN  # free space decays as before
    cm.update(scan_of((0.0, 0.0, math.pi)), 54.0)  # past the wall's decay
    assert not cm.lethal().any()


def test_a_wall_seen_briefly_decays_like_the_rest() -> None:
    cm = walled()
    see(cm, [(2.0, -0.5, 2.5, 0.5)], 0.0, 2.0)  # a wall (1 s), but seen for 2 s only
    assert cm.lethal().any()
    cm.update(scan_of((0.0, 0.0, math.pi)), 8.0)
    assert not cm.lethal().any()


def test_recovery_s_clearing_keeps_the_walls_seen_long_and_a_beam_clears_them() -> None:
    cm = walled()
    box, post = [(2.0, -0.5, 2.5, 0.5)], [(4.0, 2.0, 4.2, 2.2)]
    see(cm, box, 0.0, 1.5)
    see(cm, box + post, 2.0, 3.5)  # the post: a wall, seen for 1.5 s only
    cm.forget_older_than(4.0)
    assert value_at(cm, 2.05, 0.0) == OCCUPIED  # the long-seen wall is kept
    assert not cm.has_returns_in(np.array([3.9, 1.9]), np.array([4.3, 2.3]))  # forgotten
    cm.update(scan_of((0.0, 0.0, 0.0)), 4.5)  # the box is gone: the beams pass through
    assert value_at(cm, 2.05, 0.0) == FREE


def test_returns_not_yet_confirmed_are_found_near_a_segment() -> None:
    cm = fresh(confirm=1.0)
    cm.update(scan_of((0.0, 0.0, 0.0), boxes=[(3.0, 0.6, 3.2, 1.0)]), 0.0)
    assert not cm.lethal().any()  # one scan: not confirmed
    lo, hi = np.array([2.5, 0.0]), np.array([3.5, 1.5])
    assert cm.has_returns_in(lo, hi)
    assert not cm.has_returns_in(np.array([0.0, -1.0]), np.array([1.0, 0.0]))
    a, b = np.array([0.0, 0.0]), np.array([5.0, 0.0])  # passes 0.6 m below the face
    assert not cm.returns_near_segment(a, b, 0.35)
    assert cm.returns_near_segment(a, b, 0.7)
    assert cm.returns_near_segment(a, np.array([3.1, 0.8]), 0.35)  # into it
    assert not cm.returns_near_segment(a, np.array([3.1, 0.8]), 0.35,
                                       np.array([0.0, -1.0]), np.array([1.0, 0.0]))


def test_a_scan_s_returns_are_where_its_beams_met_something_in_the_global_frame() -> None:
    pose = (1.0, 2.0, math.pi / 2)  # facing +y
    scan = scan_of(pose, boxes=[(0.0, 4.0, 2.0, 4.2)], range_max=8.0)
    points = scan.returns
    hits = int(np.count_nonzero(scan.ranges < scan.range_max))
    assert 0 < hits < scan.ranges.shape[0] and points.shape == (hits, 2)
    assert np.allclose(points[:, 1], 4.0, atol=1e-9)  # on the wall's near face
    assert points[:, 0].min() >= -1e-9 and points[:, 0].max() <= 2.0 + 1e-9
    # The beam straight ahead returns at (1, 4).
    ahead = scan.ranges.shape[0] // 2
    before = int(np.count_nonzero(scan.ranges[:ahead] < scan.range_max))
    assert np.allclose(points[before], (1.0, 4.0))
