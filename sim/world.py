"""The obstacle world as arrays, and what of it exists at a given time.

Obstacles are split into discs and axis-aligned boxes. Each keeps the index it has
in the scenario's ``obstacles`` list (``*_ids``) so results can be reported per
scenario obstacle. A moving obstacle's centre at time t is
``center + velocity * (t - appear)`` while ``appear <= t < vanish``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import DTypeLike, NDArray

from zenav.sim.scenario import Scenario

__all__ = ["World", "WorldSnapshot"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def _frozen(values: object, shape: tuple[int, ...], dtype: DTypeLike = np.float64) -> NDArray[Any]:
    array = np.array(values, dtype=dtype).reshape(shape)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class WorldSnapshot:
    """The obstacles that exist at time ``t`` (s), in world coordinates (m).

    Discs: ``disc_centers`` (n, 2), ``disc_radii`` (n,), ``disc_velocities`` (n, 2) m/s.
    Boxes: ``box_mins`` (k, 2) lower-left and ``box_maxs`` (k, 2) upper-right corners,
    ``box_velocities`` (k, 2) m/s. ``disc_ids`` / ``box_ids`` are scenario obstacle indices.
    """

    t: float
    disc_centers: FloatArray
    disc_radii: FloatArray
    disc_velocities: FloatArray
    disc_ids: IntArray
    box_mins: FloatArray
    box_maxs: FloatArray
    box_velocities: FloatArray
    box_ids: IntArray

    @classmethod
    def build(
        cls,
        discs: Sequence[tuple[float, float, float]] = (),
        boxes: Sequence[tuple[float, float, float, float]] = (),
        t: float = 0.0,
    ) -> WorldSnapshot:
        """Static snapshot from ``(cx, cy, r)`` discs and ``(xmin, ymin, xmax, ymax)`` boxes, m.

        Ids are given in order, discs first. Handy for tests.
        """
        d = np.array(discs, dtype=np.float64).reshape(-1, 3)
        b = np.array(boxes, dtype=np.float64).reshape(-1, 4)
        n, k = len(d), len(b)
        return cls(
            t=t,
            disc_centers=d[:, :2],
            disc_radii=d[:, 2],
            disc_velocities=np.zeros((n, 2)),
            disc_ids=np.arange(n, dtype=np.int64),
            box_mins=b[:, :2],
            box_maxs=b[:, 2:],
            box_velocities=np.zeros((k, 2)),
            box_ids=np.arange(n, n + k, dtype=np.int64),
        )

    @property
    def count(self) -> int:
        """Number of obstacles that exist at this time."""
        return len(self.disc_ids) + len(self.box_ids)


@dataclass(frozen=True, eq=False)
class World:
    """All obstacles of a scenario with their motion and lifetime; arrays are read-only.

    Units: m for positions and sizes, m/s for velocities, s for ``appear`` / ``vanish``
    (``vanish`` is inf for obstacles that never go). ``size`` is (width, height), m.
    """

    size: tuple[float, float]
    disc_centers: FloatArray  # (n, 2) centre at time ``appear``
    disc_radii: FloatArray  # (n,)
    disc_velocities: FloatArray  # (n, 2)
    disc_appear: FloatArray  # (n,)
    disc_vanish: FloatArray  # (n,)
    disc_ids: IntArray  # (n,)
    box_centers: FloatArray  # (k, 2) centre at time ``appear``
    box_half_sizes: FloatArray  # (k, 2) half width, half height
    box_velocities: FloatArray  # (k, 2)
    box_appear: FloatArray  # (k,)
    box_vanish: FloatArray  # (k,)
    box_ids: IntArray  # (k,)

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> World:
        """Build the arrays from a validated scenario."""
        # Agents (behavior: orca) move by ORCA, not on a fixed line: sim/agents.py.
        discs = [(i, o) for i, o in enumerate(scenario.obstacles)
                 if o.shape == "disc" and not o.is_agent]
        boxes = [(i, o) for i, o in enumerate(scenario.obstacles) if o.shape == "box"]
        n, k = len(discs), len(boxes)
        return cls(
            size=scenario.world.size,
            disc_centers=_frozen([o.center for _, o in discs], (n, 2)),
            disc_radii=_frozen([o.radius for _, o in discs], (n,)),
            disc_velocities=_frozen([o.velocity for _, o in discs], (n, 2)),
            disc_appear=_frozen([o.appear for _, o in discs], (n,)),
            disc_vanish=_frozen([o.vanish_time for _, o in discs], (n,)),
            disc_ids=_frozen([i for i, _ in discs], (n,), np.int64),
            box_centers=_frozen([o.center for _, o in boxes], (k, 2)),
            box_half_sizes=_frozen(
                [(o.size[0] / 2.0, o.size[1] / 2.0) for _, o in boxes if o.size], (k, 2)
            ),
            box_velocities=_frozen([o.velocity for _, o in boxes], (k, 2)),
            box_appear=_frozen([o.appear for _, o in boxes], (k,)),
            box_vanish=_frozen([o.vanish_time for _, o in boxes], (k,)),
            box_ids=_frozen([i for i, _ in boxes], (k,), np.int64),
        )

    @property
    def obstacle_count(self) -> int:
        """Number of obstacles in the scenario (present or not)."""
        return len(self.disc_ids) + len(self.box_ids)

    def disc_centers_at(self, t: float) -> FloatArray:
        """Centres of all discs at time ``t`` (s), m, whether they exist then or not."""
        return self.disc_centers + self.disc_velocities * (t - self.disc_appear)[:, None]

    def box_centers_at(self, t: float) -> FloatArray:
        """Centres of all boxes at time ``t`` (s), m, whether they exist then or not."""
        return self.box_centers + self.box_velocities * (t - self.box_appear)[:, None]

    def snapshot(self, t: float) -> WorldSnapshot:
        """The obstacles that exist at time ``t`` (s): ``appear <= t < vanish``."""
        disc_on = (self.disc_appear <= t) & (t < self.disc_vanish)
        box_on = (self.box_appear <= t) & (t < self.box_vanish)
        box_centers = self.box_centers_at(t)[box_on]
        half = self.box_half_sizes[box_on]
        return WorldSnapshot(
            t=t,
            disc_centers=self.disc_centers_at(t)[disc_on],
            disc_radii=self.disc_radii[disc_on],
            disc_velocities=self.disc_velocities[disc_on],
            disc_ids=self.disc_ids[disc_on],
            box_mins=box_centers - half,
            box_maxs=box_centers + half,
            box_velocities=self.box_velocities[box_on],
            box_ids=self.box_ids[box_on],
        )
