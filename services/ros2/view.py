"""zenav's view of the world as RViz draws it (pure): tracked obstacles as a
``visualization_msgs/msg/MarkerArray`` (a cylinder per track coloured by type, an arrow
for each moving one's velocity, the planner's scenario letter and action as text) and a
planned path as ``nav_msgs/msg/Path`` and the planner's occupancy map as
``nav_msgs/msg/OccupancyGrid``. Everything is in the odometry frame, the frame
zenav's poses are in.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from zenav.schemas.messages import OccupancyMap, PlannerState, Track, TrackList
from zenav.services.ros2.convert import header, point, pose, ros_time
from zenav.services.ros2.wire import MARKER_ARRAY, OCCUPANCY_GRID, PATH, message_class

ARROW, CYLINDER, TEXT = 0, 3, 9
ADD, DELETEALL = 0, 3
TRACK_HEIGHT = 0.5
"""Height of the drawn track cylinders, m (zenav is planar)."""

COLOURS: dict[str, tuple[float, float, float, float]] = {
    "new": (1.0, 0.85, 0.1, 0.8),      # not classified yet: yellow
    "static": (0.55, 0.55, 0.6, 0.8),  # grey
    "dynamic": (0.9, 0.15, 0.15, 0.8),  # red
}


def _marker(stamp: float, frame: str, ns: str, ident: int, kind: int, **fields: Any) -> Any:
    cls = message_class("visualization_msgs/msg/Marker")
    r, g, b, a = fields.pop("rgba", (1.0, 1.0, 1.0, 1.0))
    sx, sy, sz = fields.pop("scale", (1.0, 1.0, 1.0))
    defaults: dict[str, Any] = dict(
        header=header(stamp, frame), ns=ns, id=ident, type=kind, action=ADD,
        pose=pose(0.0, 0.0, 0.0),
        scale=message_class("geometry_msgs/msg/Vector3")(x=sx, y=sy, z=sz),
        color=message_class("std_msgs/msg/ColorRGBA")(r=r, g=g, b=b, a=a),
        lifetime=message_class("builtin_interfaces/msg/Duration")(sec=0, nanosec=0),
        frame_locked=False, points=[], colors=[], texture_resource="",
        texture=message_class("sensor_msgs/msg/CompressedImage")(
            header=header(0.0, ""), format="", data=np.zeros(0, dtype=np.uint8)),
        uv_coordinates=[], text="", mesh_resource="",
        mesh_file=message_class("visualization_msgs/msg/MeshFile")(
            filename="", data=np.zeros(0, dtype=np.uint8)),
        mesh_use_embedded_materials=False,
    )
    defaults.update(fields)
    return cls(**defaults)


def track_markers(track: Track, stamp: float, frame: str) -> list[Any]:
    """A cylinder for the track, and an arrow of one second's travel when it moves."""
    diameter = max(2 * track.radius, 0.05)
    out = [_marker(stamp, frame, "tracks", track.id, CYLINDER,
                   pose=pose(track.x, track.y, 0.0), rgba=COLOURS[track.kind],
                   scale=(diameter, diameter, TRACK_HEIGHT))]
    if track.kind == "dynamic" and track.speed > 0:
        start = point(track.x, track.y, TRACK_HEIGHT / 2)
        end = point(track.x + track.vx, track.y + track.vy, TRACK_HEIGHT / 2)
        out.append(_marker(stamp, frame, "velocity", track.id, ARROW, points=[start, end],
                           rgba=(1.0, 0.4, 0.0, 1.0), scale=(0.05, 0.1, 0.1)))
    return out


def tracks_to_markers(tracks: TrackList, frame: str,
                      state: PlannerState | None = None) -> Any:
    """The MarkerArray of one track list: first a DELETEALL (tracks that ended vanish),
    then the tracks, their velocity arrows and the planner's scenario and action."""
    stamp = tracks.stamp
    markers = [_marker(stamp, frame, "", 0, CYLINDER, action=DELETEALL)]
    for track in tracks.tracks:
        markers.extend(track_markers(track, stamp, frame))
    if state is not None:
        markers.append(planner_text(state, tracks.pose.x, tracks.pose.y, frame))
    return message_class(MARKER_ARRAY)(markers=markers)


def planner_text(state: PlannerState, x: float, y: float, frame: str) -> Any:
    """The planner's scenario letter and action, floating above the robot."""
    return _marker(state.stamp, frame, "planner", 0, TEXT, pose=pose(x, y + 0.6, 0.0),
                   text=f"({state.scenario}) {state.action} {state.speed:.2f} m/s",
                   rgba=(1.0, 1.0, 1.0, 1.0), scale=(0.0, 0.0, 0.3))


def path_to_ros(points: Sequence[tuple[float, float]], stamp: float, frame: str) -> Any:
    """A ``nav_msgs/msg/Path`` through ``points`` (m), each pose facing the next point."""
    poses = []
    for i, (x, y) in enumerate(points):
        nx, ny = points[min(i + 1, len(points) - 1)]
        yaw = float(np.arctan2(ny - y, nx - x)) if (nx, ny) != (x, y) else 0.0
        poses.append(message_class("geometry_msgs/msg/PoseStamped")(
            header=header(stamp, frame), pose=pose(x, y, yaw)))
    return message_class(PATH)(header=header(stamp, frame), poses=poses)




def map_to_ros(occupancy: OccupancyMap, frame: str) -> Any:
    """A ``nav_msgs/msg/OccupancyGrid`` of the planner's map: the same cells in the same
    order (row by row from the origin's corner) and values (-1 unknown, 0 free, 100
    occupied), the origin as the pose of cell (0, 0)'s corner."""
    info = message_class("nav_msgs/msg/MapMetaData")(
        map_load_time=ros_time(occupancy.stamp), resolution=float(occupancy.resolution),
        width=occupancy.width, height=occupancy.height,
        origin=pose(float(occupancy.origin[0]), float(occupancy.origin[1]), 0.0))
    return message_class(OCCUPANCY_GRID)(
        header=header(occupancy.stamp, frame), info=info,
        data=np.asarray(occupancy.cells, dtype=np.int8))
