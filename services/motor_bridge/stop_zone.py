"""A stop zone on the raw scan, independent of perception and planning (pure, no I/O).

Like Nav2's collision monitor: a rectangle ahead of the robot, as wide as the robot plus
a margin and as long as the robot needs to stop plus a margin. If the latest scan has a
return inside it while the robot is asked to move forward, forward motion is refused;
turning on the spot is still allowed, so the planner can steer away. Nothing behind the
direction of travel counts. Since it reads the laser directly, a fault in perception,
tracking or planning cannot drive the robot into what the laser sees.
"""

from __future__ import annotations

import functools

import numpy as np
import numpy.typing as npt
from pydantic import BaseModel, Field

from zenav.services.mission import DECEL
from zenav.services.motor_bridge._loops import zone_hit


class StopZoneParams(BaseModel):
    """The stop zone's geometry: the one definition both the motor bridge (which enforces
    it) and the planner (which never asks for motion into it) include in their
    parameters, so the two can never disagree by a default."""

    stop_zone: bool = Field(True, description="refuse forward motion toward a return in the "
                            "zone ahead (reads the raw scan)")
    zone_side_margin: float = Field(0.02, ge=0, description="zone half-width beyond the "
                                    "robot radius, m")
    zone_margin: float = Field(0.08, ge=0, description="zone length beyond the robot's "
                               "front at standstill, m")
    zone_reaction: float = Field(0.3, ge=0, description="s of travel added to the zone: one "
                                 "command period and some")
    decel: float = Field(DECEL, gt=0, description="forward deceleration limit of the base, "
                         "m/s^2 (also sets how long the zone reaches)")

    def blocks(self, ranges: npt.NDArray[np.float32], angle_min: float, angle_increment: float,
               range_max: float, v: float, robot_radius: float) -> bool:
        """Whether this zone, for a robot asked to go ``v`` m/s, holds a return."""
        if not self.stop_zone:
            return False
        ahead = stop_distance(v, self.zone_reaction, self.decel, self.zone_margin)
        return zone_blocked(ranges, angle_min, angle_increment, range_max, v, robot_radius,
                            self.zone_side_margin, ahead)


def stop_distance(v: float, reaction: float, decel: float, margin: float) -> float:
    """How far ahead of the robot's front the zone reaches at speed ``v`` (m/s), m."""
    v = max(v, 0.0)
    return margin + v * reaction + v * v / (2.0 * decel)


def zone_blocked(
    ranges: npt.NDArray[np.float32],
    angle_min: float,
    angle_increment: float,
    range_max: float,
    v: float,
    robot_radius: float,
    side_margin: float,
    ahead: float,
) -> bool:
    """Whether any return lies in the rectangle ahead of a robot asked to go ``v`` m/s.

    The rectangle, in the robot frame (x ahead), spans 0 < x <= robot_radius + ahead and
    |y| <= robot_radius + side_margin. ``v <= 0`` (not moving forward) is never blocked.
    """
    if v <= 0.0:
        return False
    r = np.ascontiguousarray(ranges, dtype=np.float64)
    cosines, sines = _beam_directions(angle_min, angle_increment, r.shape[0])
    # One compiled loop over the beams, stopping at the first inside (``_loops.zone_hit``).
    return zone_hit(r, cosines, sines, range_max, robot_radius + ahead,
                    robot_radius + side_margin)


@functools.lru_cache(maxsize=8)
def _beam_directions(angle_min: float, angle_increment: float, count: int
                     ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The cosines and sines of the beams' angles (read-only): the same laser scan after
    scan, and the zone is checked twice a scan (by the planner, then the bridge)."""
    angles = angle_min + angle_increment * np.arange(count)
    cosines, sines = np.cos(angles), np.sin(angles)
    cosines.setflags(write=False)
    sines.setflags(write=False)
    return cosines, sines
