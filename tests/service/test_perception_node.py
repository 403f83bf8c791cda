"""Perception's pairing of scans with odometry, on the in-memory bus."""

from __future__ import annotations

from tests.service.harness import running
from tests.service.test_bad_input import odom, scan
from zenav.schemas import keys
from zenav.schemas.messages import ObstacleChain
from zenav.services.perception.params import PerceptionParams


async def test_a_scan_waits_for_its_odometry_and_a_newer_one_replaces_it_counted() -> None:
    async with running("perception", PerceptionParams()) as h:
        h.send(keys.ODOM, odom(0.0))
        await h.settle()
        h.send(keys.SCAN, scan(0.1))  # ahead of the odometry: it waits
        await h.settle()
        assert h.received(keys.OBSTACLES, ObstacleChain) == []
        h.send(keys.SCAN, scan(0.2))  # a newer one before 0.1's odometry came
        await h.settle()
        assert h.node.rejected["superseded"] == 1
        h.send(keys.ODOM, odom(0.2))
        await h.settle()
        assert [c.stamp for c in h.received(keys.OBSTACLES, ObstacleChain)] == [0.2]
        h.send(keys.SCAN, scan(0.3))
        h.send(keys.ODOM, odom(0.3))
        await h.settle()
        assert [c.stamp for c in h.received(keys.OBSTACLES, ObstacleChain)] == [0.2, 0.3]
        assert h.node.rejected["superseded"] == 1
