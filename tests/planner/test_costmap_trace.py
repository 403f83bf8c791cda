"""The map's ray tracing clears the cells each beam passes through, found here as
geometry (``beam_cells``), and the inflation is reused only while the lethal set is the
same."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.planner.beam_cells import beam_cells
from zenav.services.planner.costmap import Costmap, ScanData


def random_scan(rng: np.random.Generator, beams: int, near: bool) -> ScanData:
    """Returns anywhere up to the reach, or (``near``) only close by, so that the beams
    without a return leave the grid and the samples outside it must be dropped."""
    pose = (float(rng.uniform(3, 9)), float(rng.uniform(3, 9)), float(rng.uniform(-3, 3)))
    ranges = rng.uniform(0.2, 1.5 if near else 9.0, beams)
    ranges[rng.random(beams) < (0.9 if near else 0.4)] = 8.0  # no return
    ranges = np.minimum(ranges, 8.0)
    return ScanData(pose, ranges, -math.pi / 2, math.pi / (beams - 1), 8.0)


@pytest.mark.parametrize("seed", range(6))
def test_the_cells_seen_free_are_those_the_beams_pass_through(seed: int) -> None:
    rng = np.random.default_rng(seed)
    costmap = Costmap((4.0, 4.0), (8.0, 8.0), resolution=0.1, decay=60.0, inflation=0.3,
                      confirm=0.0, padding=1.0, max_size=200.0)
    for k in range(4):  # the grid grows between scans: the buffers must follow
        scan = random_scan(rng, 181 + 180 * (k % 3), near=k == 0)
        stamp = 1.0 + k
        costmap.update(scan, stamp)
        crossed, touched = beam_cells(costmap, scan)
        seen_now = {(int(i), int(j)) for i, j in np.argwhere(costmap.seen == stamp)}
        hits = {(int(i), int(j)) for i, j in np.argwhere(costmap.occupied
                                                          & (costmap.seen == stamp))}
        # Every crossed cell was seen now, free unless a return of this scan marked it;
        # no cell beyond those a beam touches was cleared.
        assert crossed and len(touched) < 1.2 * len(crossed)
        assert crossed - hits <= seen_now - hits <= touched - hits
        assert not any(costmap.occupied[c] for c in crossed - hits)


def test_the_inflation_is_reused_while_the_lethal_set_stays_and_redone_when_it_changes(
) -> None:
    costmap = Costmap((0.0, 0.0), (6.0, 0.0), resolution=0.1, decay=60.0, inflation=0.3,
                      confirm=0.5, padding=2.0, max_size=200.0)
    wall = ScanData((0.0, 0.0, 0.0), np.full(61, 3.0), -0.3, 0.01, 8.0)
    for stamp in (0.0, 0.1, 0.2, 0.3, 0.4, 0.5):
        costmap.update(wall, stamp)
    first = costmap.blocked()
    assert first.any()  # the wall is confirmed
    version = costmap.version
    costmap.update(wall, 0.6)  # the same returns: nothing new is lethal
    assert costmap.version > version  # confirmation bumps the version on every scan
    assert costmap.blocked() is first  # the inflation is not computed again
    farther = ScanData((0.0, 0.0, 0.0), np.full(61, 4.0), -0.3, 0.01, 8.0)
    for stamp in (0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3):
        costmap.update(farther, stamp)  # the wall's cells seen free, new ones confirmed
    again = costmap.blocked()
    assert again is not first
    assert not np.array_equal(again, first)
