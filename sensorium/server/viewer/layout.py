"""A Foxglove layout for a Sensorium world: ``sensorium layout SOURCE -o layout.json``, then in
Foxglove *Layouts → Import from file*.

Built with the SDK's layout types (``foxglove.layouts``), from the topics of a recording or a world
file: a 3D panel (fixed frame ``world``; the scene, every laser scan and point cloud visible), a
plot of every light sensor's illuminance and every distance sensor's range, an image panel on the
first camera image (else the first lidar or range-finder range image), and a raw-messages panel on ``/clock``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

__all__ = ["layout_json", "topics_of"]

MAX_PLOTTED = 16      # series per plot panel (a world with many sensors stays readable)


def layout_json(topics: Mapping[str, str]) -> str:
    """The layout (Foxglove's JSON) for ``topics`` (name → ROS type as published)."""
    import foxglove.layouts as fl

    three_d: dict = {"/scene": fl.BaseRendererSceneUpdateTopicSettings(visible=True)}
    for name, typ in sorted(topics.items()):
        if typ == "sensor_msgs/msg/LaserScan":
            three_d[name] = fl.BaseRendererLaserScanTopicSettings(visible=True, point_size=4.0)
        elif typ == "sensor_msgs/msg/PointCloud":       # offered as PointCloud2
            three_d[name] = fl.BaseRendererPointCloudTopicSettings(visible=True, point_size=3.0)
    series = []
    for name, typ in sorted(topics.items()):
        field = {"sensor_msgs/msg/Illuminance": "illuminance", "sensor_msgs/msg/Range": "range"}.get(typ)
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
    layout = fl.Layout(content=fl.SplitContainer(direction="row", items=[
        fl.SplitItem(proportion=2, content=fl.ThreeDeePanel(
            title="World", config=fl.ThreeDeeConfig(fixed_frame="world", follow_tf="world", topics=three_d))),
        fl.SplitItem(proportion=1, content=fl.SplitContainer(direction="column", items=side)),
    ]))
    return layout.to_json()


def topics_of(source: str | Path) -> dict[str, str]:
    """Topic → type of a recording (``.mcap``) or of the world a world file describes."""
    path = Path(source)
    if path.suffix == ".mcap":
        from sensorium.server.recording.reader import Recording

        with Recording(path) as rec:
            return {t.topic: t.ros_type for t in rec.topics()}
    from sensorium.server.daemon.topics import Topics
    from sensorium.server.sim.simulation import Simulation

    return {t.name: t.type for t in Topics(Simulation.from_file(path, precision="fast")).topics}
