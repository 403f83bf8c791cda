"""Dynamic Window Approach (DWA), the classic ROS local planner (pure, no I/O).

D. Fox, W. Burgard and S. Thrun, "The Dynamic Window Approach to Collision Avoidance",
IEEE Robotics & Automation Magazine 4(1), 23–33, 1997.

Each cycle searches the space of (v, ω) for circular arcs:

1. **Dynamic window**: the velocities reachable within one control period from the
   current ones (odometry), ``[v − v̇ Δt, v + v̇ Δt] × [ω − ω̇ Δt, ω + ω̇ Δt]``, cut to
   the robot's limits, sampled ``vx_samples`` × ``vth_samples`` (ROS
   ``dwa_local_planner`` samples 3 × 20; more here, as the window is small at 10 Hz),
   plus ω = 0.
2. **dist(v, ω)**: the arc length to the first contact on the arc's curvature v/ω,
   followed out to ``dist_cap`` (the paper's "large constant" when nothing is on it)
   every ``arc_step`` m against the scan's returns and the standing obstacles the
   tracker remembers out of view; and the forward simulation of the arc for ``sim_time``
   s (ROS: 1.7 s) against the tracked movers at their predicted positions (the tracks'
   velocities: DWA gets the same knowledge of movers as the paper's planner; scan returns
   on a mover are replaced by its prediction). Contact is the footprint plus
   ``safety_margin``. Standing still follows no curvature: its dist is the clearance
   where the robot stands.
3. **Admissible velocities**: ``v ≤ sqrt(2 · dist(v, ω) · v̇_b)``, the robot can stop
   before the first contact on the arc.
4. **Objective** ``G = α · heading + β · dist + γ · velocity``, each term in [0, 1]:
   ``heading = 1 − |θ_goal − θ| / π`` at the pose after one control period (as the
   paper), ``dist / dist_cap``, ``v / v_max``. The weights α = 2, β = 0.2, γ = 0.2 are
   the values usually quoted for the paper's experiments. The paper's smoothing of G over
   the window is left out.

``v_max`` is the mission's cruise speed, as every planner here is asked to cruise at it;
the acceleration limits are the motor bridge's. With no admissible velocity the robot
brakes as hard as the window allows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from zenav.services.baselines.common import (
    Cycle,
    FloatArray,
    disc_points,
    returns,
    world_points,
)
from zenav.services.baselines.params import DWAParams
from zenav.services.geometry import wrap_angles

Params = DWAParams
"""The parameters (also read as ``dwa.Params`` by zenav/bench/compute.py)."""


@dataclass(frozen=True)
class Decision:
    v: float
    omega: float
    admissible: int  # how many sampled arcs were admissible
    score: float


def rollout(x: float, y: float, heading: float, v: FloatArray, omega: FloatArray,
            times: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Poses along the arcs (v_i, ω_i) at ``times``: x, y, heading of shape (n, k)."""
    v, w, t = v[:, None], omega[:, None], times[None, :]
    theta = heading + w * t
    straight = np.abs(w) < 1e-6
    safe_w = np.where(straight, 1.0, w)
    px = np.where(straight, x + v * t * math.cos(heading),
                  x + v / safe_w * (np.sin(theta) - math.sin(heading)))
    py = np.where(straight, y + v * t * math.sin(heading),
                  y - v / safe_w * (np.cos(theta) - math.cos(heading)))
    return px, py, theta


def plan(cycle: Cycle, p: Params) -> Decision:
    x, y, heading = cycle.pose
    v0, w0 = cycle.velocity
    dt = p.control_period
    v_hi = min(p.v_max, v0 + p.accel * dt)
    v_lo = min(max(p.min_vel_x, v0 - p.accel * dt), v_hi)
    w_hi = min(p.max_omega, w0 + p.acc_lim_theta * dt)
    w_lo = min(max(-p.max_omega, w0 - p.acc_lim_theta * dt), w_hi)
    vs = np.linspace(v_lo, v_hi, p.vx_samples)
    ws = np.linspace(w_lo, w_hi, p.vth_samples)
    if w_lo < 0.0 < w_hi:
        ws = np.union1d(ws, [0.0])  # straight on is always a candidate
    v, w = (a.ravel() for a in np.meshgrid(vs, ws, indexing="ij"))
    steps = max(1, math.ceil(p.sim_time / p.sim_granularity - 1e-9))
    times = p.sim_granularity * np.arange(1, steps + 1, dtype=np.float64)
    px, py, theta = rollout(x, y, heading, v, w, times)

    # dist: arc length to the first contact on each curvature (radius v / omega), against
    # the scan's returns out to dist_cap, and against the movers where they will be when
    # the robot gets there (over sim_time).
    reach = p.dist_cap + p.robot_radius + p.safety_margin
    points = world_points(cycle, returns(cycle, min(reach, p.window_radius)))
    movers = cycle.movers
    if len(movers) and len(points):
        gap = np.hypot(points[:, None, 0] - movers.positions[None, :, 0],
                       points[:, None, 1] - movers.positions[None, :, 1])
        points = points[(gap > movers.radii[None, :] + p.mover_clearance).all(axis=1)]
    points = np.concatenate((points, disc_points(cycle.remembered)))
    dist = np.full(v.shape, p.dist_cap)
    if len(points):
        lengths = p.arc_step * np.arange(0, math.floor(p.dist_cap / p.arc_step) + 1,
                                         dtype=np.float64)
        moving = v > 1e-6
        curvature = np.where(moving, w / np.where(moving, v, 1.0), 0.0)
        ax, ay, _ = rollout(x, y, heading, moving.astype(np.float64), curvature, lengths)
        tree = cKDTree(points)
        here = float(tree.query([x, y], k=1)[0]) - p.robot_radius
        # Already within the margin (a mover came close, the robot cut a corner): contact
        # is the footprint itself, so that the arcs that lead out stay admissible.
        bound = p.robot_radius + (p.safety_margin if here > p.safety_margin else 0.0)
        d, _ = tree.query(np.column_stack((ax.ravel(), ay.ravel())), k=1,
                          distance_upper_bound=bound)
        hit = (d < bound).reshape(ax.shape)
        first = hit.argmax(axis=1)
        dist = np.where(hit.any(axis=1), np.maximum(first - 1, 0) * p.arc_step, dist)
        # Standing still follows no curvature: its dist is the clearance where it stands,
        # so a stop is not scored as an open road.
        standing = min(max(here + p.robot_radius - bound, 0.0), p.dist_cap)
        dist = np.where(moving, dist, standing)
    for position, velocity, radius in zip(movers.positions, movers.velocities, movers.radii,
                                          strict=True):
        mx = position[0] + velocity[0] * times
        my = position[1] + velocity[1] * times
        hit = np.hypot(px - mx[None, :], py - my[None, :]) < (
            p.robot_radius + radius + p.safety_margin)
        first = hit.argmax(axis=1)
        meet = v * times[first] - v * p.sim_granularity  # the last pose before contact
        dist = np.where(hit.any(axis=1), np.minimum(dist, np.maximum(meet, 0.0)), dist)
    admissible = v <= np.sqrt(2.0 * dist * p.decel) + 1e-9

    gx, gy = cycle.goal
    end_x, end_y, end_theta = px[:, 0], py[:, 0], theta[:, 0]  # after one period
    error = np.abs(wrap_angles(np.arctan2(gy - end_y, gx - end_x) - end_theta))
    score = (p.alpha * (1.0 - error / math.pi)
             + p.beta * np.minimum(dist, p.dist_cap) / p.dist_cap
             + p.gamma * v / p.v_max)
    if not admissible.any():  # nothing lets it stop in time: brake hardest, most clearance
        pick = int(np.lexsort((-dist, v))[0])
        return Decision(float(v[pick]), float(w[pick]), 0, float(score[pick]))
    pick = int(np.argmax(np.where(admissible, score, -np.inf)))
    return Decision(float(v[pick]), float(w[pick]), int(admissible.sum()), float(score[pick]))


class DWA:
    """Stateless apart from its parameters: one window search per scan."""

    def __init__(self, params: Params) -> None:
        self.p = params

    def step(self, cycle: Cycle) -> Decision:
        decision = plan(cycle, self.p)
        x, y, _ = cycle.pose
        distance = math.hypot(cycle.goal[0] - x, cycle.goal[1] - y)
        return Decision(min(decision.v, distance), decision.omega, decision.admissible,
                        decision.score)
