"""Never stuck: a progress checker and the recovery steps tried in turn (pure, no I/O).

In the manner of Nav2's behaviour tree. Progress is the distance still to go along the
global path: it must fall by ``progress_distance`` within ``progress_timeout`` s. Time
spent legitimately waiting (stopped or slowed for a mover, as in the paper's (e) and (g))
does not count, up to ``wait_allowance`` s in a row. The stop zone refusing motion for
``stop_zone_timeout`` s counts as no progress at once. Either starts recovery, whose
steps are tried one per failure, in this order:

1. ``replan``: forget what the map has not seen lately beyond the window round the
   robot, and plan the global path again;
2. ``spin``: turn in place a full turn, so the 180-degree laser sees all round;
3. ``back_up``: reverse a short distance (only where the robot has just been);
4. ``wait``: stand still a while, for movers to pass;

then navigation is tried again. Progress resets the sequence. When the goal has no way
on the map once every step has been tried (or after ``max_rounds`` rounds, if the map
shows none), the goal is ``unreachable``: the robot stops for good. While a way is
known, the rounds go on.

The map forgets what it has not seen for its decay time, so round a closed ring of
walls it always shows a way through the side seen first. The planner therefore also
asks the costmap's wall memory (``Costmap.cut_off``: confirmed walls, no decay, until a
beam passes through them) whether the walls seen close the goal off. While they do, no
way is known whatever the map shows, the steps start one after another without waiting
for a stall (a gain along a path through forgotten walls is no progress), and after
``max_rounds`` rounds the goal is unreachable. From the moment the memory closes the goal
off that takes at most ``replan_period`` (how often the memory is looked at) plus
``max_rounds`` times a round: one cycle (``replan``) + ``spin_angle / (0.5 max_omega) +
5`` s (the spin's limit) + ``2 backup_distance / backup_speed + 2`` s (the back-up's
limit) + ``wait_time``; about 75 s with the defaults, 29 s in ``nav-goal-walled-in``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

Step = Literal["replan", "spin", "back_up", "wait"]
STEPS: tuple[Step, ...] = ("replan", "spin", "back_up", "wait")


@dataclass(frozen=True)
class RecoverySettings:
    progress_distance: float  # m of distance to go that must be gained ...
    progress_timeout: float  # ... within this many s
    stop_zone_timeout: float  # s of motion refused by the stop zone before recovery
    wait_allowance: float  # s of legitimate waiting (for a mover) not counted
    spin_angle: float  # rad turned in place by ``spin``
    backup_distance: float  # m reversed by ``back_up``
    backup_speed: float  # m/s while reversing
    wait_time: float  # s stood still by ``wait``
    max_rounds: int  # full rounds of steps before the goal is unreachable


@dataclass
class Active:
    step: Step
    started: float  # stamp
    pose: tuple[float, float, float]  # where the step began
    turned: float = 0.0  # rad turned so far (spin)
    last_heading: float = 0.0


class Recovery:
    """Watches progress; says which recovery step, if any, drives the robot now."""

    def __init__(self, settings: RecoverySettings) -> None:
        self.s = settings
        self.check_stamp: float | None = None  # start of the current progress window
        self.check_to_go = float("inf")  # distance to go at its start
        self.waited = 0.0  # s of legitimate waiting in a row
        self.refused_since: float | None = None  # stamp the stop zone began refusing
        self.last_stamp: float | None = None
        self.level = 0  # next step to try: STEPS[level]
        self.rounds = 0
        self.active: Active | None = None
        self.unreachable = False

    def reset(self, stamp: float, to_go: float) -> None:
        self.check_stamp, self.check_to_go = stamp, to_go
        self.waited = 0.0

    def watch(self, stamp: float, to_go: float, waiting: bool, refused: bool) -> bool:
        """Feed one cycle: distance still to go (m), whether the robot legitimately waits
        for a mover, whether the stop zone refused forward motion. True when progress
        has stalled and the next recovery step should start."""
        dt = 0.0 if self.last_stamp is None else max(stamp - self.last_stamp, 0.0)
        self.last_stamp = stamp
        if self.check_stamp is None:
            self.reset(stamp, to_go)
            return False
        self.refused_since = (self.refused_since if self.refused_since is not None else stamp) \
            if refused else None
        if to_go <= self.check_to_go - self.s.progress_distance:
            self.reset(stamp, to_go)
            self.level, self.rounds = 0, 0  # progress: the sequence starts afresh
            return False
        if waiting and self.waited + dt <= self.s.wait_allowance:
            self.waited += dt
            self.check_stamp += dt  # waiting for a mover is not a lack of progress
        elif not waiting:
            self.waited = 0.0
        zone = (self.refused_since is not None
                and stamp - self.refused_since >= self.s.stop_zone_timeout)
        return zone or stamp - self.check_stamp >= self.s.progress_timeout

    def start_next(self, stamp: float, pose: tuple[float, float, float],
                   way_known: bool = False) -> Step | None:
        """Begin the next step; None (and ``unreachable``) once every round is spent with
        no way to the goal known. While the map still shows a way (``way_known``) the
        rounds start again: a goal is declared unreachable only for want of a way."""
        if self.level >= len(STEPS):
            self.level = 0
            self.rounds += 1
        if self.rounds >= self.s.max_rounds:
            if way_known:
                self.rounds = 0
            else:
                self.unreachable = True
                self.active = None
                return None
        step = STEPS[self.level]
        self.level += 1
        self.active = Active(step, stamp, pose, last_heading=pose[2])
        self.refused_since = None
        return step

    def give_up(self) -> None:
        """The goal is unreachable, whatever the rounds: the caller knows it (no room at
        the goal once a round of the steps has looked again)."""
        self.unreachable = True
        self.active = None

    def finish(self, stamp: float, to_go: float) -> None:
        """The active step is over: navigation is tried again with a fresh window."""
        self.active = None
        self.reset(stamp, to_go)
