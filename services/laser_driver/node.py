"""Laser driver service: the place where a real scanner plugs in.

It reads raw frames from a device backend, checks them against the scanner's geometry
from its parameters, and publishes :class:`LaserScan` messages. The backend here is the
simulator's raw frames on ``device/laser``; a hardware backend would publish the same
frames from the scanner's own protocol.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from zenav.schemas import keys
from zenav.schemas.messages import LaserScan, RawLaserFrame
from zenav.services.node import Node, StampGate


class Params(BaseModel):
    """The scanner's geometry; the defaults are the paper's SICK scanner."""

    model_config = ConfigDict(extra="forbid")

    frame: str = Field("laser", description="frame id written into each scan")
    fov_deg: float = Field(180.0, gt=0, le=360, description="field of view, deg, centred ahead")
    resolution_deg: float = Field(0.5, gt=0, description="angle between beams, deg")
    range_min: float = Field(0.0, ge=0, description="shorter readings are not returns, m")
    range_max: float = Field(8.0, gt=0, description="longest range, m; reported for no return")
    rate_hz: float = Field(10.0, gt=0, description="scan rate, Hz")

    @model_validator(mode="after")
    def _whole_beams(self) -> Params:
        steps = self.fov_deg / self.resolution_deg
        if abs(steps - round(steps)) > 1e-6:
            raise ValueError(
                f"fov_deg {self.fov_deg} is not a whole number of {self.resolution_deg} deg steps"
            )
        return self

    @property
    def beam_count(self) -> int:
        return round(self.fov_deg / self.resolution_deg) + 1


class FrameError(ValueError):
    """A raw frame that does not fit the scanner."""


def frame_to_scan(frame: RawLaserFrame, params: Params, seq: int) -> LaserScan:
    """Check a raw frame and turn it into a scan; raises :class:`FrameError`."""
    ranges = frame.ranges
    if ranges.size != params.beam_count:
        raise FrameError(f"frame has {ranges.size} beams, the scanner has {params.beam_count}")
    if not np.isfinite(ranges).all():
        raise FrameError(f"non-finite range at beam {int(np.flatnonzero(~np.isfinite(ranges))[0])}")
    if (ranges < 0).any():
        raise FrameError(f"negative range at beam {int(np.flatnonzero(ranges < 0)[0])}")
    clipped = np.minimum(ranges, np.float32(params.range_max))
    half = math.radians(params.fov_deg) / 2
    return LaserScan(
        stamp=frame.stamp,
        seq=seq,
        frame=params.frame,
        angle_min=-half,
        angle_max=half,
        angle_increment=math.radians(params.resolution_deg),
        scan_time=1.0 / params.rate_hz,
        range_min=params.range_min,
        range_max=params.range_max,
        ranges=clipped,
    )


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.params = params
        self.scans = node.publisher(keys.SCAN, LaserScan)
        self.gate = StampGate(node, keys.RAW_LASER)
        node.subscribe(keys.RAW_LASER, RawLaserFrame, self.on_frame, depth=2)

    def on_frame(self, frame: RawLaserFrame) -> None:
        try:  # checked before the stamp order: a bad frame must not pass as a repeat
            scan = frame_to_scan(frame, self.params, seq=0)
        except FrameError as exc:
            self.node.reject(self.node.keys.of(keys.RAW_LASER), "bad_frame", str(exc))
            return
        if not self.gate.admit(frame.stamp, self.scans):
            return
        self.scans.publish(scan.model_copy(update={"seq": self.scans.next_seq()}))


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("laser_driver"))
