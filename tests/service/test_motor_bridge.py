"""The motor bridge on the in-memory bus: limits, stale-command stop, the stop zone's
scan, bad input."""

from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest

from tests.service.harness import running
from zenav.schemas import keys
from zenav.schemas.messages import BaseCommand, LaserScan, Odometry, Pose2D, VelocityCommand
from zenav.services.motor_bridge.params import Params


def odom(t: float) -> Odometry:
    return Odometry(stamp=t, seq=0, pose=Pose2D(x=0.0, y=0.0, heading=0.0), v=0.0, omega=0.0)


def cmd(t: float, v: float, omega: float = 0.0) -> VelocityCommand:
    return VelocityCommand(stamp=t, seq=0, v=v, omega=omega)


async def test_commands_are_clamped_to_speed_and_acceleration_limits():
    params = Params(max_speed=0.2, accel=0.5, decel=1.0, max_omega=1.0, angular_accel=100.0)
    async with running("motor_bridge", params) as h:
        h.send(keys.CMD_VEL, cmd(0.0, 5.0, omega=3.0))
        await h.settle()
        h.send(keys.CMD_VEL, cmd(0.1, 5.0, omega=3.0))
        await h.settle()
        h.send(keys.CMD_VEL, cmd(1.0, 5.0, omega=-3.0))
        await h.settle()
        out = h.received(keys.BASE_CMD, BaseCommand)
    assert [round(c.v, 6) for c in out] == [0.05, 0.1, 0.2]  # 0.5 m/s^2 x 0.1 s steps, cap
    assert [c.omega for c in out] == [1.0, 1.0, -1.0]
    assert all(c.reason == "command" for c in out)


async def test_stale_commands_stop_the_robot_on_the_stamp_clock():
    params = Params(stale_timeout=0.5, accel=10.0)
    async with running("motor_bridge", params) as h:
        h.send(keys.CMD_VEL, cmd(1.0, 0.1))
        for t in (1.1, 1.3, 1.5):
            h.send(keys.ODOM, odom(t))
        await h.settle()
        assert [c.reason for c in h.received(keys.BASE_CMD, BaseCommand)] == ["command"]
        h.send(keys.ODOM, odom(1.6))  # 0.6 s after the last command
        h.send(keys.ODOM, odom(1.7))
        await h.settle()
        out = h.received(keys.BASE_CMD, BaseCommand)
        assert [c.reason for c in out] == ["command", "stale"]  # one stop, not one per tick
        assert out[-1].v == 0.0 and out[-1].omega == 0.0 and out[-1].stamp == 1.6
        h.send(keys.CMD_VEL, cmd(1.8, 0.1))  # commands resume
        await h.settle()
        assert h.received(keys.BASE_CMD, BaseCommand)[-1].reason == "command"


async def test_no_stop_before_the_first_command():
    async with running("motor_bridge", Params(stale_timeout=0.5)) as h:
        for t in (0.0, 1.0, 2.0):
            h.send(keys.ODOM, odom(t))
        await h.settle()
        assert h.received(keys.BASE_CMD, BaseCommand) == []


async def test_wall_clock_watchdog_stops_the_robot_in_realtime_mode():
    params = Params(clock="realtime", stale_timeout=0.1, watchdog_period=0.02, accel=10.0)
    async with running("motor_bridge", params) as h:
        h.send(keys.CMD_VEL, cmd(5.0, 0.1))
        await asyncio.sleep(0.3)  # no odometry either: only the wall clock notices
        out = h.received(keys.BASE_CMD, BaseCommand)
    assert [c.reason for c in out] == ["command", "stale"]
    assert out[-1].v == 0.0


async def test_repeated_command_is_answered_again_and_old_one_dropped():
    async with running("motor_bridge", Params(accel=10.0)) as h:
        for message in (cmd(2.0, 0.1), cmd(2.0, 0.1), cmd(1.0, 0.2)):
            h.send(keys.CMD_VEL, message)
            await h.settle()
        out = h.received(keys.BASE_CMD, BaseCommand)
        assert len(out) == 2 and out[0] == out[1]
        assert h.node.rejected["out_of_order"] == 1


@pytest.mark.parametrize("payload", [b"", b"\xff\xfe", b"\x93\x01\x02\x03"])
async def test_bad_payloads_are_counted_and_the_bridge_keeps_working(payload):
    async with running("motor_bridge", Params(accel=10.0)) as h:
        h.send_raw(keys.CMD_VEL, payload)
        h.send(keys.CMD_VEL, cmd(0.5, 0.1))
        await h.settle()
        assert sum(h.node.rejected.values()) == 1
        assert len(h.received(keys.BASE_CMD, BaseCommand)) == 1


async def test_a_burst_keeps_only_the_newest_commands_and_counts_the_drop():
    async with running("motor_bridge", Params(accel=10.0)) as h:
        for t in (1.0, 2.0, 3.0, 4.0):  # faster than the bridge reads: depth is 2
            h.send(keys.CMD_VEL, cmd(t, 0.1))
        await h.settle()
        stamps = [c.stamp for c in h.received(keys.BASE_CMD, BaseCommand)]
        assert stamps == [3.0, 4.0]
        assert h.node.status().dropped == {"zenav/test/cmd_vel": 2}


def scan(t: float, ahead: float = 8.0) -> LaserScan:
    """A 180° scan, clear to 8 m but for a return ``ahead`` m straight ahead."""
    ranges = np.full(361, 8.0, dtype=np.float32)
    ranges[178:183] = ahead
    return LaserScan(stamp=t, seq=0, frame="laser", angle_min=-math.pi / 2,
                     angle_max=math.pi / 2, angle_increment=math.radians(0.5), range_min=0.05,
                     range_max=8.0, ranges=ranges)


async def test_on_the_sim_clock_a_command_before_its_scan_waits_for_it():
    """The command's scan, with a return just ahead, comes after the command (a loaded
    machine): the stop zone is checked on it, not on the clear scan before."""
    async with running("motor_bridge", Params(accel=10.0)) as h:
        h.send(keys.SCAN, scan(0.0))
        h.send(keys.CMD_VEL, cmd(0.0, 0.1))
        await h.settle()
        h.send(keys.CMD_VEL, cmd(0.1, 0.1))
        await h.settle()
        assert [c.stamp for c in h.received(keys.BASE_CMD, BaseCommand)] == [0.0]  # held
        h.send(keys.SCAN, scan(0.1, ahead=0.3))
        await h.settle()
        out = h.received(keys.BASE_CMD, BaseCommand)
    assert [(c.stamp, c.reason) for c in out] == [(0.0, "command"), (0.1, "stop_zone")]
    assert out[-1].v == 0.0


async def test_a_held_command_goes_on_the_scan_before_once_overtaken_or_after_the_wait():
    async with running("motor_bridge", Params(accel=10.0, scan_wait=0.05)) as h:
        h.send(keys.SCAN, scan(0.0, ahead=0.3))
        h.send(keys.CMD_VEL, cmd(0.1, 0.1))
        h.send(keys.CMD_VEL, cmd(0.2, 0.1))  # overtakes 0.1, whose scan never came
        await h.settle()
        assert [c.stamp for c in h.received(keys.BASE_CMD, BaseCommand)] == [0.1]
        await asyncio.sleep(0.15)  # 0.2's scan does not come within scan_wait either
        await h.settle()
        out = h.received(keys.BASE_CMD, BaseCommand)
    assert [(c.stamp, c.reason) for c in out] == [(0.1, "stop_zone"), (0.2, "stop_zone")]


async def test_in_realtime_mode_a_command_is_never_held_for_its_scan():
    params = Params(clock="realtime", accel=10.0, stale_timeout=5.0)
    async with running("motor_bridge", params) as h:
        h.send(keys.SCAN, scan(0.0))
        h.send(keys.CMD_VEL, cmd(0.1, 0.1))  # checked at once, on the scan of 0.0
        await h.settle()
        h.send(keys.SCAN, scan(0.1, ahead=0.3))
        await h.settle()
        out = h.received(keys.BASE_CMD, BaseCommand)
    assert [(c.stamp, c.reason) for c in out] == [(0.1, "command")]
