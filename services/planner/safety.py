"""The speed and safety stage: check the local layer's command against every mover and
pick the nearest safe one when it is not safe (pure, no I/O).

Beyond the paper. The paper's responses answer one predicted meeting at a time along a
straight line; in a crowd a stop that lets one walker pass leaves the robot in another's
way, and a walker that does not see the robot keeps coming. This stage looks at the
command as the robot would actually drive it:

1. **Roll out** each candidate: a heading (the local layer's, or one of a fan round
   it) and a speed (0 up to the top speed). The robot is the unicycle that
   ``follow.command_toward`` drives: it turns at up to ``max_omega`` toward the heading,
   its speed falls with the cosine of the heading error, and it speeds up and slows
   down within the motor bridge's ``accel`` and ``decel``. Every ``step`` s up to
   ``horizon`` s.
2. **Predict** each mover (a track typed dynamic) at constant velocity, its clearance
   growing by ``growth`` times the distance it could cover at the top speed it has
   been seen at, since tracked velocities are estimates and walkers turn and speed up
   (0.2: a heading off by about 11 degrees). The top speed fades while the mover
   stands (``faded_top_speeds``): one standing for good stops growing.
3. **Score** each roll-out: the cost of contact with a mover, discounted by how far ahead
   it is (``1 / (1 + t / tau)``), plus the way still to go from where it ends to a point
   on the global path the top speed could reach in the horizon, plus a small cost of
   changing heading from the last choice (no dithering between equal options; none for
   a roll-out that arrives at the goal, which ends the run). Contact
   means coming within the robot radius + the mover's radius + half the safety margin
   + the growth; a pass within a further ``comfort`` m costs in proportion. Points the
   map holds (standing obstacles, inflated) are contact at once. A contact costs more
   the deeper it goes, up to twice as much where the robot would meet the mover's
   predicted centre: when every candidate touches some mover's growing clearance (a
   crosser seen late, a crowd), the one that stays out of the mover's predicted way wins
   over one that makes more progress by cutting across it.
4. A mover that has left the laser's view (``Movers.ages``: seconds since it was last
   seen) is predicted from where it was last seen, its clearance grown for the time
   since as well.
5. A roll-out that comes within ``Robot.arrive_within`` of the goal stands there, and
   its later steps are not checked: the planner stops for good at that distance, so
   what lies past the goal (a walker standing at its own goal beyond it) does not hold
   the robot short of it.

The local layer's own command stands when its roll-out keeps clear of every mover
within ``horizon``: the paper's responses are kept whenever they are safe. Otherwise the
cheapest candidate is driven for this cycle, and the next cycle checks again.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from zenav.services.geometry import wrap_angle, wrap_angles
from zenav.services.planner._loops import contacts, drive
from zenav.services.planner._loops import holding as holding_loop

Vec = npt.NDArray[np.float64]
Blocked = Callable[[Vec, Vec], npt.NDArray[np.bool_]]
"""The map's check: for each row of points (``xs[i]``, ``ys[i]``), whether any lies where
the map holds something (``Costmap.blocked_rows``)."""


@dataclass(frozen=True)
class Movers:
    """The movers in view: centres (m, 2), velocities (m, 2), radii (m,) and the top speed
    each has been seen at (m,): a walker slowed by others can speed up again."""

    positions: Vec
    velocities: Vec
    radii: Vec
    top_speeds: Vec
    ages: Vec | None = None  # s since each was last seen (None: all in view now)

    def __len__(self) -> int:
        return int(self.radii.shape[0])


@dataclass(frozen=True)
class Robot:
    """What the roll-outs need to know about the robot."""

    x: float
    y: float
    heading: float
    speed: float  # its speed now, m/s
    radius: float
    max_speed: float
    max_omega: float
    heading_gain: float
    accel: float
    decel: float
    goal: tuple[float, float] | None = None  # a roll-out that comes within
    arrive_within: float = 0.0  # this many m of the goal stops there (the planner does)


@dataclass(frozen=True)
class Settings:
    horizon: float  # s
    step: float  # s between roll-out points
    margin: float  # m kept on top of both radii
    growth: float  # m of extra clearance per m the mover covers
    comfort: float  # m beyond the clearance over which a pass still costs
    tau: float  # s: a contact t s ahead costs 1 / (1 + t / tau) of one now
    fan_step: float  # rad between candidate headings
    speeds: tuple[float, ...]  # fractions of the top speed tried
    turn_cost: float  # cost per rad of change from the last heading chosen
    from_inside: bool = False  # inside a mover's clearance now: only coming closer counts


@dataclass(frozen=True)
class Choice:
    heading: float  # world frame, rad
    speed: float  # m/s
    kept: bool  # the local layer's own command was safe and is kept
    contact: float  # s to the first contact of the chosen roll-out (inf: none)
    mover: int | None  # index in Movers of the mover that made the change, if any


STANDING_FRACTION = 0.25
"""A mover going at under this fraction of its top speed counts as standing: its top
speed fades (``faded_top_speeds``). A walker slowed to half its pace by others is not."""


def faded_top_speeds(top: dict[int, float], now: dict[int, float], dt: float,
                     fade: float) -> dict[int, float]:
    """The top speed of each mover in ``now`` (track id -> speed now, m/s): the larger of
    its speed now and its top speed before (``top``; 0 when new), which fades by
    ``exp(-dt / fade)`` over the ``dt`` s since while the mover stands (under
    ``STANDING_FRACTION`` of it; ``fade`` 0: never). A walker held up by others keeps
    its top speed, for it sets off again at the pace it had; one that has stood for a
    few ``fade`` s (at its goal, in a queue) is judged on what it does now. Movers not
    in ``now`` are not in the answer."""
    keep = math.exp(-max(dt, 0.0) / fade) if fade > 0 else 1.0
    faded = {}
    for i, speed in now.items():
        before = top.get(i, 0.0)
        standing = speed < STANDING_FRACTION * before
        faded[i] = max(before * keep if standing else before, speed)
    return faded


def rollout(robot: Robot, headings: Vec, speeds: Vec, times: Vec) -> tuple[Vec, Vec]:
    """Positions (n, k) of the robot driving toward each heading at each speed, at
    ``times`` (k,), evenly spaced from one step on. A roll-out that comes within
    ``robot.arrive_within`` of ``robot.goal`` stays at the first point it does: the
    planner stops there, so what lies past the goal is never driven into."""
    xs, ys, _ = drive_out(robot, headings, speeds, times)
    return xs, ys


def drive_out(robot: Robot, headings: Vec, speeds: Vec, times: Vec
              ) -> tuple[Vec, Vec, npt.NDArray[np.int64]]:
    """``rollout``'s positions, and per roll-out how many of its steps are driven: all of
    them, or those up to the first within ``robot.arrive_within`` of ``robot.goal``,
    where the planner stops for good; what comes after is not checked. One compiled
    loop (``_loops.drive``)."""
    n, k = headings.shape[0], times.shape[0]
    xs = np.empty((n, k))
    ys = np.empty((n, k))
    ends = np.empty(n, dtype=np.int64)
    gx, gy = robot.goal if robot.goal is not None else (0.0, 0.0)
    drive(np.ascontiguousarray(headings, dtype=np.float64),
          np.ascontiguousarray(speeds, dtype=np.float64), float(times[0]), robot.x, robot.y,
          robot.heading, robot.speed, robot.heading_gain, robot.max_omega, robot.accel,
          robot.decel, robot.goal is not None, gx, gy, robot.arrive_within, xs, ys, ends)
    return xs, ys, ends


def holding(start: tuple[float, float], movers: Movers, robot_radius: float,
            s: Settings) -> Vec:
    """Per mover: the robot's distance now (at ``start``) to it, when its clearance (of
    its age, at no time ahead) holds the robot now and ``s.from_inside`` is on; inf
    otherwise (compiled: ``_loops.holding``). See ``contact_costs``."""
    inside = np.full(len(movers), math.inf)
    if s.from_inside and len(movers):
        ages = np.zeros(len(movers)) if movers.ages is None else movers.ages
        holding_loop(start[0], start[1], np.ascontiguousarray(movers.positions),
                     np.ascontiguousarray(movers.radii),
                     np.ascontiguousarray(movers.top_speeds), np.ascontiguousarray(ages),
                     robot_radius, s.margin, s.growth, inside)
    return inside


def contact_costs(xs: Vec, ys: Vec, times: Vec, movers: Movers, robot_radius: float,
                  s: Settings, inside: Vec | None = None,
                  ends: npt.NDArray[np.int64] | None = None,
                  ) -> tuple[Vec, Vec, npt.NDArray[np.int64]]:
    """Per roll-out: the cost of its passes by the movers, the time of its first contact
    (inf: none) and the mover of that contact (-1: none). ``inside``: ``holding``'s
    answer for the roll-outs' common start (None: no mover holds the robot). ``ends``:
    ``drive_out``'s count of steps driven (None: every step); later steps are not checked.

    Mover j is predicted at ``positions[j] + velocities[j] t``; the robot at step t is in
    contact with it when their centres are less than the clearance apart: robot radius
    + mover radius + half the margin + growth x its top speed x (its age + t). A contact
    costs 10 (1 + depth), its depth the gap below the clearance over the clearance (0 at
    its edge, 1 on the predicted centre, at most 1); a pass within ``comfort`` beyond it
    costs 1 - gap / comfort. Each cost is weighted 1 / (1 + t / tau); a roll-out pays
    the largest weighted cost of each mover over the horizon, summed over the movers.

    A mover whose clearance already holds the robot (``inside``, with
    ``Settings.from_inside``) has that clearance capped at their distance now, and a
    contact with it costs 1 + 10 x its depth: only coming closer counts, by how much.
    Without the cap every candidate touches it from its first step, the first step's
    cost is about the same for all of them, and a robot standing while the mover walks
    in can score as well as one that leaves. The 1 keeps the cost rising as the gap
    shrinks: a contact costs no less than a pass just outside the capped clearance
    (``comfort``'s cost is at most 1). With 10 x the depth alone, a robot standing as a
    walker came 4 cm closer paid less than one stepping away along the clearance's edge,
    and stood (``bench nav``, unseen-walkers-doorway-152015).
    The loop over roll-outs, movers and steps is compiled (``_loops.contacts``)."""
    n, m = xs.shape[0], len(movers)
    if m == 0:
        return np.zeros(n), np.full(n, math.inf), np.full(n, -1, dtype=np.int64)
    worst = np.empty((n, m))  # the largest weighted cost of each mover, per roll-out
    first_t = np.empty(n)
    who = np.empty(n, dtype=np.int64)
    contacts(np.ascontiguousarray(xs, dtype=np.float64),
             np.ascontiguousarray(ys, dtype=np.float64),
             np.ascontiguousarray(times, dtype=np.float64),
             np.ascontiguousarray(movers.positions, dtype=np.float64),
             np.ascontiguousarray(movers.velocities, dtype=np.float64),
             np.ascontiguousarray(movers.radii, dtype=np.float64),
             np.ascontiguousarray(movers.top_speeds, dtype=np.float64),
             np.zeros(m) if movers.ages is None
             else np.ascontiguousarray(movers.ages, dtype=np.float64),
             robot_radius, s.margin, s.growth, s.comfort, s.tau,
             np.full(m, math.inf) if inside is None
             else np.ascontiguousarray(inside, dtype=np.float64),
             np.full(n, times.shape[0], dtype=np.int64) if ends is None
             else np.ascontiguousarray(ends, dtype=np.int64), worst, first_t, who)
    return worst.sum(axis=1), first_t, who


def choose(robot: Robot, proposal: tuple[float, float], movers: Movers, carrot: Vec,
           blocked: Blocked | None, last_heading: float | None, s: Settings) -> Choice:
    """Check the local layer's ``proposal`` (heading rad, speed m/s) and keep it if its
    roll-out touches no mover within the horizon; else the cheapest candidate. ``carrot``:
    the point on the global path progress is measured to; ``blocked``: which roll-outs
    pass a point the map holds (None: no map)."""
    heading, speed = proposal
    times = _times(s)
    # The proposal alone first: most cycles keep it, and the fan's roll-outs (the same
    # numbers for the proposal, row by row) are needed only when it is not safe.
    inside = holding((robot.x, robot.y), movers, robot.radius, s)
    if keeps_clear(robot, proposal, movers, blocked, s, inside):
        return Choice(heading, speed, True, math.inf, None)
    fan = np.arange(-math.pi, math.pi, s.fan_step)
    headings = np.concatenate(([heading], np.repeat(heading + fan, len(s.speeds))))
    speeds = np.concatenate(([speed], np.tile(np.asarray(s.speeds) * robot.max_speed,
                                              fan.shape[0])))
    xs, ys, cost, first_t, who = _score(robot, headings, speeds, times, movers, blocked, s,
                                        inside)
    reach = np.hypot(xs[:, -1] - carrot[0], ys[:, -1] - carrot[1])
    total = cost + reach / max(robot.max_speed * s.horizon, 1e-9)
    if last_heading is not None and not np.isfinite(inside).any():
        # (not while a mover holds the robot: leaving it may need a half turn)
        turn = s.turn_cost * np.abs(wrap_angles(headings - last_heading))
        if robot.goal is not None:
            # A roll-out that arrives ends the run, so there is no dithering to guard
            # against; near the goal the way left is worth too little to outweigh a
            # turn, and a robot beside its goal would stand there for good.
            arrives = np.hypot(xs[:, -1] - robot.goal[0],
                               ys[:, -1] - robot.goal[1]) <= robot.arrive_within + 1e-9
            turn = np.where(arrives, 0.0, turn)
        total = total + turn
    best = int(np.argmin(total))
    culprit = int(who[0]) if who[0] >= 0 else None
    return Choice(wrap_angle(float(headings[best])), float(speeds[best]),
                  best == 0, float(first_t[best]), culprit)


def keeps_clear(robot: Robot, proposal: tuple[float, float], movers: Movers,
                blocked: Blocked | None, s: Settings, inside: Vec | None = None) -> bool:
    """Whether the roll-out of ``proposal`` (heading rad, speed m/s) touches no mover and
    nothing the map holds within the horizon. ``inside``: ``holding``'s answer for the
    robot, when the caller has it."""
    _, _, cost, first_t, _ = _score(robot, np.array([proposal[0]]), np.array([proposal[1]]),
                                    _times(s), movers, blocked, s, inside)
    return bool(math.isinf(first_t[0]) and cost[0] < 10.0)


def _times(s: Settings) -> Vec:
    """The roll-out times: every ``step`` s from one step to the horizon."""
    return _steps(s.horizon, s.step)


@functools.lru_cache(maxsize=8)
def _steps(horizon: float, step: float) -> Vec:
    """``_times`` for one horizon and step, made once (read-only: it is shared)."""
    steps = max(round(horizon / step), 1)
    times = step * np.arange(1, steps + 1, dtype=np.float64)
    times.flags.writeable = False
    return times


def _score(robot: Robot, headings: Vec, speeds: Vec, times: Vec, movers: Movers,
           blocked: Blocked | None, s: Settings, inside: Vec | None = None
           ) -> tuple[Vec, Vec, Vec, Vec, npt.NDArray[np.int64]]:
    """Roll out each candidate and score its passes by the movers and the map: the
    positions (n, k), the cost, the time of the first contact and its mover. ``inside``:
    ``holding``'s answer for the robot (found here when not given)."""
    xs, ys, ends = drive_out(robot, headings, speeds, times)
    if inside is None:
        inside = holding((robot.x, robot.y), movers, robot.radius, s)
    cost, first_t, who = contact_costs(xs, ys, times, movers, robot.radius, s, inside, ends)
    # Inside the inflation already, the map cannot judge.
    if blocked is not None and not blocked(np.array([[robot.x]]), np.array([[robot.y]]))[0]:
        cost = cost + np.where(blocked(xs, ys), 10.0, 0.0)
    return xs, ys, cost, first_t, who
