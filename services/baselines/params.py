"""Parameters of the baseline planners: each extends the mission every planner is given
(:class:`zenav.services.planner.params.MissionParams`) with its own method's."""

from __future__ import annotations

import math

from pydantic import Field, model_validator

from zenav.services.mission import ACCEL, DECEL
from zenav.services.planner.params import MissionParams

__all__ = ["APFParams", "DWAParams", "ORCAParams", "VFHParams"]


class VFHParams(MissionParams):
    grid_cell: float = Field(0.1, gt=0, description="histogram grid cell size, m "
                             "(paper: 10 cm)")
    grid_extent: float = Field(60.0, gt=0, description="side of the square histogram grid, "
                               "centred on the first pose, m")
    window_cells: int = Field(33, ge=3, description="w_s: active window side, cells (odd)")
    sector_deg: float = Field(5.0, gt=0, le=45, description="alpha: polar sector width, deg")
    b: float = Field(1.0, gt=0, description="b: magnitude fall-off with distance, 1/m "
                     "(a = b d_max, so a - b d_max = 0)")
    certainty_max: int = Field(15, ge=1, description="HIMM: largest certainty value")
    increment: int = Field(3, ge=1, description="HIMM: certainty added per return in a cell")
    decrement: int = Field(1, ge=0, description="HIMM: certainty removed per beam through "
                           "a cell")
    smoothing: int = Field(5, ge=1, description="l: half-width of the smoothing window, "
                           "sectors")
    threshold: float = Field(250.0, gt=0, description="smoothed density below which a sector "
                             "is free (empirical)")
    s_max: int = Field(18, ge=1, description="valley width above which a valley is wide, "
                       "sectors (paper: 18)")
    h_m: float = Field(600.0, gt=0, description="density straight ahead at which the speed "
                       "drops to V_min (empirical)")
    v_min: float = Field(0.0, ge=0, description="V_min: speed added after the reductions, m/s")
    heading_gain: float = Field(1.5, gt=0, description="turn rate per rad of steering "
                                "error, 1/s")
    keep_valley_deg: float = Field(
        15.0, ge=0, description="beyond the 1991 paper (as VFH+ does): the valley steered "
        "through last is kept unless another is this much nearer the target, deg; without "
        "it the robot dithers between two valleys either side of an obstacle on its way")

    @model_validator(mode="after")
    def _odd_window(self) -> VFHParams:
        if self.window_cells % 2 == 0:
            raise ValueError("window_cells must be odd (the robot's cell is the centre)")
        return self

    @property
    def sectors(self) -> int:
        return max(1, round(360.0 / self.sector_deg))

    @property
    def d_max(self) -> float:
        """Distance from the robot's cell to a corner of the active window, m."""
        return math.sqrt(2.0) * (self.window_cells - 1) / 2 * self.grid_cell

    @property
    def a(self) -> float:
        return self.b * self.d_max


class DWAParams(MissionParams):
    max_vel_x: float | None = Field(None, gt=0, description="top forward speed, m/s "
                                    "(default: the cruise speed)")
    min_vel_x: float = Field(0.0, ge=0, description="lowest forward speed, m/s (no reverse)")
    accel: float = Field(ACCEL, gt=0, description="v̇: forward acceleration, m/s² "
                         "(ROS acc_lim_x; the motor bridge's)")
    decel: float = Field(DECEL, gt=0, description="v̇_b: braking deceleration for "
                         "admissibility, m/s² (the motor bridge's)")
    acc_lim_theta: float = Field(3.2, gt=0, description="ω̇: turn acceleration, rad/s² "
                                 "(ROS: 3.2)")
    control_period: float = Field(0.1, gt=0, description="Δt: one scan period, s")
    sim_time: float = Field(2.0, gt=0, description="forward simulation horizon, s")
    sim_granularity: float = Field(0.1, gt=0, description="forward simulation step, s")
    arc_step: float = Field(0.1, gt=0, description="step along each curvature when "
                            "looking for the first contact, m")
    vx_samples: int = Field(7, ge=1, description="forward speed samples in the window")
    vth_samples: int = Field(21, ge=1, description="turn rate samples in the window")
    alpha: float = Field(2.0, ge=0, description="weight of heading")
    beta: float = Field(0.2, ge=0, description="weight of dist (clearance on the arc)")
    gamma: float = Field(0.2, ge=0, description="weight of velocity")
    dist_cap: float = Field(2.0, gt=0, description="dist of an arc with nothing on it, m")
    safety_margin: float = Field(0.05, ge=0, description="gap kept between footprints on "
                                 "top of the radii, m")
    mover_clearance: float = Field(0.15, ge=0, description="scan returns this close to a "
                                   "mover's surface are the mover's, m")

    @property
    def v_max(self) -> float:
        return self.max_vel_x if self.max_vel_x is not None else self.cruise_speed


class APFParams(MissionParams):
    k_att: float = Field(1.0, gt=0, description="attractive gain, 1/s (pull per m to the goal)")
    d_star: float = Field(1.0, gt=0, description="beyond this distance to the goal the pull "
                          "is constant, m")
    k_rep: float = Field(0.02, gt=0, description="eta: repulsive gain, m³/s")
    d0: float = Field(1.0, gt=0, description="rho_0: influence distance of an obstacle, m")
    min_gap: float = Field(0.01, gt=0, description="gaps below this count as this, m "
                           "(keeps the push finite)")
    segment_gap: float = Field(0.3, gt=0, description="neighbouring returns farther apart "
                               "than this belong to different obstacles, m")
    heading_gain: float = Field(1.5, gt=0, description="turn rate per rad of angle to the "
                                "force, 1/s")


class ORCAParams(MissionParams):
    """ORCA driving the robot (CrowdNav's baseline): CrowdNav's settings, and how the
    holonomic answer becomes a unicycle command."""

    time_step: float = Field(0.25, gt=0, description="ORCA's step: the velocity must be "
                             "feasible over this time, s (CrowdNav: 0.25)")
    neighbor_dist: float = Field(10.0, gt=0, description="obstacles farther than this are "
                                 "ignored, m (CrowdNav: 10)")
    max_neighbors: int = Field(10, gt=0, description="most obstacles considered (CrowdNav: 10)")
    time_horizon: float = Field(5.0, gt=0, description="collision-free for this long, s "
                                "(CrowdNav: 5)")
    radius_margin: float = Field(0.01, ge=0, description="added to every radius, m "
                                 "(CrowdNav: 0.01)")
    slow_within: float = Field(1.0, gt=0, description="the preferred velocity is the vector "
                               "to the goal divided by this, capped at the cruise speed, s "
                               "(CrowdNav: 1)")
    heading_gain: float = Field(2.0, gt=0, description="turn rate per rad of heading error, "
                                "1/s")
    max_drive_error: float = Field(math.pi / 2, gt=0, le=math.pi, description="heading error "
                                   "above which the robot turns in place, rad")
