"""Planner parameters, with the paper's values as defaults."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class Params(BaseModel):
    model_config = ConfigDict(extra="forbid")

    goal: tuple[float, float] = Field((6.0, 0.0), description="global target, m")
    start: tuple[float, float] | None = Field(
        None, description="start of the global path, m; default: the first pose seen"
    )
    goal_tolerance: float = Field(0.25, gt=0, description="arrived within this distance, m")
    cruise_speed: float = Field(0.1, gt=0, description="V_R, m/s")
    max_speed: float = Field(0.2, gt=0, description="top speed when speeding up, m/s")
    robot_radius: float = Field(0.2, gt=0, description="disc footprint, m")
    heading_gain: float = Field(1.5, gt=0, description="turn rate per rad of heading error, 1/s")
    max_omega: float = Field(1.0, gt=0, description="turn rate limit, rad/s")
