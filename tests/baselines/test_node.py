"""A baseline as the planner service on the in-memory bus: one command per track list,
stamped with the tracks' stamp, a repeat answered with the same command, events on a
change of action."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.service.harness import planner
from zenav.schemas import keys
from zenav.schemas.keys import Topic
from zenav.schemas.messages import (
    LaserScan,
    Message,
    Odometry,
    PlannerEvent,
    PlannerState,
    Pose2D,
    TrackList,
    VelocityCommand,
)
from zenav.services.runner import PLANNERS

POSE = Pose2D(x=2.0, y=5.0, heading=0.0)


def scan(t: float, ranges: float = 8.0) -> LaserScan:
    return LaserScan(stamp=t, seq=0, frame="laser", angle_min=-math.pi / 2,
                     angle_max=math.pi / 2, angle_increment=math.radians(0.5), range_min=0.05,
                     range_max=8.0, ranges=np.full(361, ranges, dtype=np.float32))


def tracks(t: float, pose: Pose2D = POSE) -> TrackList:
    return TrackList(stamp=t, seq=0, pose=pose, tracks=[])


def test_the_baselines_are_planner_implementations():
    assert {"vfh", "dwa", "apf", "orca"} <= set(PLANNERS)


@pytest.mark.parametrize("name", ["vfh", "dwa", "apf", "orca"])
async def test_one_command_per_track_list_with_its_stamp_and_repeats_answered(name):
    async with planner(name, cruise_speed=0.2) as h:
        for t in (0.0, 0.1):
            h.send(keys.SCAN, scan(t))
            h.send(keys.ODOM, Odometry(stamp=t, seq=0, pose=POSE, v=0.2, omega=0.0))
            await h.settle()
            h.send(keys.TRACKS, tracks(t))
            await h.settle()
        h.send(keys.TRACKS, tracks(0.1))  # a retransmission
        await h.settle()
        commands = h.received(keys.CMD_VEL, VelocityCommand)
        states = h.received(keys.PLANNER_STATE, PlannerState)
    assert [c.stamp for c in commands] == [0.0, 0.1, 0.1]
    assert commands[2] == commands[1]
    assert commands[1].v > 0 and abs(commands[1].omega) < 1e-9  # open road, goal ahead
    assert [s.action for s in states] == ["keep", "keep"]


@pytest.mark.parametrize("name", ["vfh", "dwa", "apf", "orca"])
async def test_no_scan_yet_means_stop_and_the_goal_means_stop(name):
    async with planner(name) as h:
        h.send(keys.TRACKS, tracks(0.0))
        await h.settle()
        h.send(keys.SCAN, scan(0.1))
        h.send(keys.ODOM, Odometry(stamp=0.1, seq=0, pose=POSE, v=0.0, omega=0.0))
        await h.settle()
        h.send(keys.TRACKS, tracks(0.1, Pose2D(x=7.95, y=5.0, heading=0.0)))
        await h.settle()
        commands = h.received(keys.CMD_VEL, VelocityCommand)
        events = h.received(keys.EVENTS, PlannerEvent)
    assert [(c.v, c.omega) for c in commands] == [(0.0, 0.0), (0.0, 0.0)]
    assert [e.action for e in events] == ["stop", "goal"]
    assert all(e.scenario == "a" for e in events)


async def _command_at_0_1(name: str, cruise_speed: float, v0: float,
                          messages: list[tuple[Topic, Message]]) -> VelocityCommand:
    """The command for t = 0.1: a first tick at 0.0 on open road with the robot at
    ``v0`` m/s, then the messages of 0.1 in the order given."""
    async with planner(name, cruise_speed=cruise_speed) as h:
        h.send(keys.SCAN, scan(0.0))
        h.send(keys.ODOM, Odometry(stamp=0.0, seq=0, pose=POSE, v=v0, omega=0.0))
        await h.settle()
        h.send(keys.TRACKS, tracks(0.0))
        await h.settle()
        for key, message in messages:
            h.send(key, message)
            await h.settle()
        commands = h.received(keys.CMD_VEL, VelocityCommand)
    assert [c.stamp for c in commands] == [0.0, 0.1]
    return commands[1]


@pytest.mark.parametrize("name", ["vfh", "dwa", "apf", "orca"])
async def test_a_track_list_waits_for_the_scan_of_its_stamp(name):
    """Under load a track list can come before its own scan: the decision waits for it,
    so the command does not depend on the arrival order (lockstep runs stay the same)."""
    odometry = (keys.ODOM, Odometry(stamp=0.1, seq=0, pose=POSE, v=0.2, omega=0.0))
    halves = [(keys.TRACKS, tracks(0.1)), (keys.SCAN, scan(0.1, ranges=0.4))]  # a wall
    early = await _command_at_0_1(name, 0.2, 0.2, [odometry, *halves])
    late = await _command_at_0_1(name, 0.2, 0.2, [odometry, *reversed(halves)])
    assert (early.v, early.omega) == (late.v, late.omega)


@pytest.mark.parametrize("name", ["vfh", "dwa", "apf", "orca"])
async def test_a_decision_waits_for_the_odometry_of_its_instant(name):
    """Under load the odometry of a tick can come after its scan and track list: the
    decision waits for it, so the robot's velocity a baseline plans from (DWA's window)
    does not depend on the arrival order."""
    odometry = (keys.ODOM, Odometry(stamp=0.1, seq=0, pose=POSE, v=0.5, omega=0.3))
    rest = [(keys.SCAN, scan(0.1)), (keys.TRACKS, tracks(0.1))]
    first = await _command_at_0_1(name, 0.5, 0.0, [odometry, *rest])
    last = await _command_at_0_1(name, 0.5, 0.0, [*rest, odometry])
    assert (first.v, first.omega) == (last.v, last.omega)
