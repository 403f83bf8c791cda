"""The monitor's terminal screen, drawn with ``rich`` from a :class:`MonitorModel`."""

from __future__ import annotations

import time
from typing import Any

from zenav.monitor.model import MonitorModel


def _ms(value: float | int | None) -> str:
    return "-" if value is None else f"{1000 * value:.1f} ms"


def render(model: MonitorModel, now: float) -> Any:
    """The monitor's screen for ``rich``."""
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

    events = Text("\n".join(
        f"{time.strftime('%H:%M:%S', time.localtime(e.wall))} {e.kind} "
        + " ".join(f"{k}={v}" for k, v in e.data.items()) for e in model.recent))
    middle = Table.grid(padding=(0, 2))
    middle.add_row(services, rates)
    bottom = Table.grid(padding=(0, 2))
    bottom.add_row(obstacles, Group(Text("recent events", style="bold"), events))
    return Group(header, robot, plan, lat, middle, bottom)
