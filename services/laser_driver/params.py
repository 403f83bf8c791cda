"""Laser driver parameters: the scanner's geometry, and where its data comes from."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from zenav.services.mission import RANGE_MAX
from zenav.services.ros2.params import Ros2Params


class Params(BaseModel):
    """The scanner's geometry; the defaults are the paper's SICK scanner."""

    model_config = ConfigDict(extra="forbid")

    frame: str = Field("laser", description="frame id written into each scan")
    fov_deg: float = Field(180.0, gt=0, le=360, description="field of view, deg, centred ahead")
    resolution_deg: float = Field(0.5, gt=0, description="angle between beams, deg")
    range_min: float = Field(0.0, ge=0, description="shorter readings are not returns, m")
    range_max: float = Field(RANGE_MAX, gt=0,
                             description="longest range, m; reported for no return")
    rate_hz: float = Field(10.0, gt=0, description="scan rate, Hz")
    backend: Literal["native", "ros2"] = Field(
        "native", description="native: raw frames on device/laser; ros2: LaserScan and "
        "Odometry from a ROS 2 robot over rmw_zenoh (geometry taken from each scan)")
    ros2: Ros2Params = Field(default_factory=Ros2Params, description="the ROS 2 robot's "
                             "topics, frames and domain (ros2 backend)")

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
