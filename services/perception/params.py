"""Parameters of the perception service (sliding window and clustering).

The defaults are the paper's (Section 3 and the simulation set-up of Section 4): a window of
8 cells of 0.5 m and lambda = 1.2. ``gap_floor`` and ``min_beams`` go beyond the paper; their
paper values are 0.0 and 1 (see :meth:`PerceptionParams.paper`).
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, model_validator

from zenav.services.mission import CELL, WINDOW_RADIUS


class PerceptionParams(BaseModel):
    """Sliding window, grid and clustering parameters."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    window_radius: float = Field(
        WINDOW_RADIUS,
        gt=0.0,
        description="r_w, metres: radius of the sliding window around the robot; beams with "
        "rho > r_w are ignored. Paper: 8 cells x 0.5 m = 4.0 m.",
    )
    cell: float = Field(
        CELL,
        gt=0.0,
        description="r, metres: grid resolution of Eq. 2 (paper: 500 mm).",
    )
    lambda_: float = Field(
        1.2,
        gt=0.0,
        description="lambda, dimensionless: adaptive rate of the clustering threshold of Eq. 3 "
        "(paper: 1.2 for regular shapes).",
    )
    gap_floor: float = Field(
        0.15,
        ge=0.0,
        description="metres, added to the Eq. 3 threshold: theta = lambda*rho*sin(d_alpha) + "
        "gap_floor. Beyond the paper (paper value 0.0). Eq. 3 alone is about 1 cm at 1 m: "
        "below the spread of range noise (two beams at 0.03 m noise differ by 0.04 m rms) "
        "and below the point spacing on a surface seen at a grazing angle, so one obstacle "
        "breaks into many clusters that come and go. 0.15 m is 3.5 standard deviations of "
        "that difference at 0.03 m, and a gap that narrow is closed to the robot anyway "
        "(0.10 m still broke grazing box faces in the accuracy benchmark).",
    )
    min_beams: int = Field(
        2,
        ge=1,
        description="beams: clusters with fewer beams are dropped as specks. Beyond the paper "
        "(paper value 1). 2 drops single-beam returns, e.g. the grazing edge of a disc that "
        "the threshold cut off; a 0.2 m obstacle at 4 m still spans about 5 beams.",
    )

    edge_inset: float = Field(
        0.05,
        ge=0.0,
        description="metres: beyond the paper, a cluster's bounding box is shrunk by this "
        "much on each side before Eq. 2 gives its cells. An edge on a cell boundary then "
        "stays in the obstacle's cell; without it range noise smears a 0.5 m box laid on "
        "the grid over 2 x 2 cells. Paper value 0.",
    )
    motion_margin: float = Field(
        0.1,
        gt=0.0,
        description="metres: beyond the paper, the free-space motion test (motion_cue.py) "
        "counts a point as having entered (or left) empty space only past this margin; about "
        "3 standard deviations of 0.03 m range noise.",
    )
    motion_baselines: tuple[float, ...] = Field(
        (0.2, 0.5, 1.0, 2.0),
        description="seconds: earlier scans the motion test compares with. A mover is seen "
        "once it has moved motion_margin in one of them: 0.5 m/s after 0.2 s (a walker "
        "coming out from behind another is typed moving by its third scan), 0.2 m/s after "
        "0.5 s, 0.05 m/s after 2 s.",
    )
    motion_reach: float = Field(
        0.3,
        ge=0.0,
        description="metres: earlier points this close to a cluster are taken as its own for "
        "the 'vacated' half of the motion test.",
    )

    motion_split_span: float = Field(
        0.5,
        ge=0.0,
        description="metres: beyond the paper, a cluster that holds a mover pressed against "
        "a standing obstacle (a walker beside a door's jamb, closer than Eq. 3's threshold) "
        "is cut round the mover's points, those that entered space an earlier scan saw "
        "free, where the rest holds points that stood there motion_baselines' longest ago "
        "spread over at least this much (more than a walker is wide). 0: no cut, the "
        "paper's clustering.",
    )

    @model_validator(mode="after")
    def _window_holds_a_cell(self) -> PerceptionParams:
        if self.window_radius < self.cell:
            raise ValueError("window_radius must be at least one cell")
        return self

    @classmethod
    def paper(cls) -> PerceptionParams:
        """The paper's clustering exactly: Eq. 3 with no floor, single-beam clusters kept,
        no cluster cut."""
        return cls(gap_floor=0.0, min_beams=1, edge_inset=0.0, motion_split_span=0.0)
