"""The Foxglove channels of a recording, decoded with the schemas stored in the file (the
ones the Foxglove SDK publishes), as Foxglove itself reads them."""

from __future__ import annotations

import io
import math
from typing import Any

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from tests.ros2 import samples
from zenav.bag.mcapfile import BagWriter
from zenav.foxglove.scene import TOPICS
from zenav.schemas.codec import encode
from zenav.schemas.messages import (
    GlobalPath,
    GroundTruth,
    Obstacle,
    ObstacleChain,
    ObstacleTruth,
    OccupancyMap,
    PlannerEvent,
    Pose2D,
)

NS = 1_000_000_000


def obstacle_chain(stamp: float) -> ObstacleChain:
    ob = Obstacle(x=2.0, y=1.0, rho=2.2, alpha=0.4, cells=(1, 2, 3, 4), area=4, beams=(10, 20),
                  n_beams=11, first=(1.9, 0.9), last=(2.1, 1.1), chord=(2.0, 1.0), radius=0.25,
                  edges=(0, 0))
    return ObstacleChain(stamp=stamp, seq=0, pose=Pose2D(x=0.0, y=0.0, heading=0.0),
                         window_radius=3.0, cell=0.1, obstacles=[ob])


def truth(stamp: float) -> GroundTruth:
    return GroundTruth(stamp=stamp, seq=0, pose=Pose2D(x=0.5, y=0.0, heading=0.1), v=0.2,
                       obstacles=[ObstacleTruth(index=0, shape="disc", x=3.0, y=0.0,
                                                size=(0.6, 0.6), vx=-0.5, vy=0.0),
                                  ObstacleTruth(index=1, shape="box", x=1.0, y=2.0,
                                                size=(1.0, 0.5), vx=0.0, vy=0.0)])


def event(stamp: float) -> PlannerEvent:
    return PlannerEvent(stamp=stamp, seq=0, obstacle=1, kind="dynamic", scenario="f",
                        action="morphin", detail="head-on")


def path(stamp: float) -> GlobalPath:
    return GlobalPath(stamp=stamp, seq=0, points=np.array([[1.25, -0.5], [2.0, 0.5], [3.0, 4.0]]),
                      reason="start")


def record(messages: list[tuple[str, Any]]) -> tuple[dict[str, list[Any]], dict[str, str]]:
    """Record zenav messages (topic, message) and decode the Foxglove channels."""
    stream = io.BytesIO()
    writer = BagWriter(stream, "r1", foxglove=True)
    for topic, sample in messages:
        writer.add(f"zenav/r1/{topic}", encode(sample), 20 * NS)
    writer.close()
    stream.seek(0)
    reader = make_reader(stream, decoder_factories=[DecoderFactory()])
    stamps = {round(sample.stamp * NS) for _, sample in messages}
    out: dict[str, list[Any]] = {}
    schemas = {}
    for schema, channel, message, proto in reader.iter_decoded_messages(
            topics=list(TOPICS)):
        assert schema is not None and channel.message_encoding == "protobuf"
        assert schema.encoding == "protobuf"
        assert message.publish_time in stamps  # the zenav message's own stamp
        assert message.log_time == 20 * NS
        schemas[channel.topic] = schema.name
        out.setdefault(channel.topic, []).append(proto)
    return out, schemas


def occupancy(stamp: float) -> OccupancyMap:
    cells = np.zeros((2, 3), dtype=np.int8)  # (iy, ix)
    cells[0, 2], cells[1, 0] = 100, -1
    return OccupancyMap(stamp=stamp, seq=0, origin=(-1.0, -0.5), resolution=0.25, width=3,
                        height=2, cells=cells.ravel())


@pytest.fixture
def decoded():
    t = 12.5
    return record([("odom", samples.odometry(t)), ("scan", samples.scan(t)),
                   ("obstacles", obstacle_chain(t)), ("tracks", samples.tracks(t)),
                   ("planner/state", samples.state(t)), ("planner/path", path(t)),
                   ("planner/map", occupancy(t)), ("sim/truth", truth(t)),
                   ("planner/events", event(t))])


def test_every_foxglove_topic_is_written_with_its_schema(decoded):
    out, schemas = decoded
    assert set(out) == set(TOPICS)
    for topic, message_type in TOPICS.items():
        assert schemas[topic] == message_type.get_schema().name


def test_scan_transforms_and_pose(decoded):
    out, _ = decoded
    scan = out["/foxglove/scan"][0]
    assert scan.frame_id == "laser" and len(scan.ranges) == 361
    assert scan.start_angle == pytest.approx(-math.pi / 2)
    assert math.isinf(scan.ranges[10]) and scan.ranges[0] == pytest.approx(0.5)
    assert (scan.timestamp.seconds, scan.timestamp.nanos) == (12, 500_000_000)
    frames = {(t.parent_frame_id, t.child_frame_id): t for t in out["/foxglove/tf"]}
    assert set(frames) == {("odom", "base_link"), ("base_link", "laser")}
    robot = frames[("odom", "base_link")]
    assert (robot.translation.x, robot.translation.y) == (1.25, -0.5)
    assert 2 * math.atan2(robot.rotation.z, robot.rotation.w) == pytest.approx(2.0)
    pose = out["/foxglove/pose"][0]
    assert pose.frame_id == "odom" and pose.pose.position.x == 1.25


def test_scene_updates(decoded):
    out, _ = decoded
    tracks = out["/foxglove/tracks"][0]
    assert len(tracks.deletions) == 1  # each update replaces the last one
    entities = {e.id: e for e in tracks.entities}
    assert set(entities) == {"track-1", "track-2", "track-3"}
    mover = entities["track-1"]
    assert mover.frame_id == "odom" and len(mover.arrows) == 1
    assert mover.cylinders[0].color.r == pytest.approx(0.9)  # dynamic: red
    assert mover.texts[0].text == "1 dynamic"
    assert entities["track-2"].arrows == []  # standing: no arrow
    obstacles = out["/foxglove/obstacles"][0].entities[0]
    assert obstacles.cylinders[0].pose.position.x == 2.0
    first, second = out["/foxglove/plan"]  # the state, then the path with the state
    assert [e.id for e in first.entities] == ["plan"]
    plan = first.entities[0]
    assert plan.texts[0].text == "(c) slow 0.10 m/s"
    assert [(p.x, p.y) for p in plan.lines[0].points] == [(1.25, -0.5), (3.0, 4.0)]
    assert len(second.deletions) == 1
    entities = {e.id: e for e in second.entities}
    assert set(entities) == {"plan", "path"}
    assert entities["plan"].texts[0].text == "(c) slow 0.10 m/s"
    global_path = entities["path"]
    assert global_path.frame_id == "odom" and len(global_path.lines) == 1
    assert [(p.x, p.y) for p in global_path.lines[0].points] == [
        (1.25, -0.5), (2.0, 0.5), (3.0, 4.0)]
    truth_entities = {e.id: e for e in out["/foxglove/truth"][0].entities}
    assert len(truth_entities["truth"].cylinders) == 1 and len(truth_entities["truth"].cubes) == 1


def test_a_path_before_any_state_and_an_empty_path():
    empty = GlobalPath(stamp=2.0, seq=1, points=np.zeros((0, 2)), reason="no way")
    out, _ = record([("planner/path", path(1.0)), ("planner/path", empty),
                     ("planner/state", samples.state(3.0))])
    first, second, third = out["/foxglove/plan"]
    assert [e.id for e in first.entities] == ["path"] and len(first.entities[0].lines) == 1
    assert [e.id for e in second.entities] == ["path"]
    assert len(second.entities[0].lines) == 0  # no way known: the old path is gone
    assert [e.id for e in third.entities] == ["plan", "path"]


def test_the_map_is_a_grid(decoded):
    out, _ = decoded
    (grid,) = out["/foxglove/map"]
    assert grid.frame_id == "odom" and grid.column_count == 3
    assert (grid.pose.position.x, grid.pose.position.y) == (-1.0, -0.5)
    assert (grid.cell_size.x, grid.cell_size.y) == (0.25, 0.25)
    assert (grid.row_stride, grid.cell_stride) == (3, 1)
    (field,) = grid.fields
    assert (field.name, field.offset, field.type) == ("occupancy", 0, 2)  # INT8
    cells = np.frombuffer(grid.data, dtype=np.int8).reshape(2, 3)
    assert cells[0, 2] == 100 and cells[1, 0] == -1 and cells.sum() == 99


def test_planner_events_are_log_lines(decoded):
    out, _ = decoded
    (line,) = out["/foxglove/log"]
    assert line.name == "planner" and line.message == "(f) morphin obstacle 1 (dynamic): head-on"
    assert line.level == 2  # INFO in foxglove.Log


def test_the_shipped_layout_is_the_one_the_code_builds():
    from pathlib import Path

    from zenav.foxglove.layout import layout_json

    shipped = Path(__file__).resolve().parents[2] / "deploy" / "foxglove" / "zenav.json"
    assert shipped.read_text() == layout_json()
    assert '"panelType": "ThreeDee"' in shipped.read_text()
    assert '"/foxglove/tracks"' in shipped.read_text()
