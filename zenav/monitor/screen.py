"""The monitor's terminal screen, drawn with ``rich`` from a :class:`MonitorModel`."""

from __future__ import annotations

import time
from itertools import groupby
from typing import Any

from zenav.monitor.model import MonitorModel
from zenav.monitor.view import LEGEND, STYLES, Window, map_view


def _ms(value: float | int | None) -> str:
    return "-" if value is None else f"{1000 * value:.1f} ms"


def path_line(path: dict[str, Any] | None) -> str:
    """One line on the global path, from the snapshot's ``path``."""
    if path is None:
        return ("global path: none heard yet (the planner sends it when it plans again and "
                "repeats it about once a second)")
    if not path["found"]:
        return (f"global path: no way known since t={path['stamp']:.1f} s "
                f"({path['reason']}), heard {path['age']:.1f} s ago")
    plans = "1 plan" if path["plans"] == 1 else f"{path['plans']} plans"
    line = (f"global path: {path['length']:.2f} m, {path['waypoints']} waypoints, planned "
            f"at t={path['stamp']:.1f} s ({path['reason'] or 'no reason given'}), heard "
            f"{path['age']:.1f} s ago, {plans} heard")
    if path["to_go"] is not None:
        line += f"; to go {path['to_go']:.2f} m, off it {path['off_path']:.2f} m"
    return line


def map_line(occupancy: dict[str, Any] | None) -> str:
    """One line on the occupancy map, from the snapshot's ``map``."""
    if occupancy is None:
        return "map: none heard yet"
    w, h = occupancy["size"]
    return (f"map: {occupancy['width']} x {occupancy['height']} cells of "
            f"{occupancy['resolution']:.2f} m ({w:.1f} x {h:.1f} m), known "
            f"{100 * occupancy['known_fraction']:.1f} %, occupied "
            f"{100 * occupancy['occupied_fraction']:.2f} %, t={occupancy['stamp']:.1f} s, "
            f"{occupancy['age']:.1f} s old")


def view_rows(model: MonitorModel, scale: float = 0.25) -> list[str] | None:
    """The map view round the robot (see :mod:`.view`); None before the robot's pose is
    known."""
    source = model.odom if model.odom is not None else model.truth
    if source is None:
        return None
    pose = source.pose
    tracks = [(t.x, t.y, t.kind) for t in (model.tracks.tracks if model.tracks else [])]
    return map_view(Window((pose.x, pose.y), scale),
                    None if model.map is None else model.map.message,
                    None if model.path is None else model.path.message.points,
                    tracks, pose.heading)


def render(model: MonitorModel, now: float, scale: float = 0.25) -> Any:
    """The monitor's screen for ``rich``; the map view ``scale`` m per character column."""
    from rich.console import Group
    from rich.table import Table
    from rich.text import Text

    snap = model.snapshot(now)
    header = Text(f"zenav monitor  robot {model.robot_id}  "
                  f"{time.strftime('%H:%M:%S', time.localtime(now))}", style="bold")

    robot = Table(title="robot", title_justify="left", expand=False)
    for column in ("source", "x", "y", "heading", "v", "command"):
        robot.add_column(column)
    base = snap["base"]
    command = "-" if base is None else f"{base['v']:.2f} m/s ({base['reason']})"
    if snap["robot"] is not None:
        r = snap["robot"]
        robot.add_row("odometry", f"{r['x']:.2f}", f"{r['y']:.2f}", f"{r['heading_deg']:.0f}°",
                      f"{r['v']:.3f}", command)
    if snap["truth"] is not None:
        t = snap["truth"]
        robot.add_row("ground truth", f"{t['x']:.2f}", f"{t['y']:.2f}", "", f"{t['v']:.3f}", "")
    if snap["robot"] is None and snap["truth"] is None:
        robot.add_row("(no odometry yet)", "", "", "", "", command)

    planner = snap["planner"]
    plan = Text("planner: " + ("-" if planner is None else
                               f"scenario {planner['scenario']}, action {planner['action']}, "
                               f"speed {planner['speed']:.2f} m/s"))
    if snap["result"] is not None:
        res = snap["result"]
        plan.append(f"   run: {res['outcome']} at t={res['time']:.1f} s",
                    style="green" if res["outcome"] == "reached" else "red")
    latency = snap["latency"]
    lat = Text(f"scan→command latency: last {_ms(latency['last'])}, median "
               f"{_ms(latency['median'])}, p95 {_ms(latency['p95'])}, max {_ms(latency['max'])}"
               f" ({latency['n']} samples)")

    services = Table(title="services", title_justify="left")
    for column in ("service", "alive", "for", "rejoins", "rx", "rejected", "dropped"):
        services.add_column(column)
    for name, s in snap["services"].items():
        alive = {True: Text("alive", style="green"), False: Text("gone", style="bold red"),
                 None: Text("never seen", style="yellow")}[s["alive"]]
        since = "-" if s["since"] is None else f"{now - s['since']:.0f} s"
        services.add_row(name, alive, since, str(s["rejoins"]),
                         *("-" if s[k] is None else str(s[k])
                           for k in ("received", "rejected", "dropped")))

    rates = Table(title="topics", title_justify="left")
    for column in ("topic", "Hz", "flowing"):
        rates.add_column(column)
    for name, hz in snap["rates"].items():
        if name.startswith("status/"):
            continue  # the services table shows them
        flowing = snap["flowing"][name]
        rates.add_row(name, f"{hz:.1f}", Text("yes" if flowing else "stopped",
                                              style="green" if flowing else "red"))

    obstacles = Table(title="obstacles (tracks)", title_justify="left")
    for column in ("id", "type", "x", "y", "speed", "heading"):
        obstacles.add_column(column)
    for o in snap["obstacles"]:
        obstacles.add_row(str(o["id"]), o["kind"], f"{o['x']:.2f}", f"{o['y']:.2f}",
                          f"{o['speed']:.2f}", f"{o['heading_deg']:.0f}°")

    ways = Text(path_line(snap["path"]) + "\n" + map_line(snap["map"]))
    rows = view_rows(model, scale)
    view = Text()
    if rows is None:
        view.append("(no pose yet)")
    else:
        for k, row in enumerate(rows):
            for char, run in groupby(row):
                view.append(char * len(list(run)), style=STYLES.get(char))
            if k < len(rows) - 1:
                view.append("\n")
    view_box = Group(Text(f"map round the robot ({scale:g} m per column, {2 * scale:g} m per "
                          "row)", style="bold"), view, Text(LEGEND, style="dim"))

    events = Text("\n".join(
        f"{time.strftime('%H:%M:%S', time.localtime(e.wall))} {e.kind} "
        + " ".join(f"{k}={v}" for k, v in e.data.items()) for e in model.recent))
    middle = Table.grid(padding=(0, 2))
    middle.add_row(services, rates)
    spatial = Table.grid(padding=(0, 2))
    spatial.add_row(view_box, obstacles)
    return Group(header, robot, plan, ways, lat, middle, spatial,
                 Text("recent events", style="bold"), events)
