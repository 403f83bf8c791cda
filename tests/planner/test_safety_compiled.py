"""The safety stage's compiled scoring (``_loops.contacts``, what ``safety.contact_costs``
calls) gives, to the bit, the costs, first contact times and movers of the numpy array
operations it replaced, for one roll-out and for a whole fan of them."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import numpy.typing as npt
import pytest

from zenav.services.planner import safety

Vec = npt.NDArray[np.float64]


def numpy_contact_costs(xs: Vec, ys: Vec, times: Vec, movers: safety.Movers,
                        robot_radius: float, s: safety.Settings, inside: Vec | None = None,
                        ends: npt.NDArray[np.int64] | None = None,
                        ) -> tuple[Vec, Vec, npt.NDArray[np.int64]]:
    """``contact_costs`` as numpy array operations (the code ``contacts`` replaced, with
    the cap of a clearance that holds the robot now, and the steps past a roll-out's
    arrival left out)."""
    n, k = xs.shape
    if len(movers) == 0:
        return np.zeros(n), np.full(n, math.inf), np.full(n, -1, dtype=np.int64)
    px = movers.positions[:, 0, None] + movers.velocities[:, 0, None] * times  # (m, k)
    py = movers.positions[:, 1, None] + movers.velocities[:, 1, None] * times
    gap = np.hypot(xs[:, None, :] - px[None], ys[:, None, :] - py[None])  # (n, m, k)
    ages = np.zeros(len(movers)) if movers.ages is None else movers.ages
    clearance = (robot_radius + movers.radii[:, None] + s.margin / 2
                 + s.growth * movers.top_speeds[:, None] * (ages[:, None] + times))
    held = np.zeros(len(movers), dtype=bool) if inside is None else np.isfinite(inside)
    if inside is not None:
        clearance = np.where(held[:, None], inside[:, None], clearance)
    gap -= clearance[None]
    weight = 1.0 / (1.0 + times / s.tau)
    driven = np.arange(k)[None, :] < (np.full(n, k) if ends is None else ends)[:, None]
    touch: npt.NDArray[np.bool_] = np.asarray(gap < 0.0) & driven[:, None, :]
    near = np.clip(1.0 - gap / s.comfort, 0.0, 1.0) if s.comfort > 0 else touch * 1.0
    depth = np.clip(-gap / clearance[None], 0.0, 1.0)
    cost_mk = np.where(touch, np.where(held[None, :, None], 1.0 + 10.0 * depth,
                                       10.0 * (1.0 + depth)),
                       near) * weight  # (n, m, k)
    cost_mk = np.where(driven[:, None, :], cost_mk, -np.inf)
    cost = cost_mk.max(axis=2).sum(axis=1)
    any_touch: npt.NDArray[np.bool_] = np.any(touch, axis=1)  # (n, k)
    first_k = np.where(np.any(any_touch, axis=1), np.argmax(any_touch, axis=1), -1)
    first_t = np.where(first_k >= 0, times[np.maximum(first_k, 0)], math.inf)
    who = np.where(first_k >= 0,
                   touch[np.arange(n), :, np.maximum(first_k, 0)].argmax(axis=1), -1)
    return cost, first_t, who.astype(np.int64)


def random_case(seed: int, candidates: int
                ) -> tuple[Vec, Vec, Vec, safety.Movers, safety.Settings,
                           npt.NDArray[np.int64]]:
    """Roll-outs of a random robot among random movers, with random settings (a
    ``comfort`` of 0 in some, movers out of view for a while in others, a goal nearby
    where some roll-outs stop in others), and the steps each drives."""
    rng = np.random.default_rng(seed)
    s = safety.Settings(horizon=float(rng.uniform(2.0, 6.0)), step=0.2,
                        margin=float(rng.uniform(0.0, 0.3)),
                        growth=float(rng.choice([0.0, 0.2])),
                        comfort=float(rng.choice([0.0, 0.6])), tau=float(rng.uniform(0.5, 3.0)),
                        fan_step=math.radians(15.0), speeds=(0.0, 0.5, 1.0), turn_cost=0.3)
    robot = safety.Robot(x=0.0, y=0.0, heading=float(rng.uniform(-math.pi, math.pi)),
                         speed=float(rng.uniform(0.0, 1.0)), radius=0.3, max_speed=1.0,
                         max_omega=1.0, heading_gain=1.5, accel=0.5, decel=1.0,
                         goal=None if rng.integers(0, 2) else (
                             float(rng.uniform(-2.0, 2.0)), float(rng.uniform(-2.0, 2.0))),
                         arrive_within=float(rng.uniform(0.15, 0.8)))
    times = s.step * np.arange(1, round(s.horizon / s.step) + 1, dtype=np.float64)
    xs, ys, ends = safety.drive_out(robot, rng.uniform(-math.pi, math.pi, candidates),
                                    rng.uniform(0.0, 1.0, candidates), times)
    m = int(rng.integers(0, 12))
    velocities = rng.uniform(-1.2, 1.2, (m, 2))
    movers = safety.Movers(rng.uniform(-4.0, 4.0, (m, 2)), velocities,
                           rng.uniform(0.15, 0.4, m),
                           np.hypot(velocities[:, 0], velocities[:, 1]) * rng.uniform(1, 1.5, m),
                           None if rng.integers(0, 2) else rng.uniform(0.0, 2.0, m))
    return xs, ys, times, movers, s, ends


@pytest.mark.parametrize("from_inside", [False, True])
@pytest.mark.parametrize("candidates", [1, 37])
@pytest.mark.parametrize("seed", range(40))
def test_contacts_is_the_numpy_arithmetic(seed: int, candidates: int, from_inside: bool
                                          ) -> None:
    xs, ys, times, movers, s, ends = random_case(seed, candidates)
    s = dataclasses.replace(s, from_inside=from_inside)
    inside = safety.holding((0.0, 0.0), movers, 0.3, s)  # the robot starts at the origin
    got = safety.contact_costs(xs, ys, times, movers, 0.3, s, inside, ends)
    want = numpy_contact_costs(xs, ys, times, movers, 0.3, s, inside, ends)
    for a, b in zip(got, want, strict=True):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()


def test_some_random_cases_start_inside_a_clearance() -> None:
    """The cases above hold the robot inside some mover's clearance in a few of them (so
    the cap is exercised), and never when ``from_inside`` is off."""
    held = off = 0
    for seed in range(40):
        _, _, _, movers, s, _ = random_case(seed, 1)
        held += int(np.isfinite(safety.holding(
            (0.0, 0.0), movers, 0.3, dataclasses.replace(s, from_inside=True))).any())
        off += int(np.isfinite(safety.holding(
            (0.0, 0.0), movers, 0.3, dataclasses.replace(s, from_inside=False))).any())
    assert held >= 3 and off == 0


def test_the_random_cases_have_contacts_passes_and_clear_roll_outs() -> None:
    """The cases above cover contacts (costs of 10 and more), near passes (between 0 and
    10) and roll-outs clear of every mover (0), in both settings of ``comfort``."""
    seen: set[tuple[str, bool]] = set()
    for seed in range(40):
        xs, ys, times, movers, s, _ = random_case(seed, 37)
        for c in numpy_contact_costs(xs, ys, times, movers, 0.3, s)[0]:
            kind = "contact" if c >= 10.0 else "near" if c > 0.0 else "clear"
            seen.add((kind, s.comfort > 0))
    assert {("contact", True), ("near", True), ("clear", True), ("contact", False),
            ("clear", False)} <= seen


def test_some_random_roll_outs_stop_at_the_goal() -> None:
    """Some roll-outs of the cases above reach their goal and stop there (the compiled
    loop leaves their later steps out), some drive every step."""
    short = whole = 0
    for seed in range(40):
        xs, _, _, _, _, ends = random_case(seed, 37)
        short += int((ends < xs.shape[1]).sum())
        whole += int((ends == xs.shape[1]).sum())
    assert short >= 20 and whole >= 20


def numpy_arrival(robot: safety.Robot, xs: Vec, ys: Vec
                  ) -> tuple[Vec, Vec, npt.NDArray[np.int64]]:
    """Where roll-outs driven with no goal stop once they reach ``robot.goal``, as numpy
    array operations (the code the compiled ``drive`` replaced): the steps driven, and
    each later step at the point of arrival."""
    k = xs.shape[1]
    assert robot.goal is not None
    there = np.hypot(xs - robot.goal[0], ys - robot.goal[1]) <= robot.arrive_within
    ends = np.where(there.any(axis=1), np.argmax(there, axis=1) + 1, k).astype(np.int64)
    last = np.minimum(np.arange(k)[None, :], ends[:, None] - 1)
    return (np.take_along_axis(xs, last, axis=1), np.take_along_axis(ys, last, axis=1),
            ends)


@pytest.mark.parametrize("seed", range(30))
def test_drive_out_stops_where_the_numpy_code_did(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    goal = (float(rng.uniform(-2.0, 2.0)), float(rng.uniform(-2.0, 2.0)))
    robot = safety.Robot(x=0.0, y=0.0, heading=float(rng.uniform(-math.pi, math.pi)),
                         speed=float(rng.uniform(0.0, 1.0)), radius=0.3, max_speed=1.0,
                         max_omega=1.0, heading_gain=1.5, accel=0.5, decel=1.0, goal=goal,
                         arrive_within=float(rng.uniform(0.15, 0.8)))
    times = 0.2 * np.arange(1, 26, dtype=np.float64)
    headings, speeds = rng.uniform(-math.pi, math.pi, 37), rng.uniform(0.0, 1.0, 37)
    free = safety.drive_out(dataclasses.replace(robot, goal=None), headings, speeds, times)
    assert (free[2] == len(times)).all()
    got = safety.drive_out(robot, headings, speeds, times)
    for a, b in zip(got, numpy_arrival(robot, free[0], free[1]), strict=True):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("seed", range(40))
def test_holding_is_the_numpy_arithmetic(seed: int) -> None:
    _, _, _, movers, s, _ = random_case(seed, 1)
    s = dataclasses.replace(s, from_inside=True)
    start = (0.05 * seed - 1.0, 0.5)
    ages = np.zeros(len(movers)) if movers.ages is None else movers.ages
    now = np.hypot(movers.positions[:, 0] - start[0], movers.positions[:, 1] - start[1])
    clearance = 0.3 + movers.radii + s.margin / 2 + s.growth * movers.top_speeds * ages
    want = np.where(now < clearance, now, math.inf)
    got = safety.holding(start, movers, 0.3, s)
    assert got.dtype == want.dtype and got.tobytes() == want.tobytes()
