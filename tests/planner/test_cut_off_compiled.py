"""``Costmap.cut_off`` (the compiled flood ``_loops.closed_off`` over the cells outside
the walls' discs) gives the answer of the numpy and scipy test it replaced: the free
cells by scipy's distance transform, the ways by ``scipy.ndimage.label``, and the labels
within a window of start and goal compared."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import pytest
from scipy.ndimage import distance_transform_edt, label

from zenav.services.planner.costmap import Costmap


def scipy_cut_off(cm: Costmap, start: npt.NDArray[np.float64], goal: npt.NDArray[np.float64],
                  clearance: float) -> bool:
    """The test as it was (a distance transform and a labelling of the whole grid)."""
    ends = cm.cell_of(np.vstack([start, goal]))
    if not cm.inside(ends).all():
        return False
    if not cm.walls.any():
        return False
    free = np.asarray(distance_transform_edt(~cm.walls), dtype=np.float64) * cm.resolution \
        > clearance
    labels, _ = label(free)
    reach = math.ceil(clearance / cm.resolution) + 1

    def near(cell: npt.NDArray[np.int64]) -> set[int]:
        i, j = int(cell[0]), int(cell[1])
        window = labels[max(i - reach, 0):i + reach + 1, max(j - reach, 0):j + reach + 1]
        return set(np.unique(window[window > 0]).tolist())

    at_goal = near(ends[1])
    if not at_goal:
        return False  # no free cell near the goal: covered, not closed off
    return not near(ends[0]) & at_goal


def walled(rng: np.random.Generator, nx: int, ny: int) -> npt.NDArray[np.bool_]:
    """Random walls: scattered cells, straight runs (whole rows and columns among them,
    which cut the grid in two) and rings, at several densities."""
    walls = np.asarray(rng.random((nx, ny)) < float(rng.choice([0.0, 0.01, 0.05, 0.2])),
                       dtype=np.bool_)
    for _ in range(int(rng.integers(0, 6))):
        if rng.random() < 0.5:
            i = int(rng.integers(0, nx))
            j0, j1 = sorted(rng.integers(0, ny, 2).tolist())
            walls[i, j0:j1 + 1 if rng.random() < 0.7 else ny] = True
        else:
            j = int(rng.integers(0, ny))
            i0, i1 = sorted(rng.integers(0, nx, 2).tolist())
            walls[i0:i1 + 1 if rng.random() < 0.7 else nx, j] = True
    if rng.random() < 0.4:
        ci, cj, h = int(rng.integers(5, nx - 5)), int(rng.integers(5, ny - 5)), 4
        walls[ci - h:ci + h + 1, [cj - h, cj + h]] = True
        walls[[ci - h, ci + h], cj - h:cj + h + 1] = True
    return walls


@pytest.mark.parametrize("seed", range(25))
def test_cut_off_answers_as_the_distance_transform_and_labels_did(seed: int) -> None:
    rng = np.random.default_rng(seed)
    cm = Costmap((0.0, 0.0), (4.0, 3.0), resolution=0.1, decay=60.0, inflation=0.3,
                 confirm=0.0, padding=1.0, max_size=30.0)
    nx, ny = cm.shape
    answers = set()
    for _ in range(40):
        cm.walls = walled(rng, nx, ny)
        for _ in range(5):
            start = rng.uniform(-1.5, 5.5, 2)  # sometimes beyond the grid
            goal = rng.uniform(-1.5, 5.5, 2)
            clearance = float(rng.choice([0.0, 0.1, 0.2, 0.25, 0.3, 0.45]))
            want = scipy_cut_off(cm, start, goal, clearance)
            assert cm.cut_off(start, goal, clearance) == want
            answers.add(want)
    assert answers == {False, True}  # both answers met


def test_cut_off_with_an_end_beside_the_grid_edge_and_a_window_past_it() -> None:
    """The windows clipped by the grid's edges, a wall across the whole grid."""
    cm = Costmap((0.0, 0.0), (4.0, 3.0), resolution=0.1, decay=60.0, inflation=0.3,
                 confirm=0.0, padding=1.0, max_size=30.0)
    nx, ny = cm.shape
    cm.walls[:, :] = False
    cm.walls[nx // 2, :] = True
    lo = cm.origin + 0.05
    hi = cm.origin + np.array([nx, ny]) * cm.resolution - 0.05
    for start, goal, closed in (((lo[0], lo[1]), (hi[0], hi[1]), True),
                                ((lo[0], lo[1]), (lo[0], hi[1]), False)):
        s, g = np.array(start), np.array(goal)
        assert scipy_cut_off(cm, s, g, 0.2) == closed
        assert cm.cut_off(s, g, 0.2) == closed
