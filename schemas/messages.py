"""Every message exchanged between zenav services, as pydantic v2 models.

Conventions shared by all messages:

- ``stamp`` is a time in seconds on the stack's clock: the simulated clock in
  simulation (like ROS ``use_sim_time``), the host clock in real-time mode. A message
  derived from a laser scan carries that scan's stamp, so a whole pipeline pass can be
  followed by one number.
- ``seq`` counts the messages of one publisher, from 0.
- Distances in metres, angles in radians, speeds in m/s and rad/s, frame REP 103
  (x right, y up, headings from +x, counter-clockwise positive).
- Arrays travel as raw little-endian bytes inside the msgpack map (see ``codec``).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
import numpy.typing as npt
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainSerializer,
    WithJsonSchema,
    field_validator,
    model_validator,
)

ObstacleKind = Literal["new", "static", "dynamic"]
ScenarioLetter = Literal["a", "b", "c", "d", "e", "f", "g", "h"]
Action = Literal["keep", "slow", "stop", "speed_up", "morphin", "resume", "goal", "safety_stop",
                 "replan", "spin", "back_up", "wait", "unreachable", "give_way"]


def _array_validator(dtype: str, ndim: int, width: int = 5) -> Any:
    def convert(value: object) -> npt.NDArray[Any]:
        if isinstance(value, (bytes, bytearray, memoryview)):
            raw = bytes(value)
            itemsize = np.dtype(dtype).itemsize
            if len(raw) % itemsize:
                raise ValueError(f"byte length {len(raw)} is not a multiple of {itemsize}")
            array = np.frombuffer(raw, dtype=dtype)
        elif isinstance(value, np.ndarray):
            array = value.astype(dtype, copy=False)
        elif isinstance(value, (list, tuple)):
            array = np.asarray(value, dtype=dtype)
        else:
            raise ValueError(f"expected {dtype} bytes or an array, got {type(value).__name__}")
        if ndim == 2:
            if array.ndim == 1:
                if array.size % width:
                    raise ValueError(f"size {array.size} is not a multiple of the row width "
                                     f"{width}")
                array = array.reshape(-1, width)
            elif array.ndim != 2 or array.shape[1] != width:
                raise ValueError(f"expected rows of {width} values, got shape {array.shape}")
        elif array.ndim != 1:
            raise ValueError(f"expected a flat array, got shape {array.shape}")
        array.setflags(write=False)
        return array

    return convert


def _array_bytes(dtype: str) -> Any:
    def serialize(array: npt.NDArray[Any]) -> bytes:
        return np.ascontiguousarray(array, dtype=dtype).tobytes()

    return serialize


Float32Array = Annotated[
    npt.NDArray[np.float32],
    BeforeValidator(_array_validator("<f4", 1)),
    PlainSerializer(_array_bytes("<f4"), return_type=bytes),
    WithJsonSchema({"type": "string", "contentEncoding": "binary",
                    "description": "little-endian float32 values, packed"}),
]
"""A 1-D float32 array, carried as raw bytes on the wire."""

Rows5Array = Annotated[
    npt.NDArray[np.float64],
    BeforeValidator(_array_validator("<f8", 2)),
    PlainSerializer(_array_bytes("<f8"), return_type=bytes),
    WithJsonSchema({"type": "string", "contentEncoding": "binary",
                    "description": "little-endian float64 rows [t, x, y, heading, speed], packed"}),
]
"""An (n, 5) float64 array, carried as raw bytes on the wire."""

Rows3Array = Annotated[
    npt.NDArray[np.float64],
    BeforeValidator(_array_validator("<f8", 2, width=3)),
    PlainSerializer(_array_bytes("<f8"), return_type=bytes),
    WithJsonSchema({"type": "string", "contentEncoding": "binary",
                    "description": "little-endian float64 rows [t, x, y], packed"}),
]
"""An (n, 3) float64 array, carried as raw bytes on the wire."""

Rows2Array = Annotated[
    npt.NDArray[np.float64],
    BeforeValidator(_array_validator("<f8", 2, width=2)),
    PlainSerializer(_array_bytes("<f8"), return_type=bytes),
    WithJsonSchema({"type": "string", "contentEncoding": "binary",
                    "description": "little-endian float64 rows [x, y], packed"}),
]
"""An (n, 2) float64 array of points, carried as raw bytes on the wire."""

Int8Array = Annotated[
    npt.NDArray[np.int8],
    BeforeValidator(_array_validator("i1", 1)),
    PlainSerializer(_array_bytes("i1"), return_type=bytes),
    WithJsonSchema({"type": "string", "contentEncoding": "binary",
                    "description": "int8 values, packed"}),
]
"""A 1-D int8 array, carried as raw bytes on the wire."""

Finite = Annotated[float, Field(allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]


class Message(BaseModel):
    """Fields every message carries."""

    model_config = ConfigDict(
        extra="forbid", frozen=True, arbitrary_types_allowed=True, allow_inf_nan=False
    )
    TYPE: ClassVar[str] = "message"

    stamp: NonNegative = Field(description="time of the data, s, on the stack's clock")
    seq: int = Field(ge=0, description="publisher's message counter")


class Pose2D(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    x: Finite
    y: Finite
    heading: Finite = Field(description="rad from +x, counter-clockwise")


# --- sensing -------------------------------------------------------------------------


class RawLaserFrame(Message):
    """One frame as a laser device hands it over: just the ranges, in metres.

    The scanner's geometry (field of view, resolution, limits) is known to the laser
    driver from its parameters, as a real driver knows its scanner model.
    """

    TYPE = "raw_laser_frame"
    ranges: Float32Array

    @field_validator("ranges")
    @classmethod
    def _finite(cls, ranges: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
        if ranges.size == 0:
            raise ValueError("a frame needs at least one range")
        if float(ranges.min()) >= 0.0 and math.isfinite(float(ranges.max())):
            return ranges  # (two reductions say it all for a good frame; nan fails both)
        bad = ~np.isfinite(ranges)
        if bad.any():
            raise ValueError(f"non-finite range at beam {int(np.flatnonzero(bad)[0])}")
        if (ranges < 0).any():
            raise ValueError(f"negative range at beam {int(np.flatnonzero(ranges < 0)[0])}")
        return ranges


class LaserScan(Message):
    """A planar scan, with the field names of ROS ``sensor_msgs/LaserScan``.

    Beam i points at ``angle_min + i * angle_increment`` relative to the robot heading.
    A range equal to ``range_max`` means no return within reach.
    """

    TYPE = "laser_scan"
    frame: str = Field(min_length=1, max_length=64)
    angle_min: Finite
    angle_max: Finite
    angle_increment: Positive
    scan_time: NonNegative = Field(0.0, description="s between two scans, 0 if unknown")
    range_min: NonNegative
    range_max: Positive
    ranges: Float32Array

    @model_validator(mode="after")
    def _check(self) -> LaserScan:
        expected = round((self.angle_max - self.angle_min) / self.angle_increment) + 1
        if self.ranges.size != expected:
            raise ValueError(
                f"wrong beam count: {self.ranges.size} ranges for angles "
                f"{math.degrees(self.angle_min):.2f}..{math.degrees(self.angle_max):.2f} deg "
                f"step {math.degrees(self.angle_increment):.3f} deg (expected {expected})"
            )
        top = self.range_max * (1 + 1e-6)
        if float(self.ranges.min()) >= 0.0 and float(self.ranges.max()) <= top:
            return self  # (two reductions say it all for a good scan; nan fails both)
        bad = ~np.isfinite(self.ranges)
        if bad.any():
            raise ValueError(f"non-finite range at beam {int(np.flatnonzero(bad)[0])}")
        if (self.ranges < 0).any():
            raise ValueError(f"negative range at beam {int(np.flatnonzero(self.ranges < 0)[0])}")
        over = self.ranges > top
        if over.any():
            raise ValueError(
                f"range above range_max {self.range_max} at beam {int(np.flatnonzero(over)[0])}"
            )
        return self

    def angles(self) -> npt.NDArray[np.float64]:
        """Beam angles relative to the heading, rad."""
        return self.angle_min + self.angle_increment * np.arange(self.ranges.size, dtype=np.float64)


class Odometry(Message):
    """Robot pose and velocity from the base (wheel odometry, or the simulator)."""

    TYPE = "odometry"
    pose: Pose2D
    v: Finite = Field(description="forward speed, m/s")
    omega: Finite = Field(description="turn rate, rad/s")


# --- perception and tracking ---------------------------------------------------------


class Obstacle(BaseModel):
    """One cluster of consecutive beams: an obstacle O_k(t) as perception sees it."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    x: Finite = Field(description="centre Z_k (Eq. 5 then Eq. 1), global frame, m")
    y: Finite
    rho: NonNegative = Field(description="mean beam length, m")
    alpha: Finite = Field(description="mean beam angle relative to the heading, rad")
    cells: tuple[int, int, int, int] = Field(description="grid box ix_min, ix_max, iy_min, iy_max")
    area: int = Field(ge=1, description="grid area S_k, cells")
    beams: tuple[int, int] = Field(description="first and last beam index")
    n_beams: int = Field(ge=1, description="beams in the cluster")
    first: tuple[Finite, Finite] = Field(description="global point of the first beam, m")
    last: tuple[Finite, Finite] = Field(description="global point of the last beam, m")
    chord: tuple[Finite, Finite] = Field(description="midpoint of first and last, m")
    radius: NonNegative = Field(description="farthest point from the chord midpoint, m")
    edges: tuple[int, int] = Field(
        description="what lies beyond each end: 0 free, 1 occluded, 2 clipped by the window"
    )
    moved: float = Field(
        0.0, ge=0.0, le=1.0, description="free-space motion score (0 = stood still)"
    )
    moved_each: list[tuple[NonNegative, float]] = Field(
        default_factory=list, max_length=8,
        description="the motion score against each earlier scan compared with: (its stamp, "
        "score); a tracker ignores those taken before the obstacle was first seen")


class ObstacleChain(Message):
    """O_chain(t): the obstacles in the sliding window for one scan."""

    TYPE = "obstacle_chain"
    pose: Pose2D = Field(description="robot pose at scan time")
    window_radius: Positive
    cell: Positive = Field(description="grid resolution r, m")
    obstacles: list[Obstacle] = Field(max_length=400)


class Track(BaseModel):
    """An obstacle followed across scans, with its type and motion."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    id: int = Field(ge=0)
    kind: ObstacleKind
    x: Finite
    y: Finite
    vx: Finite
    vy: Finite
    speed: NonNegative
    heading: Finite = Field(description="direction of motion, rad from +x")
    radius: NonNegative
    xi: float = Field(ge=0.0, le=1.0, description="coincidence with the previous frame")
    varsigma: float = Field(ge=0.0, le=1.0, description="maximum spatial correlation")
    alpha_o_deg: float = Field(ge=0.0, le=360.0, description="the paper's alpha_o, deg "
                               "clockwise from +y")
    age: int = Field(ge=0, description="frames seen")
    cells: tuple[int, int, int, int]
    area: int = Field(ge=0, description="S_k when last seen, cells")
    visible: bool = Field(True, description="seen in this scan (False: predicted)")


MAX_TRACKS = 400
"""The most tracks one track list carries (the tracking service sends the nearest)."""


class TrackList(Message):
    TYPE = "track_list"
    pose: Pose2D = Field(description="robot pose at scan time")
    tracks: list[Track] = Field(max_length=MAX_TRACKS)


# --- planning and control ------------------------------------------------------------


class PlannerEvent(Message):
    """A decision that changes what the robot does."""

    TYPE = "planner_event"
    obstacle: int | None = Field(None, ge=0)
    kind: ObstacleKind | None = None
    scenario: ScenarioLetter
    action: Action
    detail: str = Field("", max_length=200)


class PlannerState(Message):
    """What the planner is doing now, published every cycle for monitors."""

    TYPE = "planner_state"
    scenario: ScenarioLetter
    action: Action
    target: tuple[Finite, Finite] = Field(description="current (sub-)target, m")
    speed: NonNegative = Field(description="commanded cruise speed, m/s")


class GlobalPath(Message):
    """The planner's global path: sent when it is planned again (or no way is found), and
    sent again unchanged every ``path_period`` (planner parameter, 1 s) so that a
    subscriber that joins late has it. A repeat is a new message (its own ``seq``,
    ``stamp`` the time it is sent) with the same ``points``, ``reason`` and ``planned``:
    :meth:`repeats` tells it apart."""

    TYPE = "global_path"
    points: Rows2Array = Field(description="vertices [x, y] from the robot to the goal, m; "
                               "none when no way is known")
    reason: str = Field("", max_length=100, description="why it was planned, or why no way "
                        "is known")
    planned: NonNegative | None = Field(
        None, description="stamp at which this path was planned, s: a repeat keeps it; "
        "absent: the message's own stamp")

    @property
    def planned_at(self) -> float:
        """The stamp at which this path was planned."""
        return self.stamp if self.planned is None else self.planned

    def repeats(self, earlier: GlobalPath | None) -> bool:
        """Whether this message is ``earlier`` sent again: the same plan (planned at the
        same stamp, for the same reason) with the same vertices."""
        return (earlier is not None and self.planned_at == earlier.planned_at
                and self.reason == earlier.reason
                and np.array_equal(self.points, earlier.points))

    @field_validator("points")
    @classmethod
    def _finite(cls, points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        if not np.isfinite(points).all():
            raise ValueError("non-finite path point")
        return points


class OccupancyMap(Message):
    """The planner's occupancy grid, at a low rate: cell (ix, iy) spans
    [origin + (ix, iy) * resolution, origin + (ix + 1, iy + 1) * resolution)."""

    TYPE = "occupancy_map"
    origin: tuple[Finite, Finite] = Field(description="lower-left corner of cell (0, 0), m")
    resolution: Positive = Field(description="cell side, m")
    width: int = Field(ge=1, description="cells along x")
    height: int = Field(ge=1, description="cells along y")
    cells: Int8Array = Field(description="row by row (iy, then ix), as ROS OccupancyGrid: "
                             "-1 unknown, 0 free, 100 occupied")

    @model_validator(mode="after")
    def _check(self) -> OccupancyMap:
        if self.cells.size != self.width * self.height:
            raise ValueError(f"{self.cells.size} cells for a {self.width} x {self.height} grid")
        return self

    def grid(self) -> npt.NDArray[np.int8]:
        """The cells as (width, height), indexed [ix, iy]."""
        return self.cells.reshape(self.height, self.width).T


class VelocityCommand(Message):
    """What the planner asks of the base: forward speed and turn rate."""

    TYPE = "velocity_command"
    v: Finite
    omega: Finite


class BaseCommand(Message):
    """What the motor bridge sends the base after limits and timeouts."""

    TYPE = "base_command"
    v: Finite
    omega: Finite
    reason: Literal["command", "stale", "stop_zone", "idle"] = "command"


# --- simulation only: never read by the navigation services --------------------------


class ObstacleTruth(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    index: int = Field(ge=0, description="position in the scenario's obstacle list")
    shape: Literal["box", "disc"]
    x: Finite
    y: Finite
    size: tuple[NonNegative, NonNegative] = Field(description="box width, height; disc 2r, 2r")
    vx: Finite
    vy: Finite


class GroundTruth(Message):
    TYPE = "ground_truth"
    pose: Pose2D
    v: Finite
    obstacles: list[ObstacleTruth] = Field(max_length=1000)


class AgentPath(BaseModel):
    """Where one agent (an obstacle with ``behavior: orca``) was at each simulator tick."""

    model_config = ConfigDict(extra="forbid", frozen=True, arbitrary_types_allowed=True)

    index: int = Field(ge=0, description="position in the scenario's obstacle list")
    rows: Rows3Array = Field(description="[t s, x m, y m] at the trajectory's ticks")


class RunResult(Message):
    """How a simulated run ended, published once by the simulator."""

    TYPE = "run_result"
    scenario: str
    outcome: Literal["reached", "collision", "timeout"]
    time: NonNegative
    path_length: NonNegative
    min_clearance: float = Field(
        allow_inf_nan=True, description="m; inf when no obstacle was ever present"
    )
    collided_with: int | None = None
    trajectory: Rows5Array
    agents: list[AgentPath] = Field(
        default_factory=list, description="the agents' paths (scenarios with agents only)"
    )


# --- health --------------------------------------------------------------------------


class ServiceStatus(Message):
    """Counters a service publishes about itself, once a second."""

    TYPE = "service_status"
    service: str
    received: dict[str, int] = Field(description="messages accepted, per input key")
    rejected: dict[str, int] = Field(description="messages rejected, per reason kind")
    dropped: dict[str, int] = Field(description="messages dropped by newest-wins, per key")
    handler_errors: int = 0


ALL_MESSAGES: tuple[type[Message], ...] = (
    RawLaserFrame,
    LaserScan,
    Odometry,
    ObstacleChain,
    TrackList,
    PlannerEvent,
    PlannerState,
    GlobalPath,
    OccupancyMap,
    VelocityCommand,
    BaseCommand,
    GroundTruth,
    RunResult,
    ServiceStatus,
)
