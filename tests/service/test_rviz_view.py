"""zenav rviz on the in-memory bus: a track list in, a MarkerArray on the ROS 2 wire out,
with the planner's latest state as a text marker and the view's liveliness tokens."""

from __future__ import annotations

import asyncio

from tests.ros2 import samples
from zenav.rviz import RvizView
from zenav.schemas import keys
from zenav.schemas.codec import encode
from zenav.schemas.keys import Keys
from zenav.services.ros2 import wire
from zenav.services.transport import InMemoryBus


async def test_tracks_become_markers_for_rviz():
    bus = InMemoryBus()
    view = RvizView(bus, "robot0", domain_id=3, topic="/zenav/markers")
    task = asyncio.create_task(view.run())
    k = Keys("robot0")
    try:
        bus.deliver(k.of(keys.PLANNER_STATE), encode(samples.state()))
        await asyncio.sleep(0.01)
        bus.deliver(k.of(keys.TRACKS), b"garbage")  # ignored, not fatal
        await asyncio.sleep(0.01)
        bus.deliver(k.of(keys.TRACKS), encode(samples.tracks()))
        await asyncio.sleep(0.01)
        key = wire.topic_key(3, "/zenav/markers", wire.MARKER_ARRAY)
        sent = [p for kk, p in bus.published if kk == key]
        tokens = [wire.parse_token(t) for t in view.ros.tokens]
    finally:
        task.cancel()
        view.close()
    assert len(sent) == 1 and view.sent == 1
    markers = wire.deserialize(sent[0], wire.MARKER_ARRAY).markers
    assert {m.ns for m in markers} == {"", "tracks", "velocity", "planner"}
    assert next(m for m in markers if m.ns == "planner").text.startswith("(c) slow")
    assert {(t.kind, t.topic) for t in tokens} == {("NN", None), ("MP", "/zenav/markers")}
