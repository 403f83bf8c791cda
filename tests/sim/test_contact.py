"""Clearance and swept contact between the robot disc and moving obstacles."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from zenav.sim.contact import clearance, clearances, first_contact
from zenav.sim.scenario import ObstacleSpec, RobotSpec, Scenario, WorldSpec
from zenav.sim.world import World, WorldSnapshot


def world_of(*obstacles: ObstacleSpec) -> World:
    """A World holding ``obstacles`` (robot placement is irrelevant here, so unchecked)."""
    scenario = Scenario.model_construct(
        name="contact",
        world=WorldSpec(size=(100.0, 100.0), cell=0.5),
        robot=RobotSpec(start=(0.0, 0.0), goal=(1.0, 1.0), speed=0.1, radius=0.2),
        obstacles=list(obstacles),
    )
    return World.from_scenario(scenario)


def disc(center: tuple[float, float], radius: float, **kw: object) -> ObstacleSpec:
    return ObstacleSpec.model_validate({"shape": "disc", "center": center, "radius": radius, **kw})


def box(center: tuple[float, float], size: tuple[float, float], **kw: object) -> ObstacleSpec:
    return ObstacleSpec.model_validate({"shape": "box", "center": center, "size": size, **kw})


# --- clearance -------------------------------------------------------------------------


def test_clearance_to_a_disc_and_to_a_box_by_hand() -> None:
    snapshot = WorldSnapshot.build(discs=[(3.0, 0.0, 1.0)], boxes=[(2.0, 2.0, 3.0, 3.0)])
    gaps, ids = clearances((0.0, 0.0), 0.5, snapshot)
    assert gaps == pytest.approx([1.5, math.sqrt(8.0) - 0.5])  # disc; box corner (2, 2)
    assert list(ids) == [0, 1]
    assert clearance((0.0, 0.0), 0.5, snapshot) == pytest.approx(1.5)
    # Straight below the box's bottom face y = 2.
    assert clearance((2.5, 0.0), 0.5, WorldSnapshot.build(boxes=[(2, 2, 3, 3)])) == 1.5


def test_clearance_is_negative_when_overlapping() -> None:
    assert clearance((2.5, 0.0), 0.5, WorldSnapshot.build(discs=[(3.0, 0.0, 1.0)])) == -1.0
    # Centre of a 2 x 2 box: 1 m inside its faces, plus the radius.
    assert clearance((1.0, 1.0), 0.5, WorldSnapshot.build(boxes=[(0, 0, 2, 2)])) == -1.5


def test_clearance_without_obstacles_is_infinite() -> None:
    assert clearance((1.0, 1.0), 0.5, WorldSnapshot.build()) == math.inf


# --- world snapshots ---------------------------------------------------------------------


def test_snapshot_moves_obstacles_from_their_appear_time_and_drops_gone_ones() -> None:
    world = world_of(
        box((5.0, 5.0), (1.0, 2.0)),
        disc((0.0, 0.0), 0.5, velocity=(1.0, 2.0), appear=2.0, vanish=6.0),
    )
    early, mid, late = world.snapshot(1.0), world.snapshot(4.0), world.snapshot(6.0)
    assert list(early.disc_ids) == [] and list(late.disc_ids) == []
    assert list(mid.disc_ids) == [1]
    assert mid.disc_centers[0] == pytest.approx([2.0, 4.0])  # 2 s after appearing
    assert list(mid.box_ids) == [0]
    assert mid.box_mins[0] == pytest.approx([4.5, 4.0])
    assert mid.box_maxs[0] == pytest.approx([5.5, 6.0])
    assert world.obstacle_count == 2 and late.count == 1


# --- first contact -----------------------------------------------------------------------

FAST = 100.0  # m/s: crosses the whole 10 m corridor within one 0.1 s tick


def test_fast_disc_crossing_the_robot_between_ticks_is_caught() -> None:
    world = world_of(disc((0.0, 5.0), 0.2, velocity=(FAST, 0.0)))
    robot = (5.0, 5.0)
    # Sampling at the ticks sees nothing: it is at x = 0 before and x = 10 after.
    assert clearance(robot, 0.2, world.snapshot(0.0)) > 4.0
    assert clearance(robot, 0.2, world.snapshot(0.1)) > 4.0
    contact = first_contact(robot, robot, 0.2, world, 0.0, 0.1)
    assert contact is not None
    t, index = contact
    assert index == 0
    assert t == pytest.approx(4.6 / FAST)  # centres 0.4 m apart at x = 4.6


@pytest.mark.parametrize(("offset", "hits"), [(0.401, False), (0.399, True), (-0.401, False)])
def test_near_miss_is_not_contact(offset: float, hits: bool) -> None:
    world = world_of(disc((0.0, 5.0 + offset), 0.2, velocity=(FAST, 0.0)))
    assert (first_contact((5.0, 5.0), (5.0, 5.0), 0.2, world, 0.0, 0.1) is not None) is hits


def test_robot_tunnelling_through_a_thin_wall_is_caught() -> None:
    world = world_of(box((5.0, 5.0), (0.1, 4.0)))
    contact = first_contact((0.0, 5.0), (10.0, 5.0), 0.2, world, 0.0, 0.1)
    assert contact is not None
    assert contact[0] == pytest.approx(0.1 * 4.75 / 10.0)  # front of the disc at x = 4.95
    assert contact[1] == 0


def test_box_corner_contact_time_by_hand() -> None:
    world = world_of(box((0.5, 0.5), (1.0, 1.0)))  # [0, 1] x [0, 1]
    # Straight at the corner (1, 1) from (2, 2): contact when 0.5 m from it.
    contact = first_contact((2.0, 2.0), (1.0, 1.0), 0.5, world, 0.0, 1.0)
    assert contact is not None
    assert contact[0] == pytest.approx(1.0 - 0.5 / math.sqrt(2.0))
    # Horizontally at y = 1.45: first touches the rounded corner, x = 1 + sqrt(0.5^2 - 0.45^2).
    contact = first_contact((3.0, 1.45), (-1.0, 1.45), 0.5, world, 0.0, 1.0)
    assert contact is not None
    assert contact[0] == pytest.approx((3.0 - (1.0 + math.sqrt(0.25 - 0.45**2))) / 4.0)


def test_passing_the_box_corner_inside_its_bounding_square_is_not_contact() -> None:
    world = world_of(box((0.5, 0.5), (1.0, 1.0)))
    # Line x + y = 2 + 0.55 * sqrt(2): 0.55 m from the corner at its closest, radius 0.5.
    c = 2.0 + 0.55 * math.sqrt(2.0)
    assert first_contact((c - 3.0, 3.0), (3.0, c - 3.0), 0.5, world, 0.0, 1.0) is None
    closest = (c / 2.0, c / 2.0)
    assert 1.0 < closest[0] < 1.5  # inside the inflated bounding square [-0.5, 1.5]^2


def test_obstacle_appearing_on_the_robot_inside_the_interval() -> None:
    world = world_of(disc((5.0, 5.0), 0.3, appear=0.05))
    assert first_contact((5.0, 5.0), (5.0, 5.0), 0.2, world, 0.0, 0.1) == (0.05, 0)
    late = world_of(disc((5.0, 5.0), 0.3, appear=0.15))
    assert first_contact((5.0, 5.0), (5.0, 5.0), 0.2, late, 0.0, 0.1) is None


def test_moving_obstacle_appearing_mid_interval_starts_from_its_center() -> None:
    # Appears at t = 0.05 at x = 0, then travels at 100 m/s: reaches x = 4.6 at t = 0.096.
    world = world_of(disc((0.0, 5.0), 0.2, velocity=(FAST, 0.0), appear=0.05))
    contact = first_contact((5.0, 5.0), (5.0, 5.0), 0.2, world, 0.0, 0.1)
    assert contact is not None
    assert contact[0] == pytest.approx(0.05 + 4.6 / FAST)


@pytest.mark.parametrize(("vanish", "hits"), [(0.040, False), (0.050, True)])
def test_obstacle_vanishing_inside_the_interval(vanish: float, hits: bool) -> None:
    world = world_of(disc((0.0, 5.0), 0.2, velocity=(FAST, 0.0), vanish=vanish))
    contact = first_contact((5.0, 5.0), (5.0, 5.0), 0.2, world, 0.0, 0.1)
    assert (contact is not None) is hits
    if contact is not None:
        assert contact[0] == pytest.approx(0.046)


def test_earliest_contact_is_reported_with_its_scenario_index() -> None:
    world = world_of(
        disc((50.0, 50.0), 1.0),
        box((7.0, 5.0), (1.0, 1.0)),  # front face x = 6.5: contact at robot x = 6.3
        disc((9.0, 5.0), 0.5),
        box((6.0, 8.0), (1.0, 1.0)),  # off the path
    )
    contact = first_contact((5.0, 5.0), (10.0, 5.0), 0.2, world, 10.0, 11.0)
    assert contact is not None
    assert contact[0] == pytest.approx(10.0 + 1.3 / 5.0)
    assert contact[1] == 1


def test_already_touching_at_the_start_is_contact_at_the_start() -> None:
    world = world_of(disc((1.0, 0.0), 0.5))
    assert first_contact((0.3, 0.0), (0.0, 0.0), 0.2, world, 2.0, 2.1) == (2.0, 0)
    # Zero-length interval: an overlap check.
    assert first_contact((0.3, 0.0), (0.3, 0.0), 0.2, world, 2.0, 2.0) == (2.0, 0)
    assert first_contact((0.0, 0.0), (0.0, 0.0), 0.2, world, 2.0, 2.0) is None


def test_reversed_interval_is_rejected() -> None:
    with pytest.raises(ValueError, match="t1 must be >= t0"):
        first_contact((0.0, 0.0), (1.0, 0.0), 0.2, world_of(), 1.0, 0.5)


# --- invariants --------------------------------------------------------------------------

coord = st.floats(0.0, 10.0, allow_nan=False)
speed = st.floats(-20.0, 20.0, allow_nan=False)
extent = st.floats(0.1, 2.0, allow_nan=False)


@st.composite
def obstacles(draw: st.DrawFn) -> ObstacleSpec:
    velocity = (draw(speed), draw(speed))
    appear = draw(st.floats(-1.0, 1.0))
    vanish = draw(st.one_of(st.none(), st.floats(appear + 0.01, 2.0)))
    if draw(st.booleans()):
        return disc(
            (draw(coord), draw(coord)),
            draw(extent),
            velocity=velocity,
            appear=appear,
            vanish=vanish,
        )
    return box(
        (draw(coord), draw(coord)),
        (draw(extent), draw(extent)),
        velocity=velocity,
        appear=appear,
        vanish=vanish,
    )


@settings(max_examples=200, deadline=None)
@given(
    p0=st.tuples(coord, coord),
    p1=st.tuples(coord, coord),
    specs=st.lists(obstacles(), min_size=1, max_size=4),
)
def test_contact_agrees_with_sampled_clearance(
    p0: tuple[float, float], p1: tuple[float, float], specs: list[ObstacleSpec]
) -> None:
    world = world_of(*specs)
    radius, t0, t1 = 0.3, 0.0, 1.0
    contact = first_contact(p0, p1, radius, world, t0, t1)
    end = t1 if contact is None else contact[0]

    def gap_at(t: float) -> float:
        centre = np.array(p0) + (np.array(p1) - np.array(p0)) * (t - t0) / (t1 - t0)
        return clearance(centre, radius, world.snapshot(t))

    # Before the contact (or over the whole interval) the sampled gap stays positive ...
    for t in np.linspace(t0, end, 200, endpoint=False):
        if t < end - 1e-9:
            assert gap_at(t) > -1e-9
    # ... and at the contact the robot touches the reported obstacle.
    if contact is not None:
        t, index = contact
        snapshot = world.snapshot(t)
        centre = np.array(p0) + (np.array(p1) - np.array(p0)) * t
        gaps, ids = clearances(centre, radius, snapshot)
        assert index in ids
        assert gaps[list(ids).index(index)] <= 1e-6


@given(
    start=st.tuples(coord, coord),
    velocity=st.tuples(speed, speed),
    shape=st.sampled_from(["disc", "box"]),
)
def test_contact_depends_only_on_relative_motion(
    start: tuple[float, float], velocity: tuple[float, float], shape: str
) -> None:
    # Robot moving at u past a static obstacle == static robot, obstacle moving at -u.
    center, dt = (5.0, 5.0), 0.5
    end = (start[0] + velocity[0] * dt, start[1] + velocity[1] * dt)
    back = (-velocity[0], -velocity[1])
    if shape == "disc":
        still, moving = disc(center, 0.7), disc(center, 0.7, velocity=back)
    else:
        still, moving = box(center, (1.0, 0.6)), box(center, (1.0, 0.6), velocity=back)
    a = first_contact(start, end, 0.25, world_of(still), 0.0, dt)
    b = first_contact(start, start, 0.25, world_of(moving), 0.0, dt)
    assert (a is None) == (b is None)
    if a is not None and b is not None:
        assert a[0] == pytest.approx(b[0], abs=1e-9)
        assert a[1] == b[1] == 0
