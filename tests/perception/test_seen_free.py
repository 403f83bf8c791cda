"""The motion cue's free-space test (compiled) answers as its definition says: a point
counts as seen free when the beam nearest its bearing and both neighbours reached more
than the margin beyond it; points off the fan's inner beams, or not numbers, never do."""

from __future__ import annotations

import math

import numpy as np
import pytest

from zenav.services.perception.motion_cue import ScanSnapshot, seen_free


def by_definition(scan: ScanSnapshot, points: np.ndarray, margin: float) -> list[bool]:
    """Point by point, in plain Python with the math module."""
    x, y, heading = scan.pose
    n = len(scan.ranges)
    out = []
    for px, py in points:
        if not (math.isfinite(px) and math.isfinite(py)):
            out.append(False)
            continue
        bearing = math.remainder(math.atan2(py - y, px - x) - heading, 2 * math.pi)
        beam = round((bearing - scan.angle_min) / scan.angle_increment)
        if beam < 0:  # before the first beam: a turn further on (a full circle turned)
            beam += round(2 * math.pi / abs(scan.angle_increment))
        if not 1 <= beam <= n - 2:
            out.append(False)
            continue
        reach = min(scan.ranges[beam - 1: beam + 2])
        out.append(bool(reach > math.hypot(px - x, py - y) + margin))
    return out


@pytest.mark.parametrize("seed", range(4))
def test_seen_free_agrees_with_its_definition(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pose = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)), float(rng.uniform(-4, 4)))
    ranges = rng.uniform(0.5, 8.0, 181)
    scan = ScanSnapshot(0.0, pose, ranges, -math.pi / 2, math.pi / 180, 8.0)
    # Points all round the robot (behind it too), some exactly between two beams' reaches.
    bearing = rng.uniform(-math.pi, math.pi, 400) + pose[2]
    distance = rng.uniform(0.0, 9.0, 400)
    points = np.column_stack([pose[0] + distance * np.cos(bearing),
                              pose[1] + distance * np.sin(bearing)])
    points[:3] = [[math.nan, 0.0], [0.0, math.inf], [math.nan, math.nan]]
    got = seen_free(scan, points, 0.1).tolist()
    want = by_definition(scan, points, 0.1)
    # Bearings within a rounding error of half a beam may round either way: compare the
    # rest, and make sure they are nearly all of them.
    half = [abs(((math.atan2(py - pose[1], px - pose[0]) - pose[2] + math.pi) % (2 * math.pi)
                 - math.pi - scan.angle_min) / scan.angle_increment % 1 - 0.5) < 1e-9
            if math.isfinite(px) and math.isfinite(py) else False for px, py in points]
    compared = [(g, w) for g, w, h in zip(got, want, half, strict=True) if not h]
    assert len(compared) >= 395
    assert [g for g, _ in compared] == [w for _, w in compared]
    assert any(got) and not all(got)
    assert got[:3] == [False, False, False]


@pytest.mark.parametrize("shift", [1, 90, 180, 359])
def test_a_full_circle_turned_to_start_elsewhere_sees_the_same_free_space(shift: int) -> None:
    # Perception starts a 360-degree scan at another beam when its seam cuts an obstacle
    # (clustering.rotate_scan): the beams then run past pi, and a point's bearing below
    # the new first beam is a turn further on.
    rng = np.random.default_rng(shift)
    pose = (0.5, -1.0, 2.0)
    ranges = rng.uniform(0.5, 8.0, 360)
    step = math.pi / 180
    plain = ScanSnapshot(0.0, pose, ranges, -math.pi, step, 8.0)
    turned = ScanSnapshot(0.0, pose, np.roll(ranges, -shift), -math.pi + shift * step, step,
                          8.0)
    # Points on beams' exact bearings, away from both scans' first and last beams (whose
    # neighbours lie across an end, so neither scan judges them).
    beams = np.array([b for b in range(360)
                      if min(b, (b - shift) % 360) >= 2 and max(b, (b - shift) % 360) <= 357])
    distance = rng.uniform(0.0, 9.0, beams.size)
    bearing = -math.pi + beams * step + pose[2]
    points = np.column_stack([pose[0] + distance * np.cos(bearing),
                              pose[1] + distance * np.sin(bearing)])
    want = seen_free(plain, points, 0.1).tolist()
    assert seen_free(turned, points, 0.1).tolist() == want
    assert by_definition(turned, points, 0.1) == want
    assert any(want) and not all(want)
