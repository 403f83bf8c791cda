"""Each of the paper's equations (1-15, 17) pinned twice: to numbers worked by hand, and to
the production path, which must call the very function pinned (a spy counts the calls; a
copy of the equation inlined elsewhere would leave the count at zero and fail here).
Where the production path is a compiled pass that computes an equation inside its loop
(Eqs. 1, 2, 3 and 6 in perception's window, runs and edges, written once in
``services/perception/_equations.pxi``, which the pinned functions call too; Eqs. 7-13
in tracking's ``best_match``), a spy cannot count: the test checks instead that what the
pass gives is, to the bit, what the pinned function gives for the same numbers.

The production paths are the ones the services run: ``Perceiver.process`` (perception's
node), ``Tracker.update`` (tracking's node) and ``Planner.step`` (the planner's node).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from tests.planner.scans import scan_of
from zenav.schemas.messages import LaserScan
from zenav.services.perception import clustering, motion_cue
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.services.planner import costmap, decide, morphin
from zenav.services.planner.params import Params as PlannerParams
from zenav.services.planner.prediction import Obstacle
from zenav.services.tracking import correlation, tracker
from zenav.services.tracking.params import TrackingParams

HALF_DEG = math.radians(0.5)
PAPER = PerceptionParams(gap_floor=0.0, min_beams=1, edge_inset=0.0)


class Spy:
    """Wraps ``module.name`` so that calls through the module are counted."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch, module: ModuleType, name: str) -> None:
        self.calls = 0
        real: Callable[..., Any] = getattr(module, name)

        def counted(*args: Any, **kwargs: Any) -> Any:
            self.calls += 1
            return real(*args, **kwargs)

        monkeypatch.setattr(module, name, counted)


# --- production paths ---------------------------------------------------------------


def perceive(ranges: list[float], pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
             params: PerceptionParams = PAPER, stamp: float = 0.0,
             perceiver: Perceiver | None = None) -> clustering.Clusters:
    """One scan through perception's own path (what its node calls per scan)."""
    # no return is range_max on the wire (a reading >= range_max counts as none)
    r = np.minimum(np.asarray(ranges, dtype=np.float32), np.float32(8.0))
    scan = LaserScan(stamp=stamp, seq=0, frame="laser", angle_min=0.0,
                     angle_max=HALF_DEG * (len(r) - 1), angle_increment=HALF_DEG,
                     range_min=0.05, range_max=8.0, ranges=r)
    return (perceiver or Perceiver(params)).process(scan, pose)


def track_two_frames(method: str = "paper") -> list[tracker.Track]:
    """Two frames of one obstacle that moved 0.5 m, through the tracker's update."""
    p = PerceptionParams()
    perceiver = Perceiver(p)
    track = tracker.Tracker(TrackingParams(method=method))
    out: list[tracker.Track] = []
    for i, rho in enumerate((2.0, 2.5)):
        ranges = [math.inf] * 40
        for b in range(10, 30):
            ranges[b] = rho
        clusters = perceive(ranges, stamp=i * 0.5, params=p, perceiver=perceiver)
        out = track.update(i * 0.5, (0.0, 0.0, 0.0), clusters)
    return out


def plan_round_a_box() -> decide.Decision:
    """The planner meeting a standing box on its way (scenario (b): Morphin, Eq. 17)."""
    planner = decide.Planner(PlannerParams(goal=(6.0, 0.0), start=(0.0, 0.0), confirm_time=0.0))
    box = Obstacle(id=1, kind="static", position=(2.0, 0.0), velocity=(0.0, 0.0), radius=0.3,
                   cells=(4, 4, 0, 0))
    return planner.step((0.0, 0.0, 0.0), [box], stamp=1.0)


# --- Eq. 1 --------------------------------------------------------------------------


def test_eq1_by_hand() -> None:
    # Robot at (1, 2) facing +y; a beam straight ahead (alpha 0) at 2 m ends at (1, 4);
    # the beam 90 degrees to the right (alpha -pi/2, the paper's 0 degrees) at (3, 2).
    x, y = clustering.to_global((1.0, 2.0, math.pi / 2), [2.0, 2.0], [0.0, -math.pi / 2])
    assert np.allclose(x, [1.0, 3.0]) and np.allclose(y, [4.0, 2.0])


POSE = (1.25, -0.75, 2.0)  # a pose where every term of Eq. 1 counts


def test_eq1_is_what_perception_computes() -> None:
    """The window's points (each cluster's first and last) and the Eq. 5 centres are
    Eq. 1 of their ranges and angles, to the bit."""
    ranges = [2.0, 2.0, 2.0, math.inf, 3.1, 3.1, 3.1]
    c = perceive(ranges, pose=POSE)
    assert len(c) == 2
    cx, cy = clustering.to_global(POSE, c.mean_rho, c.mean_alpha)
    assert c.centre.tobytes() == np.column_stack((cx, cy)).tobytes()
    beams = c.beams.reshape(-1)
    rho = np.asarray(ranges, dtype=np.float32).astype(np.float64)  # as on the wire
    px, py = clustering.to_global(POSE, rho[beams], beams * HALF_DEG)
    ends = np.column_stack((px, py)).reshape(-1, 2, 2)
    assert c.first_point.tobytes() == ends[:, 0].copy().tobytes()
    assert c.last_point.tobytes() == ends[:, 1].copy().tobytes()


def test_eq1_is_what_the_motion_cue_uses(monkeypatch: pytest.MonkeyPatch) -> None:
    """The free-space motion test puts each scan's points in the global frame by Eq. 1
    too: perception hands it the window's points the clustering made global
    (``scan_window``), one Eq. 1 pass for both; the cue makes none of its own."""
    own = Spy(monkeypatch, motion_cue, "to_global")
    perceiver = Perceiver(PAPER)
    ranges = [2.0, 2.0, 2.0]
    perceive(ranges, pose=POSE, perceiver=perceiver)
    assert own.calls == 0
    _, _, kept = perceiver.cue._scans[-1]
    px, py = clustering.to_global(POSE, ranges, np.arange(3) * HALF_DEG)
    assert kept.tobytes() == np.column_stack((px, py)).tobytes()


def test_the_motion_cue_points_are_eq1() -> None:
    # Robot at (1, 2) facing +y, beams 0 and 2 at alpha -90 and -89 degrees (0.5 degree
    # step from -90): beam 0 at 2 m ends at (3, 2), beam 2 at 4 m at
    # (1 + 4 cos 1 deg, 2 + 4 sin 1 deg) = (4.999391, 2.069810).
    snap = motion_cue.ScanSnapshot(0.0, (1.0, 2.0, math.pi / 2), np.array([2.0, 9.0, 4.0]),
                                   -math.pi / 2, HALF_DEG, 8.0)
    assert snap.points(np.array([0, 2])) == pytest.approx(
        np.array([[3.0, 2.0], [4.999391, 2.069810]]), abs=1e-6)


def test_the_compiled_loops_wrap_as_geometry_does() -> None:
    """The motion cue's bearings and the safety roll-out's heading errors are wrapped in
    compiled code (``services/_angles.pxi``); that wrap gives what geometry.py's does,
    to the bit, at the edges of the range and far beyond it."""
    from zenav.services import _angles
    from zenav.services.geometry import wrap_angles

    edges = np.array([0.0, -0.0, math.pi, -math.pi, 2 * math.pi, -2 * math.pi,
                      3 * math.pi, -3 * math.pi, np.nextafter(math.pi, 4.0),
                      np.nextafter(-math.pi, -4.0), 1e-17, -1e-17, 1e6, -1e6, 123.456])
    angles = np.concatenate([edges, np.random.default_rng(0).uniform(-50.0, 50.0, 1000)])
    wrapped = _angles.wrap_angles(angles)
    assert np.array_equal(wrapped, wrap_angles(angles))
    assert ((wrapped > -math.pi) & (wrapped <= math.pi)).all()


def test_eq1_is_what_the_map_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    """The planner's occupancy map (beyond the paper) places each return by Eq. 1 too:
    a wall 3 m ahead of a robot at (0, 0) facing +x is marked at x = 3."""
    spy = Spy(monkeypatch, costmap, "to_global")
    cm = costmap.Costmap((0.0, 0.0), (6.0, 0.0), resolution=0.1, decay=60.0, inflation=0.35,
                         confirm=0.0, padding=2.0, max_size=100.0)
    cm.update(scan_of((0.0, 0.0, 0.0), boxes=[(3.0, -1.0, 3.2, 1.0)]), 0.0)
    # each beam's direction, once; a return lies at its range along that direction
    assert spy.calls == 1
    i, j = cm.cell_of(np.array([[3.05, 0.0]]))[0]
    assert int(cm.values()[i, j]) == costmap.OCCUPIED


def test_eq1_is_what_tracking_calls_to_join_pieces(monkeypatch: pytest.MonkeyPatch) -> None:
    """The tracker's centre of an obstacle in two pieces goes through Eq. 1 too."""
    spy = Spy(monkeypatch, tracker, "to_global")
    t = tracker.Tracker(TrackingParams())
    m = t._measure([0, 1], _two_pieces(), (0.0, 0.0, 0.0), False)
    assert spy.calls == 1
    # beam-weighted mean rho (2*2 + 2*3) / 4 = 2.5 and alpha (2*0 + 2*0.1) / 4 = 0.05
    assert m.centre == pytest.approx((2.5 * math.cos(0.05), 2.5 * math.sin(0.05)))


def _two_pieces() -> clustering.Clusters:
    f = np.array
    return clustering.Clusters(
        centre=f([[2.0, 0.0], [3.0, 0.3]]), mean_rho=f([2.0, 3.0]), mean_alpha=f([0.0, 0.1]),
        box=f([[4, 4, 0, 0], [6, 6, 1, 1]]), area=f([1, 1]), beams=f([[0, 1], [2, 3]]),
        n_beams=f([2, 2]), first_point=f([[2.0, 0.0], [3.0, 0.3]]),
        last_point=f([[2.0, 0.0], [3.0, 0.3]]), chord_centre=f([[2.0, 0.0], [3.0, 0.3]]),
        radius=f([0.1, 0.1]), edge_start=f([0, 0]), edge_end=f([0, 0]),
        pose=(0.0, 0.0, 0.0), cell=0.5)


# --- Eq. 2 --------------------------------------------------------------------------


def test_eq2_by_hand() -> None:
    # floor(x / 0.5 + 1/2): 0.24 -> floor(0.98) = 0, 0.26 -> floor(1.02) = 1,
    # -0.26 -> floor(-0.02) = -1, 1.74 -> floor(3.98) = 3
    assert clustering.grid_index([0.24, 0.26, -0.26, 1.74], 0.5).tolist() == [0, 1, -1, 3]


def test_eq2_is_what_perception_computes() -> None:
    """Each cluster's grid box is Eq. 2 of the least and greatest x and y of its points
    (no edge inset), to the bit."""
    c = perceive([2.0, 2.0, 2.0, 2.0, 2.0], pose=POSE)
    assert len(c) == 1
    px, py = clustering.to_global(POSE, [2.0] * 5, np.arange(5) * HALF_DEG)
    want = clustering.grid_index([px.min(), px.max(), py.min(), py.max()], PAPER.cell)
    assert c.box[0].tolist() == want.tolist()


def test_eq2_is_what_morphin_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    in_morphin = Spy(monkeypatch, morphin, "grid_index")
    plan_round_a_box()
    assert in_morphin.calls >= 1


# --- Eq. 3 --------------------------------------------------------------------------


def test_eq3_by_hand() -> None:
    # theta = 1.2 * 2 m * sin(0.5 deg) = 2.4 * 0.0087265 = 0.0209437 m; the floor adds 0.15
    assert float(clustering.join_threshold(2.0, HALF_DEG, PAPER)) == pytest.approx(0.0209437,
                                                                                   abs=1e-7)
    floored = PerceptionParams()
    assert float(clustering.join_threshold(2.0, HALF_DEG, floored)) == pytest.approx(0.1709437,
                                                                                     abs=1e-7)


def test_eq3_decides_the_breaks() -> None:
    """Neighbouring points at 2 m lie 2 * 2 m * sin(0.25 deg) = 0.017453 m apart: under
    Eq. 3's threshold with the paper's lambda 1.2 (0.020944 m), one cluster; over it
    with lambda 0.9 (0.015708 m), a cluster per beam."""
    chord = 2 * 2.0 * math.sin(HALF_DEG / 2)
    wide, narrow = PAPER, PAPER.model_copy(update={"lambda_": 0.9})
    assert (float(clustering.join_threshold(2.0, HALF_DEG, narrow)) < chord
            < float(clustering.join_threshold(2.0, HALF_DEG, wide)))
    assert len(perceive([2.0, 2.0, 2.0], params=wide)) == 1
    assert len(perceive([2.0, 2.0, 2.0], params=narrow)) == 3


# --- Eq. 4 and Eq. 5: a worked obstacle chain ------------------------------------------


def test_eq4_worked_obstacle_chain() -> None:
    """Seven beams at 0, 0.5, ..., 3 degrees (robot at the origin facing +x), window 4 m:

    ranges 2, 2, 2, none, 3, 3, 6.

    * beams 0-2: neighbours 2 * 2 sin(0.25 deg) = 0.01745 m apart, under
      theta = 1.2 * 2 * sin(0.5 deg) = 0.02094 m (Eq. 3): one cluster O_1;
    * beam 3 has no return and is skipped: beam 2 is compared with beam 4, about 1 m
      apart, over theta = 1.2 * 3 * sin(0.5 deg) = 0.03142: a new cluster O_2;
    * beams 4-5: 3 * 2 sin(0.25 deg) = 0.02618 < 0.03142: both in O_2;
    * beam 6 (6 m) lies outside r_w = 4 m and is not clustered.

    O_chain(t) = {O_1, O_2} (Eq. 4). Eq. 5: O_1 has mean alpha 0.5 deg, mean rho 2, so
    Z_1 = (2 cos 0.5, 2 sin 0.5) = (1.999924, 0.017453); O_2 has 2.25 deg and 3 m,
    Z_2 = (2.997688, 0.117782). Eq. 2 / 6: O_1's points have x ~ 2.0, y in [0, 0.035]:
    cells x 4, y 0, S_1 = 1; O_2's x ~ 2.997, y in [0.105, 0.131]: x 6, y 0, S_2 = 1.
    """
    chain = perceive([2.0, 2.0, 2.0, math.inf, 3.0, 3.0, 6.0])
    assert len(chain) == 2
    assert chain.beams.tolist() == [[0, 2], [4, 5]]
    assert chain.n_beams.tolist() == [3, 2]
    assert chain.mean_rho == pytest.approx([2.0, 3.0], abs=1e-6)
    assert np.degrees(chain.mean_alpha) == pytest.approx([0.5, 2.25])
    assert chain.centre == pytest.approx(np.array([[1.999924, 0.017453],
                                                   [2.997688, 0.117782]]), abs=1e-5)
    assert chain.box.tolist() == [[4, 4, 0, 0], [6, 6, 0, 0]]
    assert chain.area.tolist() == [1, 1]


def test_eq5_by_hand() -> None:
    # runs [1, 2] and [3, 4] (alpha [0, 0.1] and [0.2, 0.3]): means 1.5, 3.5 and 0.05, 0.25
    rho, alpha = clustering.cluster_means(np.array([1.0, 2.0, 3.0, 4.0]),
                                          np.array([0.0, 0.1, 0.2, 0.3]),
                                          np.array([0, 2]), np.array([2, 2]))
    assert rho == pytest.approx([1.5, 3.5]) and alpha == pytest.approx([0.05, 0.25])


def test_eq5_is_what_perception_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    spy = Spy(monkeypatch, clustering, "cluster_means")
    perceive([2.0, 2.0, 2.0])
    assert spy.calls == 1


# --- Eq. 6 --------------------------------------------------------------------------


def test_eq6_by_hand() -> None:
    # x 2..4 (3 cells) by y 1..1 (1 cell) = 3; x 0..1 by y 0..2 = 2 * 3 = 6
    assert clustering.box_area([[2, 4, 1, 1], [0, 1, 0, 2]]).tolist() == [3, 6]


def test_eq6_is_what_perception_computes_and_tracking_calls(
        monkeypatch: pytest.MonkeyPatch) -> None:
    c = perceive([2.0, 2.0, math.inf, 1.0, 1.0, 1.0, 1.0], pose=POSE)
    assert len(c) == 2
    assert c.area.tolist() == clustering.box_area(c.box).tolist()
    in_correlation = Spy(monkeypatch, correlation, "box_area")
    track_two_frames()
    assert in_correlation.calls >= 1


# --- Eqs. 7-13 ------------------------------------------------------------------------
# S(t) = x 0..3, y 0..2 (12 cells); S(t-1) = x 2..5, y 1..4 (16 cells).
A = (0, 3, 0, 2)
B = (2, 5, 1, 4)


def test_eqs7_to_9_by_hand() -> None:
    # Eq. 9: sorted x bounds 0 2 3 5 -> x_b3 - x_b2 + 1 = 2; y bounds 0 1 2 4 -> 2; 4 cells
    assert int(correlation.overlap_cells(A, B)) == 4
    # Eq. 8: x_max(t-1) = 1 < x_min(t) = 3: no overlap
    assert int(correlation.overlap_cells((3, 4, 0, 1), (0, 1, 0, 1))) == 0
    # Eq. 7: the same box overlaps fully, S n S = S
    assert int(correlation.overlap_cells(A, A)) == 12


def test_eq10_and_11_by_hand() -> None:
    assert int(correlation.union_cells(12, 16, 4)) == 24  # 12 + 16 - 4
    assert float(correlation.coincidence(4, 12)) == pytest.approx(1 / 3)  # xi = 4 / 12


def test_eq12_and_13_by_hand() -> None:
    # eta = 1 - 4 / 24 = 0.833333; delta between (0, 0) and (0.3, 0.4) = 0.5 m = 1 cell
    assert float(correlation.non_overlap_rate(4, 24)) == pytest.approx(5 / 6)
    assert float(correlation.centre_distance((0.0, 0.0), (0.3, 0.4), 0.5)) == pytest.approx(1.0)
    # varsigma = 0.5 / (1 + 1) + 0.5 / (0.5 + 1) = 0.25 + 0.333333 = 0.583333
    assert float(correlation.spatial_correlation(1.0, 0.5)) == pytest.approx(0.5833333)


def test_best_match_by_hand() -> None:
    """The pair above through best_match (what the tracker calls): every quantity as
    worked out by hand."""
    best = correlation.best_match([(0.0, 0.0)], [A], [(0.3, 0.4)], [B], cell=0.5)
    assert best.index == [0]
    assert best.xi[0] == pytest.approx(1 / 3)  # Eq. 11, 4 / 12
    assert best.delta[0] == pytest.approx(1.0)  # Eq. 13, cells
    # Eq. 12 with eta = 1 - 4 / 24: 0.5 / 2 + 0.5 / (1 + 5/6) = 0.25 + 0.272727 = 0.522727
    assert best.varsigma_max[0] == pytest.approx(0.5227273)


def per_pair(cur: tuple[tuple[float, float], tuple[int, int, int, int]],
             prev: tuple[tuple[float, float], tuple[int, int, int, int]],
             cell: float) -> tuple[float, float, float]:
    """varsigma, delta and xi of one pair, equation by equation through the pinned
    functions (Eq. 6 from clustering)."""
    (cc, bc), (cp, bp) = cur, prev
    inter = correlation.overlap_cells(bc, bp)  # Eqs. 7-9
    area_c = clustering.box_area(bc)
    union = correlation.union_cells(area_c, clustering.box_area(bp), inter)  # Eq. 10
    xi = correlation.coincidence(inter, area_c)  # Eq. 11
    eta = correlation.non_overlap_rate(inter, union)  # Eq. 13
    delta = correlation.centre_distance(cc, cp, cell)  # Eq. 13
    return correlation.spatial_correlation(delta, eta), delta, xi  # Eq. 12


@pytest.mark.parametrize("seed", range(20))
def test_eqs7_to_13_are_what_tracking_calls(seed: int) -> None:
    """The tracker's best_match is compiled: it calls these very equation functions in
    C, where a spy cannot count. What it returns is, to the bit, their composition taken
    pair by pair in Python (a copy of an equation inlined in the kernel that differed in
    any operation would show here), and Eq. 14's first maximum of it."""
    rng = np.random.default_rng(seed)

    def chain(k: int) -> list[tuple[tuple[float, float], tuple[int, int, int, int]]]:
        out = []
        for _ in range(k):
            x, y = rng.normal(0.0, 2.0, 2).tolist()
            ix, iy = int(x / 0.5), int(y / 0.5)
            w, h = rng.integers(0, 4, 2).tolist()
            out.append(((x, y), (ix, ix + w, iy, iy + h)))
        return out

    cur, prev = chain(int(rng.integers(1, 7))), chain(int(rng.integers(1, 7)))
    prev[-1] = cur[0]  # a tie of the first maximum with an identical obstacle
    best = correlation.best_match([c for c, _ in cur], [b for _, b in cur],
                                  [c for c, _ in prev], [b for _, b in prev], cell=0.5)
    for i, row in enumerate(cur):
        pairs = [per_pair(row, other, 0.5) for other in prev]
        j = max(range(len(pairs)), key=lambda k: (pairs[k][0], -k))  # first maximum
        assert best.index[i] == j
        assert (best.varsigma_max[i], best.delta[i], best.xi[i]) == pairs[j]


# --- Eq. 14 and the decision tree ------------------------------------------------------


def test_eq14_by_hand() -> None:
    prev = [((5.0, 0.0), (10, 10, 0, 0)), ((0.0, 0.0), (0, 0, 0, 0)), ((0.5, 0.0), (1, 1, 0, 0))]
    # varsigma to each: 0.5/11 + 0.5/2 = 0.295455; 0.5 + 0.5 = 1; 0.5/2 + 0.5/2 = 0.5
    varsigma = [per_pair(((0.0, 0.0), (0, 0, 0, 0)), p, 0.5)[0] for p in prev]
    assert varsigma == pytest.approx([0.2954545, 1.0, 0.5])
    best = correlation.best_match([(0.0, 0.0)], [(0, 0, 0, 0)], [c for c, _ in prev],
                                  [b for _, b in prev], cell=0.5)
    assert best.index == [1] and best.varsigma_max == [1.0]


def test_eq14_and_the_tree_are_what_tracking_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    best = Spy(monkeypatch, tracker, "best_match")
    tree = Spy(monkeypatch, tracker, "classify")
    track_two_frames("paper")
    assert best.calls == 2 and tree.calls == 2  # one per frame, one obstacle each


def test_the_tree_decides_the_type_in_paper_mode(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tracker, "classify", lambda *a, **k: "dynamic")
    assert [t.kind for t in track_two_frames("paper")] == ["dynamic"]


# --- Eq. 15 -------------------------------------------------------------------------


def test_eq15_by_hand() -> None:
    # from (0, 0) to (1, 1) in T = 0.5 s: d_o = sqrt 2 = 1.414214 m, v_o = 2.828427 m/s,
    # alpha_o = arctan(dx / dy) = arctan(1) = 45 deg (clockwise from +y)
    m = correlation.motion((1.0, 1.0), (0.0, 0.0), 0.5)
    assert (m.d_o, m.v_o, m.alpha_o_deg) == pytest.approx((1.4142136, 2.8284271, 45.0))
    assert correlation.motion((0.0, -1.0), (0.0, 0.0), 1.0).alpha_o_deg == pytest.approx(180.0)


def test_eq15_is_what_tracking_calls_in_paper_mode(monkeypatch: pytest.MonkeyPatch) -> None:
    spy = Spy(monkeypatch, tracker, "motion")
    tracks = track_two_frames("paper")
    assert spy.calls == 1  # the second frame against the first
    # the obstacle's Eq. 5 centre moved from 2 m to 2.5 m ahead in 0.5 s: 1 m/s along +x
    assert tracks[0].speed == pytest.approx(1.0, rel=0.02)


def test_eq15_direction_has_one_formula(monkeypatch: pytest.MonkeyPatch) -> None:
    """alpha_o from a heading: 90 - degrees(heading), wrapped to [0, 360): +y is 0, +x 90,
    -y 180 and -x 270. Eq. 15 (the paper's tracker) and the default tracker's velocity
    both turn a heading into alpha_o through this one function."""
    assert [correlation.alpha_o_from_heading(h) for h in
            (math.pi / 2, 0.0, -math.pi / 2, math.pi)] == pytest.approx([0.0, 90.0, 180.0, 270.0])
    spy = Spy(monkeypatch, correlation, "alpha_o_from_heading")
    correlation.motion((1.0, 1.0), (0.0, 0.0), 0.5)
    assert spy.calls == 1
    in_tracker = Spy(monkeypatch, tracker, "alpha_o_from_heading")
    track_two_frames("smoothed")
    assert in_tracker.calls >= 1


# --- Eq. 17 -------------------------------------------------------------------------


def test_eq17_by_hand() -> None:
    # y = 1 * |0.2| + 1.3 * 3 + 0.6 * 0.25 = 0.2 + 3.9 + 0.15 = 4.25; W = 1 / (4 + 1) = 0.2
    assert morphin.morphin_cost(-0.2, 3.0, 0.25, (1.0, 1.3, 0.6)) == pytest.approx(4.25)
    assert morphin.shared_term(4) == pytest.approx(0.2)


def test_eq17_is_what_the_planner_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    cost = Spy(monkeypatch, morphin, "morphin_cost")
    w = Spy(monkeypatch, morphin, "shared_term")
    decision = plan_round_a_box()
    assert decision.action == "morphin" and decision.scenario == "b"
    assert cost.calls >= 1 and w.calls >= 1
