"""Simulator parameters: the scenario, the clock, the simulated base's limits."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from zenav.services.mission import LIVE_SERVICES, MAX_OMEGA


class Params(BaseModel):
    model_config = ConfigDict(extra="forbid")

    scenario: Path | None = Field(None, description="scenario YAML file (required)")
    clock: Literal["lockstep", "realtime"] = "lockstep"
    realtime_factor: float = Field(1.0, gt=0, description="sim s per wall s in realtime mode")
    base_accel: float = Field(1.0, gt=0, description="the simulated base's own acceleration "
                              "limit, m/s^2 (above the motor bridge's accel)")
    base_decel: float = Field(2.0, gt=0, description="the simulated base's own deceleration "
                              "limit, m/s^2 (above the motor bridge's decel: a stop-zone stop "
                              "brakes with it)")
    max_omega: float = Field(MAX_OMEGA, gt=0, description="turn rate limit of the base, rad/s "
                             "(the robot's, as the planner's and the motor bridge's)")
    base_angular_accel: float = Field(8.0, gt=0, description="the simulated base's own turn "
                                      "rate change limit, rad/s^2 (above the bridge's)")
    wait_for: list[str] = Field(
        default_factory=lambda: list(LIVE_SERVICES),
        description="services whose liveliness is awaited before the clock starts",
    )
    startup_timeout: float = Field(60.0, gt=0, description="wall s to wait for them")
    retransmit_after: float = Field(0.5, gt=0, description="wall s before a frame is resent")
    answer_timeout: float = Field(30.0, gt=0, description="wall s without an answer: fail")
    result_repeat: float = Field(0.5, gt=0, description="wall s between result repeats")
    realtime_history: float = Field(
        60.0, gt=0, description="realtime: s of trajectory kept for the run result (a live "
        "stack runs for hours; lockstep runs keep every tick)"
    )
    base_timeout: float = Field(
        1.0, gt=0, description="realtime: the simulated base holds its last command at most "
        "this many wall s, then stops (a base's own watchdog, for when the bridge is gone)"
    )
