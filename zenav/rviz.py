"""``zenav rviz``: zenav's view for RViz on a ROS 2 robot's own wire (rmw_zenoh).

Read-only, from any host: it follows zenav's tracks and planner state and publishes
``visualization_msgs/msg/MarkerArray`` on ``/zenav/markers`` (a cylinder per tracked
obstacle coloured by type, a velocity arrow per mover, the planner's scenario letter and
action as text above the robot), in the odometry frame, and the planner's global path
(``planner/path``) as ``nav_msgs/msg/Path`` on ``/zenav/plan`` as the planner sends it
(when it plans again, and the same path again about once a second, so that an RViz
started late shows it; a Path with no poses when no way is known), and
its occupancy map (``planner/map``, about once a second) as
``nav_msgs/msg/OccupancyGrid`` on ``/zenav/map``. In RViz: Add > By topic >
/zenav/markers, /zenav/plan and /zenav/map (the map display's durability: volatile).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import sys
from typing import Any

from zenav.argtypes import count, nonempty, positive_float
from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import GlobalPath, OccupancyMap, PlannerState, TrackList
from zenav.services.ros2.node import Ros2Node
from zenav.services.ros2.view import map_to_ros, path_to_ros, tracks_to_markers
from zenav.services.ros2.wire import MARKER_ARRAY, OCCUPANCY_GRID, PATH, WireError, qualify
from zenav.services.runner import add_transport_arguments
from zenav.services.transport import Bus
from zenav.tooling import (
    Heard,
    add_connect_timeout,
    note_if_quiet,
    open_bus,
    quiet_note,
    run_tool,
    stop_on_signals,
    tool_setup,
)

MAX_DOMAIN_ID = 232
"""The highest ROS_DOMAIN_ID (the one :class:`zenav.services.ros2.wire.NodeIdentity`
accepts)."""


class RvizView:
    """Tracks and planner state in, MarkerArray out (one per track list); global paths
    in, Path out (one per path message, repeats included); maps in, OccupancyGrid out
    (one per map)."""

    def __init__(self, bus: Bus, robot_id: str, *, domain_id: int = 0,
                 topic: str = "/zenav/markers", frame: str = "odom",
                 path_topic: str = "/zenav/plan", map_topic: str = "/zenav/map",
                 node_name: str = "zenav_view") -> None:
        self.keys = Keys(robot_id)
        self.frame = frame
        self.ros = Ros2Node(bus, node_name, domain_id)
        self.markers = self.ros.publisher(qualify(topic), MARKER_ARRAY)
        self.path = self.ros.publisher(qualify(path_topic), PATH)
        self.map = self.ros.publisher(qualify(map_topic), OCCUPANCY_GRID)
        self.tracks = bus.subscribe(self.keys.of(keys.TRACKS), depth=1)
        self.states = bus.subscribe(self.keys.of(keys.PLANNER_STATE), depth=1)
        self.paths = bus.subscribe(self.keys.of(keys.PATH), depth=1)
        self.maps = bus.subscribe(self.keys.of(keys.MAP), depth=1)
        self.heard = Heard()  # any message of the robot's, for the quiet note
        self.state: PlannerState | None = None
        self.sent = 0
        self.paths_sent = 0
        self.maps_sent = 0

    def on_state(self, payload: bytes) -> None:
        self.heard.mark()
        with contextlib.suppress(DecodeError):
            self.state = decode(payload, PlannerState, self.keys.of(keys.PLANNER_STATE))

    def on_path(self, payload: bytes) -> None:
        self.heard.mark()
        try:
            path = decode(payload, GlobalPath, self.keys.of(keys.PATH), keys.PATH.max_bytes)
        except DecodeError:
            return
        points = [(float(x), float(y)) for x, y in path.points]
        self.path.publish(path_to_ros(points, path.stamp, self.frame))
        self.paths_sent += 1

    def on_map(self, payload: bytes) -> None:
        self.heard.mark()
        try:
            occupancy = decode(payload, OccupancyMap, self.keys.of(keys.MAP), keys.MAP.max_bytes)
        except DecodeError:
            return
        self.map.publish(map_to_ros(occupancy, self.frame))
        self.maps_sent += 1

    def on_tracks(self, payload: bytes) -> None:
        self.heard.mark()
        try:
            tracks = decode(payload, TrackList, self.keys.of(keys.TRACKS),
                            keys.TRACKS.max_bytes)
        except DecodeError:
            return
        self.markers.publish(tracks_to_markers(tracks, self.frame, self.state))
        self.sent += 1

    async def run(self) -> None:
        async def states() -> None:
            while True:
                self.on_state((await self.states.get())[1])

        async def paths() -> None:
            while True:
                self.on_path((await self.paths.get())[1])

        async def maps() -> None:
            while True:
                self.on_map((await self.maps.get())[1])

        loop = asyncio.get_running_loop()
        tasks = [loop.create_task(states()), loop.create_task(paths()),
                 loop.create_task(maps())]
        try:
            while True:
                self.on_tracks((await self.tracks.get())[1])
        finally:
            for task in tasks:
                task.cancel()

    def close(self) -> None:
        self.tracks.close()
        self.states.close()
        self.paths.close()
        self.maps.close()
        self.ros.close()


async def serve(transport: Any, robot_id: str, args: argparse.Namespace) -> None:
    stop = asyncio.Event()
    stop_on_signals(stop)
    if args.duration is not None:
        asyncio.get_running_loop().call_later(args.duration, stop.set)
    bus = await open_bus(transport, stop, args.connect_timeout, "zenav rviz")
    if bus is None:  # stopped while connecting
        return
    view = RvizView(bus, robot_id, domain_id=args.domain_id, topic=args.topic, frame=args.frame,
                    path_topic=args.path_topic, map_topic=args.map_topic)
    task = asyncio.get_running_loop().create_task(view.run())
    quiet = asyncio.get_running_loop().create_task(
        note_if_quiet(view.heard, stop, quiet_note("rviz", transport, robot_id)))
    print(f"zenav rviz: robot {robot_id}'s tracks and planner state to {args.topic}, its path "
          f"to {args.path_topic} and its map to {args.map_topic} (ROS_DOMAIN_ID "
          f"{args.domain_id}, frame {args.frame}); Ctrl-C stops", flush=True)
    try:
        await stop.wait()
    finally:
        quiet.cancel()
        task.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await task
        view.close()
        bus.close()


def main(args: argparse.Namespace) -> int:
    setup = tool_setup(args, "rviz")
    if setup is None:
        return 2
    for option, topic in (("--topic", args.topic), ("--path-topic", args.path_topic),
                          ("--map-topic", args.map_topic)):
        try:
            qualify(topic)
        except WireError as exc:
            print(f"zenav rviz: {option}: {exc}", file=sys.stderr)
            return 2
    robot_id, transport = setup
    return run_tool("rviz", serve(transport, robot_id, args))


def add_command(sub: Any) -> None:
    rviz = sub.add_parser(
        "rviz", help="publish zenav's tracks, planner state, global path and map for RViz "
        "over rmw_zenoh",
        description="Tracked obstacles (type colour, velocity arrows) and the planner's "
        "scenario and action as visualization_msgs/msg/MarkerArray on a ROS 2 topic, "
        "the planner's global path as nav_msgs/msg/Path on another and its occupancy map "
        "as nav_msgs/msg/OccupancyGrid on a third.")
    rviz.add_argument("--domain-id", type=count(0, MAX_DOMAIN_ID), default=0,
                      help=f"ROS_DOMAIN_ID, 0 to {MAX_DOMAIN_ID} (default 0)")
    rviz.add_argument("--topic", default="/zenav/markers",
                      help="MarkerArray topic (default /zenav/markers)")
    rviz.add_argument("--path-topic", default="/zenav/plan",
                      help="Path topic (default /zenav/plan)")
    rviz.add_argument("--map-topic", default="/zenav/map",
                      help="OccupancyGrid topic (default /zenav/map)")
    rviz.add_argument("--frame", type=nonempty, default="odom",
                      help="frame of zenav's poses (default odom)")
    rviz.add_argument("--duration", type=positive_float, help="stop after this many s")
    add_transport_arguments(rviz)
    add_connect_timeout(rviz)
    rviz.set_defaults(func=main)
