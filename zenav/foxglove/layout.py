"""The Foxglove layout shipped in ``deploy/foxglove/zenav.json``, built with the SDK's
layout types: a 3D panel (the scene in the odom frame, following the robot), the
planner's log, and a plot of the robot's position."""

from __future__ import annotations

import json
from collections.abc import Callable

import foxglove.layouts as fl

from zenav.foxglove.scene import BASE, ODOM, TOPICS


def _grid_settings() -> fl.BaseRendererGridTopicSettings:
    """The occupancy map: free cells faint, occupied ones dark, unknown ones (-1, below
    the range) as faint as free, drawn behind the scene."""
    return fl.BaseRendererGridTopicSettings(
        visible=True, color_mode="gradient", color_field="occupancy",
        gradient=("#ffffff10", "#303030e0"), min_value=0.0, max_value=100.0,
        draw_behind=True)


def _topic_settings() -> dict[str, fl.BaseRendererTopicSettings]:
    """Every 3D topic visible, each with the settings type of its message."""
    kinds: dict[str, Callable[[], fl.BaseRendererTopicSettings]] = {
        "LaserScan": lambda: fl.BaseRendererLaserScanTopicSettings(visible=True),
        "PoseInFrame": lambda: fl.BaseRendererPoseTopicSettings(visible=True),
        "SceneUpdate": lambda: fl.BaseRendererSceneUpdateTopicSettings(visible=True),
        "Grid": _grid_settings}
    return {topic: kinds[kind.__name__]() for topic, kind in TOPICS.items()
            if kind.__name__ in kinds}


def layout() -> fl.Layout:
    scene = fl.ThreeDeePanel(title="zenav", config=fl.ThreeDeeConfig(
        fixed_frame=ODOM, follow_tf=BASE, follow_mode="follow-position",
        topics=_topic_settings()))
    events = fl.LogPanel(title="planner events",
                         config=fl.LogConfig(topic_to_render="/foxglove/log"))
    pose = fl.PlotPanel(title="robot position", config=fl.PlotConfig(paths=[
        fl.PlotSeries(value=f"/foxglove/pose.pose.position.{axis}", enabled=True)
        for axis in ("x", "y")]))
    return fl.Layout(content=fl.SplitContainer(direction="row", items=[
        fl.SplitItem(proportion=2, content=scene),
        fl.SplitItem(proportion=1, content=fl.SplitContainer(direction="column", items=[
            fl.SplitItem(content=events), fl.SplitItem(content=pose)])),
    ]))


def layout_json() -> str:
    """The layout as the shipped file holds it (indented, to read and diff)."""
    return json.dumps(json.loads(layout().to_json()), indent=2) + "\n"
