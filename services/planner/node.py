"""Planner service: reads tracks (which carry the robot pose at scan time) and
publishes one velocity command per scan, toward the goal along the global path."""

from __future__ import annotations

import math

from zenav.schemas import keys
from zenav.schemas.messages import PlannerState, TrackList, VelocityCommand
from zenav.services.node import Node, StampGate
from zenav.services.planner.follow import command_toward
from zenav.services.planner.params import Params


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.params = params
        self.commands = node.publisher(keys.CMD_VEL, VelocityCommand, urgent=True)
        self.state = node.publisher(keys.PLANNER_STATE, PlannerState)
        self.gate = StampGate()
        node.subscribe(keys.TRACKS, TrackList, self.on_tracks, depth=2)

    def on_tracks(self, tracks: TrackList) -> None:
        order = self.gate.check(tracks.stamp)
        if order == "repeat":
            self.commands.republish()
            return
        if order == "old":
            self.node.reject(self.node.keys.of(keys.TRACKS), "out_of_order",
                             f"tracks stamped {tracks.stamp} after {self.gate.last}")
            return
        p = self.params
        pose = tracks.pose
        at_goal = math.hypot(p.goal[0] - pose.x, p.goal[1] - pose.y) <= p.goal_tolerance / 2
        if at_goal:
            v, omega = 0.0, 0.0
        else:
            v, omega = command_toward(
                pose.x, pose.y, pose.heading, p.goal, p.cruise_speed, p.heading_gain, p.max_omega
            )
        self.commands.publish(
            VelocityCommand(stamp=tracks.stamp, seq=self.commands.next_seq(), v=v, omega=omega)
        )
        self.state.publish(
            PlannerState(
                stamp=tracks.stamp,
                seq=self.state.next_seq(),
                scenario="a",
                action="goal" if at_goal else "keep",
                target=p.goal,
                speed=v,
            )
        )


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("planner"))
