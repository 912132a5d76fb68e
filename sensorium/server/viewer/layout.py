"""A Foxglove layout for a Sensorium world: ``sensorium layout SOURCE -o layout.json``, then in
Foxglove *Layouts → Import from file*.

Built with the SDK's layout types (``foxglove.layouts``), from the topics of a recording or a world
file: a 3D panel (fixed frame ``world``; the scene, every laser scan and point cloud visible), a
plot of every light sensor's illuminance, every distance sensor's range and every robot's battery
percentage, an image panel on the
first camera image (else the first lidar or range-finder range image), a raw-messages panel on ``/clock``
and one on each robot's ``/<robot>/robot_window`` (the latest text its controller sent), for the
robots with a controller (a world file) or whose window texts a recording holds: one tab each in one
panel, at most :data:`MAX_WINDOW_TABS` (the first by name), so a world of many robots keeps its layout.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

__all__ = ["layout_json", "layout_for"]

MAX_PLOTTED = 16      # series per plot panel (a world with many sensors stays readable)
MAX_WINDOW_TABS = 8   # robot-window tabs: more would not fit the tab bar of a side panel
WINDOW = "/robot_window"


def layout_json(topics: Mapping[str, str], windows: Iterable[str] = ()) -> str:
    """The layout (Foxglove's JSON) for ``topics`` (name → ROS type as published) and the robots
    whose ``/<robot>/robot_window`` it shows (``windows``)."""
    import foxglove.layouts as fl

    three_d: dict = {"/scene": fl.BaseRendererSceneUpdateTopicSettings(visible=True)}
    for name, typ in sorted(topics.items()):
        if typ == "sensor_msgs/msg/LaserScan":
            three_d[name] = fl.BaseRendererLaserScanTopicSettings(visible=True, point_size=4.0)
        elif typ == "sensor_msgs/msg/PointCloud":       # offered as PointCloud2
            three_d[name] = fl.BaseRendererPointCloudTopicSettings(visible=True, point_size=3.0)
    series = []
    for name, typ in sorted(topics.items()):
        field = {"sensor_msgs/msg/Illuminance": "illuminance", "sensor_msgs/msg/Range": "range",
                 "sensor_msgs/msg/BatteryState": "percentage"}.get(typ)
        if field:
            series.append(fl.PlotSeries(value=f"{name}.{field}"))
    # a camera's image first (…/image), then range images
    images = sorted((n for n, t in topics.items() if t == "sensor_msgs/msg/Image"),
                    key=lambda n: (not n.endswith("/image"), n))
    side = [fl.SplitItem(content=fl.PlotPanel(title="Sensor values",
                                              config=fl.PlotConfig(paths=series[:MAX_PLOTTED], show_legend=True)))]
    if images:
        side.append(fl.SplitItem(content=fl.ImagePanel(
            title="Camera image" if images[0].endswith("/image") else "Range image",
            config=fl.ImageConfig(image_mode=fl.ImageModeConfig(image_topic=images[0])))))
    side.append(fl.SplitItem(content=fl.RawMessagesPanel(title="Raw messages",
                                                         config=fl.RawMessagesConfig(topic_path="/clock"))))
    shown = sorted(set(windows))[:MAX_WINDOW_TABS]
    panels = [fl.RawMessagesPanel(title=f"{r} robot window", config=fl.RawMessagesConfig(topic_path=f"/{r}{WINDOW}"))
              for r in shown]
    if len(panels) == 1:
        side.append(fl.SplitItem(content=panels[0]))
    elif panels:
        side.append(fl.SplitItem(content=fl.TabContainer(tabs=[fl.TabItem(title=r, content=p)
                                                               for r, p in zip(shown, panels)])))
    layout = fl.Layout(content=fl.SplitContainer(direction="row", items=[
        fl.SplitItem(proportion=2, content=fl.ThreeDeePanel(
            title="World", config=fl.ThreeDeeConfig(fixed_frame="world", follow_tf="world", topics=three_d))),
        fl.SplitItem(proportion=1, content=fl.SplitContainer(direction="column", items=side)),
    ]))
    return layout.to_json()


def layout_for(source: str | Path) -> str:
    """The layout of a recording (``.mcap``: its topics; a robot window for each robot whose window
    texts, either way, it holds) or of the world a world file describes (its topics; a robot window
    for each robot with a controller, ``<none>`` having none)."""
    path = Path(source)
    if path.suffix == ".mcap":
        from sensorium.server.recording.reader import Recording

        with Recording(path) as rec:
            infos = rec.topics()
        said = {t.topic.removesuffix("/to_controller") for t in infos if t.count}
        return layout_json({t.topic: t.ros_type for t in infos},
                           [t[1:-len(WINDOW)] for t in said if t.startswith("/") and t.endswith(WINDOW)])
    from sensorium.server.daemon.topics import Topics
    from sensorium.server.sim.simulation import Simulation

    sim = Simulation.from_file(path, precision="fast")
    return layout_json({t.name: t.type for t in Topics(sim).topics},
                       [name for name, robot in sim.robots.items() if robot.controller != "<none>"])
