"""The picture of a run: world, obstacles, global path, trajectory and decisions."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import Circle, Rectangle

from zenav.sim.scenario import Scenario

OUTCOME_COLOURS = {"reached": "tab:green", "collision": "tab:red", "timeout": "tab:orange"}


def plot_run(scenario: Scenario, record: dict[str, Any], path: Path) -> None:
    """Write ``path`` (PNG) for a run record as written to run.json."""
    width, height = scenario.world.size
    fig, ax = plt.subplots(figsize=(7, 7 * height / width if width else 7))
    ax.set_xlim(0, width)
    ax.set_ylim(0, height)
    ax.set_aspect("equal")
    cell = scenario.world.cell
    if width / cell <= 60 and height / cell <= 60:
        ax.set_xticks([i * cell for i in range(int(width / cell) + 1)], minor=True)
        ax.set_yticks([i * cell for i in range(int(height / cell) + 1)], minor=True)
        ax.grid(which="minor", color="0.92", linewidth=0.5)
    end = float(record["time"])
    for index, ob in enumerate(scenario.obstacles):
        moving = ob.velocity is not None and any(ob.velocity)
        colour = "tab:purple" if moving else "0.35"
        t_show = max(ob.appear, min(end, ob.vanish_time - 1e-6))
        cx, cy = ob.center_at(t_show) if moving else ob.center
        if ob.shape == "disc":
            assert ob.radius is not None
            patch: Any = Circle((cx, cy), ob.radius, color=colour, alpha=0.7)
        else:
            assert ob.size is not None
            patch = Rectangle((cx - ob.size[0] / 2, cy - ob.size[1] / 2), ob.size[0], ob.size[1],
                              color=colour, alpha=0.7)
        ax.add_patch(patch)
        if moving:
            x0, y0 = ob.center
            ax.plot([x0, cx], [y0, cy], ls=":", color=colour, lw=1)
        ax.annotate(str(index), (cx, cy), ha="center", va="center", fontsize=7, color="white")
    start, goal = scenario.robot.start, scenario.robot.goal
    ax.plot([start[0], goal[0]], [start[1], goal[1]], ls="--", color="tab:green", lw=1,
            label="global path")
    traj = record["trajectory"]
    xs = [row[1] for row in traj]
    ys = [row[2] for row in traj]
    outcome = record["outcome"]
    ax.plot(xs, ys, color="tab:blue", lw=1.5, label="trajectory")
    ax.add_patch(Circle((xs[-1], ys[-1]), scenario.robot.radius, fill=False,
                        color=OUTCOME_COLOURS.get(outcome, "k"), lw=1.5))
    ax.plot(*start, marker="o", color="tab:green")
    ax.plot(*goal, marker="*", markersize=12, color="tab:green")
    goal_circle = Circle(goal, scenario.robot.goal_tolerance, fill=False, ls=":", color="tab:green")
    ax.add_patch(goal_circle)
    times = [row[0] for row in traj]
    for event in record["events"]:
        i = min(range(len(times)), key=lambda k: abs(times[k] - event["t"]))
        ax.plot(xs[i], ys[i], marker="x", color="tab:red", markersize=6)
        ax.annotate(f"{event['scenario']}:{event['action']}", (xs[i], ys[i]),
                    textcoords="offset points", xytext=(4, 4), fontsize=7, color="tab:red")
    clearance = record.get("min_clearance")
    clearance_text = "-" if clearance is None or math.isinf(clearance) else f"{clearance:.2f} m"
    ax.set_title(f"{record['scenario']} ({record['planner']}): {outcome} at {end:.1f} s, "
                 f"path {record['path_length']:.2f} m, min clearance {clearance_text}",
                 fontsize=9)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper left", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
