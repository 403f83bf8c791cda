"""A mover pressed against something standing gets a cluster of its own: the cuts
(``moving_cuts``), the clustering that makes them (``cluster_window(..., cuts)``), the
motion cue's two tests per point (``MotionCue.point_motion``) and perception as it runs
them (``Perceiver.process``)."""

from __future__ import annotations

import math

import numpy as np

from zenav.schemas.messages import LaserScan
from zenav.services.perception.clustering import (
    EDGE_FREE,
    EDGE_OCCLUDED,
    Window,
    cluster_window,
    moving_cuts,
    scan_window,
)
from zenav.services.perception.motion_cue import MotionCue, ScanSnapshot
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.sim.raycast import simulate_scan
from zenav.sim.world import WorldSnapshot

ANGLES = -math.pi / 2 + math.radians(0.5) * np.arange(361)


def line(n: int, start: float = 0.0, step: float = 0.1) -> np.ndarray:
    """``n`` points along +y from (3, start), ``step`` m apart."""
    return np.column_stack([np.full(n, 3.0), start + step * np.arange(n)])


def flags(text: str) -> np.ndarray:
    return np.array([c == "x" for c in text])


def test_a_mover_beside_a_wall_is_cut_off_on_the_wall_side_only() -> None:
    # Ten wall points that stayed (0.9 m), five that moved, five seen for the first time.
    entered = flags("..........xxxxx.....")
    stayed = flags("xxxxxxxxxx..........")
    cuts = moving_cuts(np.array([0]), np.array([19]), entered, stayed, line(20), 3, 0.5)
    assert cuts.tolist() == [10]


def test_a_mover_between_two_jambs_is_cut_off_on_both_sides() -> None:
    entered = flags("......xxxxxx......")
    stayed = flags("xxxxxx......xxxxxx")
    cuts = moving_cuts(np.array([0]), np.array([17]), entered, stayed, line(18), 3, 0.5)
    assert cuts.tolist() == [6, 12]


def test_no_cut_where_the_still_side_is_narrower_than_a_walker_or_the_run_short() -> None:
    # A walker that stood 2 s ago: its trailing points stayed, over 0.4 m only.
    walker = moving_cuts(np.array([0]), np.array([9]), flags("xxxxx....."),
                         flags(".....xxxxx"), line(10), 3, 0.5)
    # Two moving points in a wall: noise, not a mover.
    speck = moving_cuts(np.array([0]), np.array([19]), flags("..........xx........"),
                        flags("xxxxxxxxxx..xxxxxxxx"), line(20), 3, 0.5)
    assert walker.size == 0 and speck.size == 0


def test_each_cluster_is_cut_within_its_own_points() -> None:
    # Two clusters back to back: the first all wall, the second wall then mover.
    entered = flags("........" + "......xxxx")
    stayed = flags("xxxxxxxx" + "xxxxxx....")
    cuts = moving_cuts(np.array([0, 8]), np.array([7, 17]), entered, stayed, line(18), 3, 0.5)
    assert cuts.tolist() == [14]


def wall_window() -> tuple[Window, PerceptionParams]:
    """A scan of one wall 3 m ahead, across the whole view's middle."""
    world = WorldSnapshot.build(discs=[], boxes=[(3.0, -1.0, 3.2, 1.0)])
    ranges = simulate_scan((0.0, 0.0), 0.0, ANGLES, world, 8.0, 0.0, np.random.default_rng(0))
    params = PerceptionParams()
    window = scan_window(ranges, -math.pi / 2, math.radians(0.5), 0.0, 8.0, (0.0, 0.0, 0.0),
                         params.window_radius)
    return window, params


def test_cluster_window_cuts_where_told_and_codes_the_cut_ends_occluded() -> None:
    window, params = wall_window()
    whole = cluster_window(window, math.radians(0.5), (0.0, 0.0, 0.0), params)
    assert len(whole) == 1
    middle = int(np.searchsorted(window.beams, whole.beams[0, 0])) + 20
    cut = cluster_window(window, math.radians(0.5), (0.0, 0.0, 0.0), params,
                         np.array([middle]))
    assert len(cut) == 2
    assert cut.beams[0, 0] == whole.beams[0, 0] and cut.beams[1, 1] == whole.beams[0, 1]
    assert cut.beams[1, 0] == window.beams[middle] == cut.beams[0, 1] + 1
    assert cut.edge_end[0] == EDGE_OCCLUDED and cut.edge_start[1] == EDGE_OCCLUDED
    assert cut.edge_start[0] == whole.edge_start[0] == EDGE_FREE
    assert int(cut.n_beams.sum()) == int(whole.n_beams[0])


def test_point_motion_tells_entered_from_stayed_against_the_oldest_scan() -> None:
    cue = MotionCue((0.5, 2.0), margin=0.1, reach=0.3, window_radius=4.0)
    ranges = np.full(181, 8.0)
    ranges[80:101] = 3.0  # a wall 3 m ahead, +-10 degrees
    beam0 = ScanSnapshot(0.0, (0.0, 0.0, 0.0), ranges, -math.pi / 2, math.pi / 180, 8.0)
    cue.score_each(beam0, 0.0, np.array([[80, 100]]))
    points = np.array([[2.0, 0.0], [3.0, 0.0], [3.0, 1.0]])  # before the wall, on it, beside
    assert cue.point_motion(1.0, points) is None  # no scan 2 s old yet
    motion = cue.point_motion(2.0, points)
    assert motion is not None
    entered, stayed = motion
    # before the wall and beside it the beams went past; only the wall stood there
    assert entered.tolist() == [True, False, True]
    assert stayed.tolist() == [False, True, False]


def jamb_scans(params: PerceptionParams) -> list[int]:
    """A walker (0.25 m) comes at 0.4 m/s through a door beside its jamb, 0.07 m from
    it, toward the standing robot: the clusters per scan (two walls and the walker, or
    fewer where the walker joins a wall), from when the walker is first seen."""
    perceiver = Perceiver(params)
    rng = np.random.default_rng(3)
    counts = []
    for i in range(45):
        t = 0.1 * i
        world = WorldSnapshot.build(discs=[(4.5 - 0.4 * t, 0.32, 0.25)],
                                    boxes=[(3.0, -2.0, 3.2, 0.0), (3.0, 1.2, 3.2, 3.0)])
        ranges = simulate_scan((0.0, 0.0), 0.0, ANGLES, world, 8.0, 0.01, rng)
        scan = LaserScan(stamp=t, seq=i, frame="laser", angle_min=-math.pi / 2,
                         angle_max=math.pi / 2, angle_increment=math.radians(0.5),
                         range_min=0.0, range_max=8.0, ranges=ranges)
        counts.append(len(perceiver.process(scan, (0.0, 0.0, 0.0))))
    return counts[10:]  # the walker within the 4 m window from t = 1 s


def test_perception_keeps_a_walker_at_a_jamb_apart_from_the_wall() -> None:
    # As it passes the jamb the paper's joining rule with the 0.15 m floor joins walker
    # and wall for a few scans; with the cut the walker keeps a cluster of its own.
    joined = jamb_scans(PerceptionParams(motion_split_span=0.0))
    apart = jamb_scans(PerceptionParams())
    assert 2 in joined
    assert set(apart) == {3}
