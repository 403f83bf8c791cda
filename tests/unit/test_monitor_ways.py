"""The monitor's global path and occupancy map: the model's figures from hand-made
messages, the map view in characters, and the screen's lines."""

from __future__ import annotations

import io
import math

import numpy as np
import numpy.typing as npt
import pytest
from rich.console import Console

from zenav.cli import main as zenav_main
from zenav.monitor.model import MonitorModel, along_path, path_length
from zenav.monitor.screen import render
from zenav.monitor.view import (
    ARROWS,
    FREE,
    GOAL,
    OCCUPIED,
    PATH,
    UNKNOWN,
    Window,
    map_view,
    occupancy_chars,
)
from zenav.schemas.codec import encode
from zenav.schemas.messages import (
    GlobalPath,
    Message,
    OccupancyMap,
    Odometry,
    Pose2D,
    Track,
    TrackList,
)

T0 = 1_000_000.0


def feed(model: MonitorModel, topic: str, message: Message, at: float) -> None:
    model.on_sample(f"zenav/r1/{topic}", encode(message), T0 + at)


def occupancy(grid: npt.NDArray[np.int8], origin: tuple[float, float] = (0.0, 0.0),
              resolution: float = 0.1, stamp: float = 2.0) -> OccupancyMap:
    """A map message from a grid indexed [ix, iy] (the message is row by row, iy first)."""
    width, height = grid.shape
    return OccupancyMap(stamp=stamp, seq=0, origin=origin, resolution=resolution, width=width,
                        height=height, cells=np.ascontiguousarray(grid.T).ravel())


def wall_with_gap() -> npt.NDArray[np.int8]:
    """10 x 8 m at 0.1 m: free below y = 6 m, unknown above; a wall at x = 6.0-6.2 m with
    a gap from y = 4 to 5 m."""
    grid = np.zeros((100, 80), dtype=np.int8)
    grid[:, 60:] = -1
    grid[60:62, :40] = 100
    grid[60:62, 50:60] = 100
    return grid


def odom(x: float, y: float, heading: float = 0.0, t: float = 2.0) -> Odometry:
    return Odometry(stamp=t, seq=0, pose=Pose2D(x=x, y=y, heading=heading), v=0.2, omega=0.0)


def track(id_: int, kind: str, x: float, y: float) -> Track:
    return Track(id=id_, kind=kind, x=x, y=y, vx=0.0, vy=0.0, speed=0.0, heading=0.0,
                 radius=0.2, xi=0.5, varsigma=0.5, alpha_o_deg=0.0, age=3, cells=(1, 2, 3, 4),
                 area=4)


def test_path_length_and_the_way_still_to_go_along_it():
    points = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0]])
    assert path_length(points) == pytest.approx(7.0)
    assert path_length(points[:1]) == 0.0
    assert along_path(points, 1.0, 0.5) == pytest.approx((6.0, 0.5))  # beside the first leg
    assert along_path(points, 3.5, 3.0) == pytest.approx((1.0, 0.5))  # beside the second
    assert along_path(points, -2.0, 0.0) == pytest.approx((7.0, 2.0))  # behind the start
    assert along_path(points, 3.0, 6.0) == pytest.approx((0.0, 2.0))  # past the goal
    repeated = np.array([[0.0, 0.0], [0.0, 0.0], [2.0, 0.0]])  # a zero-length leg
    assert along_path(repeated, 1.0, 1.0) == pytest.approx((1.0, 1.0))


def test_paths_and_maps_heard_are_in_the_snapshot_and_paths_are_events():
    model = MonitorModel("r1")
    assert model.snapshot(T0)["path"] is None and model.snapshot(T0)["map"] is None
    feed(model, "planner/path", GlobalPath(stamp=0.0, seq=0, points=np.array(
        [[2.0, 3.0], [8.0, 3.0]]), reason="start"), 0.1)
    detour = np.array([[3.0, 3.0], [5.5, 4.5], [6.5, 4.5], [8.0, 3.0]])
    feed(model, "planner/path", GlobalPath(stamp=1.5, seq=1, points=detour,
                                           reason="blocked beyond the window"), 1.6)
    feed(model, "odom", odom(4.25, 4.0), 2.0)
    feed(model, "planner/map", occupancy(wall_with_gap()), 2.1)
    snap = model.snapshot(T0 + 2.6)
    legs = [math.hypot(2.5, 1.5), 1.0, math.hypot(1.5, 1.5)]
    path = snap["path"]
    assert path["reason"] == "blocked beyond the window" and path["stamp"] == 1.5
    assert path["waypoints"] == 4 and path["length"] == pytest.approx(sum(legs), abs=1e-3)
    assert path["found"] is True and path["goal"] == [8.0, 3.0]
    assert path["age"] == pytest.approx(1.0) and path["plans"] == 2
    assert path["points"] == detour.tolist()
    # (4.25, 4.0) is beside the first leg: 1.25 m along x and 1 m along y from its start.
    along, off = (1.25 * 2.5 + 1.0 * 1.5) / legs[0], abs(1.25 * 1.5 - 1.0 * 2.5) / legs[0]
    assert path["off_path"] == pytest.approx(off, abs=1e-3)
    assert path["to_go"] == pytest.approx(sum(legs) - along, abs=1e-3)
    occupancy_figures = snap["map"]
    assert occupancy_figures["width"] == 100 and occupancy_figures["height"] == 80
    assert occupancy_figures["size"] == [10.0, 8.0] and occupancy_figures["resolution"] == 0.1
    assert occupancy_figures["known_fraction"] == pytest.approx(60 / 80)
    assert occupancy_figures["occupied_cells"] == 2 * 50
    assert occupancy_figures["occupied_fraction"] == pytest.approx(100 / 8000)
    assert occupancy_figures["age"] == pytest.approx(0.5)
    paths = [e.data for e in model.drain_events() if e.kind == "path"]
    assert paths == [
        {"reason": "start", "waypoints": 2, "length": 6.0, "stamp": 0.0},
        {"reason": "blocked beyond the window", "waypoints": 4,
         "length": round(sum(legs), 3), "stamp": 1.5}]


def test_a_path_with_no_way_is_shown_as_such():
    model = MonitorModel("r1")
    feed(model, "odom", odom(1.0, 1.0), 0.0)
    feed(model, "planner/path", GlobalPath(stamp=4.0, seq=3, points=np.zeros((0, 2)),
                                           reason="retry"), 4.0)
    snap = model.snapshot(T0 + 4.5)
    assert snap["path"]["found"] is False and snap["path"]["goal"] is None
    assert snap["path"]["to_go"] is None and snap["path"]["points"] == []
    console = Console(file=io.StringIO(), width=140, record=True, color_system=None)
    console.print(render(model, T0 + 4.5))
    assert ("global path: no way known since t=4.0 s (retry), heard 0.5 s ago"
            in console.export_text())


def test_repeats_of_a_path_refresh_it_but_are_not_new_plans():
    """The planner sends an unchanged path again every path_period, stamped when sent:
    the monitor keeps it fresh, counts one plan and reports one ``path`` event, and a
    monitor that joined late (its first message a repeat) shows when it was planned."""
    points = np.array([[2.0, 3.0], [8.0, 3.0]])
    model = MonitorModel("r1")
    feed(model, "planner/path", GlobalPath(stamp=0.5, seq=0, points=points, reason="start",
                                           planned=0.5), 0.5)
    for k in (1, 2, 3):  # the repeats, one a second, stamped when sent
        feed(model, "planner/path", GlobalPath(stamp=0.5 + k, seq=k, points=points,
                                               reason="start", planned=0.5), 0.5 + k)
    snap = model.snapshot(T0 + 3.75)["path"]
    assert snap["plans"] == 1 and snap["stamp"] == 0.5 and snap["sent"] == 3.5
    assert snap["age"] == pytest.approx(0.25) and snap["seq"] == 3
    assert [e.data["stamp"] for e in model.drain_events() if e.kind == "path"] == [0.5]
    # The same vertices planned again (a new plan stamp) is a new plan; so is "no way".
    feed(model, "planner/path", GlobalPath(stamp=4.5, seq=4, points=points, reason="replan",
                                           planned=4.5), 4.5)
    none = np.zeros((0, 2))
    for k in (5, 6):
        feed(model, "planner/path", GlobalPath(stamp=float(k + 0.5), seq=k, points=none,
                                               reason="no way to the goal", planned=5.5),
             k + 0.5)
    snap = model.snapshot(T0 + 7.0)["path"]
    assert snap["plans"] == 3 and snap["found"] is False and snap["stamp"] == 5.5
    assert [(e.data["reason"], e.data["waypoints"]) for e in model.drain_events()
            if e.kind == "path"] == [("replan", 2), ("no way to the goal", 0)]
    # A monitor started late: its first message is a repeat, planned long before.
    late = MonitorModel("r1")
    feed(late, "planner/path", GlobalPath(stamp=3.5, seq=3, points=points, reason="start",
                                          planned=0.5), 3.5)
    assert late.snapshot(T0 + 3.5)["path"]["stamp"] == 0.5
    console = Console(file=io.StringIO(), width=150, record=True, color_system=None)
    console.print(render(late, T0 + 4.0))
    assert ("global path: 6.00 m, 2 waypoints, planned at t=0.5 s (start), heard 0.5 s "
            "ago, 1 plan heard") in console.export_text()


def test_the_map_in_characters_marks_occupied_free_and_unknown():
    grid = occupancy(wall_with_gap())
    # Centred so that character edges fall on whole metres: 1 m a column, 2 m a row.
    window = Window((5.5, 4.0), scale=1.0, columns=11, rows=5)
    chars = occupancy_chars(grid, window)
    rows = ["".join(r) for r in chars]
    # Columns are x 0-1, ..., 10-11 (off the map); rows top to bottom y 7-9 (unknown
    # cells, then off the map), 5-7, 3-5, 1-3, -1-1: free but for the wall at x 6.0-6.2.
    # In 3-5 the 1 m gap does not clear the 2 m character: any occupied cell marks it.
    assert rows[0] == UNKNOWN * 11
    assert rows[1:] == [FREE * 6 + OCCUPIED + FREE * 3 + UNKNOWN] * 4


def test_large_map_cells_leave_no_holes_between_characters():
    grid = occupancy(np.full((4, 4), 100, dtype=np.int8), resolution=1.0)  # 4 x 4 m
    window = Window((2.0, 2.0), scale=0.1, columns=11, rows=5)  # 1.1 x 1.0 m, all inside
    assert {c for row in occupancy_chars(grid, window) for c in row} == {OCCUPIED}


def test_the_view_draws_path_goal_tracks_and_robot_over_the_map():
    grid = occupancy(wall_with_gap())
    window = Window((5.0, 4.0), scale=0.5, columns=17, rows=9)  # x 0.75-9.25, y -0.5-8.5
    path = np.array([[2.0, 4.5], [8.0, 4.5]])  # through the gap
    rows = map_view(window, grid, path, [(3.0, 2.0, "dynamic"), (20.0, 2.0, "static")],
                    heading=math.pi / 2)
    assert len(rows) == 9 and all(len(r) == 17 for r in rows)
    assert rows[4][8] == ARROWS[2]  # the robot at the centre, heading +y
    # Characters are x 0.75 + 0.5 k, rows y -0.5 + k; the path's row is y 4.5-5.5, where
    # the wall's upper part (y 5-6) is: the path is not drawn over it.
    assert window.index(5.0, 4.5) == (3, 8)
    assert rows[3] == FREE * 2 + PATH * 8 + OCCUPIED + PATH * 3 + GOAL + FREE * 2
    goal_at = window.index(8.0, 4.5)
    assert goal_at is not None and rows[goal_at[0]][goal_at[1]] == GOAL
    track_at = window.index(3.0, 2.0)
    assert track_at is not None and rows[track_at[0]][track_at[1]] == "D"
    assert not any("S" in r for r in rows)  # the static track is outside the view
    wall_at = window.index(6.1, 2.0)
    assert wall_at is not None and rows[wall_at[0]][wall_at[1]] == OCCUPIED
    # A path through the wall leaves the wall's characters as they are.
    through = map_view(window, grid, np.array([[2.0, 2.0], [8.0, 2.0]]))
    assert through[wall_at[0]][wall_at[1]] == OCCUPIED
    assert through[wall_at[0]][wall_at[1] - 1] == PATH
    # Without a map or a heading: blank, and the robot a ring.
    bare = map_view(window)
    assert bare[4][8] == "o" and set("".join(bare)) == {UNKNOWN, "o"}


def test_the_screen_shows_path_map_and_the_view_round_the_robot():
    model = MonitorModel("r1")
    feed(model, "odom", odom(4.0, 4.5, heading=0.0), 2.0)
    feed(model, "tracks", TrackList(stamp=2.0, seq=0, pose=odom(4.0, 4.5).pose,
                                    tracks=[track(3, "dynamic", 5.0, 4.5)]), 2.0)
    feed(model, "planner/path", GlobalPath(stamp=1.5, seq=1, points=np.array(
        [[3.0, 4.5], [8.0, 4.5]]), reason="off the path"), 1.6)
    feed(model, "planner/map", occupancy(wall_with_gap()), 2.1)
    console = Console(file=io.StringIO(), width=150, record=True, color_system=None)
    console.print(render(model, T0 + 2.6))
    text = console.export_text()
    assert ("global path: 5.00 m, 2 waypoints, planned at t=1.5 s (off the path), heard 1.0 s "
            "ago, 1 plan heard; to go 4.00 m, off it 0.00 m") in text
    assert ("map: 100 x 80 cells of 0.10 m (10.0 x 8.0 m), known 75.0 %, occupied 1.25 %, "
            "t=2.0 s, 0.5 s old") in text
    assert "map round the robot (0.25 m per column, 0.5 m per row)" in text
    lines = text.splitlines()
    top = lines.index(next(line for line in lines if line.startswith("map round the robot")))
    view = [line[:41] for line in lines[top + 1:top + 22]]
    # Columns are x -1.125 + 0.25 k. The robot at (4, 4.5) is the centre; the path from
    # x = 3, the track 1 m (4 columns) ahead, the goal 4 m (16 columns) ahead; left of
    # x = -0.125 there is no map. The gap's row (y 4.25-4.75) is clear of the wall.
    assert view[10] == UNKNOWN * 4 + FREE * 12 + PATH * 4 + ARROWS[0] + PATH * 3 + "D" \
        + PATH * 11 + GOAL + FREE * 4
    for row in (9, 11):  # the rows above and below hold the wall (x 6.0-6.2: columns 28, 29)
        assert view[row][26:32] == FREE * 2 + OCCUPIED * 2 + FREE * 2


def test_a_map_scale_of_zero_is_refused_in_one_line(capsys):
    with pytest.raises(SystemExit) as refused:  # the parser refuses it
        zenav_main(["monitor", "--map-scale", "0"])
    assert refused.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["zenav monitor: argument --map-scale: must be > 0 (got 0)"]
