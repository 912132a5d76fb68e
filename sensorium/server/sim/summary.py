"""A world file's summary (``sensorium info WORLD``, also its ``--json`` form): what it contains and
how much geometry the scene builds from it (hence here, next to :mod:`.scene`, not in world/)."""

from __future__ import annotations

from pathlib import Path

from sensorium.schemas import world as wm
from sensorium.server.sim.scene import Scene
from sensorium.server.world.loader import load_world

__all__ = ["world_summary", "device_line", "drive_line"]


def device_line(d) -> str:
    if isinstance(d, wm.Lidar):
        return (f"Lidar {d.type}/{d.projection} {d.horizontal_resolution}x{d.number_of_layers} "
                f"fov {d.field_of_view:.4g} range [{d.min_range:g}, {d.max_range:g}]")
    if isinstance(d, wm.DistanceSensor):
        return f"DistanceSensor {d.type} rays {d.number_of_rays} aperture {d.aperture:g} max {d.lookup_table[-1][0] if d.lookup_table else 0:g} m"
    if isinstance(d, wm.LightSensor):
        return f"LightSensor occlusion {'on' if d.occlusion else 'off'}"
    if isinstance(d, wm.PositionSensor):
        if d.motor is None:
            return f"PositionSensor on a joint nothing turns here (present, reads its position, {float(d.position):g})"
        return f"PositionSensor on {d.motor!r} noise {d.noise:g} resolution {d.resolution:g}"
    if isinstance(d, wm.LED):
        lights = f", {len(d.lights)} light(s) on while it is" if d.lights else ""
        return f"LED {'gradual' if d.gradual else f'{len(d.color)} colours'}{lights}"
    return d.device


def drive_line(r: wm.Robot) -> str:
    """How the robot moves: its drive, what the .wbt import made of its wheels (or none)."""
    if r.omni_drive is not None:
        wheels = ", ".join(f"{w.motor or 'free wheel'} at ({w.position[0]:g}, {w.position[1]:g}) m about ({w.axis[0]:g}, "
                           f"{w.axis[1]:g}), radius {w.radius:g} m" for w in r.omni_drive.wheels)
        return f"omni wheels, {len(r.omni_drive.wheels)}: {wheels}"
    if r.steered_drive is not None:
        wheels = ", ".join(f"{w.motor or 'free wheel'} at ({w.position[0]:g}, {w.position[1]:g}) m"
                           + (f" steered by {w.steer}" if w.steer is not None else f" heading {w.heading:g} rad")
                           + f", radius {w.radius:g} m" for w in r.steered_drive.wheels)
        return f"steered wheels, {len(r.steered_drive.wheels)}: {wheels}"
    if r.mecanum_drive is not None:
        m = r.mecanum_drive
        return (f"mecanum: wheels of radius {m.wheel_radius:g} m at (±{m.lx:g}, ±{m.ly:g}) m, rollers "
                f"{list(m.rollers)} (front left, front right, rear left, rear right: {m.front_left_motor}, "
                f"{m.front_right_motor}, {m.rear_left_motor}, {m.rear_right_motor})")
    if r.ackermann_drive is not None:
        a = r.ackermann_drive
        return (f"car-like (Ackermann): wheelbase {a.wheelbase:g} m, tracks {a.track_front:g}/{a.track_rear:g} m")
    if r.differential_drive is not None:
        d = r.differential_drive
        skid = d.skid_steer
        kind = (f"skid-steer, {1 + len(skid.left)} + {1 + len(skid.right)} wheels" if skid is not None
                else f"two-wheel ({d.left_motor}, {d.right_motor})")
        cx, cy = d.axle_center
        centre = f", turning about ({cx:g}, {cy:g}) m from its origin" if (cx or cy) else ""
        if d.reversed_motors:
            kind += f", mounted mirrored: {', '.join(d.reversed_motors)}"
        if d.step_rule == "mid_heading":
            return (f"{kind}: wheels of radius {d.wheel_radius:g} m, axle {d.axle_length:g} m, each step straight along "
                    "the mid-step heading (Webots' rule without Physics)")
        return f"{kind}: wheels of radius {d.wheel_radius:g} m, {d.axle_length:g} m apart{centre}"
    return "none (the robot does not move itself)"


def _geometry_line(s: wm.Solid) -> str:
    kinds = [s.geometry.type] if s.geometry is not None else []
    kinds += [p.geometry.type for p in s.shapes]
    text = "+".join(kinds) or "no shape"
    if s.children:
        text += f", {len(s.children)} child solid{'s' if len(s.children) != 1 else ''}"
    if s.lights:
        text += f", {len(s.lights)} light{'s' if len(s.lights) != 1 else ''}"
    return text


def world_summary(path: str | Path) -> dict:
    loaded = load_world(path)
    w = loaded.world
    scene = Scene(w, loaded.base_dir, images=dict(loaded.textures))
    return {
        "world": w.world_info.name,
        "file": str(path),
        "basic_time_step_ms": w.world_info.basic_time_step,
        "random_seed": w.world_info.random_seed,
        "solids": [{"name": s.name, "geometry": _geometry_line(s), "seen_by": s.seen_by} for s in w.solids],
        "triangles": scene.triangle_count,
        "lights": [{"name": lt.name, "type": lt.type, "on": lt.on} for lt in w.lights],
        "robots": [
            {"name": r.name, "synchronization": r.synchronization, "supervisor": r.supervisor,
             "controller": r.controller, "controller_args": list(r.controller_args),
             "controller_given": "controller" in r.model_fields_set, "drive": drive_line(r),
             "devices": [{"name": d.name, "device": d.device, "summary": device_line(d)} for d in r.devices]}
            for r in w.robots
        ],
        "warnings": loaded.warnings,
        "losses": [{"kind": x.kind, "name": x.name, "robot": x.robot, "where": x.where, "why": x.why}
                   for x in loaded.losses],
        "report": loaded.report.lines(),
    }
