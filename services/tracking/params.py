"""Parameters of the tracking service.

The decision-tree thresholds and the spatial-correlation weights are the paper's (Section 4.1).
``method`` selects the paper's per-frame decision tree with the two-frame motion of Eq. 15
("paper"), or this project's track-based estimate ("smoothed": a constant-velocity Kalman
filter per track, type from the filtered speed). Fields marked *(smoothed)* only act when
``method == "smoothed"``; fields marked *(paper)* only when ``method == "paper"``.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from zenav.services.mission import WINDOW_RADIUS


class TrackingParams(BaseModel):
    """Thresholds, association, drop time and velocity-filter settings."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    method: Literal["paper", "smoothed"] = Field(
        "smoothed",
        description="'paper': type from the decision tree on this frame against the previous "
        "chain, motion from Eq. 15 over the two frames. 'smoothed': Kalman-filtered track "
        "position and velocity, type from the filtered speed. The paper's xi, varsigma and "
        "delta are computed and reported in both.",
    )

    # --- the paper's decision tree (Sec. 3.3) and Eqs. 12-13 ---
    theta_varsigma1: float = Field(
        0.30, gt=0.0, lt=1.0, description="theta_varsigma1: varsigma_max below it -> new."
    )
    theta_varsigma2: float = Field(
        0.70, gt=0.0, lt=1.0, description="theta_varsigma2: varsigma_max above it -> static."
    )
    theta_delta: float = Field(
        0.4,
        ge=0.0,
        description="theta_delta, grid CELLS: in the middle band, centre distance below it -> "
        "static. delta is counted in cells (0.4 cells = 0.2 m at r = 0.5 m), see "
        "correlation.py for why.",
    )
    theta_xi: float = Field(
        0.5, ge=0.0, le=1.0, description="theta_xi: coincidence below it -> dynamic."
    )
    y_delta: float = Field(0.5, ge=0.0, description="y_delta: weight of 1/(delta+1) in Eq. 12.")
    y_eta: float = Field(0.5, ge=0.0, description="y_eta: weight of 1/(eta+1) in Eq. 12.")
    compare_dt: float = Field(
        0.0,
        ge=0.0,
        description="T, seconds: the chain the decision tree (and, in 'paper', Eq. 15) "
        "compares with is the newest one at least this old; 0 = the previous frame. The "
        "paper never fixes T; at 10 Hz a walker moves a tenth of a cell per frame, too "
        "little for the tree (theta_delta = 0.4 cells), so the paper profile compares with "
        "the frame 1 s back (the typing accuracy against T is in "
        "docs/tracking-accuracy.txt).",
    )

    # --- track keeping (both methods) ---
    drop_after: float = Field(
        1.0, gt=0.0, description="seconds: a track not seen for longer than this is dropped."
    )
    fov_deg: float = Field(
        180.0, gt=0.0, le=360.0,
        description="degrees, centred on the heading: the scanner's field of view. A static "
        "track outside it (or beyond window_radius) cannot be seen, so it is remembered for "
        "'memory' seconds instead of dropped after drop_after: the obstacle beside or behind "
        "the robot is still there while it drives past.",
    )
    window_radius: float = Field(
        WINDOW_RADIUS, gt=0.0, description="metres: how far obstacles are seen (the sliding "
        "window r_w)."
    )
    memory: float = Field(
        30.0, ge=0.0, description="seconds: how long a static track out of view is kept."
    )
    memory_min_age: int = Field(
        20, ge=1, description="frames: only a track seen this often is remembered out of "
        "view (a mover glimpsed at the edge of the view is not made a standing ghost)."
    )
    reacquire: float = Field(
        6.0, ge=0.0, description="seconds: a track born where a mover dropped beside or "
        "behind the laser's field of view within this long is predicted to be (at its last "
        "velocity) is that mover seen again: it takes "
        "back the mover's id, type and velocity instead of starting 'new' (a walker that "
        "left the view while the robot turned is not a new obstacle when it comes back); "
        "0: never.",
    )
    gate: float = Field(
        0.5,
        gt=0.0,
        description="metres: a cluster is associated with a track only if its centre is within "
        "track radius + gate of the track's predicted centre.",
    )
    piece_gap: float = Field(
        0.3,
        ge=0.0,
        description="metres: a cluster left over after association that starts within a few "
        "beams and this distance of an associated cluster's end is a chip of that obstacle "
        "(a grazing surface broken by noise) and joins its track instead of starting one.",
    )
    merge_hold: float = Field(
        2.0,
        ge=0.0,
        description="seconds: while one cluster covers two confirmed tracks (two obstacles seen "
        "as one), both tracks are kept and coast on their prediction for at most this long.",
    )
    new_frames: int = Field(
        2,
        ge=1,
        description="frames (smoothed): a track is 'new' for its first new_frames frames.",
    )

    # --- smoothed estimate ---
    position: Literal["mean", "chord"] = Field(
        "mean",
        description="(smoothed) measured point of a cluster: 'mean' = the Eq. 5 centre, "
        "'chord' = midpoint of its end points. The chord midpoint moves less with the "
        "viewpoint but rests on two beams, so it jitters by a beam step as the obstacle "
        "crosses beams; the Eq. 5 mean averages every beam and measured 2-3x smaller speed "
        "errors in the accuracy benchmark, its viewpoint drift being slow.",
    )
    dynamic_speed: float = Field(
        0.2,
        gt=0.0,
        description="m/s (smoothed): a track becomes dynamic when its filtered speed is above "
        "this and above speed_sigmas standard deviations.",
    )
    static_speed: float = Field(
        0.1,
        ge=0.0,
        description="m/s (smoothed): a dynamic track becomes static again below this speed "
        "(hysteresis against flicker).",
    )
    moved_threshold: float = Field(
        0.3, ge=0.0, le=1.0,
        description="(smoothed) free-space motion score (perception's motion cue) at or above "
        "which a cluster counts as having moved.",
    )
    cue_warmup: float = Field(
        0.5, ge=0.0, description="seconds (smoothed): a track this young, which the motion cue "
        "cannot judge yet, is dynamic when its filtered speed is above dynamic_speed and "
        "significant; older tracks go by the cue.",
    )
    moved_hold: float = Field(
        1.0, ge=0.0, description="seconds (smoothed): a track stays dynamic this long after "
        "the motion cue last fired.",
    )
    speed_sigmas: float = Field(
        2.0, ge=0.0, description="(smoothed) significance of the speed needed to call dynamic."
    )
    accel_std: float = Field(
        0.2,
        gt=0.0,
        description="m/s^2 (smoothed): white-acceleration process noise of the constant-velocity "
        "Kalman filter (spectral density accel_std^2, m^2/s^3). Lower gives a steadier speed "
        "and a slower answer to a change of course; 0.2 suits walkers that keep their "
        "course for seconds (0.5 doubled the speed error in the accuracy benchmark).",
    )
    meas_std: float = Field(
        0.03,
        gt=0.0,
        description="metres (smoothed): standard deviation of a measured cluster position.",
    )
    partial_meas_std: float = Field(
        0.25,
        gt=0.0,
        description="metres (smoothed): standard deviation used instead of meas_std when the "
        "cluster is partly hidden (occluded, clipped by the window or the field of view): "
        "its centre then moves with what is visible, not with the obstacle.",
    )
    hidden_fit: bool = Field(
        True,
        description="(smoothed) a walker seen in part (one end of its cluster free, the "
        "other cut off by the field of view, the window or something in front) is measured "
        "as the disc of its last whole view that touches the free end's beam: its centre and "
        "radius come from that disc instead of from the visible sliver.",
    )
    fitted_meas_std: float = Field(
        0.08,
        gt=0.0,
        description="metres (smoothed): standard deviation of a position measured by "
        "hidden_fit.",
    )
    jump_sigmas: float = Field(
        4.0,
        gt=0.0,
        description="(smoothed) an innovation beyond this many standard deviations is taken as "
        "a jump of the measured point (what is visible changed), not as motion: the "
        "position is reset to the measurement and the velocity kept. A jump that no change "
        "of view explains (or one beyond the obstacle's diameter) may be another obstacle "
        "taken for this one: the velocity is then kept only as a guess, with a new track's "
        "uncertainty (init_speed_std), and learnt again from the next scans.",
    )
    init_speed_std: float = Field(
        1.0, gt=0.0, description="m/s (smoothed): prior standard deviation of a new track's speed."
    )

    @model_validator(mode="after")
    def _ordered(self) -> TrackingParams:
        if not self.theta_varsigma1 < self.theta_varsigma2:
            raise ValueError("theta_varsigma1 must be below theta_varsigma2")
        if not self.static_speed <= self.dynamic_speed:
            raise ValueError("static_speed must not exceed dynamic_speed")
        return self
