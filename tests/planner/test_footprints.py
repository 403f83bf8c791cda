"""The planner's footprint stage: a mover's track point is the Eq. 5 centre of its visible
surface; ``Planner.footprints`` places the mover's disc at the centre that point implies.

Checked against perception itself: a disc is scanned, clustered (the centre and radius
the tracker measures), and the footprint must land on the disc's true centre, where the
Eq. 5 centre falls about 0.8 radius short of it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.planner.scans import scan_of
from zenav.schemas.messages import LaserScan
from zenav.services.geometry import disc_distance, disc_mean_range
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.services.planner.costmap import ScanData
from zenav.services.planner.decide import Planner
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import Obstacle


@pytest.mark.parametrize("radius", [0.15, 0.2, 0.3, 0.5])
@pytest.mark.parametrize("distance", [0.6, 1.0, 2.0, 5.0])
def test_disc_distance_undoes_the_mean_range(distance: float, radius: float) -> None:
    seen_at = disc_mean_range(distance, radius)
    assert seen_at < distance - 0.7 * radius  # Eq. 5's centre lies well in front
    assert disc_distance(seen_at, radius) == pytest.approx(distance, abs=1e-6)


def seen_disc(pose: tuple[float, float, float], centre: tuple[float, float],
              radius: float) -> tuple[Obstacle, ScanData]:
    """The disc as perception measures it from ``pose``, typed dynamic, and the scan."""
    data = scan_of(pose, discs=[(centre[0], centre[1], radius)])
    scan = LaserScan(stamp=0.0, seq=0, frame="laser", angle_min=data.angle_min,
                     angle_max=data.angle_min + data.angle_increment * (data.ranges.size - 1),
                     angle_increment=data.angle_increment, range_min=0.05,
                     range_max=data.range_max, ranges=data.ranges.astype(np.float32))
    clusters = Perceiver(PerceptionParams()).process(scan, pose)
    assert len(clusters) == 1
    x, y = (float(v) for v in clusters.centre[0])
    track = Obstacle(1, "dynamic", (x, y), (0.3, 0.0), float(clusters.radius[0]), (0, 0, 0, 0))
    return track, data


def planner(**changes: object) -> Planner:
    return Planner(Params.model_validate({"goal": (8.0, 3.0), "mover_centre": True,
                                          **changes}))


@pytest.mark.parametrize("radius", [0.2, 0.3])
@pytest.mark.parametrize(("pose", "centre"), [
    ((0.0, 0.0, 0.0), (1.0, 0.0)),
    ((0.0, 0.0, 0.0), (2.0, 0.6)),
    ((1.0, 2.0, math.radians(120.0)), (0.0, 3.5)),
    ((0.0, 0.0, 0.0), (3.0, -1.0)),
])
def test_a_movers_footprint_sits_on_the_disc_perception_saw(
        pose: tuple[float, float, float], centre: tuple[float, float], radius: float) -> None:
    track, scan = seen_disc(pose, centre, radius)
    assert math.dist(track.position, centre) > 0.6 * radius  # on the near surface
    (placed,) = planner().footprints(pose, [track], scan)
    # (within what perception's radius, a few cm short of a near disc's, allows)
    assert math.dist(placed.position, centre) < 0.05
    assert (placed.velocity, placed.radius, placed.id) == (track.velocity, track.radius, 1)


def test_a_mover_seen_in_part_keeps_its_tracks_point() -> None:
    pose = (0.0, 0.0, 0.0)
    edge, scan = seen_disc(pose, (0.0, 1.5), 0.3)  # astride the 180 degree view's edge
    behind_post, _ = seen_disc(pose, (2.5, 0.0), 0.3)
    post = scan_of(pose, discs=[(0.0, 1.5, 0.3), (1.2, 0.0, 0.1), (2.5, 0.0, 0.3)])
    p = planner()
    assert p.footprints(pose, [edge], scan) == [edge]
    assert p.footprints(pose, [behind_post], post) == [behind_post]  # hidden in the middle
    assert p.footprints(pose, [edge, behind_post], None) == [edge, behind_post]


def test_only_movers_move_and_by_default_every_track_stays_as_measured() -> None:
    pose = (0.0, 0.0, 0.0)
    scan = scan_of(pose, discs=[(2.3, 0.0, 0.3)])
    walker = Obstacle(1, "dynamic", (2.0, 0.0), (0.0, 0.5), 0.3, (0, 0, 0, 0))
    post = Obstacle(2, "static", (0.0, 2.0), (0.0, 0.0), 0.3, (0, 0, 0, 0))
    newcomer = Obstacle(3, "new", (1.0, -1.0), (0.0, 0.0), 0.3, (0, 0, 0, 0))
    placed = planner().footprints(pose, [walker, post, newcomer], scan)
    assert placed[0].position[0] == pytest.approx(2.0 + 0.8 * 0.3, abs=0.03)
    assert placed[0].position[1] == 0.0
    assert placed[1:] == [post, newcomer]
    as_measured = Planner(Params.model_validate({"goal": (8.0, 3.0)}))  # the default
    assert not as_measured.p.mover_centre
    assert as_measured.footprints(pose, [walker, post, newcomer], scan) == [
        walker, post, newcomer]
