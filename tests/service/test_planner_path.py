"""The planner's global path on the in-memory bus: sent when planned, sent again unchanged
every ``path_period`` (so that a subscriber that joins late has it within that time), and
sent empty, with the reason, when the map shows no way to the goal."""

from __future__ import annotations

import math

import numpy as np

from tests.planner.scans import scan_of
from tests.service.harness import Harness, running
from tests.service.test_planner_node import POSE, params, tracks
from zenav.schemas import keys
from zenav.schemas.codec import decode
from zenav.schemas.messages import GlobalPath, LaserScan
from zenav.services.planner.decide import Planner
from zenav.services.planner.global_path import GlobalPlan
from zenav.services.planner.node import current_path

STRAIGHT = [[2.0, 3.0], [8.0, 3.0]]
"""The first path: the straight start-goal line (start (2, 3), goal (8, 3))."""


def scan(t: float, boxes: list[tuple[float, float, float, float]]) -> LaserScan:
    data = scan_of(POSE, boxes=boxes)
    return LaserScan(stamp=t, seq=0, frame="laser", angle_min=data.angle_min,
                     angle_max=-data.angle_min, angle_increment=data.angle_increment,
                     range_min=0.0, range_max=data.range_max,
                     ranges=data.ranges.astype(np.float32))


async def step(h: Harness, k: int, boxes: list[tuple[float, float, float, float]]) -> float:
    """One scan and its track list, stamped k / 10 s, decided."""
    t = round(k * 0.1, 6)
    h.send(keys.SCAN, scan(t, boxes))
    h.send(keys.TRACKS, tracks(t))
    await h.settle()
    return t


async def test_an_unchanged_path_is_sent_again_every_period_for_late_subscribers():
    """Nothing in the way: the planner never plans again after its first path, yet a
    subscriber that attaches after that first send has the path within path_period."""
    async with running("planner", params(path_period=1.0)) as h:
        await step(h, 0, [])
        late = h.bus.subscribe(h.keys.of(keys.PATH), depth=100)
        heard_at = None
        for k in range(1, 26):
            t = await step(h, k, [])
            if heard_at is None and late.pending():
                heard_at = t
        taken = late.take()
        sent = h.received(keys.PATH, GlobalPath)
    assert heard_at is not None and heard_at <= 1.0  # within the period of the first send
    assert taken is not None
    first = decode(taken[1], GlobalPath)
    assert first.points.tolist() == STRAIGHT and first.reason == "start"
    assert first.planned == 0.0 and first.stamp == 1.0  # sent again now, planned then
    # Every send: the first at once, then one a period, each a new message with its own
    # seq and stamp and the same plan; all of them repeats of the first.
    assert [(p.stamp, p.seq) for p in sent] == [(0.0, 0), (1.0, 1), (2.0, 2)]
    assert all(p.points.tolist() == STRAIGHT and p.reason == "start" and p.planned == 0.0
               for p in sent)
    assert all(later.repeats(sent[0]) for later in sent[1:])


async def test_no_way_to_the_goal_is_sent_as_an_empty_path_at_once_then_repeated():
    """A box standing on the goal: once the map has confirmed it, the path is planned
    again and no way is found. The planner sends a path with no vertices and the reason
    at that cycle (not at the next repeat) and then every period, instead of leaving the
    old line as the last word."""
    box = [(8.0, 2.0, 9.0, 4.0)]  # its face on the goal (8, 3)
    lost = None
    async with running("planner", params(path_period=0.75)) as h:
        for k in range(41):
            t = await step(h, k, box)
            plan = h.service.planner.plan
            if lost is None and plan is not None and not plan.found:
                lost = t
        sent = h.received(keys.PATH, GlobalPath)
    assert lost is not None and plan is not None  # the premise: the planner knows no way
    before = [p for p in sent if p.stamp < lost]
    assert before and all(p.points.tolist() == STRAIGHT for p in before)
    after = sent[len(before):]
    assert all(len(p.points) == 0 and p.reason == plan.reason for p in after)
    assert after[0].stamp == lost and after[0].planned == lost
    # Then one a period (0.75 s, on the 0.1 s cycle: the first cycle at or past it).
    assert [p.stamp for p in after[1:]] == [round(lost + 0.8 * k, 6) for k in range(1, 4)]
    assert all(p.repeats(after[0]) for p in after[1:])


def test_a_goal_declared_unreachable_is_an_empty_path_that_says_so():
    """What the planner publishes as its path, read from the planner itself."""
    planner = Planner(params())
    key, points, reason = current_path(planner) or ((), None, "")
    assert points is not None and points.tolist() == STRAIGHT and reason == "start"
    planner.plan = GlobalPlan(np.empty((0, 2)), math.inf, "no way to the goal")
    no_way = current_path(planner)
    assert no_way is not None and len(no_way[1]) == 0 and no_way[2] == "no way to the goal"
    planner.recovery.unreachable = True
    given_up = current_path(planner)
    assert given_up is not None and len(given_up[1]) == 0
    assert given_up[2] == "goal unreachable: no way to the goal"
    assert len({key, no_way[0], given_up[0]}) == 3  # each a change, sent at once
