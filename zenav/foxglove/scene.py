"""zenav's messages as Foxglove's well-known schemas (pure: messages in, messages out).

Topics (all under ``/foxglove/``), frames ``odom`` (the world: zenav's poses),
``base_link`` (the robot) and the scan's frame (the scanner, at the robot's centre):

- ``scan``: ``foxglove.LaserScan`` (no-return beams as +inf, so nothing is drawn there);
- ``tf``: ``foxglove.FrameTransform`` odom -> base_link from odometry, and base_link ->
  the scan frame (identity: zenav's scanner is at the robot's centre);
- ``pose``: ``foxglove.PoseInFrame`` of the robot in odom;
- ``obstacles``: ``foxglove.SceneUpdate``, perception's clusters as flat cylinders;
- ``tracks``: ``foxglove.SceneUpdate``, tracks coloured by type (new yellow, static grey,
  dynamic red) with an arrow of one second's travel and the track id;
- ``plan``: ``foxglove.SceneUpdate``, the planner's line to its current (sub-)target with
  its scenario letter and action, and its latest global path (``planner/path``) as a
  blue line from the robot to the goal (each update carries both, since it replaces the
  last one);
- ``map``: ``foxglove.Grid``, the planner's occupancy map (``planner/map``): one INT8
  field ``occupancy`` per cell, -1 unknown, 0 free, 100 occupied, as ROS draws it;
- ``truth``: ``foxglove.SceneUpdate``, the simulator's ground truth (green, translucent);
- ``log``: ``foxglove.Log``, one line per planner event.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from foxglove import messages as fm

from zenav.schemas.messages import (
    GlobalPath,
    GroundTruth,
    LaserScan,
    Message,
    ObstacleChain,
    OccupancyMap,
    Odometry,
    PlannerEvent,
    PlannerState,
    TrackList,
)

ODOM = "odom"
BASE = "base_link"
HEIGHT = 0.5
"""Height of drawn obstacles, m (zenav is planar)."""

TOPICS: dict[str, type[Any]] = {
    "/foxglove/scan": fm.LaserScan,
    "/foxglove/tf": fm.FrameTransform,
    "/foxglove/pose": fm.PoseInFrame,
    "/foxglove/obstacles": fm.SceneUpdate,
    "/foxglove/tracks": fm.SceneUpdate,
    "/foxglove/plan": fm.SceneUpdate,
    "/foxglove/map": fm.Grid,
    "/foxglove/truth": fm.SceneUpdate,
    "/foxglove/log": fm.Log,
}
"""Every Foxglove topic zenav writes, with its message type."""

KIND_COLOURS = {"new": (1.0, 0.85, 0.1, 0.8), "static": (0.55, 0.55, 0.6, 0.8),
                "dynamic": (0.9, 0.15, 0.15, 0.8)}


def timestamp(stamp: float) -> fm.Timestamp:
    sec = math.floor(stamp)
    nsec = min(round((stamp - sec) * 1e9), 999_999_999)
    return fm.Timestamp(sec=int(sec), nsec=int(nsec))


def colour(rgba: tuple[float, float, float, float]) -> fm.Color:
    r, g, b, a = rgba
    return fm.Color(r=r, g=g, b=b, a=a)


def quaternion(yaw: float) -> fm.Quaternion:
    return fm.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def pose(x: float, y: float, yaw: float = 0.0, z: float = 0.0) -> fm.Pose:
    return fm.Pose(position=fm.Vector3(x=x, y=y, z=z), orientation=quaternion(yaw))


def laser_scan(scan: LaserScan) -> fm.LaserScan:
    ranges = np.asarray(scan.ranges, dtype=np.float64).copy()
    ranges[ranges >= scan.range_max] = math.inf
    return fm.LaserScan(timestamp=timestamp(scan.stamp), frame_id=scan.frame,
                        pose=pose(0.0, 0.0), start_angle=scan.angle_min,
                        end_angle=scan.angle_max, ranges=ranges.tolist(), intensities=[])


def robot_transform(odometry: Odometry) -> fm.FrameTransform:
    p = odometry.pose
    return fm.FrameTransform(timestamp=timestamp(odometry.stamp), parent_frame_id=ODOM,
                             child_frame_id=BASE, translation=fm.Vector3(x=p.x, y=p.y, z=0.0),
                             rotation=quaternion(p.heading))


def scanner_transform(scan: LaserScan) -> fm.FrameTransform:
    return fm.FrameTransform(timestamp=timestamp(scan.stamp), parent_frame_id=BASE,
                             child_frame_id=scan.frame, translation=fm.Vector3(x=0, y=0, z=0),
                             rotation=quaternion(0.0))


def robot_pose(odometry: Odometry) -> fm.PoseInFrame:
    p = odometry.pose
    return fm.PoseInFrame(timestamp=timestamp(odometry.stamp), frame_id=ODOM,
                          pose=pose(p.x, p.y, p.heading))


def _entity(stamp: float, ident: str, **primitives: Any) -> fm.SceneEntity:
    return fm.SceneEntity(timestamp=timestamp(stamp), frame_id=ODOM, id=ident, **primitives)


def _update(stamp: float, entities: list[fm.SceneEntity]) -> fm.SceneUpdate:
    """A whole new scene: everything drawn before on this topic is deleted first."""
    return fm.SceneUpdate(
        deletions=[fm.SceneEntityDeletion(timestamp=timestamp(stamp),
                                          type=fm.SceneEntityDeletionType.All)],
        entities=entities)


def _disc(x: float, y: float, radius: float, rgba: tuple[float, float, float, float],
          height: float = HEIGHT) -> fm.CylinderPrimitive:
    d = max(2 * radius, 0.05)
    return fm.CylinderPrimitive(pose=pose(x, y, z=height / 2),
                                size=fm.Vector3(x=d, y=d, z=height),
                                bottom_scale=1.0, top_scale=1.0, color=colour(rgba))


def obstacles(chain: ObstacleChain) -> fm.SceneUpdate:
    cylinders = [_disc(o.x, o.y, o.radius, (0.2, 0.5, 1.0, 0.6), height=0.1)
                 for o in chain.obstacles]
    return _update(chain.stamp, [_entity(chain.stamp, "obstacles", cylinders=cylinders)])


def tracks(track_list: TrackList) -> fm.SceneUpdate:
    entities = []
    for t in track_list.tracks:
        arrows, texts = [], [fm.TextPrimitive(
            pose=pose(t.x, t.y, z=HEIGHT + 0.2), billboard=True, font_size=14.0,
            scale_invariant=True, color=colour((1, 1, 1, 1)), text=f"{t.id} {t.kind}")]
        if t.kind == "dynamic" and t.speed > 0:
            arrows.append(fm.ArrowPrimitive(
                pose=pose(t.x, t.y, math.atan2(t.vy, t.vx), z=HEIGHT / 2),
                shaft_length=max(t.speed - 0.1, 0.01), shaft_diameter=0.04, head_length=0.1,
                head_diameter=0.1, color=colour((1.0, 0.4, 0.0, 1.0))))
        entities.append(_entity(track_list.stamp, f"track-{t.id}",
                                cylinders=[_disc(t.x, t.y, t.radius, KIND_COLOURS[t.kind])],
                                arrows=arrows, texts=texts))
    return _update(track_list.stamp, entities)


def path_entity(path: GlobalPath) -> fm.SceneEntity:
    """The global path as a line strip, robot to goal (no line when no way is known)."""
    points = [fm.Point3(x=float(x), y=float(y), z=0.03) for x, y in path.points]
    lines = [] if len(points) < 2 else [fm.LinePrimitive(
        type=fm.LinePrimitiveLineType.LineStrip, pose=pose(0.0, 0.0), thickness=0.03,
        scale_invariant=False, points=points, color=colour((0.2, 0.6, 1.0, 0.9)))]
    return _entity(path.stamp, "path", lines=lines)


def plan(state: PlannerState | None, odometry: Odometry | None,
         path: GlobalPath | None = None) -> fm.SceneUpdate:
    """The line from the robot to the planner's current target and its decision, and the
    global path; stamped with the newer of the two."""
    entities = [] if path is None else [path_entity(path)]
    stamps = [m.stamp for m in (state, path) if m is not None]
    stamp = max(stamps) if stamps else 0.0
    if state is not None:
        entities.insert(0, _target_entity(state, odometry))
    return _update(stamp, entities)


def _target_entity(state: PlannerState, odometry: Odometry | None) -> fm.SceneEntity:
    tx, ty = state.target
    x, y = (odometry.pose.x, odometry.pose.y) if odometry is not None else (tx, ty)
    line = fm.LinePrimitive(type=fm.LinePrimitiveLineType.LineStrip, pose=pose(0.0, 0.0),
                            thickness=0.04, scale_invariant=False,
                            points=[fm.Point3(x=x, y=y, z=0.05), fm.Point3(x=tx, y=ty, z=0.05)],
                            color=colour((0.2, 0.9, 0.3, 1.0)))
    text = fm.TextPrimitive(pose=pose(x, y, z=HEIGHT + 0.5), billboard=True, font_size=16.0,
                            scale_invariant=True, color=colour((1, 1, 1, 1)),
                            text=f"({state.scenario}) {state.action} {state.speed:.2f} m/s")
    return _entity(state.stamp, "plan", lines=[line], texts=[text])


def occupancy_grid(occupancy: OccupancyMap) -> fm.Grid:
    """The map as a grid of one INT8 field, rows along y from the map's origin."""
    ox, oy = occupancy.origin
    r = occupancy.resolution
    return fm.Grid(timestamp=timestamp(occupancy.stamp), frame_id=ODOM, pose=pose(ox, oy),
                   column_count=occupancy.width, cell_size=fm.Vector2(x=r, y=r),
                   row_stride=occupancy.width, cell_stride=1,
                   fields=[fm.PackedElementField(
                       name="occupancy", offset=0, type=fm.PackedElementFieldNumericType.Int8)],
                   data=np.ascontiguousarray(occupancy.cells, dtype=np.int8).tobytes())


def truth(ground: GroundTruth) -> fm.SceneUpdate:
    green = (0.2, 0.9, 0.3, 0.35)
    cylinders, cubes = [], []
    for o in ground.obstacles:
        if o.shape == "disc":
            cylinders.append(_disc(o.x, o.y, o.size[0] / 2, green))
        else:
            cubes.append(fm.CubePrimitive(pose=pose(o.x, o.y, z=HEIGHT / 2),
                                          size=fm.Vector3(x=o.size[0], y=o.size[1], z=HEIGHT),
                                          color=colour(green)))
    robot = ground.pose
    return _update(ground.stamp, [_entity(ground.stamp, "truth", cylinders=cylinders,
                                          cubes=cubes),
                                  _entity(ground.stamp, "truth-robot", arrows=[
                                      fm.ArrowPrimitive(pose=pose(robot.x, robot.y,
                                                                  robot.heading, z=0.1),
                                                        shaft_length=0.25, shaft_diameter=0.05,
                                                        head_length=0.1, head_diameter=0.12,
                                                        color=colour(green))])])


def log(event: PlannerEvent) -> fm.Log:
    about = "" if event.obstacle is None else f" obstacle {event.obstacle} ({event.kind})"
    detail = f": {event.detail}" if event.detail else ""
    return fm.Log(timestamp=timestamp(event.stamp), level=fm.LogLevel.Info, name="planner",
                  message=f"({event.scenario}) {event.action}{about}{detail}")


class SceneBuilder:
    """zenav messages in, (Foxglove topic, message) pairs out; keeps the latest odometry
    for the plan line, and the latest planner state and global path, which share the
    plan scene."""

    def __init__(self) -> None:
        self.odometry: Odometry | None = None
        self.state: PlannerState | None = None
        self.path: GlobalPath | None = None

    def convert(self, message: Message) -> list[tuple[str, Any]]:
        if isinstance(message, LaserScan):
            out: list[tuple[str, Any]] = [("/foxglove/scan", laser_scan(message))]
            out.insert(0, ("/foxglove/tf", scanner_transform(message)))
            return out
        if isinstance(message, Odometry):
            self.odometry = message
            return [("/foxglove/tf", robot_transform(message)),
                    ("/foxglove/pose", robot_pose(message))]
        if isinstance(message, ObstacleChain):
            return [("/foxglove/obstacles", obstacles(message))]
        if isinstance(message, TrackList):
            return [("/foxglove/tracks", tracks(message))]
        if isinstance(message, PlannerState):
            self.state = message
            return [("/foxglove/plan", plan(message, self.odometry, self.path))]
        if isinstance(message, GlobalPath):
            self.path = message
            return [("/foxglove/plan", plan(self.state, self.odometry, message))]
        if isinstance(message, OccupancyMap):
            return [("/foxglove/map", occupancy_grid(message))]
        if isinstance(message, GroundTruth):
            return [("/foxglove/truth", truth(message))]
        if isinstance(message, PlannerEvent):
            return [("/foxglove/log", log(message))]
        return []
