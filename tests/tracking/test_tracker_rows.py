"""The tracker reads a chain's per-cluster values as Python numbers (``_Rows``); the
motion score since a track's birth taken from them is numpy's masked maximum, the
area of one box is Eq. 6 as ``box_area`` counts a row, and the output record is built
field by field in order."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from zenav.services.perception.clustering import Clusters, box_area
from zenav.services.tracking.correlation import alpha_o_from_heading
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Tracker, _moved_since_born, _Rows, _State


def chain(each: np.ndarray, refs: np.ndarray) -> Clusters:
    n = each.shape[0]
    f1, f2, i1 = np.zeros(n), np.zeros((n, 2)), np.zeros(n, dtype=np.int64)
    return Clusters(centre=f2, mean_rho=f1, mean_alpha=f1, box=np.zeros((n, 4), np.int64),
                    area=i1, beams=np.zeros((n, 2), np.int64), n_beams=i1, first_point=f2,
                    last_point=f2, chord_centre=f2, radius=f1, edge_start=i1, edge_end=i1,
                    pose=(0.0, 0.0, 0.0), cell=0.5, moved=each.max(axis=1, initial=0.0),
                    moved_each=each, moved_refs=refs)


def numpy_score(clusters: Clusters, c: int, born: float) -> float:
    """The numpy expression the Python loop replaced."""
    assert clusters.moved_each is not None and clusters.moved_refs is not None
    since = np.isfinite(clusters.moved_refs) & (clusters.moved_refs >= born - 1e-9)
    return float(clusters.moved_each[c][since].max(initial=0.0))


@pytest.mark.parametrize("seed", range(5))
def test_the_score_since_birth_is_numpys_masked_maximum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    refs = np.array([np.nan, 9.0, 9.5, 10.0 - 1e-10, 10.0])  # one older than any scan
    each = rng.uniform(0.0, 1.0, (6, refs.size))
    each[rng.random(each.shape) < 0.3] = 0.0
    each[1, 3] = np.nan  # a score that could not be measured
    clusters = chain(each, refs)
    rows = _Rows.of(clusters)
    for c in range(each.shape[0]):
        for born in (0.0, 9.0, 9.0 + 1e-10, 9.2, 10.0, 11.0):
            got, want = _moved_since_born(rows, c, born), numpy_score(clusters, c, born)
            assert got == want or (math.isnan(got) and math.isnan(want))
    assert math.isnan(_moved_since_born(rows, 1, 9.2))
    assert _moved_since_born(rows, 0, 11.0) == 0.0  # no earlier scan since: nothing moved


def test_without_the_per_scan_scores_the_chains_own_score_counts() -> None:
    each = np.array([[0.2, 0.7], [0.0, 0.1]])
    clusters = chain(each, np.array([1.0, 2.0]))
    bare = dataclasses.replace(clusters, moved_each=None, moved_refs=None)
    rows = _Rows.of(bare)
    assert [_moved_since_born(rows, c, 5.0) for c in range(2)] == [0.7, 0.1]


def test_one_box_as_a_tuple_is_eq6_as_the_array_form_counts_it() -> None:
    """box_area's fast path for one box of Python ints (the tracker's) gives, as a Python
    int, what its numpy form gives for the same rows."""
    rng = np.random.default_rng(3)
    lo = rng.integers(-50, 50, (200, 2))
    size = rng.integers(0, 20, (200, 2))
    boxes = np.column_stack([lo[:, 0], lo[:, 0] + size[:, 0], lo[:, 1], lo[:, 1] + size[:, 1]])
    want = box_area(boxes).tolist()
    got = [box_area((a, b, c, d)) for a, b, c, d in boxes.tolist()]
    assert got == want and all(type(n) is int for n in got)
    assert box_area((2, 4, 1, 1)) == 3  # x 2..4 by y 1..1


@pytest.mark.parametrize("method", ["smoothed", "paper"])
def test_the_output_record_puts_each_value_in_its_named_field(method: str) -> None:
    """``_output`` builds the Track positionally: each field gets the state's value of the
    same name (every value distinct, so a swap shows)."""
    state = _State(
        id=7, kind="dynamic", x=1.25, y=-2.5, vx=0.3, vy=0.4, p00=0.01, p01=0.02, p11=0.03,
        centre=(1.5, -2.25), radius=0.45, box=(2, 5, -6, -3), area=16, partial=False,
        n_parts=1, xi=0.61, varsigma=0.83, delta=1.7, paper_vx=0.12, paper_vy=-0.16,
        paper_d=0.02, age=9, last_seen=3.5, merged_since=None,
    )  # fmt: skip
    track = Tracker(TrackingParams(method=method))._output(state, 0.1, True)
    vx, vy = (0.3, 0.4) if method == "smoothed" else (0.12, -0.16)
    heading = math.atan2(vy, vx)
    assert track._asdict() == {
        "id": 7, "kind": "dynamic",
        "x": 1.25 if method == "smoothed" else 1.5,
        "y": -2.5 if method == "smoothed" else -2.25,
        "vx": vx, "vy": vy, "speed": math.hypot(vx, vy), "heading": heading,
        "alpha_o_deg": alpha_o_from_heading(heading),
        "distance": math.hypot(vx, vy) * 0.1 if method == "smoothed" else 0.02,
        "xi": 0.61, "varsigma": 0.83, "delta": 1.7, "radius": 0.45, "age": 9,
        "last_seen": 3.5, "box": (2, 5, -6, -3), "area": 16, "visible": True,
    }  # fmt: skip
