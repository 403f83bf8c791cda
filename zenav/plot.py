"""Report plotting: the picture of a run (``run.png``), the figures of ``zenav paper``
(the paper-style figure and the animation) and the chart of ``zenav bench nav``.

The figures are :class:`matplotlib.figure.Figure` objects drawn by the Agg backend
straight to their files: pyplot (its figure manager, its backend machinery) is not
imported, which spares ``zenav run`` a third of a second after every run; the animation
writes its frames with Pillow. Every drawing function still
holds :data:`PLOT_LOCK` (matplotlib's settings are global): runs drawn from several threads
(the batch runner) draw one figure at a time.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Rectangle

from zenav.schemas.messages import GlobalPath, OccupancyMap
from zenav.sim.scenario import ObstacleSpec, Scenario

OUTCOME_COLOURS = {"reached": "tab:green", "collision": "tab:red", "timeout": "tab:orange"}
STATIC_COLOUR = "0.35"
MOVER_COLOUR = "tab:purple"
MAP_FREE_COLOUR = "#dce9f5"
MAP_OCCUPIED_COLOUR = "#f2a65a"
"""The planner's map in run.png: cells it has seen free, and cells it holds occupied
(confirmed hits, before inflation); unknown cells are left blank."""

PLOT_LOCK = threading.RLock()
"""Held while a figure is drawn (pyplot is not thread-safe)."""


def draw_obstacle(ax: Any, ob: ObstacleSpec, centre: Sequence[float], colour: str,
                  alpha: float | None = None) -> None:
    """One obstacle, a disc or a box, at ``centre``."""
    cx, cy = float(centre[0]), float(centre[1])
    if ob.shape == "disc" and ob.radius is not None:
        ax.add_patch(Circle((cx, cy), ob.radius, color=colour, alpha=alpha))
    elif ob.size is not None:
        ax.add_patch(Rectangle((cx - ob.size[0] / 2, cy - ob.size[1] / 2), ob.size[0],
                               ob.size[1], color=colour, alpha=alpha))


GRID_ZORDER = 1.5
"""Where matplotlib puts an axes' grid: above the map image, below every mark."""


def _world(ax: Any, scenario: Scenario, grid_colour: str | None, max_cells: int = 0) -> None:
    """Limits, equal aspect and (with ``grid_colour``) the grid's cells as thin lines,
    unless the world has more than ``max_cells`` cells a side (0: no limit).

    The lines are two collections, not a minor tick per cell with its grid line: each
    tick is several artists with a label of its own, and at 40 cells a side they were a
    third of the time spent drawing ``run.png``."""
    width, height = scenario.world.size
    ax.set_xlim(0, width)
    ax.set_ylim(0, height)
    ax.set_aspect("equal")
    cell = scenario.world.cell
    if grid_colour is None or (max_cells and max(width, height) / cell > max_cells):
        return
    ax.vlines(np.arange(0, width + 1e-9, cell), 0, height, colors=grid_colour,
              linewidth=0.5, zorder=GRID_ZORDER)
    ax.hlines(np.arange(0, height + 1e-9, cell), 0, width, colors=grid_colour,
              linewidth=0.5, zorder=GRID_ZORDER)


def _global_path(ax: Any, scenario: Scenario, lw: float = 1, label: str | None = None) -> None:
    start, goal = scenario.robot.start, scenario.robot.goal
    ax.plot([start[0], goal[0]], [start[1], goal[1]], ls="--", color="tab:green", lw=lw,
            label=label)


def draw_occupancy(ax: Any, occupancy: OccupancyMap) -> None:
    """The planner's map under everything else: seen-free cells pale blue, occupied cells
    orange, unknown ones blank; with a legend entry for each."""
    grid = occupancy.grid()
    values = np.where(grid < 0, np.nan, np.where(grid > 50, 1.0, 0.0))
    colours = ListedColormap([MAP_FREE_COLOUR, MAP_OCCUPIED_COLOUR]).with_extremes(
        bad=(0.0, 0.0, 0.0, 0.0))
    x0, y0 = occupancy.origin
    r = occupancy.resolution
    ax.imshow(values.T, origin="lower", cmap=colours, vmin=0.0, vmax=1.0,
              extent=(x0, x0 + r * occupancy.width, y0, y0 + r * occupancy.height),
              interpolation="nearest", zorder=0)
    ax.fill([], [], color=MAP_FREE_COLOUR, label="map: seen free")
    ax.fill([], [], color=MAP_OCCUPIED_COLOUR, label="map: occupied")


EARLIER_PATH_COLOUR = "tab:olive"
EARLIER_LISTED = 6
"""Earlier paths named one by one in the legend; more are drawn and counted."""


def draw_earlier_paths(ax: Any, paths: Sequence[GlobalPath]) -> None:
    """Global paths the planner gave up (oldest first), thin and dotted, each numbered
    at its first vertex; the legend gives the first few reasons."""
    drawn = [p for p in paths if len(p.points) >= 2]
    for k, earlier in enumerate(drawn, start=1):
        xs, ys = earlier.points[:, 0], earlier.points[:, 1]
        label = None
        if k <= EARLIER_LISTED:
            label = (f"path {k} (t={earlier.planned_at:.1f} s, "
                     f"{earlier.reason or 'no reason'})")
        elif k == EARLIER_LISTED + 1:
            label = f"paths {k}-{len(drawn)}"
        ax.plot(xs, ys, ls=":", color=EARLIER_PATH_COLOUR, lw=0.9, alpha=0.8, label=label)
        ax.annotate(str(k), (float(xs[0]), float(ys[0])), textcoords="offset points",
                    xytext=(-8, -8), fontsize=6, color=EARLIER_PATH_COLOUR)


LEGEND_WIDTH = 2.8
"""Inches beside the map kept for run.png's legend, so that it never hides the run."""


def _finish(fig: Any, ax: Any, path: Path, legend: str) -> None:
    """Axis labels and legend (``legend``: a matplotlib location inside the axes, or
    ``"beside"``: to the right of them, in the room of ``LEGEND_WIDTH``); write ``path``
    and close the figure."""
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if legend == "beside":
        ax.set_anchor("W")  # the equal-aspect box at the left of its room, the legend next
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                  fontsize=7)
    else:
        ax.legend(loc=legend, fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def _figure(width: float, height: float) -> tuple[Figure, Any]:
    """A figure of ``width`` x ``height`` inches with one axes, outside pyplot."""
    fig = Figure(figsize=(width, height))
    return fig, fig.subplots()


def _nearest_rows(record: dict[str, Any], t: float) -> int:
    times = [row[0] for row in record["trajectory"]]
    return min(range(len(times)), key=lambda k: abs(times[k] - t))


# --- run.png ------------------------------------------------------------------------------


def plot_run(scenario: Scenario, record: dict[str, Any], path: Path,
             occupancy: OccupancyMap | None = None,
             paths: Sequence[GlobalPath] = ()) -> None:
    """Write ``path`` (PNG) for a run record as written to run.json; with the planner's
    last map when given (:func:`draw_occupancy`), its last global path when the record
    has one (``path``; else the straight start-goal line), and the global paths planned
    before it when given (``paths``, oldest first, the last being the record's), each
    numbered at its first vertex with its reason in the legend."""
    width, height = scenario.world.size
    with PLOT_LOCK:
        # The map 7 in wide (at least 3 in high, for the legend's rows), the legend beside.
        fig, ax = _figure(7 + LEGEND_WIDTH, max(7 * height / width if width else 7, 3.0))
        _world(ax, scenario, "0.92", max_cells=60)
        if occupancy is not None:
            draw_occupancy(ax, occupancy)
            ax.set_xlim(0, width)
            ax.set_ylim(0, height)
        end = float(record["time"])
        agent_paths = record.get("agents", {})  # ORCA agents: their paths come from the run
        for index, ob in enumerate(scenario.obstacles):
            moving = ob.is_agent or (ob.velocity is not None and any(ob.velocity))
            colour = MOVER_COLOUR if moving else STATIC_COLOUR
            t_show = max(ob.appear, min(end, ob.vanish_time - 1e-6))
            cx, cy = ob.center_at(t_show) if moving else ob.center
            rows = agent_paths.get(str(index))
            if rows:
                ax.plot([r[1] for r in rows], [r[2] for r in rows], ls=":", color=colour, lw=1)
                cx, cy = rows[-1][1], rows[-1][2]
            draw_obstacle(ax, ob, (cx, cy), colour, alpha=0.7)
            if moving and not rows:
                x0, y0 = ob.center
                ax.plot([x0, cx], [y0, cy], ls=":", color=colour, lw=1)
            ax.annotate(str(index), (cx, cy), ha="center", va="center", fontsize=7,
                        color="white")
        start, goal = scenario.robot.start, scenario.robot.goal
        draw_earlier_paths(ax, paths[:-1])
        if record.get("path"):
            px, py = zip(*record["path"], strict=True)
            last = "global path (last)" if not paths else (
                f"global path (last: t={paths[-1].planned_at:.1f} s, "
                f"{paths[-1].reason or 'no reason'})")
            ax.plot(px, py, ls="--", color="tab:green", lw=1, label=last)
        elif "path" in record:  # the planner's last word was that it knows no way
            why = f", {paths[-1].reason}" if paths and paths[-1].reason else ""
            ax.plot([], [], ls="--", color="tab:green", lw=1,
                    label=f"global path (last): none{why}")
        else:
            _global_path(ax, scenario, label="global path")
        traj = record["trajectory"]
        xs = [row[1] for row in traj]
        ys = [row[2] for row in traj]
        outcome = record["outcome"]
        ax.plot(xs, ys, color="tab:blue", lw=1.5, label="trajectory")
        ax.add_patch(Circle((xs[-1], ys[-1]), scenario.robot.radius, fill=False,
                            color=OUTCOME_COLOURS.get(outcome, "k"), lw=1.5))
        ax.plot(*start, marker="o", color="tab:green")
        ax.plot(*goal, marker="*", markersize=12, color="tab:green")
        ax.add_patch(Circle(goal, scenario.robot.goal_tolerance, fill=False, ls=":",
                            color="tab:green"))
        x_lo, x_hi = ax.get_xlim()
        y_lo, y_hi = ax.get_ylim()
        near = LABEL_NEAR * max(x_hi - x_lo, y_hi - y_lo)
        points = []
        for event in record["events"]:
            i = _nearest_rows(record, event["t"])
            ax.plot(xs[i], ys[i], marker="x", color="tab:red", markersize=6)
            points.append((float(xs[i]), float(ys[i]),
                           f"{event['scenario']}:{event['action']}"))
        for x, y, text in label_groups(points, near):
            ax.annotate(text, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7,
                        color="tab:red", va="bottom")
        clearance = record.get("min_clearance")
        clearance_text = ("-" if clearance is None or math.isinf(clearance)
                          else f"{clearance:.2f} m")
        ax.set_title(f"{record['scenario']} ({record['planner']}): {outcome} at {end:.1f} s, "
                     f"path {record['path_length']:.2f} m, min clearance {clearance_text}",
                     fontsize=9)
        _finish(fig, ax, path, "beside")


LABEL_NEAR = 0.04
"""Events closer than this fraction of the plot's larger side share one label."""
LABEL_LINES = 4
"""Lines in a shared label before the rest are counted ("+3 more")."""


def label_groups(points: Sequence[tuple[float, float, str]],
                 near: float) -> list[tuple[float, float, str]]:
    """Event labels that would overprint each other merged: each event joins the first
    earlier group whose anchor lies within ``near`` of it (the anchor is the group's first
    event), and a group's label lists its events in time order, one per line."""
    groups: list[tuple[float, float, list[str]]] = []
    for x, y, text in points:
        for gx, gy, texts in groups:
            if math.hypot(x - gx, y - gy) < near:
                texts.append(text)
                break
        else:
            groups.append((x, y, [text]))
    labels = []
    for gx, gy, texts in groups:
        shown = texts if len(texts) <= LABEL_LINES else [
            *texts[:LABEL_LINES - 1], f"+{len(texts) - LABEL_LINES + 1} more"]
        labels.append((gx, gy, "\n".join(shown)))
    return labels


# --- zenav paper --------------------------------------------------------------------------


def decision_points(record: dict[str, Any]) -> list[tuple[float, float, float, str]]:
    """(t, x, y, label) of every event that is not plain driving."""
    traj = record["trajectory"]
    found = []
    for event in record["events"]:
        if event["action"] in ("keep", "resume") and event["scenario"] in "a":
            continue
        i = _nearest_rows(record, event["t"])
        found.append((event["t"], traj[i][1], traj[i][2],
                      f"{event['scenario']}:{event['action']}"))
    return found


def _mover_track(ax: Any, ob: ObstacleSpec, end: float, traj: np.ndarray, colour: str
                 ) -> tuple[float, float]:
    """A mover's path, dotted, with an arrow where it came closest to the robot; that
    place."""
    t0, t1 = ob.appear, min(ob.vanish_time, end)
    stops = np.linspace(t0, max(t0, t1 - 1e-6), 60)
    path_xy = np.array([ob.center_at(t) for t in stops])
    ax.plot(path_xy[:, 0], path_xy[:, 1], ls=":", color=colour, lw=1)
    robot_at = np.array([np.interp(stops, traj[:, 0], traj[:, 1]),
                         np.interp(stops, traj[:, 0], traj[:, 2])]).T
    k = int(np.argmin(np.hypot(*(path_xy - robot_at).T)))
    cx, cy = path_xy[k]
    tip = path_xy[min(k + 3, len(path_xy) - 1)]
    ax.annotate("", xy=tuple(tip), xytext=(cx, cy),
                arrowprops={"arrowstyle": "->", "color": colour})
    return float(cx), float(cy)


def draw_experiment(scenario: Scenario, record: dict[str, Any], path: Path,
                    window_radius: float, title: str) -> None:
    """The paper-style figure: grid, obstacles and movers' paths, global path,
    trajectory, the sliding windows where decisions happened (V1..) and the decision
    points with their scenario letter and action."""
    width, height = scenario.world.size
    end = float(record["time"])
    traj = np.asarray(record["trajectory"])
    with PLOT_LOCK:
        fig, ax = _figure(7.5, 7.5 * height / width)
        _world(ax, scenario, "0.9")
        for index, ob in enumerate(scenario.obstacles):
            moving = not ob.is_static
            colour = MOVER_COLOUR if moving else STATIC_COLOUR
            cx, cy = _mover_track(ax, ob, end, traj, colour) if moving else ob.center
            draw_obstacle(ax, ob, (cx, cy), colour, alpha=0.75)
            label = f"{'D' if moving else 'S'}{index}"
            ax.annotate(label, (cx, cy), xytext=(3, 3), textcoords="offset points", fontsize=7)
        start, goal = scenario.robot.start, scenario.robot.goal
        if record.get("path"):
            px, py = zip(*record["path"], strict=True)
            ax.plot(px, py, ls="--", color="tab:green", lw=1, label="global path (last)")
        elif "path" not in record:  # an empty one: the planner's last word was no way
            _global_path(ax, scenario, label="global path")
        ax.plot(traj[:, 1], traj[:, 2], color="tab:blue", lw=1.6, label="trajectory")
        points = decision_points(record)
        windows: list[tuple[float, float]] = []
        for _, x, y, label in points:  # the windows where decisions happened, spaced out
            if label.split(":")[1] in ("morphin", "stop", "slow", "speed_up") and all(
                    math.dist((x, y), w) > window_radius / 2 for w in windows):
                windows.append((x, y))
        for k, (x, y) in enumerate(windows[:4]):
            ax.add_patch(Circle((x, y), window_radius, fill=False, ls="--", color="tab:orange",
                                lw=0.8))
            ax.annotate(f"V{k + 1}", (x + window_radius * 0.7, y + window_radius * 0.7),
                        color="tab:orange", fontsize=8)
        for _, x, y, label in points:
            ax.plot(x, y, marker="x", color="tab:red", markersize=6)
            ax.annotate(label, (x, y), xytext=(4, -9), textcoords="offset points", fontsize=7,
                        color="tab:red")
        ax.plot(*start, marker="o", color="tab:green")
        ax.plot(*goal, marker="*", markersize=12, color="tab:green")
        ax.set_title(f"{title}: {record['outcome']} at {end:.1f} s (simulated)", fontsize=10)
        _finish(fig, ax, path, "lower right")


def draw_animation(scenario: Scenario, record: dict[str, Any], path: Path,
                   window_radius: float, fps: int = 8, seconds_per_frame: float = 1.0) -> None:
    """An animated GIF of the run: obstacles where they were, the robot and its window.

    The axes (frame, ticks, labels) are drawn once and kept as the background; each frame
    restores it and draws only what changes, in the order a full draw would (by zorder).
    Drawing every frame whole, ticks and all, took a minute of ``zenav paper``'s two."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    traj = np.asarray(record["trajectory"])
    frames = np.arange(0.0, float(record["time"]) + 1e-9, seconds_per_frame)
    width, height = scenario.world.size
    with PLOT_LOCK:
        fig = Figure(figsize=(5, 5 * height / width))
        canvas: Any = FigureCanvasAgg(fig)  # (matplotlib leaves its methods untyped)
        ax = fig.subplots()
        _world(ax, scenario, None)
        ax.set_title("", fontsize=9)  # placed by the full draw, its text set per frame
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        images = []
        for t in frames:
            before = set(ax.get_children())
            _global_path(ax, scenario, lw=0.8)
            for ob in scenario.obstacles:
                if ob.exists_at(t):
                    draw_obstacle(ax, ob, ob.center_at(t),
                                  STATIC_COLOUR if ob.is_static else MOVER_COLOUR)
            i = int(np.searchsorted(traj[:, 0], t, side="right")) - 1
            i = max(0, min(i, len(traj) - 1))
            ax.plot(traj[: i + 1, 1], traj[: i + 1, 2], color="tab:blue", lw=1.2)
            x, y, heading = traj[i, 1], traj[i, 2], traj[i, 3]
            ax.add_patch(Circle((x, y), scenario.robot.radius, color="tab:blue", alpha=0.8))
            ax.add_patch(Circle((x, y), window_radius, fill=False, ls="--", color="tab:orange",
                                lw=0.8))
            ax.plot([x, x + 0.4 * math.cos(heading)], [y, y + 0.4 * math.sin(heading)],
                    color="k", lw=1)
            ax.title.set_text(f"{scenario.name}  t = {t:5.1f} s")
            marks = [a for a in ax.get_children() if a not in before]
            canvas.restore_region(background)
            # The marks, then the spines over them, as the axes draws its children.
            for artist in sorted([*marks, *ax.spines.values()], key=lambda a: a.get_zorder()):
                ax.draw_artist(artist)
            fig.draw_artist(ax.title)
            images.append(Image.frombuffer("RGBA", canvas.get_width_height(),
                                           bytes(canvas.buffer_rgba()), "raw", "RGBA", 0, 1))
            for artist in marks:
                artist.remove()
        images[0].save(path, save_all=True, append_images=images[1:],
                       duration=int(1000 / fps), loop=0)


# --- zenav bench nav ----------------------------------------------------------------------

OUTCOME_BARS = (("reached", "#3a923a"), ("timeout", "#e0a030"), ("collision", "#c83737"))


def draw_bench_chart(planners: Sequence[str], outcomes: dict[str, list[float]],
                     success: dict[str, list[float]], path: Path) -> None:
    """Left, stacked bars of each planner's outcomes (``outcomes[outcome]``: share of runs
    per planner, NaN for none); right, grouped bars of success per world family
    (``success[family]``: % per planner)."""
    with PLOT_LOCK:
        fig = Figure(figsize=(12, 4.5))
        left, right = fig.subplots(1, 2)
        bottom = [0.0] * len(planners)
        for label, colour in OUTCOME_BARS:
            shown = [0.0 if math.isnan(v) else 100 * v for v in outcomes[label]]
            left.bar(planners, shown, bottom=bottom, color=colour, label=label)
            bottom = [b + v for b, v in zip(bottom, shown, strict=True)]
        left.set_ylabel("runs, %")
        left.set_title("outcome per planner, all worlds")
        left.legend(loc="lower right")
        names = list(success)
        width = 0.8 / max(len(planners), 1)
        for i, p in enumerate(planners):
            rates = [success[f][i] for f in names]
            right.bar([k + i * width for k in range(len(names))], rates, width=width, label=p)
        right.set_xticks([k + width * (len(planners) - 1) / 2 for k in range(len(names))])
        right.set_xticklabels(names)
        right.set_ylabel("success, %")
        right.set_ylim(0, 105)
        right.set_title("success per world family")
        right.legend(loc="lower right", fontsize="small")
        fig.tight_layout()
        fig.savefig(path, dpi=110)
