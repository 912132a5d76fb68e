"""Validated world → scene: ray-engine bodies, per-shape metadata, lights, robot poses.

Every top-level solid is one static body (until it is moved) holding its own shapes and those of
its nested children, poses composed at load time; every robot is one movable body (its body
shapes). Lights attached to a solid or robot are kept with their local frame and placed in the
world on demand (``world_lights``; ``sensor_lights`` for light sensors, whose spot axes follow
Webots' LightSensor rather than its renderer). The global shape index returned by the ray engine indexes ``Scene.shapes``, which
carries what the devices need: owner robot, and the red channel and roughness infra-red sensors
read. Textured shapes also have a sampler (``Scene.textures``, world/textures.py; None in a world
without textures): ``infra_red_terms`` turns hits into the colour terms of Webots' pickColor.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import light as light_math
from sensorium.server.devices.shading import background_radiance, srgb_to_linear
from sensorium.server.raycast.engine import Precision, RayEngine, ShapeEntry
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.meshes import elevation_grid_mesh, load_mesh, triangles_mesh
from sensorium.server.world.poses import pose_from_model
from sensorium.server.world.textures import Checked, Decoded, TextureSampler, resolve_texture_url, uses_alpha

_IDENTITY = Pose.identity()
# a removed shape's model while its number is kept (Scene._forget_shapes): no geometry, no appearance
_NO_MODEL = wm.Shape.model_construct(geometry=None, appearance=None)


@dataclass(frozen=True, slots=True)
class ShapeInfo:
    name: str            # solid name, or "<robot>/body"
    owner: int           # robot index, -1 for world solids
    red: float           # infra-red reflectance: base_color.r * (1 - transparency); 1 without appearance
    roughness: float
    transparency: float


def primitive_from_model(g: wm.Box | wm.Sphere | wm.Cylinder | wm.Capsule | wm.Cone | wm.Plane | wm.Triangles
                         | wm.Mesh | wm.ElevationGrid | None, base_dir: Path) -> geo.Primitive:
    """A validated geometry model → its primitive (``TypeError`` for None or an unknown model)."""
    if isinstance(g, wm.Box):
        return geo.Box(size=tuple(g.size))
    if isinstance(g, wm.Sphere):
        return geo.Sphere(radius=g.radius, subdivision=g.subdivision)
    if isinstance(g, wm.Cylinder):
        return geo.Cylinder(radius=g.radius, height=g.height, subdivision=g.subdivision)
    if isinstance(g, wm.Capsule):
        return geo.Capsule(radius=g.radius, height=g.height, subdivision=g.subdivision)
    if isinstance(g, wm.Cone):
        return geo.Cone(bottom_radius=g.bottom_radius, height=g.height, subdivision=g.subdivision)
    if isinstance(g, wm.Plane):
        return geo.Plane(size=None if g.size is None else tuple(g.size))
    if isinstance(g, wm.Mesh):
        return load_mesh(base_dir / g.url, g.scale, material=g.material_index, name=g.name)
    if isinstance(g, wm.Triangles):
        return triangles_mesh(g.vertices, g.faces)
    if isinstance(g, wm.ElevationGrid):
        return elevation_grid_mesh(g.height, g.x_dimension, g.x_spacing, g.y_dimension, g.y_spacing)
    raise TypeError(f"unknown geometry {g!r}")


def _shape_info(name: str, owner: int, shape: wm.Shape | wm.Solid) -> ShapeInfo:
    a = shape.appearance
    if a is None:
        return ShapeInfo(name, owner, red=1.0, roughness=0.0, transparency=0.0)
    return ShapeInfo(name, owner, red=a.base_color[0] * (1.0 - a.transparency), roughness=a.roughness,
                     transparency=a.transparency)


def _base_color(shape: wm.Shape | wm.Solid) -> tuple[float, float, float]:
    a = shape.appearance
    return (1.0, 1.0, 1.0) if a is None else tuple(float(v) for v in a.base_color)  # type: ignore[return-value]


def emissive_of(shape: wm.Shape | wm.Solid) -> tuple[float, float, float]:
    """The radiance a shape's surface sends whatever the lights: its emissive colour (Webots' Phong
    and PBR shaders add it to the lit colour; a PBRAppearance's emissiveIntensity, which only WREN's
    forward shader applies, comes on top: :func:`emissive_scale`)."""
    a = shape.appearance
    if a is None:
        return (0.0, 0.0, 0.0)
    return tuple(float(v) for v in a.emissive_color)  # type: ignore[return-value]


def emissive_intensities(models: list[wm.Shape | wm.Solid]) -> np.ndarray | None:
    """Per shape (and a trailing 1 for no hit) a PBRAppearance's emissiveIntensity (1 for an
    ``Appearance`` node's, which has none), or None when every one is 1."""
    values = [1.0 if m.appearance is None or m.appearance.phong else float(m.appearance.emissive_intensity)
              for m in models]
    return np.array(values + [1.0]) if any(v != 1.0 for v in values) else None


def emissive_scale(glow: np.ndarray, intensity: np.ndarray, translucent: np.ndarray, shape: np.ndarray,
                   shadow_volumes: bool | np.ndarray) -> None:
    """Multiply the hits' emissive rows ``glow`` (n, 3: colour or emissiveColorMap texel) in place by
    their shapes' emissiveIntensity where WREN's forward shader draws them: a ``translucent`` hit
    (its translucent pass) always, an opaque one only while no light that is on casts shadows
    (``shadow_volumes`` False); WREN's shadow-volume ambient-emissive shader, which draws opaque
    shapes otherwise, applies the intensity in wireframe rendering only. ``shadow_volumes``: one
    answer, or one per hit (a batched camera's copies)."""
    k = np.take(intensity, shape)
    if np.any(shadow_volumes):
        k = np.where(translucent | ~np.asarray(shadow_volumes, dtype=bool), k, 1.0)
    glow *= k[:, None]


def emissive_rows(emissive: np.ndarray | None, shape: np.ndarray) -> np.ndarray | None:
    """The hit shapes' emissive radiance (n, 3), which Webots' shaders add to the lit colour (where
    a texture changes it, changed by :func:`surface_colors`' ``glow``); None in a world where
    nothing glows (``emissive`` None)."""
    return None if emissive is None else np.take(emissive, shape, axis=0)


TIMES_TEXEL, FROM_MAP = 1, 2
"""What :func:`emissive_texels` says of a shape's emissive colour besides 0 (the colour as it is)."""


def _emissive_texel(model: wm.Shape | wm.Solid) -> int:
    a = model.appearance
    if a is None:
        return 0
    if a.emissive_map is not None:
        return FROM_MAP
    return TIMES_TEXEL if a.phong and a.texture is not None else 0


def emissive_texels(models: list[wm.Shape | wm.Solid]) -> np.ndarray | None:
    """Per shape (and a trailing 0 for no hit) how a texture makes its emissive colour, or None when
    no shape's does: ``TIMES_TEXEL``, an ``Appearance`` node's with an image is multiplied by the
    texture's colour (WREN's Phong shader multiplies the sum of emissive and lit colours by the
    texel; its PBR shader adds a PBRAppearance's as it is); ``FROM_MAP``, a PBRAppearance's
    emissiveColorMap gives it (its texel replaces the colour in WREN's PBR shaders)."""
    codes = [_emissive_texel(m) for m in models]
    return np.array(codes + [0], dtype=np.int8) if any(codes) else None


def emissive_arrays(colors: list[tuple[float, float, float]], models: list[wm.Shape | wm.Solid]
                    ) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Per shape (and a trailing 0 for no hit) the emissive radiance, and :func:`emissive_texels`: both
    None when nothing glows (no emissive colour, no emissive map), the second None too when no
    texture changes a glow."""
    texel = emissive_texels(models)
    mapped = texel is not None and bool((texel == FROM_MAP).any())
    if not mapped and not any(any(c) for c in colors):
        return None, None
    return np.array(list(colors) + [(0.0, 0.0, 0.0)], dtype=np.float64).reshape(-1, 3), texel


def _maps(a: wm.Appearance) -> tuple:
    """What of an appearance the texture sampler reads."""
    return a.texture, a.roughness_map, a.occlusion_map, a.emissive_map, a.texture_transform


def translucent(appearance: wm.Appearance | None, base_dir: Path, images: Checked | None = None) -> bool:
    """Whether WREN draws a shape of this appearance as translucent: a transparency above 0 or a
    base image whose pixel format has alpha (an RGBA PNG even where every alpha is 255: Webots'
    ``WbImageTexture`` tests the format, not the pixels). Webots casts no shadow from such a shape
    and shadows none on it. ``images``: the world's images as its check read them (the image is
    read from its file only when they do not hold it)."""
    if appearance is None:
        return False
    if appearance.transparency > 0.0:
        return True
    t = appearance.texture
    if t is not None and images is not None and t.url in images:
        return images[t.url][1][2]
    return t is not None and uses_alpha(resolve_texture_url(t.url, base_dir, allow_outside=True), t.url)


def receives_shadows(transparency: np.ndarray, alpha: np.ndarray | None, shape: np.ndarray) -> np.ndarray:
    """Per hit (shape −1, the arrays' last entry: True): whether shadows fall on it -- not on a
    translucent shape (:func:`translucent`: ``transparency`` above 0, or ``alpha``, its image's
    pixel format has alpha), which WREN draws in its translucent pass, unshadowed."""
    out = transparency[shape] <= 0.0
    return out if alpha is None else out & ~alpha[shape]


def _entry(shape: wm.Shape | wm.Solid, base_dir: Path, local: Pose | None = None,
           images: Checked | None = None) -> ShapeEntry:
    transparent = shape.appearance is not None and shape.appearance.transparency >= 1.0
    assert shape.geometry is not None
    return ShapeEntry(
        primitive=primitive_from_model(shape.geometry, base_dir),
        local_pose=local if local is not None else Pose.identity(),
        bounding=shape.seen_by in ("both", "bounding") and not isinstance(shape.geometry, wm.Cone),   # as Webots
        visual=shape.seen_by in ("both", "visual"),
        transparent=transparent,
        casts_shadow=shape.cast_shadows and not translucent(shape.appearance, base_dir, images),
    )


def solid_parts(solid: wm.Solid, frame: Pose) -> Iterator[tuple[str, Pose, wm.Shape | wm.Solid]]:
    """Every shape of a solid and its nested children: (name, pose in ``frame``'s parent, shape)."""
    for _, name, pose, shape in owned_solid_parts(solid, frame):
        yield name, pose, shape


def owned_solid_parts(solid: wm.Solid, frame: Pose, path: tuple[int, ...] = ()
                      ) -> Iterator[tuple[tuple[int, ...], str, Pose, wm.Shape | wm.Solid]]:
    """:func:`solid_parts`, each with the path of the solid whose shape it is: () the top one, a nested
    child's its ``children`` index at each level (the Supervisor's nested table keys its nodes so)."""
    if solid.geometry is not None:
        yield path, solid.name, frame, solid
    for part in solid.shapes:
        yield path, part.name or solid.name, frame.compose(pose_from_model(part.pose)), part
    for k, child in enumerate(solid.children):
        yield from owned_solid_parts(child, frame.compose(pose_from_model(child.pose)), (*path, k))


def solid_lights(solid: wm.Solid, frame: Pose, nested: bool = False
                 ) -> Iterator[tuple[wm.PointLight | wm.SpotLight | wm.DirectionalLight, Pose]]:
    """Every light fixed to a solid or its children, with its frame relative to the top solid. A
    nested child's spot lights get the axis light sensors use (``sensor_aimed``: its own rotation)."""
    own = pose_from_model(solid.pose) if nested else None
    for lt in solid.lights:
        yield (lt if own is None else sensor_aimed(lt, own)), frame
    for child in solid.children:
        yield from solid_lights(child, frame.compose(pose_from_model(child.pose)), True)


def charger_glow(solid: wm.Solid, shapes: int, lights: int, solids: int) -> tuple[list[int], list[int]]:
    """A Charger's glowing shapes and lights, as indices among its solid's (:func:`solid_parts` and
    :func:`solid_lights` order): its first ``shapes`` shapes and ``lights`` own lights, and every shape
    and light of its first ``solids`` children (WbCharger searches the solids in its first child as
    it searches groups)."""
    all_shapes = len(list(solid_parts(solid, Pose.identity())))
    own_shapes = (solid.geometry is not None) + len(solid.shapes)
    nested = solid.children[:solids]
    nested_shapes = sum(len(list(solid_parts(c, Pose.identity()))) for c in nested)
    nested_lights = sum(len(list(solid_lights(c, Pose.identity()))) for c in nested)
    glowing = sorted({*range(min(shapes, all_shapes)), *range(own_shapes, own_shapes + nested_shapes)})
    own_lights = len(solid.lights)
    return glowing, [*range(min(lights, own_lights)), *range(own_lights, own_lights + nested_lights)]


def sensor_aimed(model, own: Pose):
    """A spot light of a nested solid with the beam axis Webots' LightSensor uses: ``direction``
    turned by that solid's own rotation only (``WbLightSensor::computeLightMeasurement`` turns it by
    the nearest enclosing Pose's ``rotation`` field, not by the frames above it; cameras, like
    Webots' renderer, turn it by all of them: ``place_light``). A light that has the axis already
    (``light_sensor_direction``, e.g. from a .wbt file) keeps it."""
    if model.type != "SpotLight" or model.light_sensor_direction is not None:
        return model
    aim = tuple(float(v) for v in own.apply_dirs(np.asarray(model.direction)))
    return model.model_copy(update={"light_sensor_direction": aim})


def robot_led_lights(robot: wm.Robot) -> list[tuple[str, list]]:
    """Each LED of ``robot`` holding lights, with its lights in the robot's frame (``place_light`` by the
    LED's pose) as the LED holds them before its first ``set``: off and black (``WbLed::postFinalize``:
    value 0). A spot light's light-sensor axis is turned by the LED's own rotation, as a nested solid's
    (``sensor_aimed``: the LED is the nearest enclosing Pose). The robot carries them from there as it
    carries its own ``lights`` (the batched simulation's ``CarriedLights`` too)."""
    out = []
    for d in robot.devices:
        if isinstance(d, wm.LED) and d.lights:
            frame = pose_from_model(d.pose)
            out.append((d.name, [place_light(sensor_aimed(lt, frame), frame).model_copy(
                update={"on": False, "color": (0.0, 0.0, 0.0)}) for lt in d.lights]))
    return out


def link_aimed(model, displacement: Pose):
    """A placed spot light riding on a joint, its light-sensor axis (``light_sensor_direction``, when
    it has one) turned by the joint's displacement: Webots' LightSensor turns a spot light's
    direction by the own rotation of the Solid holding it, the joint's end point, which the joint turns."""
    if model.type != "SpotLight" or model.light_sensor_direction is None:
        return model
    aim = tuple(float(v) for v in displacement.apply_dirs(np.asarray(model.light_sensor_direction)))
    return model.model_copy(update={"light_sensor_direction": aim})


def for_light_sensors(model):
    """A placed light model (``place_light``) as light sensors see it: a spot light's
    ``light_sensor_direction``, when it has one, is its direction (world axes, fixed)."""
    if model.type != "SpotLight" or model.light_sensor_direction is None:
        return model
    return model.model_copy(update={"direction": model.light_sensor_direction})


def robot_parts(robot: wm.Robot) -> Iterator[tuple[str, Pose, wm.Shape]]:
    if robot.body is not None:
        yield f"{robot.name}/body", Pose.identity(), robot.body
    for part in robot.shapes:
        yield f"{robot.name}/{part.name or 'body'}", pose_from_model(part.pose), part


def robot_bodies(robot: wm.Robot) -> list[tuple[str | None, list[tuple[str, Pose, wm.Shape]]]]:
    """A robot's shapes as the scene's bodies hold them: (None, the robot's own body's parts) first,
    then (joint, the parts riding it: its link, ``on_joint``) in the order the joints first appear,
    each group's parts in :func:`robot_parts` order. The scene numbers a robot's shapes in this order."""
    groups: dict[str | None, list] = {}
    for part in robot_parts(robot):
        groups.setdefault(getattr(part[2], "on_joint", None), []).append(part)
    return sorted(groups.items(), key=lambda kv: kv[0] is not None)


def scene_robot_parts(robot: wm.Robot) -> list[tuple[str, Pose, wm.Shape]]:
    """A robot's shapes in the scene's numbering (:func:`robot_bodies` flattened): :func:`robot_parts`'
    order unless a shape rides a joint."""
    return [part for _, group in robot_bodies(robot) for part in group]


def robot_bounding_parts(robot: wm.Robot, base_dir: Path) -> list[tuple[Any, Pose]]:
    """A robot's shapes that bound it (``seen_by`` both or bounding) as (primitive, pose in the robot
    frame): what kinematic contact and the ground's support ceiling take its body to be."""
    return [(primitive_from_model(shape.geometry, base_dir), local) for _, local, shape in robot_parts(robot)
            if shape.seen_by in ("both", "bounding")]


def place_light(model, pose: Pose):
    """A light model with ``location``/``direction`` moved from its owner's frame to the world.

    A DirectionalLight's direction stays in world axes wherever it is attached (as in Webots, whose
    renderer ignores a directional light's parent transform). A SpotLight's direction is turned by
    the whole frame, as Webots' renderer turns it (what cameras see); light sensors read
    ``for_light_sensors`` of the result."""
    upd: dict = {}
    if hasattr(model, "location"):
        upd["location"] = tuple(float(v) for v in pose.apply(np.asarray(model.location)))
    if model.type == "SpotLight":
        upd["direction"] = tuple(float(v) for v in pose.apply_dirs(np.asarray(model.direction)))
    return model.model_copy(update=upd)


_LIGHT_KINDS = {"PointLight": light_math.LightKind.POINT, "SpotLight": light_math.LightKind.SPOT,
                "DirectionalLight": light_math.LightKind.DIRECTIONAL}


def light_from_model(m) -> light_math.Light:
    """A light model (world coordinates, e.g. from :meth:`Scene.world_lights`) as the light model of
    server/devices/light.py computes with it."""
    fields = dict(kind=_LIGHT_KINDS[m.type], intensity=m.intensity, ambient_intensity=m.ambient_intensity, color=m.color)
    if m.type != "DirectionalLight":
        fields.update(position=m.location, attenuation=m.attenuation, radius=m.radius)
    if m.type != "PointLight":
        fields.update(direction=m.direction)
    if m.type == "SpotLight":
        fields.update(beam_width=m.beam_width, cut_off_angle=m.cut_off_angle)
    return light_math.Light(**fields)


def surface_colors(colors: np.ndarray, sampler: TextureSampler | None, world_to_shape: Callable[[int], Pose],
                   shape: np.ndarray, origins: np.ndarray, directions: np.ndarray, distance: np.ndarray,
                   glow: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """The albedo (n, 3) a camera sees at hits (world frame; shape −1: white): the base colour,
    times the texel of a textured shape converted from sRGB to linear (Webots' shaders;
    where picking fails, 1), blended with a pen's ink (``(1 − c)·colour + c·ink``) read where the
    pen painted it (texture set 1, as Webots' shaders; infra-red reads it at set 0). ``colors``: base colours per shape (a trailing white for −1);
    ``world_to_shape``: a shape's world-to-shape pose now. ``glow``: the hits' emissive rows (n, 3)
    and the per-shape flags of :func:`emissive_texels`: a flagged shape's rows are multiplied in
    place by the texture's colour read here (``(1 − c)·texel + c·ink``), as WREN's Phong shader
    multiplies its emissive colour; an emissive-mapped shape's rows become its map's texel (where
    picking fails, the colour stays), as WREN's PBR shaders take it."""
    col = np.take(colors, shape, axis=0)   # (faster than fancy indexing of (n, 3) rows)
    if sampler is None:
        return col
    for s, rows, o, d, uv, picked in _texel_coords(sampler, sampler.textured, world_to_shape, shape, origins,
                                                   directions, distance):
        sampler.lookups += len(rows)
        base = col[rows]
        texel = None
        if s in sampler.shapes:
            texel = np.where(picked[:, None], srgb_to_linear(sampler.texels(s, uv, "base")), 1.0)
            base = base * texel
        layer = sampler.ink.get(s)
        ink = None
        if layer is not None:     # the paint texture as Webots' shaders sample it: at texture set 1
            ink, c = layer.pick(np.where(picked[:, None], sampler.ink_uv(s, o, d, distance[rows], uv), 0.0))
            c = np.where(picked, c.astype(np.float64), 0.0)[:, None]
            base = (1.0 - c) * base + c * ink
        col[rows] = base
        if glow is not None and glow[1][s] == TIMES_TEXEL and texel is not None:
            glow[0][rows] *= texel if ink is None else (1.0 - c) * texel + c * ink
    if glow is not None and sampler.has_emissive_map:      # an emissive map's texel replaces the colour
        for s, rows, _, _, uv, picked in _texel_coords(sampler, sampler.emissive_mapped, world_to_shape, shape,
                                                       origins, directions, distance):
            sampler.lookups += len(rows)
            glow[0][rows] = np.where(picked[:, None], sampler.emissive_texels(s, uv), glow[0][rows])
    return col


def surface_opacity(sampler: TextureSampler, world_to_shape: Callable[[int], Pose], shape: np.ndarray,
                    origins: np.ndarray, directions: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """The texture alpha (n,) a camera sees at hits on shapes whose image has transparent texels
    (``sampler.alpha``; 1 on every other shape and where picking fails): the texel's alpha at the
    coordinates :func:`surface_colors` reads its colour at (Webots' shaders take the texel's alpha
    as the fragment's, times ``1 − transparency``; the pen's ink changes colours only)."""
    out = np.ones(len(shape))
    for s, rows, _, _, uv, picked in _texel_coords(sampler, sampler.alpha, world_to_shape, shape, origins,
                                                   directions, distance):
        out[rows] = np.where(picked, sampler.opacity(s, uv), 1.0)
    return out


def _texel_coords(sampler: TextureSampler, chosen: np.ndarray, world_to_shape: Callable[[int], Pose],
                  shape: np.ndarray, origins: np.ndarray, directions: np.ndarray, distance: np.ndarray):
    """Per shape ``s`` with ``chosen[s]`` among the hits, in shape order: ``(s, rows, o, d, uv,
    picked)`` -- its hits' rows, their rays in the shape's frame, and the texture coordinates (0
    where picking fails, ``picked`` False) that colours and alpha are both read at."""
    hit = chosen[shape].nonzero()[0]
    on = shape[hit]
    for s in sorted(set(on.tolist())):
        rows = hit[on == s]
        inv = world_to_shape(s)
        o, d = _in_blocks(inv, origins, rows, True), _in_blocks(inv, directions, rows, False)
        uv, picked = sampler.uv(s, o, d, distance[rows])
        yield s, rows, o, d, np.where(picked[:, None], uv, 0.0), picked


_POSE_ROWS = 32768
"""Rows of a camera's hits moved into a shape's frame per ``Pose.apply`` call: a larger product is
multi-threaded by OpenBLAS, whose threads stall beside the engine's on a busy machine."""


def _in_blocks(pose: Pose, x: np.ndarray, rows: np.ndarray, points: bool) -> np.ndarray:
    """``pose.apply(x[rows])`` (``apply_dirs`` unless ``points``), ``_POSE_ROWS`` rows per product:
    each row's values those of the one product."""
    n = len(rows)
    if n <= _POSE_ROWS:
        return pose.apply(x[rows]) if points else pose.apply_dirs(x[rows])
    out = np.empty((n, 3))
    for a in range(0, n, _POSE_ROWS):
        r = rows[a:a + _POSE_ROWS]
        out[a:a + _POSE_ROWS] = pose.apply(x[r]) if points else pose.apply_dirs(x[r])
    return out


def infra_red_terms(red_of: np.ndarray, roughness_of: np.ndarray, sampler: TextureSampler | None,
                    world_to_shape: Callable[[int], Pose], shape: np.ndarray, origins: np.ndarray,
                    directions: np.ndarray, distance: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(red, roughness, occlusion) an infra-red ray reads at its hit (WbShape::pickColor):
    ``red = base_color.r·(1 − transparency)·texel.r`` on textured shapes (the texel at Webots'
    texture coordinates of the hit, in the shape's frame, float64), the shape's red elsewhere;
    roughness from a roughness map where there is one; occlusion from an occlusion map (else 0).
    ``shape`` −1 (no hit) reads the trailing "no hit" entries of ``red_of`` and ``roughness_of``
    (per shape); ``world_to_shape``: a shape's world-to-shape pose now."""
    red = red_of[shape]
    rough = roughness_of[shape]
    occl = np.zeros(len(shape))
    if sampler is None:
        return red, rough, occl
    hit = sampler.textured[shape].nonzero()[0]
    on = shape[hit]
    for s in sorted(set(on.tolist())):
        rows = hit[on == s] if len(hit) > 1 else hit
        inv = world_to_shape(s)
        o, d = inv.apply(origins[rows]), inv.apply_dirs(directions[rows])
        read, rmap, omap, picked = sampler.infra_red(s, o, d, distance[rows], red[rows])
        red[rows] = read
        if rmap is not None:
            rough[rows] = rmap if picked is None else np.where(picked, rmap, rough[rows])
        if omap is not None:
            occl[rows] = omap if picked is None else np.where(picked, omap, 0.0)
    return red, rough, occl



def recognisable_owners(world) -> dict[str | int, tuple[int, list, str]]:
    """What cameras with a Recognition node report: owner (robot index, solid name) -> (the
    Supervisor's node id: robots 1..R in world order, then the top-level solids; recognition colours;
    model)."""
    out: dict[str | int, tuple[int, list, str]] = {}
    for i, r in enumerate(world.robots):
        if r.recognition_colors:
            out[i] = (i + 1, [tuple(c) for c in r.recognition_colors], r.model)
    for j, sd in enumerate(world.solids):
        if sd.recognition_colors:
            out[sd.name] = (len(world.robots) + 1 + j, [tuple(c) for c in sd.recognition_colors], sd.model)
    return out


# a radar target: robot index, top-level solid name, or (its robot or top-level solid, k): a solid inside it
TargetKey = str | int | tuple[int, int] | tuple[str, int]


def nested_radar_solids(solid: wm.Solid) -> list[tuple[Pose, float, range]]:
    """The solids inside a top-level solid with a radar cross section > 0, in tree order (each before
    those inside it): (pose in the top solid's frame, cross section, the indices of its shapes and of
    those of the solids inside it among the top solid's shapes, in ``solid_parts`` order)."""
    out: list[tuple[Pose, float, range]] = []
    if not any(child.children or child.radar_cross_section > 0.0 for child in solid.children):
        return out                                   # (most solids: no walk)
    count = 0

    def walk(s: wm.Solid, frame: Pose, nested: bool) -> None:
        nonlocal count
        start = count
        count += (s.geometry is not None) + len(s.shapes)
        k = len(out)
        if nested and s.radar_cross_section > 0.0:
            out.append((frame, float(s.radar_cross_section), range(0)))
        for child in s.children:
            walk(child, frame.compose(pose_from_model(child.pose)), True)
        if nested and s.radar_cross_section > 0.0:
            out[k] = (frame, float(s.radar_cross_section), range(start, count))

    walk(solid, Pose.identity(), False)
    return out


def radar_targets(world) -> dict[TargetKey, float]:
    """What radars detect: target (robot index, (robot index, k) for the robot's ``radar_targets[k]``,
    top-level solid name, (its name, k) for the k-th solid inside it with a cross section) -> its
    radar cross section (m², > 0): each robot in world order followed by the solids it carries, then
    each top-level solid followed by those inside it (the Supervisor's node order)."""
    out: dict[TargetKey, float] = {}
    for i, r in enumerate(world.robots):
        if r.radar_cross_section > 0.0:
            out[i] = float(r.radar_cross_section)
        out.update(((i, k), float(t.radar_cross_section)) for k, t in enumerate(r.radar_targets))
    for sd in world.solids:
        out.update(solid_radar_targets(sd))
    return out


def solid_radar_targets(solid: wm.Solid) -> dict[TargetKey, float]:
    """A top-level solid's radar targets: itself (cross section > 0), then the solids inside it."""
    out: dict[TargetKey, float] = {solid.name: float(solid.radar_cross_section)} if solid.radar_cross_section > 0.0 else {}
    out.update(((solid.name, k), rcs) for k, (_, rcs, _) in enumerate(nested_radar_solids(solid)))
    return out


def blind_devices(shape: Any) -> tuple[str, ...]:
    """The devices of its robot whose visual rays do not see a robot shape: the device whose own Solid it
    belongs to (``of_device``) and those it is turned away from (``unseen_by``, a split mesh's piece)."""
    device = getattr(shape, "of_device", None)
    return (*(() if device is None else (device,)), *getattr(shape, "unseen_by", ()))


class Scene:
    """Geometry and poses of a world; the only owner of the ray engine."""

    def __init__(self, world: wm.World, base_dir: Path, precision: Precision | str = Precision.EXACT,
                 images: Checked | None = None):
        """``images``: the world's images as its check read them (``LoadedWorld.textures``): shown
        as they are, their files not read again."""
        self.engine = RayEngine(Precision(precision))
        self.images: Checked = images or {}
        self.shapes: list[ShapeInfo] = []
        self.solid_names = [s.name for s in world.solids]
        self.solid_name_set = set(self.solid_names)     # (every name the world has had: never reused)
        self._solid_body: dict[str, int] = {}
        self.solid_poses: dict[str, Pose] = {}
        self.triangle_count = 0            # of the bodies in the world now (a removed solid's leave the count)
        self._solid_triangles: dict[str, int] = {}
        self._parts: list[tuple[str | int | None, Pose, wm.Shape | wm.Solid]] = []   # per shape: owner, frame, model
        # lights: (model, owner, pose in the owner's frame); owner None = world, str = solid, int = robot,
        # (robot, joint) = a robot's light riding on that joint (``on_joint``; an LED's lights: the LED's)
        self._lights: list[tuple[object, str | int | tuple[int, str] | None, Pose]] = [
            (lt, None, Pose.identity()) for lt in world.lights]
        self._led_lights: dict[tuple[int, str], list] = {}   # (robot, LED) -> its lights' models now
        self._led_state: dict[tuple[int, str], tuple[bool, tuple]] = {}   # (robot, LED) -> its last (on, colour)
        # (robot index or solid name, index among its lights) -> the light as loaded, for those a Supervisor set
        self._set_carried: dict[tuple[str | int, int], object] = {}
        self.removed_carried: set[tuple[str | int, int]] = set()   # those a Supervisor removed (same keys)
        # (robot, k) -> its radar_targets[k], (solid, k) -> the k-th solid inside it with a cross section:
        # its pose in the robot's or solid's frame, the joint it rides on, its shapes
        self.carried_targets: dict[tuple[int, int] | tuple[str, int], tuple[Pose, str | None, tuple[int, ...]]] = {}
        for s in world.solids:
            pose = pose_from_model(s.pose)
            self.solid_poses[s.name] = pose
            self._lights += [(lt, s.name, f) for lt, f in solid_lights(s, Pose.identity())]
            self._nested_targets(s)
            parts = list(solid_parts(s, Pose.identity()))
            if parts:
                # a solid holding a cone gets a tier of its own, as a moved solid does: packets.c (which
                # judges the static tier's hits) does not know cones, so the numpy path judges that tier
                # alone instead of the whole static geometry
                cone = any(isinstance(shape.geometry, wm.Cone) for _, _, shape in parts)
                self._solid_body[s.name] = self._add_body(parts, base_dir, pose, owner=-1, movable=cone, key=s.name)
        self.robot_names = [r.name for r in world.robots]
        self.robot_poses: list[Pose] = []
        self._robot_body: dict[int, int] = {}
        self._link_body: dict[tuple[int, str], int] = {}       # (robot, joint) -> its link's body
        self._shape_link: dict[int, tuple[int, str]] = {}      # shape -> (robot, joint) it rides on
        self.link_poses: dict[tuple[int, str], Pose] = {}      # (robot, joint) -> its link's displacement now
        self._device_shapes: dict[tuple[int, str], frozenset[int]] = {}   # (robot, device) -> its own shapes
        for i, r in enumerate(world.robots):
            pose = pose_from_model(r.pose)
            self.robot_poses.append(pose)
            self._lights += [(lt, i if lt.on_joint is None else (i, lt.on_joint), Pose.identity()) for lt in r.lights]
            led_joint = {d.name: d.on_joint for d in r.devices if isinstance(d, wm.LED)}
            for name, models in robot_led_lights(r):    # off and black until the LED is set (WbLed)
                self._led_lights[(i, name)] = models
                carrier = i if led_joint[name] is None else (i, led_joint[name])
                self._lights += [(m, carrier, Pose.identity()) for m in models]
            # a joint's link (the shapes riding on it: ``on_joint``) is a movable body of its own, owned
            # by the robot; every other shape is the robot's body, as in a robot without joints
            owned: dict[str, set[int]] = {}
            placed: dict[int, int] = {}                      # id(shape model) -> its shape index
            for joint, group in robot_bodies(r):
                first = len(self.shapes)
                body = self._add_body(group, base_dir, pose, owner=i, movable=True, key=i)
                if joint is None:
                    self._robot_body[i] = body
                else:
                    self._link_body[(i, joint)] = body
                    self._shape_link.update((first + k, (i, joint)) for k in range(len(group)))
                for k, (_, _, shape) in enumerate(group):
                    if r.radar_targets:
                        placed[id(shape)] = first + k
                    for device in blind_devices(shape):
                        owned.setdefault(device, set()).add(first + k)
            self._device_shapes.update({(i, d): frozenset(ids) for d, ids in owned.items()})
            for k, t in enumerate(r.radar_targets):          # solids it carries that radars detect apart
                self.carried_targets[(i, k)] = (pose_from_model(t.pose), t.on_joint,
                                                tuple(sorted({placed[id(r.shapes[j])] for j in t.shapes})))
        self._loaded_lights = list(self._lights)      # as loaded (an LED's: off and black), for restore_carried_lights
        self._attached = {owner[0] if isinstance(owner, tuple) else owner for _, owner, _ in self._lights
                          if owner is not None}
        # the links carrying lights: light sensors and cameras recompute their lights when one moves
        self._light_links = {owner for _, owner, _ in self._lights if isinstance(owner, tuple)}
        # textures: one sampler for the world's images (None without any), read by infra-red only
        self._base_dir = base_dir
        self._ink_evaporation = world.world_info.ink_evaporation
        sampler = TextureSampler([(shape.geometry, shape.appearance) for _, _, shape in self._parts], base_dir,
                                 ink_evaporation=self._ink_evaporation, given=self.images)
        self.textures: TextureSampler | None = sampler if sampler else None   # made on a first pen stroke
        self._inverse: dict[int, tuple[Pose, Pose]] = {}     # shape -> (owner pose, world-to-shape pose)
        # a Supervisor's appearance changes: shape -> its model as loaded, and the field values it set
        self._loaded_models: dict[int, wm.Shape | wm.Solid] = {}
        self.appearance_values: dict[int, dict[str, Any]] = {}
        self.removed_shapes: set[int] = set()       # Shape nodes a Supervisor removed (:meth:`remove_shapes`)
        self._link_frames: dict[tuple[int, str], tuple[Pose, Pose, Pose]] = {}   # link -> (robot, link, world)
        self.lights_version = 0        # changes whenever a light moves with its owner
        self.solids_version = 0        # changes whenever a top-level solid moves, is added or removed (gym's TopDown)
        self.removed_lights: set[int] = set()   # top-level lights a Supervisor removed (their indices)
        self.shapes_version = 0        # changes whenever a Supervisor adds shapes (cameras' recognition rebuilds)
        self.appearance_version = 0    # changes whenever a shape's appearance changes or a reset restores it (Foxglove's scene)
        self._glow: dict[int, tuple[float, float, float]] = {}    # shape -> a Charger's emissive colour for it
        self._shape_arrays()
        # what cameras see past everything: the HDR radiance Webots clears with (shows as the sky colour)
        self.background = background_radiance(world.background.sky_color)
        # Webots' Fog as cameras mix it in: (linear colour, visibility range, type); None without fog or
        # with a visibility range of 0 (Webots then turns it off), so a world without fog computes nothing more
        fog = world.fog
        self.fog: tuple[np.ndarray, float, str] | None = None
        if fog is not None and fog.visibility_range > 0.0:
            self.fog = (srgb_to_linear(np.asarray(fog.color, dtype=np.float64)), float(fog.visibility_range),
                        fog.fog_type)
        self.base_dir = Path(base_dir)
        self.recognisable = recognisable_owners(world)
        self.radar_targets = radar_targets(world)

    def _nested_targets(self, solid: wm.Solid) -> None:
        """The radar targets inside a top-level solid about to join the scene (its shapes come next)."""
        first = len(self.shapes)
        for k, (frame, _, shapes) in enumerate(nested_radar_solids(solid)):
            self.carried_targets[(solid.name, k)] = (frame, None, tuple(first + i for i in shapes))

    def _shape_arrays(self) -> None:
        """The per-shape arrays devices index by hit shape (-1, no hit, reads the trailing entry)."""
        # infra-red reads these per hit shape
        self.red = np.array([s.red for s in self.shapes] + [1.0])
        self.roughness = np.array([s.roughness for s in self.shapes] + [0.0])
        # cameras read these (sim/cameras.py): base colour (white without appearance) and transparency
        self.colors = np.array([_base_color(shape) for _, _, shape in self._parts] + [(1.0, 1.0, 1.0)]).reshape(-1, 3)
        self.transparency = np.array([s.transparency for s in self.shapes] + [0.0])
        self._rebuild_emissive()

    def _rebuild_emissive(self) -> None:
        """Every shape's emissive row now and how a texture makes it (``emissive_texel``, see
        :func:`emissive_arrays`: both None when nothing glows)."""
        models = [m for _, _, m in self._parts]
        self.emissive, self.emissive_texel = emissive_arrays(
            [self._emissive_now(k, m) for k, m in enumerate(models)], models)
        # a PBRAppearance's emissiveIntensity per shape (None: all 1, or nothing glows): emissive_scale
        self.emissive_intensity = None if self.emissive is None else emissive_intensities(models)

    def _refresh_emissive(self, shape: int) -> None:
        """One shape's emissive row after its model or glow changed: the arrays built when it is the first
        to glow (or to have a texture make its glow), dropped when it was the last."""
        model = self._parts[shape][2]
        glow = self._emissive_now(shape, model)
        code = _emissive_texel(model)
        intensity = emissive_intensities([model])
        if self.emissive is None or (self.emissive_texel is None and code) or \
                (self.emissive_intensity is None and intensity is not None):
            if self.emissive is not None or any(glow) or code:
                self._rebuild_emissive()
            return
        self.emissive[shape] = glow
        if self.emissive_intensity is not None:
            self.emissive_intensity[shape] = 1.0 if intensity is None else intensity[0]
        if self.emissive_texel is not None:
            self.emissive_texel[shape] = code
            if not self.emissive_texel.any():
                self.emissive_texel = None
        if not self.emissive.any() and (self.emissive_texel is None or not (self.emissive_texel == FROM_MAP).any()):
            self.emissive = self.emissive_texel = self.emissive_intensity = None

    def _emissive_now(self, shape: int, model: wm.Shape | wm.Solid) -> tuple[float, float, float]:
        """:func:`emissive_of` a shape, its colour a Charger's glow (``set_glow``) where it has one."""
        glow = self._glow.get(shape)
        if glow is None or model.appearance is None:
            return emissive_of(model)
        return tuple(float(v) for v in glow)  # type: ignore[return-value]

    def solid_shapes(self, name: str) -> list[int]:
        """The shapes of top-level solid ``name`` (its own, then its nested solids'), in order."""
        return [k for k, (key, _, _) in enumerate(self._parts) if key == name]

    def appearance_changes(self, name: str) -> dict[int, tuple[wm.Appearance | None, dict]]:
        """What a Supervisor changed of top-level solid ``name``'s shapes' appearances, by each shape's place
        among the solid's shapes: its appearance now and the values set (:meth:`take_appearance_changes`)."""
        return {k: (self._parts[shape][2].appearance, dict(self.appearance_values.get(shape, {})))
                for k, shape in enumerate(self.solid_shapes(name)) if shape in self._loaded_models}

    def take_appearance_changes(self, name: str, changes: dict[int, tuple[wm.Appearance | None, dict]]) -> None:
        """:meth:`appearance_changes` given to top-level solid ``name`` built again with the same shapes (a
        Supervisor set a Pose's frame inside it): each of its shapes at those places looks as it did (a reset
        brings back the appearance the world file gives it)."""
        mine = self.solid_shapes(name)
        for k, (appearance, values) in changes.items():
            if appearance is not None:
                self.set_texture(mine[k], appearance)
            if values:
                self.appearance_values[mine[k]] = values

    def glow_of(self, shape: int) -> tuple[float, float, float] | None:
        """A Charger's emissive colour for a shape now (:meth:`set_glow`), None where no Charger set one."""
        return self._glow.get(shape)

    def set_glow(self, shape: int, color: tuple[float, float, float]) -> None:
        """A Charger's glowing shape's emissive colour now (WbCharger sets its Material's or
        PBRAppearance's ``emissiveColor``): cameras add it from the next image; the shape's model keeps
        the world file's colour. WbCharger writes that field at each step, so a Supervisor's own value of
        it, read back until now, gives way to it."""
        written = self.appearance_values.get(shape)
        if written:
            written.pop("material.emissiveColor", None)
            written.pop("appearance.emissiveColor", None)
            if not written:
                del self.appearance_values[shape]
        if self._glow.get(shape) == color:
            return
        self._glow[shape] = color
        self._refresh_emissive(shape)

    def set_appearance(self, shape: int, appearance: wm.Appearance) -> None:
        """A Supervisor's new colour, roughness or transparency for one shape (Webots' Material and
        PBRAppearance fields): from the next measurement every sensor reads it as if the world file had
        said it. Only that shape's entries change; a transparency crossing 0 or 1 also changes which
        rays see the shape and its shadows (:meth:`_seen_again`: its body's ray scenes are made again
        at the next cast). ``appearance_version`` moves unless the appearance is the same as now (the
        Foxglove scene draws it again)."""
        if shape not in self.removed_shapes and self._take_appearance(shape, appearance):
            self._seen_again(shape)

    def remove_shapes(self, shapes: Collection[int]) -> None:
        """Shapes a Supervisor removed from inside a robot or solid (a ``Shape`` node: a split mesh's pieces
        together): from the next cast they are as a shape of transparency 1 -- no camera, range finder, lidar
        or infra-red or laser ray sees them, they cast no shadow, the Foxglove scene draws them clear --
        while bounding rays still meet a shape that is also its solid's boundingObject (Webots keeps that
        node). They stay removed through a reset and any later appearance change (Webots' reset does not
        bring back a removed node)."""
        for shape in shapes:
            if shape in self.removed_shapes:
                continue
            current = self._parts[shape][2].appearance or wm.Appearance()
            self._take_appearance(shape, current.model_copy(update={"transparency": 1.0}))
            self.removed_shapes.add(shape)
            self._seen_again(shape)

    def _take_appearance(self, shape: int, appearance: wm.Appearance) -> bool:
        """The shape's model takes ``appearance`` (its per-shape entries; the loaded model kept for a
        reset); False when it is the same as now (nothing to redraw)."""
        model = self._parts[shape][2]
        if appearance == model.appearance:
            return False
        self._loaded_models.setdefault(shape, model)
        self._use_model(shape, model.model_copy(update={"appearance": appearance}))
        self.appearance_version += 1
        return True

    def _seen_again(self, shape: int) -> None:
        """The ray engine's flags of a shape as :func:`_entry` makes them from its model now (invisible
        at a transparency of 1, no shadow from a translucent shape), its image's format read from the
        image the sampler holds (no file read); the engine remakes its scenes only when they change."""
        model = self._parts[shape][2]
        a = model.appearance
        held = self.textures.shapes.get(shape) if self.textures is not None else None
        if a is None or a.transparency > 0.0 or a.texture is None or held is None:
            lucent = translucent(a, self._base_dir, self.images)
        else:
            lucent = held.base.translucent
        self.engine.set_shape_seen(shape, transparent=a is not None and a.transparency >= 1.0,
                                   casts_shadow=model.cast_shadows and not lucent)

    def set_texture(self, shape: int, appearance: wm.Appearance,
                    given: Mapping[str, tuple[Path, Decoded]] | None = None) -> None:
        """:meth:`set_appearance` with new images (an ImageTexture's url or wrap a Supervisor set, or
        its texture gone): the texture sampler takes them for that shape (``given``: url -> the file
        and its image as the caller read and checked it, not read again), so every sensor sees them
        from the next measurement as if the world file had named them -- shadows too: a base image
        whose pixel format has alpha makes the shape cast none (:meth:`_seen_again`)."""
        if shape in self.removed_shapes:
            return
        if self.textures is None and (appearance.texture is not None or appearance.emissive_map is not None):
            # (no shape textured until now)
            self.textures = TextureSampler([(s.geometry, s.appearance) for _, _, s in self._parts], self._base_dir,
                                           ink_evaporation=self._ink_evaporation, given=self.images)
        self._take_appearance(shape, appearance)
        if self.textures is not None:
            self.textures.set_shape(shape, appearance, given)
        self._seen_again(shape)

    def _use_model(self, shape: int, model: wm.Shape | wm.Solid) -> None:
        key, local, _ = self._parts[shape]
        self._parts[shape] = (key, local, model)
        info = _shape_info(self.shapes[shape].name, self.shapes[shape].owner, model)
        self.shapes[shape] = info
        self.red[shape], self.roughness[shape], self.transparency[shape] = info.red, info.roughness, info.transparency
        self.colors[shape] = _base_color(model)
        self._refresh_emissive(shape)

    def shape_model(self, shape: int) -> wm.Shape | wm.Solid:
        """A shape's model now (its appearance as a Supervisor last set it)."""
        return self._parts[shape][2]

    def loaded_model(self, shape: int) -> wm.Shape | wm.Solid:
        """A shape's model as the world loaded it (before any Supervisor change)."""
        return self._loaded_models.get(shape, self._parts[shape][2])

    def restore_appearances(self) -> None:
        """Every shape's appearance as loaded (``simulationReset``)."""
        kept = {shape: self._loaded_models[shape] for shape in self.removed_shapes if shape in self._loaded_models}
        for shape, model in self._loaded_models.items():
            if shape in kept:        # removed: stays removed
                continue
            retextured = self._parts[shape][2].appearance
            self._use_model(shape, model)       # a shape loaded without an appearance gets none back
            if self.textures is not None and retextured is not None and model.appearance is not None and \
                    (_maps(retextured) != _maps(model.appearance) or retextured.texture is not None):
                # (the same url may show its file read again since the load: the loaded image comes back)
                self.textures.set_shape(shape, model.appearance)
            self._seen_again(shape)
        if len(self._loaded_models) > len(kept):
            self.appearance_version += 1
        self._loaded_models = kept
        self.appearance_values.clear()

    def drawn_models(self) -> dict[int, wm.Shape | wm.Solid]:
        """The shapes whose appearance a Supervisor changed, for drawing them as they look now (the
        Foxglove scene, which walks the world's own models): ``id()`` of the model the world holds ->
        the model now. Empty while nothing changed (or after a reset)."""
        return {id(model): self._parts[shape][2] for shape, model in self._loaded_models.items()}

    def _add_body(self, parts: list, base_dir: Path, pose: Pose, owner: int, movable: bool,
                  key: str | int | None = None, entries: list[ShapeEntry] | None = None) -> int:
        if entries is None:
            entries = [_entry(shape, base_dir, local, self.images) for _, local, shape in parts]
        self._parts += [(key, local, shape) for _, local, shape in parts]
        triangles = sum(geo.triangle_count(e.primitive) for e in entries)
        self.triangle_count += triangles
        if isinstance(key, str):
            self._solid_triangles[key] = triangles
        self.shapes += [_shape_info(name, owner, shape) for name, _, shape in parts]
        return self.engine.add_body(entries, pose, owner=owner, movable=movable)

    def world_lights(self) -> list:
        """Every light model with its location and direction in world coordinates (now)."""
        out = []
        top = -1
        counts: dict[str | int, int] = {}       # each carrier's lights so far (those a Supervisor removed)
        for model, owner, local in self._lights:
            if owner is None:
                top += 1
                if top not in self.removed_lights:
                    out.append(model)
                continue
            if self.removed_carried:
                carrier = owner[0] if isinstance(owner, tuple) else owner
                k = counts[carrier] = counts.get(carrier, -1) + 1
                if (carrier, k) in self.removed_carried:
                    continue
            if isinstance(owner, tuple):      # on a joint: where its link has moved it
                displacement = self.link_poses.get(owner, _IDENTITY)
                placed = place_light(model, self.robot_poses[owner[0]].compose(displacement).compose(local))
                out.append(link_aimed(placed, displacement))
            else:
                frame = self.robot_poses[owner] if isinstance(owner, int) else self.solid_poses[owner]
                out.append(place_light(model, frame.compose(local)))
        return out

    def sensor_lights(self) -> list:
        """``world_lights`` as light sensors see them (``for_light_sensors``: a spot light's axis by
        Webots' LightSensor rule)."""
        return [for_light_sensors(m) for m in self.world_lights()]

    def set_led_lights(self, robot: int, led: str, on: bool, color: tuple[float, float, float]) -> None:
        """An LED's new state (``WbLed::setMaterialsAndLightsColor``): its lights take ``color`` and are
        on exactly when ``on``; light sensors and cameras recompute their light arrays at their next
        measurement (``lights_version``). Nothing changes (nor is recomputed) when the state is the same as
        the LED's last (``WbLed::setValue`` returns on the same value): a Supervisor's write to its lights'
        fields stays until the LED's state changes."""
        old = self._led_lights.get((robot, led))
        state = (bool(on), tuple(color))
        if not old or self._led_state.get((robot, led), (False, (0.0, 0.0, 0.0))) == state:
            return
        self._led_state[(robot, led)] = state
        new = [m.model_copy(update={"on": on, "color": color}) for m in old]
        swap = {id(a): b for a, b in zip(old, new)}
        self._lights = [(swap.get(id(m), m), owner, local) for m, owner, local in self._lights]
        self._led_lights[(robot, led)] = new
        self.lights_version += 1

    def solid_light_slots(self, name: str) -> list[int]:
        """Where top-level solid ``name``'s lights (its own, then its nested solids', as
        :func:`solid_lights`) are among the scene's lights, for :meth:`set_light_color`."""
        return [k for k, (_, owner, _) in enumerate(self._lights) if owner == name]

    def light_model(self, slot: int) -> Any:
        """A light's model now (``slot``: see :meth:`solid_light_slots`)."""
        return self._lights[slot][0]

    def set_light_color(self, slot: int, color: tuple[float, float, float]) -> None:
        """A light's colour now (a Charger's, ``WbLight::setColor``): light sensors and cameras
        recompute their light arrays at their next measurement (``lights_version``); nothing changes
        when it is the same."""
        model, owner, local = self._lights[slot]
        if tuple(model.color) == tuple(color):
            return
        self._lights[slot] = (model.model_copy(update={"color": tuple(color)}), owner, local)
        self.lights_version += 1

    def carried_light_slots(self, owner: str | int) -> list[int]:
        """Where robot ``owner``'s lights (its index: its own ``lights``, then its LEDs') or top-level solid
        ``owner``'s (its name: :func:`solid_lights` order) are among the scene's lights now."""
        return [k for k, (_, o, _) in enumerate(self._lights)
                if o == owner or (isinstance(o, tuple) and o[0] == owner)]

    def set_carried_light(self, owner: str | int, index: int, model: object) -> None:
        """Replace light ``index`` of a robot or top-level solid (:meth:`carried_light_slots`; a Supervisor
        field change, its ``location``/``direction`` in the owner's frame): it keeps its carrier and frame;
        light sensors and cameras recompute their light arrays at their next measurement
        (``lights_version``). The light as loaded comes back at :meth:`restore_carried_lights`."""
        slot = self.carried_light_slots(owner)[index]
        old, carrier, local = self._lights[slot]
        if (owner, index) not in self._set_carried:
            loaded = [m for m, o, _ in self._loaded_lights if o == owner or (isinstance(o, tuple) and o[0] == owner)]
            self._set_carried[(owner, index)] = loaded[index] if index < len(loaded) else old
        self._lights[slot] = (model, carrier, local)
        self._led_swap(old, model)
        self.lights_version += 1

    def _led_swap(self, old: object, new: object) -> None:
        """An LED's light replaced (a Supervisor's set): the LED's next state change starts from it."""
        for models in self._led_lights.values():
            for j, m in enumerate(models):
                if m is old:
                    models[j] = new
                    return

    def changed_carried(self) -> set[tuple[str | int, int]]:
        """The (owner, index) of the carried lights a Supervisor set or removed."""
        return set(self._set_carried) | self.removed_carried

    def remove_carried_light(self, owner: str | int, index: int) -> None:
        """Take light ``index`` of a robot or top-level solid out for good (a Supervisor's ``node.remove()``):
        light sensors and cameras stop counting it at their next measurement (``lights_version``); the
        others keep their indices (its slot stays, unlit by :meth:`world_lights`)."""
        if (owner, index) not in self.removed_carried:
            self.removed_carried.add((owner, index))
            self.lights_version += 1

    def restore_carried_lights(self) -> None:
        """The lights :meth:`set_carried_light` changed, as loaded (a simulation reset: an LED's off and
        black, as its reset leaves them; those of a removed solid stay gone)."""
        for (owner, index), model in self._set_carried.items():
            slots = self.carried_light_slots(owner)
            if index < len(slots):
                now, carrier, local = self._lights[slots[index]]
                self._lights[slots[index]] = (model, carrier, local)
                self._led_swap(now, model)
        if self._set_carried:
            self._set_carried.clear()
            self.lights_version += 1

    def top_lights(self) -> list:
        """The world's top-level light models (the world file's ``lights``, in order; the Supervisor's
        light nodes)."""
        return [model for model, owner, _ in self._lights if owner is None]

    def set_top_light(self, index: int, model: object) -> None:
        """Replace top-level light ``index`` (a Supervisor field change): light sensors and cameras
        recompute their light arrays at their next measurement (``lights_version``)."""
        k = [i for i, (_, owner, _) in enumerate(self._lights) if owner is None][index]
        self._lights[k] = (model, None, Pose.identity())
        self.lights_version += 1

    def remove_top_light(self, index: int) -> None:
        """Take top-level light ``index`` out for good (a Supervisor's ``node.remove()``): light
        sensors and cameras stop counting it at their next measurement (``lights_version``). Its
        index stays its own (``top_lights`` keeps every loaded light; the Supervisor's ids are stable)."""
        if index not in self.removed_lights:
            self.removed_lights.add(index)
            self.lights_version += 1

    def remove_solid(self, name: str) -> None:
        """Take top-level solid ``name`` out for good (a Supervisor's ``node.remove()``): its body
        leaves the ray engine (every ray kind stops seeing it at the next cast), its pose leaves
        ``solid_poses`` (topics and scene views), recognition stops listing it and lights it carries
        go out. Its shape ids stay (never reused)."""
        if name not in self.solid_poses:
            raise KeyError(name)
        del self.solid_poses[name]
        self.solids_version += 1
        body = self._solid_body.pop(name, None)
        if body is not None:
            dead = self.engine.body_shapes(body)
            self.engine.remove_body(body)
            self._forget_shapes(dead)
        self.triangle_count -= self._solid_triangles.pop(name, 0)
        self.recognisable.pop(name, None)
        for key in [k for k in self.carried_targets if k[0] == name]:
            del self.carried_targets[key]
        for key in [k for k in self.radar_targets if k == name or (isinstance(k, tuple) and k[0] == name)]:
            del self.radar_targets[key]
        if name in self._attached:
            self._lights = [entry for entry in self._lights if entry[1] != name]
            self._attached.discard(name)
            self.lights_version += 1
        for key in [k for k in self._set_carried if k[0] == name]:     # (a solid built again starts afresh)
            del self._set_carried[key]
        self.removed_carried = {k for k in self.removed_carried if k[0] != name}

    def _forget_shapes(self, dead: list[int]) -> None:
        """The shapes of a removed body let go: what was kept per shape (a Supervisor's appearance changes,
        the world-to-shape poses) dropped; when the engine freed the last shapes' numbers (every body after
        them removed too), every per-shape list and array ends where the engine's shapes now end, so the
        next import numbers its shapes there again (a fresh world's numbers); a shape followed by one still
        there keeps its number, its entry pointing at no owner and no model (recognition, radar and the
        texture sampler skip it; no ray reaches it)."""
        for shape in dead:
            self._inverse.pop(shape, None)
            self._loaded_models.pop(shape, None)
            self.appearance_values.pop(shape, None)
            self.removed_shapes.discard(shape)
        n = self.engine.shape_count
        kept = [shape for shape in dead if shape < n]
        for shape in kept:
            self._parts[shape] = (None, _IDENTITY, _NO_MODEL)
        if self.textures is not None:
            self.textures.forget(kept, n)
        if n < len(self.shapes):
            del self.shapes[n:], self._parts[n:]
            self._glow = {k: c for k, c in self._glow.items() if k < n}
            self.red = np.append(self.red[:n], self.red[-1])
            self.roughness = np.append(self.roughness[:n], self.roughness[-1])
            self.colors = np.concatenate([self.colors[:n], self.colors[-1:]])
            self.transparency = np.append(self.transparency[:n], self.transparency[-1])
            self._rebuild_emissive()
            self.shapes_version += 1

    def solid_entries(self, solid: wm.Solid) -> tuple[list, list[ShapeEntry]]:
        """A top-level solid's parts (``solid_parts``) and their ray-engine entries, built before
        anything changes (a mesh that cannot be read raises here, the scene untouched)."""
        parts = list(solid_parts(solid, Pose.identity()))
        return parts, [_entry(shape, self._base_dir, local, self.images) for _, local, shape in parts]

    def solid_triangles(self, name: str) -> int:
        """The triangles of top-level solid ``name``'s body (0 for a removed one)."""
        return self._solid_triangles.get(name, 0)

    def add_solid(self, solid: wm.Solid, node_id: int, prepared: tuple[list, list[ShapeEntry]] | None = None,
                  again: bool = False) -> None:
        """A top-level solid a Supervisor imported (``importMFNodeFromString``): its body joins the
        ray engine (every ray kind sees it from the next cast), its pose ``solid_poses``, its
        lights the light arrays, its recognition colours the cameras' objects (as Supervisor node
        ``node_id``). Its shape ids follow the shapes numbered now (the numbers of the last bodies removed
        are taken again: :meth:`_forget_shapes`). ``again``: a
        solid built again under the name of one just removed (a PROTO field set), keeping its place."""
        name = solid.name
        if name in self.solid_poses or (name in self.solid_name_set) != again:
            raise KeyError(f"a solid named {name!r} exists or existed" if not again else f"no removed solid {name!r}")
        parts, entries = prepared if prepared is not None else self.solid_entries(solid)
        pose = pose_from_model(solid.pose)
        self._nested_targets(solid)
        if not again:
            self.solid_names.append(name)
            self.solid_name_set.add(name)
        self.solid_poses[name] = pose
        self.solids_version += 1
        if parts:
            cone = any(isinstance(shape.geometry, wm.Cone) for _, _, shape in parts)
            self._solid_body[name] = self._add_body(parts, self._base_dir, pose, owner=-1, movable=cone, key=name,
                                                    entries=entries)
            self._shape_arrays()
            models = [(shape.geometry, shape.appearance) for _, _, shape in parts]
            if self.textures is not None:
                self.textures.extend(models)
            elif any(a is not None and (a.texture is not None or a.emissive_map is not None) for _, a in models):
                self.textures = TextureSampler([(s.geometry, s.appearance) for _, _, s in self._parts], self._base_dir,
                                               ink_evaporation=self._ink_evaporation, given=self.images)
            self.shapes_version += 1
        carried = [(lt, name, f) for lt, f in solid_lights(solid, Pose.identity())]
        if carried:
            self._lights += carried
            self._attached.add(name)
            self.lights_version += 1
        if solid.recognition_colors:
            self.recognisable[name] = (node_id, [tuple(c) for c in solid.recognition_colors], solid.model)
        self.radar_targets.update(solid_radar_targets(solid))

    def add_top_light(self, model: object) -> int:
        """A top-level light a Supervisor imported: light sensors and cameras count it from their
        next measurement. Returns its index among the top-level lights (after every existing one)."""
        index = len(self.top_lights())
        self._lights.append((model, None, Pose.identity()))
        self.lights_version += 1
        return index

    def device_shapes(self, robot: int, device: str) -> frozenset[int]:
        """The shapes (``Scene.shapes`` indices) of a device's own Solid (``of_device``) and those
        turned away from it (``unseen_by``), which its visual rays do not see (sim/own_shapes.py)."""
        return self._device_shapes.get((robot, device), frozenset())

    def robot_body(self, index: int) -> int | None:
        """The engine body of robot ``index`` (None for a robot without a body)."""
        return self._robot_body.get(index)

    def device_body(self, index: int, joint: str | None) -> int | None:
        """The engine body a device of robot ``index`` is rigidly mounted on: its joint's link
        (``joint``: the device's ``on_joint``; None when that link has no shapes), else the robot's."""
        return self._robot_body.get(index) if joint is None else self._link_body.get((index, joint))

    def set_robot_pose(self, index: int, pose: Pose) -> None:
        self.robot_poses[index] = pose
        if index in self._attached:
            self.lights_version += 1
        body = self._robot_body.get(index)
        if body is not None:
            self.engine.set_body_pose(body, pose)
        if self._link_body:
            for (r, joint), link in self._link_body.items():
                if r == index:
                    self.engine.set_body_pose(link, pose.compose(self.link_poses.get((r, joint), _IDENTITY)))

    def set_link_pose(self, index: int, joint: str, displacement: Pose) -> None:
        """Joint ``joint`` of robot ``index`` moved: what rides on it is ``displacement`` (robot frame)
        from where the world file placed it (sim/joints.py ``Links``)."""
        self.link_poses[(index, joint)] = displacement
        if (index, joint) in self._light_links:
            self.lights_version += 1
        body = self._link_body.get((index, joint))
        if body is not None:
            self.engine.set_body_pose(body, self.robot_poses[index].compose(displacement))

    def set_solid_pose(self, name: str, pose: Pose) -> None:
        if name not in self.solid_poses:
            raise KeyError(name)
        if pose is not self.solid_poses[name]:     # a reset hands back the same pose of a solid never moved
            self.solids_version += 1
        self.solid_poses[name] = pose
        if name in self._attached:
            self.lights_version += 1
        if name in self._solid_body:
            self.engine.set_body_pose(self._solid_body[name], pose)

    def move_shapes(self, moved: dict[int, tuple[Pose, wm.Shape | wm.Solid]]) -> None:
        """Shapes of a top-level solid placed anew in its frame (a Supervisor set a Pose inside it, only shapes
        under it): shape -> (its pose in the solid's frame, its model as the solid now loads it). Each keeps
        its number, its entries and the appearance a Supervisor gave it; every ray kind sees it there from the
        next cast, as the solid built again would show it."""
        for shape, (local, model) in moved.items():
            key, _, now = self._parts[shape]
            if shape in self._loaded_models:       # (its look a Supervisor's: the loaded model is the new one)
                self._loaded_models[shape] = model
                model = now.model_copy(update={"pose": getattr(model, "pose", None)})
            self._parts[shape] = (key, local, model)
            self._inverse.pop(shape, None)
        self.engine.set_shape_poses({shape: local for shape, (local, _) in moved.items()})
        self.solids_version += 1
        self.shapes_version += 1

    def _carrier(self, shape: int, key: str | int) -> Pose:
        """The pose a shape is fixed in: its owner's, or a robot's composed with its link's."""
        owner = self.robot_poses[key] if isinstance(key, int) else self.solid_poses[key]
        link = self._shape_link.get(shape) if self._shape_link else None
        if link is not None and link in self.link_poses:
            kept = self._link_frames.get(link)
            displacement = self.link_poses[link]
            if kept is None or kept[0] is not owner or kept[1] is not displacement:
                kept = self._link_frames[link] = (owner, displacement, owner.compose(displacement))
            return kept[2]
        return owner

    def on_link(self, shape: int) -> bool:
        """Whether a shape rides on a joint's link (``on_joint``): ``carrier`` places it then."""
        return shape in self._shape_link

    def carrier(self, shape: int) -> Pose:
        """The pose a shape is fixed in now: its owner's, on a joint its owner's ∘ its link's."""
        return self._carrier(shape, self._parts[shape][0])  # type: ignore[arg-type]

    def shape_pose(self, shape: int) -> Pose:
        """The world pose of a shape now (its owner's pose ∘ its link's, on a joint ∘ its frame)."""
        key, local, _ = self._parts[shape]
        return self._carrier(shape, key).compose(local)

    def _world_to_shape(self, shape: int) -> Pose:
        """The inverse of a shape's world pose, kept while its owner's pose object is the same."""
        key, local, _ = self._parts[shape]
        owner = self._carrier(shape, key)
        kept = self._inverse.get(shape)
        if kept is None or kept[0] is not owner:
            kept = self._inverse[shape] = (owner, owner.compose(local).inverse())
        return kept[1]

    def paint(self, shape: int, origin: np.ndarray, direction: np.ndarray, distance: float, lead_size: float,
              color, density: float) -> int:
        """A pen's stroke where its ray (world frame) hit ``shape`` at ``distance``: ink laid in the
        shape's ink layer (textures.InkLayer), made on the first stroke; returns the texels inked."""
        if self.textures is None:
            self.textures = TextureSampler([(shape_.geometry, shape_.appearance) for _, _, shape_ in self._parts],
                                           self._base_dir, ink_evaporation=self._ink_evaporation, given=self.images)
        inv = self._world_to_shape(shape)
        return self.textures.paint(shape, inv.apply(np.asarray(origin, dtype=np.float64)),
                                   inv.apply_dirs(np.asarray(direction, dtype=np.float64)), float(distance),
                                   lead_size, color, density)

    def evaporate_ink(self, step_ms: float) -> None:
        """One basic step of the world's ink evaporation (``world_info.ink_evaporation``)."""
        if self.textures is not None and self._ink_evaporation > 0.0:
            self.textures.evaporate_ink(step_ms)

    def clear_ink(self) -> None:
        """All ink gone (a simulation reset, as Webots' Pen reset clears every paint texture)."""
        if self.textures is not None:
            self.textures.clear_ink()

    def part(self, shape: int) -> tuple[str | int | None, Pose, wm.Shape | wm.Solid]:
        """A shape's owner (solid name, robot index), its frame in the owner and its model."""
        return self._parts[shape]

    def owner_pose(self, key: str | int) -> Pose:
        """The pose of a shape owner: a robot (index) or a top-level solid (name)."""
        return self.robot_poses[key] if isinstance(key, int) else self.solid_poses[key]

    def target_pose(self, key: TargetKey) -> Pose:
        """A radar target's pose now: a robot's or top-level solid's, or that of a solid inside one (on a
        robot's joint, where the joint has put it)."""
        if not isinstance(key, tuple):
            return self.owner_pose(key)
        local, joint, _ = self.carried_targets[key]
        frame = self.owner_pose(key[0])
        if joint is not None:
            frame = frame.compose(self.link_poses.get((key[0], joint), _IDENTITY))   # type: ignore[index]
        return frame.compose(local)

    def target_shapes(self, key: TargetKey) -> tuple[int, ...]:
        """A radar target's shapes (``shapes`` indices): every shape of a robot or top-level solid, a
        solid's inside one its own (and those of the solids inside it)."""
        if isinstance(key, tuple):
            return self.carried_targets[key][2]
        return tuple(i for i in range(len(self.shapes)) if self._parts[i][0] == key)

    def surface_colors(self, shape: np.ndarray, origins: np.ndarray, directions: np.ndarray,
                       distance: np.ndarray, glow: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """The albedo (n, 3) a camera sees at hits (world frame; shape −1: white): see
        :func:`surface_colors` (``glow`` too)."""
        return surface_colors(self.colors, self.textures, self._world_to_shape, shape, origins, directions, distance,
                              glow)

    def receives_shadows(self, shape: np.ndarray) -> np.ndarray:
        """:func:`receives_shadows` of hits on this scene's shapes."""
        return receives_shadows(self.transparency, self.translucent_shapes, shape)

    @property
    def translucent_shapes(self) -> np.ndarray | None:
        """Per shape (−1 last, False): whether its base image's pixel format has alpha (even 255
        everywhere: WREN draws it translucent, without shadows); None in a world without any."""
        t = self.textures
        return t.translucent if t is not None and t.has_translucent else None

    @property
    def alpha_shapes(self) -> np.ndarray | None:
        """Per shape (−1 last, False): whether its image has transparent texels; None in a world
        without any (cameras then composite only what ``transparency`` asks for)."""
        t = self.textures
        return t.alpha if t is not None and t.has_alpha else None

    def surface_opacity(self, shape: np.ndarray, origins: np.ndarray, directions: np.ndarray,
                        distance: np.ndarray) -> np.ndarray:
        """The texture alpha (n,) a camera sees at hits: see :func:`surface_opacity`."""
        assert self.textures is not None
        return surface_opacity(self.textures, self._world_to_shape, shape, origins, directions, distance)

    def infra_red_terms(self, shape: np.ndarray, origins: np.ndarray, directions: np.ndarray,
                        distance: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(red, roughness, occlusion) an infra-red ray reads at its hit: see :func:`infra_red_terms`."""
        return infra_red_terms(self.red, self.roughness, self.textures, self._world_to_shape, shape, origins,
                               directions, distance)
