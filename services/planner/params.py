"""Planner parameters. The paper's values are the defaults where it gives them."""

from __future__ import annotations

import math
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from zenav.services.mission import (
    ACCEL,
    CELL,
    MAX_OMEGA,
    MAX_REVERSE_SPEED,
    MAX_SPEED,
    ROBOT_RADIUS,
    SCAN_WAIT,
    WINDOW_RADIUS,
)
from zenav.services.motor_bridge.stop_zone import StopZoneParams


class MissionParams(BaseModel):
    """What every planner implementation is given (``zenav run`` fills it from the
    scenario): the mission, the robot and the world grid."""

    model_config = ConfigDict(extra="forbid")

    # --- the mission ----------------------------------------------------------------
    goal: tuple[float, float] = Field((6.0, 0.0), description="global target, m")
    start: tuple[float, float] | None = Field(
        None, description="start of the global path, m; default: the first pose seen"
    )
    goal_tolerance: float = Field(0.25, gt=0, description="arrived within this distance, m")
    scan_wait: float = Field(
        SCAN_WAIT, gt=0, description="wall s the planner waits for the scan of a track "
        "list's stamp before deciding without it (the paper planner: without a map update "
        "or a stop zone check; a baseline: on the newest scan before); in real time the "
        "next track list (0.1 s later at 10 Hz) ends the wait sooner"
    )

    # --- the robot ------------------------------------------------------------------
    cruise_speed: float = Field(0.1, gt=0, description="V_R, m/s")
    max_speed: float = Field(MAX_SPEED, gt=0, description="top speed when speeding up, m/s")
    robot_radius: float = Field(ROBOT_RADIUS, gt=0, description="disc footprint, m")
    max_omega: float = Field(MAX_OMEGA, gt=0, description="turn rate limit, rad/s")

    # --- the world model ------------------------------------------------------------
    cell: float = Field(CELL, gt=0, description="grid resolution r, m (Eq. 2)")
    window_radius: float = Field(WINDOW_RADIUS, gt=0,
                                 description="r_w: obstacles beyond are ignored, m")
    moving_speed: float = Field(
        0.03, ge=0, description="tracks slower than this are treated as standing still, m/s"
    )


class Params(MissionParams, StopZoneParams):
    """The paper planner's parameters. The stop zone's geometry (``stop_zone``,
    ``zone_*``, ``decel``) is the motor bridge's own model, included, not copied."""

    heading_gain: float = Field(1.5, gt=0, description="turn rate per rad of heading error, 1/s")
    safety_margin: float = Field(
        0.1, ge=0, description="gap kept between footprints on top of both radii, m"
    )
    lookahead: float = Field(
        1.0, gt=0, description="the robot steers for the global path this far ahead of its "
        "projection on it, m: on the path that is straight on, off it a way back"
    )

    # --- collision prediction -------------------------------------------------------
    mover_centre: bool = Field(
        False, description="beyond the paper, off by default: a mover (a track typed "
        "dynamic) that the scan sees whole is placed at the centre of the disc whose "
        "Eq. 5 centre its track is, about 0.8 of its radius farther from the robot "
        "(geometry.disc_distance): the Eq. 5 centre lies on the visible surface, so the "
        "track's footprint reaches nearer the robot than the walker does. On CrowdNav's "
        "circle crossing (invisible humans, cases 0-499 and 9000-9499) it took 0.35 s off "
        "the mean time to goal with the 360 degree laser, one collision fewer in 500; "
        "with the paper's 180 degree laser 4 and 5 more collisions in 500, hence off"
    )
    horizon: float = Field(
        12.0, gt=0, description="longest time ahead a meeting with a mover is acted on, s: "
        "velocity errors grow with it, and the robot has time to answer a later one later"
    )
    meet_rule: Literal["closest", "same_time"] = Field(
        "closest", description="what makes a crosser a threat (e): closest (beyond the "
        "paper): the footprints come within the clearance within the horizon; same_time (the "
        "paper's): robot and crosser are at the PCP at the same time, each while within the "
        "clearance of it, with no horizon (prediction.py)"
    )
    head_on_cos: float = Field(
        -0.8, description="cos of the angle between motions below which a mover is head-on (f)"
    )
    threat_hysteresis: float = Field(
        0.1, ge=0, description="extra margin an obstacle already answered must clear before "
        "it stops counting as a threat, m"
    )
    same_way_cos: float = Field(
        0.8, description="cos of the angle above which a mover goes the robot's way (g)"
    )

    confirm_time: float = Field(
        2.0, ge=0, description="a standing obstacle is answered with a detour once seen this "
        "long (perception needs up to 2 s to see a slow mover move), s"
    )
    confirm_distance: float = Field(
        0.6, ge=0, description="... unless the path meets it closer than this, m"
    )
    wall_radius: float = Field(
        0.5, ge=0, description="a standing obstacle at least this big (its radius, m) is "
        "no (b) while too young for the map if the map's returns in its cell box keep off "
        "the way: the box of a wall's corner seen round a bend covers the bend's inside. "
        "A smaller one (a post, a walker standing) is judged on its box, as in the paper"
    )

    safety_horizon: float = Field(
        6.0, gt=0, description="the longest time the speed and safety stage rolls the "
        "robot out against the movers, s (safety.py)"
    )
    safety_step: float = Field(0.2, gt=0, description="s between roll-out points")
    safety_growth: float = Field(
        0.2, ge=0, description="clearance added to a mover's predicted position per m it "
        "covers (tracked velocities are estimates; walkers turn)"
    )
    top_speed_fade: float = Field(
        2.0, ge=0, description="a mover's top speed (how fast its predicted clearance grows) "
        "fades by a factor e every this many s while it stands (under a quarter of it), so "
        "a walker standing at its goal stops being treated as one about to set off at full "
        "speed, s; 0: never"
    )
    safety_comfort: float = Field(
        0.6, ge=0, description="a pass within this much beyond the clearance still costs, m"
    )
    safety_from_inside: bool = Field(
        True, description="a mover whose clearance already holds the robot is contact only "
        "where a roll-out comes closer to it than now, costed by how much, and the cost of "
        "turning from the last heading is waived meanwhile (safety.py)"
    )
    safety_tau: float = Field(
        1.5, gt=0, description="a contact t s ahead costs 1 / (1 + t / tau) of one now, s"
    )
    safety_fan_deg: float = Field(
        15.0, gt=0, le=90, description="angle between the headings tried all round, deg"
    )
    safety_speeds: tuple[float, ...] = Field(
        (0.0, 0.25, 0.5, 0.75, 1.0), description="fractions of max_speed tried per heading"
    )
    safety_turn_cost: float = Field(
        0.3, ge=0, description="cost per rad of heading change from the last choice"
    )
    mover_memory: float = Field(
        6.0, ge=0, description="a mover whose track is lost while it is out of the laser's "
        "view (beside or behind the robot, or hidden behind something nearer) is still "
        "predicted by the speed and safety stage from where it was last seen for up to "
        "this long, s, and past it while it still walks at the robot fast enough to "
        "reach it within safety_horizon; dropped at once "
        "when it should be in view and is not (0: never)"
    )
    drive_on_growth: float = Field(
        2.0, ge=0, description="when the (e) responses ask for a stop or a lower speed "
        "and no detour is under way, the robot drives on at V_R if the speed and safety "
        "stage's roll-out at V_R toward the target keeps clear of every mover, seen or "
        "remembered, with safety_growth times this factor; 0: the responses stand (as "
        "with speed_check off)"
    )
    accel: float = Field(ACCEL, gt=0, description="forward acceleration limit of the "
                         "commands (the motor bridge's), m/s^2")

    # --- Algorithm 1 (the paper profile sets these to the paper's rules) -------------
    threats_per_cycle: Literal["all", "one"] = Field(
        "all", description="'all': beyond the paper, every threat in the window is answered "
        "at once (the lowest speed any asks for, a detour round all). 'one': Algorithm 1, "
        "the first threat in scan order (right to left) is answered and the rest wait for "
        "a later cycle"
    )
    slow_step: float = Field(
        0.0, ge=0, description="Delta V_R, m/s per cycle: > 0 answers (e) and (g) with "
        "Algorithm 1's V_R - Delta V_R (back to V_R once no collision is predicted); 0: "
        "beyond the paper, the speed that lets the crosser pass or keeps the gap behind"
    )
    speed_check: bool = Field(
        True, description="beyond the paper: refuse a speed at which a seen mover would "
        "touch the robot within safety_horizon, and step aside when no speed is safe"
    )
    fast_fallback: bool = Field(
        True, description="beyond the paper: when no detour round a head-on mover (f) is "
        "clear at V_R, plan one at max_speed"
    )

    # --- responses ------------------------------------------------------------------
    speed_up_buffer: float = Field(
        2.0, ge=0, description="(e): speed up only if the robot clears the meeting point "
        "this long before the obstacle arrives, s"
    )
    min_slow_fraction: float = Field(
        0.4, gt=0, le=1, description="(e): slowing below this fraction of V_R means stopping"
    )
    follow_gap: float = Field(0.6, gt=0, description="(g): free distance kept behind, m")
    follow_gain: float = Field(0.3, gt=0, description="(g): speed change per m of gap error, 1/s")
    stop_gap: float = Field(0.25, ge=0, description="(g): stop below this free distance, m")

    # --- simplified Morphin (Eq. 17) ------------------------------------------------
    kappa: tuple[float, float, float] = Field(
        (1.0, 1.3, 0.6), description="kappa_1..3: weights of |G|, Delta L and W (paper values)"
    )
    fan_step_deg: float = Field(5.0, gt=0, description="angle between candidate paths, deg")
    fan_max_deg: float = Field(85.0, gt=0, lt=90, description="widest candidate, deg")
    escape_fan_deg: float = Field(
        175.0, gt=0, lt=180, description="beyond the paper: widest candidate when the "
        "paper's fan is blocked all round, deg"
    )
    extend_past: bool = Field(
        True, description="beyond the paper: lengthen candidates by the clearance so the "
        "sub-target lies past the obstacle instead of beside it (paper: False)"
    )
    switch_penalty: float = Field(
        10.0, ge=0, description="beyond the paper: extra cost of re-planning a detour to the "
        "other side of the obstacle than the one under way"
    )
    replan_slack: float = Field(
        0.05, ge=0, description="on a detour, the margin may shrink by this much before the "
        "way to the sub-target counts as blocked and the detour is planned again, m"
    )
    around_obstacles: bool = Field(
        True, description="beyond the paper: Delta L is the distance to the goal around the "
        "standing obstacles seen so far, not in a straight line (paper: False)"
    )
    dead_end_penalty: float = Field(
        5.0, ge=0, description="beyond the paper: extra cost of a sub-target that leads back "
        "or from which the global path cannot be seen again"
    )
    subtarget_reached: float = Field(
        0.15, gt=0, description="a sub-target this close counts as reached, m"
    )
    resume_hysteresis: float = Field(
        0.1, ge=0, description="extra clearance the direct way must have before a detour "
        "is given up, m"
    )

    # --- the map (costmap.py) ---------------------------------------------------------
    use_map: bool = Field(
        True, description="beyond the paper: build an occupancy map from the scans and "
        "follow a global path planned on it (paper: False, the straight start-goal line)"
    )
    map_resolution: float = Field(
        0.1, gt=0, description="map cell side, m: half the robot radius, so a 1 m gap "
        "between two walls stays passable after inflation, and the grid search over a "
        "20 m square stays near 40,000 cells"
    )
    map_decay: float = Field(
        60.0, gt=0, description="a cell not seen for this long is unknown again, s: longer "
        "than the tracks' 30 s memory, so the map outlives what the local layer forgets"
    )
    map_wall_decay: float = Field(
        600.0, gt=0, description="a wall of the map's memory (its returns came for "
        "map_wall_confirm, no beam through it since) stays an obstacle this long after it "
        "was last seen, s, and recovery's clearing keeps it: the walls of a maze or a long "
        "corridor outlive map_decay, so the path does not go back through walls left "
        "behind (at least map_decay)"
    )
    map_wall_confirm: float = Field(
        5.0, ge=0, description="returns must come for this long before a wall is kept past "
        "map_decay and through recovery's clearing, s: a slow walker beyond perception's "
        "window leaves marks confirmed after map_confirm, not kept"
    )
    map_confirm: float = Field(
        1.0, ge=0, description="a return must stay in its cell this long before the map "
        "counts it as an obstacle, s: a mover beyond perception's window (untyped) moves on "
        "before that, a standing obstacle is confirmed in ten scans"
    )
    map_padding: float = Field(
        3.0, gt=0, description="margin of the grid round start, goal and every return, m; "
        "also the step it grows by"
    )
    map_max_size: float = Field(200.0, gt=0, description="largest grid side, m")
    map_period: float = Field(1.0, gt=0, description="s between two published maps")
    path_period: float = Field(
        1.0, gt=0, description="s between two sends of an unchanged global path (or of "
        "none, when no way is known): a new path is sent at once, and sent again at this "
        "period so that a viewer or recorder that joins late has it within this time"
    )

    # --- the global path (global_path.py) ---------------------------------------------
    path_deviation: float = Field(
        0.3, gt=0, description="the path is planned again when the robot is farther than "
        "this from it (after a detour, say), m"
    )
    replan_period: float = Field(
        1.0, ge=0, description="shortest time between two re-plans that the map alone "
        "asks for (a blocked path), s"
    )

    # --- recovery (recovery.py) -------------------------------------------------------
    recovery: bool = Field(
        True, description="beyond the paper: watch progress and recover (replan, spin, back "
        "up, wait; unreachable) when it stalls (paper: False)"
    )
    progress_distance: float = Field(
        0.5, gt=0, description="distance to go that must be gained within "
        "progress_timeout, m (Nav2's progress checker: 0.5 m)"
    )
    progress_timeout: float | None = Field(
        None, gt=0, description="s; default: the longer of 10 s (Nav2's) and the time to "
        "cover progress_distance at a fifth of the cruise speed (25 s at 0.1 m/s)"
    )
    stop_zone_timeout: float = Field(
        5.0, gt=0, description="s of forward motion refused by the stop zone before recovery"
    )
    wait_allowance: float = Field(
        40.0, ge=0, description="s of waiting for a mover ((e), (g)) in a row that do not "
        "count against progress"
    )
    spin_deg: float = Field(360.0, gt=0, description="recovery spin: turn in place, deg")
    backup_distance: float = Field(0.3, ge=0, description="recovery back-up: reverse, m")
    backup_speed: float = Field(0.05, gt=0, description="recovery back-up speed, m/s")
    wait_time: float = Field(5.0, ge=0, description="recovery wait: stand still, s")
    recovery_rounds: int = Field(
        2, ge=1, description="rounds of the four recovery steps without progress, with no "
        "way to the goal on the map (or the goal cut off by the walls seen, when the steps "
        "run back to back), before the goal is declared unreachable"
    )

    goal_braking: bool = Field(
        True, description="beyond the paper: on a free run at the goal, ask for the speed "
        "from which braking at decel stops the robot on it, sqrt(2 decel d), where the stop "
        "zone at that speed stays clear for zone_reaction s more, instead of slowing to the "
        "distance d (one second of travel); not toward a goal settled off the map's cells"
    )

    final_approach_speed: float = Field(
        0.05, ge=0, description="beyond the paper: the last stretch to a goal beside what the "
        "laser sees (a wall within the radius plus half safety_margin of it) is judged on the "
        "scan's returns: no (b) detour while the straight way keeps the radius plus the stop "
        "zone's reach at this speed off them to a point within goal_tolerance of the goal; "
        "where the zone at the speed asked would refuse the goal, the robot closes in at this "
        "speed (m/s, the zone is shortest then); it has arrived once within the tolerance "
        "with no nearer point to be had; a goal with no such point within the tolerance is "
        "unreachable after one round of the recovery steps. 0: off"
    )

    # --- giving way (give_way.py) -----------------------------------------------------
    give_way: bool = Field(
        True, description="beyond the paper: between walls (the map holds something within "
        "give_way_reach on both sides of the robot), step aside from the one mover coming "
        "head-on and wait, facing it, until it has passed, instead of a detour that turns "
        "back along the corridor (needs use_map)"
    )
    give_way_reach: float = Field(
        1.5, gt=0, description="how far the spot aside may be, and how far to each side "
        "the map is looked at for walls, m"
    )
    give_way_limit: float = Field(
        60.0, gt=0, description="longest a spot aside is held, s"
    )
    give_way_patience: float = Field(
        3.0, gt=0, description="a spot aside is given up when the mover has not been seen, "
        "or not seen moving, for this long, s"
    )
    max_reverse_speed: float = Field(
        MAX_REVERSE_SPEED, gt=0, description="the motor bridge's reverse speed limit, m/s: "
        "a spot aside across the mover's line and behind the robot is timed at it"
    )

    def arrival_distance(self) -> float:
        """m: the planner stops for good this close to the goal, half the tolerance the
        run is judged by, so it stops inside it."""
        return self.goal_tolerance / 2

    def effective_progress_timeout(self) -> float:
        if self.progress_timeout is not None:
            return self.progress_timeout
        return max(10.0, self.progress_distance / (0.2 * self.cruise_speed))

    def spin_angle(self) -> float:
        return math.radians(self.spin_deg)
