"""Tracker behaviour on simulated scans: types, motion, ids, dropping, split and merge."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
import pytest

from zenav.services.perception.clustering import Clusters, cluster_scan
from zenav.services.perception.params import PerceptionParams
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Track, Tracker
from zenav.sim.raycast import simulate_scan
from zenav.sim.world import WorldSnapshot

ANGLES = -math.pi / 2 + math.radians(0.5) * np.arange(361)
INC = math.radians(0.5)
DT = 0.1
Pose = tuple[float, float, float]
Disc = tuple[float, float, float]  # cx, cy, r
Box = tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
World = Callable[[float], tuple[list[Disc], list[Box]]]


def scan_clusters(
    pose: Pose,
    discs: Sequence[Disc] = (),
    boxes: Sequence[Box] = (),
    noise: float = 0.0,
    rng: np.random.Generator | None = None,
    perception: PerceptionParams | None = None,
) -> Clusters:
    snap = WorldSnapshot.build(discs=discs, boxes=boxes)
    gen = rng if rng is not None else np.random.default_rng(0)
    ranges = simulate_scan(pose[:2], pose[2], ANGLES, snap, 8.0, noise, gen)
    return cluster_scan(ranges, -math.pi / 2, INC, 0.0, 8.0, pose, perception or PerceptionParams())


def drive(
    world: World,
    pose_at: Callable[[float], Pose],
    seconds: float,
    params: TrackingParams | None = None,
    noise: float = 0.0,
    perception: PerceptionParams | None = None,
) -> list[tuple[float, list[Track]]]:
    """Run the tracker over 10 Hz scans; return (stamp, tracks) per frame."""
    tracker = Tracker(params)
    rng = np.random.default_rng(7)
    out = []
    for i in range(round(seconds / DT)):
        t = i * DT
        discs, boxes = world(t)
        pose = pose_at(t)
        clusters = scan_clusters(pose, discs, boxes, noise, rng, perception)
        out.append((t, tracker.update(t, pose, clusters)))
    return out


def still(t: float) -> Pose:
    return (0.0, 0.0, 0.0)


def driving_and_turning(t: float) -> Pose:
    """0.2 m/s ("full speed") with the heading swinging +-0.5 rad at up to 0.4 rad/s."""
    steps = max(1, round(t / 0.001))
    ts = (np.arange(steps) + 0.5) * (t / steps)
    h = 0.5 * np.sin(0.8 * ts)
    x = float(np.sum(np.cos(h))) * 0.2 * t / steps
    y = float(np.sum(np.sin(h))) * 0.2 * t / steps
    return (x, y, 0.5 * math.sin(0.8 * t))


def nearest(tracks: list[Track], x: float, y: float, reach: float = 0.6) -> Track | None:
    best = min(tracks, key=lambda tr: math.hypot(tr.x - x, tr.y - y), default=None)
    if best is None or math.hypot(best.x - x, best.y - y) > reach:
        return None
    return best


STATICS: tuple[list[Disc], list[Box]] = (
    [(2.5, -1.0, 0.25)],
    [(2.75, 0.75, 3.25, 1.25)],
)


@pytest.mark.parametrize("method", ["paper", "smoothed"])
@pytest.mark.parametrize("noise", [0.0, 0.01])
def test_static_obstacles_stay_static_while_the_robot_drives_and_turns(
    method: str, noise: float
) -> None:
    # The paper method needs its own clustering to be the paper's; the smoothed one uses
    # the default (floored) threshold. Either way: no static obstacle becomes dynamic.
    perception = PerceptionParams.paper() if method == "paper" and noise == 0.0 else None
    frames = drive(
        lambda t: STATICS,
        driving_and_turning,
        5.0,
        TrackingParams.model_validate({"method": method}),
        noise,
        perception,
    )
    ids: dict[str, set[int]] = {"disc": set(), "box": set()}
    for i, (_, tracks) in enumerate(frames):
        for name, (x, y) in (("disc", (2.5, -1.0)), ("box", (3.0, 1.0))):
            tr = nearest(tracks, x, y)
            assert tr is not None
            ids[name].add(tr.id)
            if i >= 2:
                assert tr.kind == "static", (i, name, tr)
    if method == "smoothed":
        assert len(ids["disc"]) == 1 and len(ids["box"]) == 1  # one id each, all along
        final = frames[-1][1]
        assert all(tr.speed < 0.1 for tr in final)


@pytest.mark.parametrize(("speed", "alpha_o"), [(0.45, 80.83), (0.76, 62.47), (0.805, 180.09)])
def test_a_mover_is_dynamic_with_its_speed_and_heading(speed: float, alpha_o: float) -> None:
    heading = math.radians(90.0 - alpha_o)
    vx, vy = speed * math.cos(heading), speed * math.sin(heading)
    start = (2.5 - vx * 1.5, 0.3 - vy * 1.5)

    def world(t: float) -> tuple[list[Disc], list[Box]]:
        return [(start[0] + vx * t, start[1] + vy * t, 0.2)], []

    frames = drive(world, driving_and_turning, 3.0, TrackingParams(), noise=0.01)
    ids = set()
    for t, tracks in frames:
        x, y, _ = world(t)[0][0]
        tr = nearest(tracks, x, y)
        assert tr is not None
        ids.add(tr.id)
        if t >= 1.0 - 1e-9:  # seen for 1 s
            assert tr.kind == "dynamic"
            assert tr.speed == pytest.approx(speed, rel=0.10)
            err = math.degrees(math.remainder(tr.heading - heading, math.tau))
            assert abs(err) < 5.0
            assert tr.alpha_o_deg == pytest.approx(alpha_o % 360.0, abs=5.0)
            assert tr.distance == pytest.approx(tr.speed * DT)
    assert len(ids) == 1  # one id for the whole run


def test_first_frames_are_new_then_typed() -> None:
    frames = drive(lambda t: STATICS, still, 0.4, TrackingParams(new_frames=2))
    kinds = [sorted(tr.kind for tr in tracks) for _, tracks in frames]
    assert kinds[0] == ["new", "new"]
    assert kinds[1] == ["new", "new"]
    assert kinds[2] == ["static", "static"]
    assert [tr.age for tr in frames[3][1]] == [4, 4]


def test_paper_method_reports_eq15_between_frames() -> None:
    # A box translating by exactly 0.1 m per 0.1 s frame seen from a still robot: its Eq. 5
    # centre moves by about the same, so Eq. 15 gives about 1 m/s along +y.
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        return [], [(2.0, -1.0 + t, 2.4, -0.6 + t)]

    frames = drive(world, still, 1.0, TrackingParams(method="paper"))
    tr = frames[-1][1][0]
    assert tr.speed == pytest.approx(1.0, rel=0.15)
    assert tr.alpha_o_deg == pytest.approx(0.0, abs=15.0)
    assert tr.distance == pytest.approx(tr.speed * DT)
    assert 0.0 <= tr.xi <= 1.0
    assert 0.0 < tr.varsigma <= 1.0


def test_a_vanished_obstacle_is_dropped_after_the_configured_time() -> None:
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        return ([(2.0, 0.0, 0.2)] if t < 1.0 - 1e-9 else []), []

    frames = drive(world, still, 2.0, TrackingParams(drop_after=0.5))
    by_t = {round(t, 1): tracks for t, tracks in frames}
    assert len(by_t[0.9]) == 1 and by_t[0.9][0].visible
    track_id = by_t[0.9][0].id
    for t in (1.0, 1.2, 1.3):  # unseen for 0.1 .. 0.4 s: kept, coasting
        assert [tr.id for tr in by_t[t]] == [track_id]
        assert not by_t[t][0].visible
        assert by_t[t][0].last_seen == pytest.approx(0.9)
    assert by_t[1.5] == []  # unseen for 0.6 s > 0.5 s


def test_a_one_frame_speck_does_not_linger() -> None:
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        speck = [(1.0, 1.5, 0.05)] if abs(t - 0.5) < 1e-9 else []
        return [(2.0, 0.0, 0.2), *speck], []

    frames = drive(world, still, 0.8, TrackingParams(drop_after=1.0))
    counts = [len(tracks) for _, tracks in frames]
    assert counts == [1, 1, 1, 1, 1, 2, 1, 1]


def test_ids_persist_and_new_obstacles_get_new_ids() -> None:
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        later = [(1.5, 2.0, 0.2)] if t >= 1.0 - 1e-9 else []
        return [(2.0, -1.0, 0.25), *later], [(2.75, 0.75, 3.25, 1.25)]

    frames = drive(world, driving_and_turning, 2.0)
    first_ids = {tr.id for tr in frames[0][1]}
    assert first_ids == {1, 2}
    assert {tr.id for tr in frames[9][1]} == {1, 2}
    assert {tr.id for tr in frames[-1][1]} == {1, 2, 3}


def test_split_by_an_occluder_keeps_one_id() -> None:
    # A 1.2 m wide box at x = 3; from t = 1 s a thin post stands in front of its middle and
    # cuts its cluster in two. The box keeps its id (both pieces), the post gets a new one.
    box: Box = (3.0, -0.6, 3.3, 0.6)

    def world(t: float) -> tuple[list[Disc], list[Box]]:
        post = [(1.5, 0.0, 0.05)] if t >= 1.0 - 1e-9 else []
        return post, [box]

    tracker = Tracker()
    box_id = None
    for i in range(20):
        t = i * DT
        discs, boxes = world(t)
        clusters = scan_clusters(still(t), discs, boxes)
        tracks = tracker.update(t, still(t), clusters)
        if t < 1.0 - 1e-9:
            assert len(clusters) == 1 and len(tracks) == 1
            box_id = tracks[0].id
            continue
        assert len(clusters) == 3  # two pieces of the box and the post
        assert len(tracks) == 2
        box_track = nearest(tracks, 3.0, 0.0)
        post_track = nearest(tracks, 1.5, 0.0, reach=0.2)
        assert box_track is not None and post_track is not None
        assert box_track.id == box_id
        assert post_track.id != box_id
        assert box_track.kind == "static"
        assert box_track.radius > 0.5  # the footprint spans both pieces


def test_merge_of_a_mover_with_a_static_obstacle_keeps_both_ids() -> None:
    # A walker passes 5 cm beside a static box: for a while they are one cluster.
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        return [(2.45, 2.0 - 0.8 * t, 0.2)], [(1.7, -0.25, 2.2, 0.25)]

    frames = drive(world, still, 5.0, TrackingParams(), noise=0.01)
    walker_ids, box_ids = set(), set()
    merged_frames = 0
    for t, tracks in frames:
        y = 2.0 - 0.8 * t
        if abs(y) > 2.5:
            continue
        box = nearest(tracks, 1.95, 0.0)
        walker = nearest(tracks, 2.45, y)
        assert box is not None and walker is not None
        if not walker.visible:
            merged_frames += 1
        box_ids.add(box.id)
        walker_ids.add(walker.id)
        if t > 0.5:
            assert box.kind == "static", t
    assert merged_frames > 0  # the merge did happen
    assert len(box_ids) == 1
    assert len(walker_ids) == 1
    assert box_ids != walker_ids
    walker = nearest(frames[-1][1], 2.45, 2.0 - 0.8 * frames[-1][0])
    assert walker is not None and walker.kind == "dynamic"


def test_two_walkers_crossing_keep_their_ids() -> None:
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        return [(2.5, -1.5 + 0.6 * t, 0.2), (2.9, 1.5 - 0.6 * t, 0.2)], []

    frames = drive(world, still, 5.0, TrackingParams(), noise=0.01)
    first = {round(tr.y): tr.id for tr in frames[2][1]}
    last = frames[-1][1]
    a = nearest(last, 2.5, -1.5 + 0.6 * frames[-1][0])
    b = nearest(last, 2.9, 1.5 - 0.6 * frames[-1][0])
    assert a is not None and b is not None
    assert a.id == first[-1] and b.id == first[1]
    assert a.vy > 0.3 and b.vy < -0.3


def test_stamps_must_increase() -> None:
    tracker = Tracker()
    c = scan_clusters(still(0.0), *STATICS)
    tracker.update(1.0, still(0.0), c)
    with pytest.raises(ValueError, match="does not follow"):
        tracker.update(1.0, still(0.0), c)


def test_deterministic() -> None:
    runs = [drive(lambda t: STATICS, driving_and_turning, 1.0, noise=0.01) for _ in range(2)]
    assert runs[0] == runs[1]


def test_empty_chains() -> None:
    tracker = Tracker()
    assert tracker.update(0.0, still(0.0), Clusters.empty()) == []
    c = scan_clusters(still(0.0), *STATICS)
    assert len(tracker.update(0.1, still(0.0), c)) == 2
    assert len(tracker.update(0.2, still(0.0), Clusters.empty())) == 0  # tentative: dropped


def test_a_track_that_jumps_onto_another_walker_learns_its_velocity_again() -> None:
    # A walker going up (+y) vanishes and, 0.45 m off its predicted place, a second one
    # going down is seen: the track takes it (the same view of one disc, a jump). The
    # first walker's velocity is no clue to the second's, so the track must learn it
    # again from the next scans, not hold the old one while the position keeps jumping.
    def world(t: float) -> tuple[list[Disc], list[Box]]:
        if t < 2.0:
            return [(2.5, -1.0 + 0.7 * t, 0.25)], []
        return [(2.5 + 0.45, 0.4 - 0.9 * (t - 2.0), 0.25)], []

    frames = drive(world, still, 2.35, TrackingParams(), noise=0.01)
    before = nearest(frames[19][1], 2.5, -1.0 + 0.7 * 1.9)
    assert before is not None and before.vy > 0.5
    ids = {tr.id for t, tracks in frames if t >= 2.0 for tr in tracks}
    assert ids == {before.id}, "the second walker was not taken for the first"
    after = nearest(frames[-1][1], 2.95, 0.4 - 0.9 * frames[-1][0] + 1.8)
    assert after is not None
    # Two scans after the jump its velocity points down (the old one kept: still up).
    assert after.vy < -0.3, (after.vx, after.vy)
