"""Typed access to the fields of a parsed .wbt node, and node-to-model pieces that need no context:
geometry, appearance, lights, devices. Defaults are those of Webots' reference manual; a field of
the wrong shape is an error naming file, line and column."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from sensorium.server.world.wbt import resets
from sensorium.server.world.wbt.parser import Node, WbtSyntaxError

# told of each value Webots would reset: (node, field, "Sphere.radius: 0 is not > 0; using 1 (as Webots does)")
Reset = Callable[[Node, str, str], None]


class Fields:
    """Typed getters on one node; errors point at the field (or the node when it is absent).

    The checked getters (``positive``, ``within``, ``color``, ...) apply Webots' resets (resets.py):
    a value Webots would not use is replaced by the one it uses and ``reset`` is told; without a
    ``reset`` to tell, such a value is an error."""

    def __init__(self, node: Node, source: str, reset: Reset | None = None):
        self.node = node
        self.source = source
        self.reset = reset

    def sub(self, node: Node) -> Fields:
        """The fields of a node held by this one (its Material, Recognition, ...), told alike."""
        return Fields(node, node.source or self.source, self.reset)

    def used(self, name: str, written: Any, used: Any, why: str) -> Any:
        """``used`` in place of ``written`` (``why``: what is wrong with it; "" when nothing is),
        ``reset`` told; an error when there is no ``reset`` to tell."""
        if not why:
            return used
        if self.reset is None:
            raise self.error(name, f"{resets.shown(written)} {why}")
        self.reset(self.node, name, f"{self.node.type}.{name}: {resets.shown(written)} {why}; "
                                    f"using {resets.shown(used)} (as Webots does)")
        return used

    def positive(self, name: str, default: float, reset: float = 1.0) -> float:
        """A number that must be > 0 (else ``reset``)."""
        v = self.num(name, default)
        return float(self.used(name, v, *resets.positive(v, reset)))

    def non_negative(self, name: str, default: float, reset: float = 0.0) -> float:
        """A number that must be >= 0 (else ``reset``)."""
        v = self.num(name, default)
        return float(self.used(name, v, *resets.non_negative(v, reset)))

    def within(self, name: str, default: float, lo: float, hi: float, reset: float) -> float:
        """A number within [lo, hi] (else ``reset``)."""
        v = self.num(name, default)
        return float(self.used(name, v, *resets.within(v, lo, hi, reset)))

    def positive_vec(self, name: str, default: tuple[float, ...], reset: tuple[float, ...]) -> tuple[float, ...]:
        """A vector whose components must all be > 0 (else the whole of it is ``reset``)."""
        v = self.vec(name, default)
        return tuple(self.used(name, v, *resets.positive_vector(v, reset)))

    def color(self, name: str, default: tuple[float, float, float]) -> tuple[float, ...]:
        """An SFColor, each component clamped to [0, 1]."""
        v = self.vec(name, default)
        return tuple(self.used(name, v, *resets.color(v)))

    def colors(self, name: str, default: list[tuple[float, ...]]) -> list[tuple[float, ...]]:
        """An MFColor, each component of each colour clamped to [0, 1] (one message for the field)."""
        rows = self.rows(name, 3, default)
        fixed = [resets.color(r)[0] for r in rows]
        if fixed != [tuple(r) for r in rows]:
            flat = [x for r in rows for x in r]
            self.used(name, flat, [x for r in fixed for x in r], "has components outside [0, 1]")
        return fixed

    def error(self, name: str | None, message: str) -> WbtSyntaxError:
        line, col = self.node.field_pos.get(name, (self.node.line, self.node.col)) if name else (self.node.line, self.node.col)
        where = f"{self.node.type}.{name}" if name else self.node.type
        return WbtSyntaxError(self.source, line, col, f"{where}: {message}")

    def has(self, name: str) -> bool:
        return name in self.node.fields

    def num(self, name: str, default: float) -> float:
        v = self.node.fields.get(name, default)
        if isinstance(v, bool) or not isinstance(v, float | int):
            raise self.error(name, f"expected one number, got {_show(v)}")
        return float(v)

    def integer(self, name: str, default: int) -> int:
        v = self.num(name, default)
        if v != int(v):
            raise self.error(name, f"expected an integer, got {v}")
        return int(v)

    def integers(self, name: str) -> list[int]:
        """An MFInt32 field (``coordIndex``): every value a whole number."""
        nums = self.numbers(name)
        try:
            out = list(map(int, nums))
            if out == nums:     # every one whole (compared at C speed)
                return out
        except (ValueError, OverflowError):
            pass
        out = []
        for v in nums:
            if v != int(v):
                raise self.error(name, f"expected integers, got {v}")
            out.append(int(v))
        return out

    def index_array(self, name: str) -> np.ndarray | list[int]:
        """``integers`` as one int64 array (a mesh's ``coordIndex``: no Python int per entry); the list
        ``integers`` gives, with its error, when some value is not whole or beyond 64 bits."""
        a = self.number_array(name)
        if a.size == 0 or (np.abs(a).max() < 2.0 ** 63 and np.array_equal(a, np.trunc(a))):
            return a.astype(np.int64)
        return self.integers(name)

    def number_array(self, name: str) -> np.ndarray:
        """``numbers`` as one float64 array, the same values (a long run as parsed: read at C speed,
        without the list copy)."""
        v = self.node.fields.get(name, [])
        if isinstance(v, list) and set(map(type, v)) == {float}:
            return np.array(v, dtype=np.float64)
        return np.array(self.numbers(name), dtype=np.float64)

    def row_array(self, name: str, width: int) -> np.ndarray:
        """``flat_rows`` as a float64 array of shape (n, width) (an absent field: none), the same error."""
        flat = self.number_array(name)
        if len(flat) % width:
            raise self.error(name, f"expected groups of {width} numbers, got {len(flat)} numbers")
        return flat.reshape(-1, width)

    def vec(self, name: str, default: tuple[float, ...]) -> tuple[float, ...]:
        v = self.node.fields.get(name, default)
        if isinstance(v, float | int) and not isinstance(v, bool):
            v = (float(v),)
        if not isinstance(v, tuple) or len(v) != len(default):
            raise self.error(name, f"expected {len(default)} numbers, got {_show(v)}")
        return tuple(float(x) for x in v)

    def flag(self, name: str, default: bool) -> bool:
        v = self.node.fields.get(name, default)
        if not isinstance(v, bool):
            raise self.error(name, f"expected TRUE or FALSE, got {_show(v)}")
        return v

    def string(self, name: str, default: str) -> str:
        v = self.node.fields.get(name, default)
        if isinstance(v, list) and len(v) == 1 and isinstance(v[0], str):
            v = v[0]
        if not isinstance(v, str):
            raise self.error(name, f"expected a string, got {_show(v)}")
        return v

    def strings(self, name: str) -> list[str]:
        v = self.node.fields.get(name, [])
        if isinstance(v, str):
            v = [v]
        if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
            raise self.error(name, f"expected a list of strings, got {_show(v)}")
        return v

    def node_(self, name: str) -> Node | None:
        v = self.node.fields.get(name)
        if v is None:
            return None
        if isinstance(v, list) and len(v) == 1 and isinstance(v[0], Node):
            v = v[0]
        if not isinstance(v, Node):
            raise self.error(name, f"expected a node or NULL, got {_show(v)}")
        return v

    def nodes(self, name: str) -> list[Node]:
        v = self.node.fields.get(name, [])
        if isinstance(v, Node):
            v = [v]
        if not isinstance(v, list) or not all(isinstance(x, Node) for x in v):
            raise self.error(name, f"expected a list of nodes, got {_show(v)}")
        return v

    def numbers(self, name: str) -> list[float]:
        """An MF field of numbers, flattened (``[ 0 0 0, 1 1 0 ]`` → six numbers)."""
        v = self.node.fields.get(name, [])
        if isinstance(v, list) and set(map(type, v)) == {float}:     # a long run as parsed: copied at C speed
            return list(v)
        out: list[float] = []
        for x in v if isinstance(v, list) else [v]:
            if isinstance(x, tuple):
                out += x
            elif isinstance(x, float | int) and not isinstance(x, bool):
                out.append(float(x))
            else:
                raise self.error(name, f"expected numbers, got {_show(x)}")
        return out

    def rows(self, name: str, width: int, default: list[tuple[float, ...]]) -> list[tuple[float, ...]]:
        if name not in self.node.fields:
            return default
        flat = self.flat_rows(name, width)
        return list(zip(*[iter(flat)] * width))       # consecutive groups of width

    def flat_rows(self, name: str, width: int) -> list[float]:
        """``rows``' numbers, not grouped (an absent field: none)."""
        flat = self.numbers(name)
        if len(flat) % width:
            raise self.error(name, f"expected groups of {width} numbers, got {len(flat)} numbers")
        return flat


def _projection(f: Fields) -> str:
    """A Camera's or RangeFinder's projection; an unknown one is planar (WbAbstractCamera::updateProjection)."""
    projection = f.string("projection", "planar")
    if projection not in ("planar", "spherical", "cylindrical"):
        projection = f.used("projection", projection, "planar", "is not planar, spherical or cylindrical")
    return projection


def _field_of_view(f: Fields, projection: str, default: float) -> float:
    """A camera's, range finder's or lidar's fieldOfView: a non-positive one, or one over pi with a
    planar projection, is 0.7854 (WbAbstractCamera::updateFieldOfView)."""
    fov = f.positive("fieldOfView", default, 0.7854)
    if projection == "planar" and fov > math.pi:
        fov = f.used("fieldOfView", fov, 0.7854, "is > pi with a planar projection")
    return fov


def _image(f: Fields, spherical_as: str) -> dict:
    """What a Camera and a RangeFinder read alike (WbAbstractCamera): fieldOfView, width, height,
    projection, near and lens, each reset as Webots resets it; R2023's deprecated ``spherical TRUE`` on a
    planar one reads as ``spherical_as`` (WbCamera::init / WbRangeFinder::init)."""
    projection = _projection(f)
    if f.flag("spherical", False) and projection == "planar":
        projection = spherical_as
    out = {"field_of_view": _field_of_view(f, projection, 0.785398),
           "width": _positive_int(f, "width", 64, 1), "height": _positive_int(f, "height", 64, 1),
           "projection": projection, "near": f.positive("near", 0.01, 0.01)}
    lens = _lens(f)
    if lens is not None:
        out["lens"] = lens
    return out


def _child(f: Fields, field: str, node_type: str) -> Fields | None:
    """The fields of the SFNode ``field``, which must be a ``node_type`` node or NULL (None)."""
    node = f.node_(field)
    if node is None:
        return None
    if node.type != node_type:
        raise f.error(field, f"expected a {node_type} node or NULL, got a {node.type} node")
    return f.sub(node)


def _lens(f: Fields) -> dict | None:
    """A Camera's or RangeFinder's Lens node (Webots' defaults), or None (NULL). Its centre is
    left to the loader, which resets it as Webots does (loader.lens_center_reset)."""
    lf = _child(f, "lens", "Lens")
    if lf is None:
        return None
    return {"center": list(lf.vec("center", (0.5, 0.5))),
            "radial_coefficients": list(lf.vec("radialCoefficients", (0.0, 0.0))),
            "tangential_coefficients": list(lf.vec("tangentialCoefficients", (0.0, 0.0)))}


def _zoom(f: Fields) -> dict | None:
    """A Camera's Zoom node (Webots' defaults 0.5 and 1.5 rad), or None (NULL): a negative
    minFieldOfView is 0 and one above maxFieldOfView is maxFieldOfView, as WbZoom resets them."""
    zf = _child(f, "zoom", "Zoom")
    if zf is None:
        return None
    low, high = zf.non_negative("minFieldOfView", 0.5, 0.0), zf.num("maxFieldOfView", 1.5)
    if low > high:
        low = zf.used("minFieldOfView", low, high, f"is > maxFieldOfView {high:g}")
    return {"min_field_of_view": low, "max_field_of_view": high}


def _focus(f: Fields) -> dict | None:
    """A Camera's Focus node (Webots' defaults 0), or None (NULL); a negative value is 0, as WbFocus resets it."""
    ff = _child(f, "focus", "Focus")
    if ff is None:
        return None
    return {"focal_distance": ff.non_negative("focalDistance", 0.0, 0.0),
            "focal_length": ff.non_negative("focalLength", 0.0, 0.0),
            "min_focal_distance": ff.non_negative("minFocalDistance", 0.0, 0.0),
            "max_focal_distance": ff.non_negative("maxFocalDistance", 0.0, 0.0)}


def _max_range(f: Fields, min_range: float, default: float) -> float:
    """A lidar's maxRange: one not above minRange is minRange + 1 (WbLidar::updateMaxRange)."""
    max_range = f.num("maxRange", default)
    if max_range <= min_range:
        max_range = f.used("maxRange", max_range, min_range + 1.0, f"is not > minRange {min_range:g}")
    return max_range


def _positive_int(f: Fields, name: str, default: int, reset: int) -> int:
    """An SFInt32 that must be > 0 (else ``reset``, told as ``Fields.positive``)."""
    value = f.integer(name, default)
    return int(f.positive(name, default, reset)) if value <= 0 else value


def _show(v: Any) -> str:
    if isinstance(v, Node):
        return f"a {v.type} node"
    if isinstance(v, tuple):
        return f"{len(v)} numbers"
    if isinstance(v, list):
        return f"a list of {len(v)}"
    return repr(v)


# ---------------------------------------------------------------- lights and devices

def light(node: Node, f: Fields) -> dict:
    out: dict[str, Any] = {"type": node.type,
                           "ambient_intensity": f.num("ambientIntensity", 0.0),
                           "intensity": f.num("intensity", 1.0),
                           "color": list(f.vec("color", (1.0, 1.0, 1.0))),
                           "on": f.flag("on", True),
                           "cast_shadows": f.flag("castShadows", False)}
    if node.type != "DirectionalLight":
        attenuation = f.vec("attenuation", (1.0, 0.0, 0.0))
        if min(attenuation) < 0:     # Webots makes it 0 0 0 (WbPointLight::updateAttenuation): no finite light
            raise f.error("attenuation", f"{resets.shown(attenuation)} has a negative component: Webots resets it to "
                                         "0 0 0, an infinite irradiance, which is refused here (1 0 0 is no attenuation)")
        out["attenuation"] = list(attenuation)
        out["location"] = list(f.vec("location", (0.0, 0.0, 0.0)))
        out["radius"] = f.non_negative("radius", 100.0, 0.0)      # WbPointLight/WbSpotLight::updateRadius
    if node.type != "PointLight":
        out["direction"] = list(f.vec("direction", (0.0, 0.0, -1.0)))
    if node.type == "SpotLight":
        out["beam_width"] = f.num("beamWidth", 1.570796)
        out["cut_off_angle"] = f.num("cutOffAngle", 0.785398)
    return out


def device(node: Node, f: Fields) -> dict:
    """Device fields (not its name or pose) in the world format's names."""
    t = node.type
    if t == "DistanceSensor":
        return {"device": t, "lookup_table": [list(r) for r in f.rows("lookupTable", 3, [(0.0, 0.0, 0.0), (0.1, 1000.0, 0.0)])],
                "type": f.string("type", "generic"), "number_of_rays": f.integer("numberOfRays", 1),
                "aperture": f.num("aperture", 1.5708), "gaussian_width": f.num("gaussianWidth", 1.0),
                "resolution": f.num("resolution", -1.0), "red_color_sensitivity": f.num("redColorSensitivity", 1.0)}
    if t == "LightSensor":
        return {"device": t, "lookup_table": [list(r) for r in f.rows("lookupTable", 3, [(0.0, 0.0, 0.0), (1.0, 1000.0, 0.0)])],
                "color_filter": list(f.color("colorFilter", (1.0, 1.0, 1.0))), "occlusion": f.flag("occlusion", False),
                "resolution": f.num("resolution", -1.0)}
    # Webots' resets (WbAbstractCamera, WbLidar, WbRangeFinder, WbCamera, WbRenderingDevice update
    # functions): a non-positive near or minRange is 0.01, a negative noise 0, ...
    if t == "Lidar":
        projection = f.string("projection", "cylindrical")
        lidar_type = f.string("type", "fixed")
        if lidar_type.lower() not in ("fixed", "rotating"):       # WbLidar::updateType
            lidar_type = f.used("type", lidar_type, "fixed", "is neither fixed nor rotating")
        vertical = f.positive("verticalFieldOfView", 0.2, 0.1)   # WbLidar::updateVerticalFieldOfView
        if vertical > math.pi:
            vertical = f.used("verticalFieldOfView", vertical, math.pi, "is > pi")
        min_range = f.positive("minRange", 0.01, 0.01)
        min_frequency = f.positive("minFrequency", 1.0, 0.01)
        return {"device": t, "tilt_angle": f.num("tiltAngle", 0.0),
                "horizontal_resolution": _positive_int(f, "horizontalResolution", 512, 1),
                "field_of_view": _field_of_view(f, projection, 1.5708), "vertical_field_of_view": vertical,
                "number_of_layers": _positive_int(f, "numberOfLayers", 4, 1), "near": f.positive("near", 0.01, 0.01),
                "min_range": min_range, "max_range": _max_range(f, min_range, 1.0),
                "type": lidar_type, "projection": projection,
                "noise": f.non_negative("noise", 0.0, 0.0), "resolution": f.num("resolution", -1.0),
                "default_frequency": f.positive("defaultFrequency", 10.0, min_frequency), "min_frequency": min_frequency,
                "max_frequency": f.positive("maxFrequency", 25.0, min_frequency)}
    if t == "RangeFinder":
        return {"device": t, **_image(f, "cylindrical"),
                "min_range": f.positive("minRange", 0.01, 0.01), "max_range": f.num("maxRange", 1.0),
                "noise": f.non_negative("noise", 0.0, 0.0), "resolution": f.num("resolution", -1.0),
                "motion_blur": f.non_negative("motionBlur", 0.0, 0.0)}
    if t == "Camera":
        out = {"device": t, **_image(f, "spherical"),
               "far": f.non_negative("far", 0.0, 0.0), "exposure": f.non_negative("exposure", 1.0, 1.0),
               "anti_aliasing": f.flag("antiAliasing", False), "noise": f.non_negative("noise", 0.0, 0.0),
               "motion_blur": f.non_negative("motionBlur", 0.0, 0.0)}
        rec = f.node_("recognition")
        if rec is not None:
            rf = f.sub(rec)
            out["recognition"] = {"max_range": rf.num("maxRange", 100.0), "max_objects": rf.integer("maxObjects", -1),
                                  "occlusion": rf.integer("occlusion", 1), "frame_color": list(rf.color("frameColor", (1.0, 0.0, 0.0))),
                                  "frame_thickness": rf.integer("frameThickness", 1),
                                  "segmentation": rf.flag("segmentation", False)}
        zoom = _zoom(f)
        if zoom is not None:
            out["zoom"] = zoom
        focus = _focus(f)
        if focus is not None:
            out["focus"] = focus
        return out
    if t == "PositionSensor":
        return {"device": t, "noise": f.num("noise", 0.0), "resolution": f.num("resolution", -1.0)}
    if t == "LED":
        colours = f.colors("color", [(1.0, 0.0, 0.0)])
        return {"device": t, "color": [list(c) for c in colours], "gradual": f.flag("gradual", False)}
    raise AssertionError(t)


def pen(f: Fields) -> dict:
    """A Pen's fields in the world format's names (Webots' defaults; its colour clamped to [0, 1]
    as an SFColor is, with a warning; its density left to the loader's Webots clamping)."""
    colour = list(f.color("inkColor", (0.0, 0.0, 0.0)))
    return {"ink_color": colour, "ink_density": f.num("inkDensity", 0.5), "lead_size": max(f.num("leadSize", 0.002), 0.0),
            "max_distance": f.num("maxDistance", 0.0), "write": f.flag("write", True)}


def display(f: Fields) -> dict:
    """A Display's size (Display.wrl: 64 × 64; below 1 set to 1 with a warning, as
    WbRenderingDevice::updateWidth/updateHeight do)."""
    return {"width": _positive_int(f, "width", 64, 1), "height": _positive_int(f, "height", 64, 1)}


def vacuum_gripper(f: Fields) -> dict:
    """A VacuumGripper's strengths and contact points as WbVacuumGripper resets them: a strength below 0
    other than -1 (infinite) is -1, contactPoints below 1 is 3, each with its warning."""
    out: dict[str, Any] = {}
    for field, key in (("tensileStrength", "tensile_strength"), ("shearStrength", "shear_strength")):
        v = f.num(field, -1.0)
        out[key] = float(f.used(field, v, -1.0, "must be positive or -1 (infinite)") if v < 0.0 and v != -1.0 else v)
    out["contact_points"] = _positive_int(f, "contactPoints", 3, 3)
    return out


def connector(f: Fields) -> dict:
    """A Connector's fields in the world format's names (Connector.wrl defaults), with the values
    WbConnector resets said and replaced: a negative distance tolerance or number of rotations 0,
    the axis and rotation tolerances clipped to [0, pi], a negative strength other than -1 made -1,
    a locked passive connector unlocked."""
    out: dict[str, Any] = {"type": f.string("type", "symmetric")}
    out["distance_tolerance"] = f.non_negative("distanceTolerance", 0.01)
    for name, key in (("axisTolerance", "axis_tolerance"), ("rotationTolerance", "rotation_tolerance")):
        v = f.num(name, 0.2)
        clipped = min(max(v, 0.0), math.pi)
        out[key] = float(f.used(name, v, clipped, "is outside [0, pi]" if clipped != v else ""))
    n = f.integer("numberOfRotations", 4)
    out["number_of_rotations"] = int(f.used("numberOfRotations", n, max(n, 0), "is negative" if n < 0 else ""))
    for name, key in (("tensileStrength", "tensile_strength"), ("shearStrength", "shear_strength")):
        v = f.num(name, -1.0)
        bad = v < 0.0 and v != -1.0
        out[key] = float(f.used(name, v, -1.0 if bad else v, "is neither >= 0 nor -1" if bad else ""))
    locked = f.flag("isLocked", False)
    bad = locked and out["type"] == "passive"
    out["is_locked"] = bool(f.used("isLocked", locked, locked and not bad,
                                   "on a passive connector (it cannot lock)" if bad else ""))
    return out


DEVICE_NAMES = {"DistanceSensor": "distance sensor", "LightSensor": "light sensor", "Lidar": "lidar",
                "RangeFinder": "range-finder", "Camera": "camera",
                "PositionSensor": "position sensor", "LED": "led", "RotationalMotor": "rotational motor"}


# ---------------------------------------------------------------- appearance

def appearance(node: Node | None, source: str, warn, resolve=None, reset: Reset | None = None) -> dict | None:
    """Appearance / PBRAppearance → the world format's appearance (what infra-red sensors read).

    As Webots' pickColor: a PBRAppearance is ``baseColor × (1 − transparency)`` times its
    ``baseColorMap`` texel (roughness and occlusion maps read where the base map is); an Appearance
    with a loaded ``texture`` reads white × ``(1 − transparency)`` × texel (WbAppearance::diffuseColor
    replaces the material's colour by white), without one its material's diffuseColor. A texture
    that cannot be loaded here (missing file, not PNG/JPEG, webots:// or remote url) is noted with
    ``warn(node, "texture: <why>")`` and read as Webots reads a texture it could not load.
    ``resolve(node, url) -> (url or None, why)``: where a url of a PROTO file or ``webots://`` is
    (the converter's asset resolution); without it urls are relative to ``source``. Values Webots
    resets (a colour outside [0, 1], a transparency or roughness outside [0, 1]) are reset as there,
    ``reset`` told of each (``Fields``)."""
    if node is None:
        return None
    f = Fields(node, source, reset)
    if node.type == "PBRAppearance":     # WbPbrAppearance::sanitizeFields: 0 for either outside [0, 1]
        out: dict[str, Any] = {"base_color": list(f.color("baseColor", (1.0, 1.0, 1.0))),
                               "transparency": f.within("transparency", 0.0, 0.0, 1.0, 0.0),
                               "roughness": f.within("roughness", 0.0, 0.0, 1.0, 0.0)}
        emissive = f.color("emissiveColor", (0.0, 0.0, 0.0))
        if any(emissive):          # (the model's defaults otherwise: a world without glow dumps as before)
            out["emissive_color"] = list(emissive)
        intensity = f.non_negative("emissiveIntensity", 1.0, 1.0)    # (WbPbrAppearance: a negative one is reset to 1)
        if intensity != 1.0:
            out["emissive_intensity"] = intensity
        base = image_texture(f.node_("baseColorMap"), source, warn, resolve)
        if base is not None:
            out["texture"] = base
            for field, key in (("roughnessMap", "roughness_map"), ("occlusionMap", "occlusion_map")):
                extra = image_texture(f.node_(field), source, warn, resolve)
                if extra is not None:
                    out[key] = extra
        def warn_glow(n: Node, message: str) -> None:        # (named: the summary line says what such a map reads)
            warn(n, message.replace("texture: ", f"texture: {GLOW_MAP}: ", 1))
        glow_map = image_texture(f.node_("emissiveColorMap"), source, warn_glow, resolve)
        if glow_map is not None:
            out["emissive_map"] = glow_map
        if f.node_("baseColorMap") is not None or glow_map is not None:      # (kept for a url a Supervisor sets)
            _texture_transform(f, source, out)
        return out
    if node.type == "Appearance":
        material = f.node_("material")
        texture = image_texture(f.node_("texture"), source, warn, resolve)
        out = {"base_color": [1.0, 1.0, 1.0]}
        if material is not None:
            m = f.sub(material)        # WbMaterial::updateTransparency: 0.5 for one outside [0, 1]
            diffuse = m.color("diffuseColor", (0.8, 0.8, 0.8))
            if texture is None:
                out["base_color"] = list(diffuse)
            out["transparency"] = m.within("transparency", 0.0, 0.0, 1.0, 0.5)
            emissive = m.color("emissiveColor", (0.0, 0.0, 0.0))
            if any(emissive):
                out["emissive_color"] = list(emissive)
        if texture is not None:
            out["texture"] = texture
        if f.node_("texture") is not None:           # (kept for a url a Supervisor sets)
            _texture_transform(f, source, out)
            out["phong"] = True        # its emissive colour times the texel (only a textured one differs)
        return out
    warn(node, f"appearance {node.type}: not built in (a PROTO?); taken as white")
    return None


MATERIAL_FIELDS: dict[str, tuple[str, Any]] = {
    "ambientIntensity": ("SFFloat", 0.2), "diffuseColor": ("SFColor", (0.8, 0.8, 0.8)),
    "emissiveColor": ("SFColor", (0.0, 0.0, 0.0)), "shininess": ("SFFloat", 0.2),
    "specularColor": ("SFColor", (0.0, 0.0, 0.0)), "transparency": ("SFFloat", 0.0)}
"""Webots' Material fields a Supervisor reads: type, Webots' default."""

PBR_FIELDS: dict[str, tuple[str, Any]] = {
    "baseColor": ("SFColor", (1.0, 1.0, 1.0)), "transparency": ("SFFloat", 0.0), "roughness": ("SFFloat", 0.0),
    "metalness": ("SFFloat", 1.0), "IBLStrength": ("SFFloat", 1.0), "normalMapFactor": ("SFFloat", 1.0),
    "occlusionMapStrength": ("SFFloat", 1.0), "emissiveColor": ("SFColor", (0.0, 0.0, 0.0)),
    "emissiveIntensity": ("SFFloat", 1.0)}
"""Webots' PBRAppearance fields a Supervisor reads (its maps are SFNode fields): type, Webots' default."""

TEXTURE_FIELDS: dict[str, tuple[str, Any]] = {
    "url": ("MFString", ()), "repeatS": ("SFBool", True), "repeatT": ("SFBool", True), "filtering": ("SFInt32", 4)}
"""Webots' ImageTexture fields a Supervisor reads."""

GEOMETRY_FIELDS: dict[str, dict[str, tuple[str, Any]]] = {
    "Box": {"size": ("SFVec3f", (0.1, 0.1, 0.1))},
    "Sphere": {"radius": ("SFFloat", 0.1), "subdivision": ("SFInt32", 1), "ico": ("SFBool", True)},
    "Cylinder": {"radius": ("SFFloat", 0.05), "height": ("SFFloat", 0.1), "subdivision": ("SFInt32", 36),
                 "bottom": ("SFBool", True), "side": ("SFBool", True), "top": ("SFBool", True)},
    "Capsule": {"radius": ("SFFloat", 0.05), "height": ("SFFloat", 0.1), "subdivision": ("SFInt32", 12),
                "bottom": ("SFBool", True), "side": ("SFBool", True), "top": ("SFBool", True)},
    "Cone": {"bottomRadius": ("SFFloat", 0.05), "height": ("SFFloat", 0.1), "subdivision": ("SFInt32", 12),
             "bottom": ("SFBool", True), "side": ("SFBool", True)},
    "Plane": {"size": ("SFVec2f", (1.0, 1.0))},
}
"""The geometry fields a Supervisor reads (the cheap ones: sizes, not a mesh's points)."""


def _written(f: Fields, table: dict[str, tuple[str, Any]], prefix: str, out: dict[str, Any]) -> None:
    """The fields of ``table`` that the node writes, as ``prefix.field`` in ``out`` (the others are
    Webots' defaults, which the reader supplies)."""
    for name, (kind, default) in table.items():
        if f.has(name):
            try:
                _write(f, name, kind, default, sys.intern(f"{prefix}.{name}"), out)
            except WbtSyntaxError:      # a value the conversion does not read and Webots would refuse: its default
                pass


def _write(f: Fields, name: str, kind: str, default: Any, key: str, out: dict[str, Any]) -> None:
    """One written field's value into ``out[key]`` (WbtSyntaxError: not of its type)."""
    if kind == "SFColor":
        out[key] = tuple(float(v) for v in f.color(name, default))
    elif kind in ("SFVec3f", "SFVec2f"):
        out[key] = tuple(float(v) for v in f.vec(name, default))
    elif kind == "SFFloat":
        out[key] = float(f.num(name, default))
    elif kind == "SFInt32":
        out[key] = float(f.integer(name, default))
    elif kind == "SFBool":
        out[key] = bool(f.flag(name, default))
    elif kind == "MFString":
        out[key] = tuple(f.strings(name))


def shape_node(node: Node, source: str, keep_def, key) -> dict:
    """A Shape as a Supervisor serves it (schemas.world.ShapeNode): DEFs (``keep_def(node)``: whether
    the world file's DEF is served), its appearance node's type and the written values of its
    appearance's, material's, texture's and geometry's fields; ``key(node)``: the number of its
    appearance and material nodes (the same for a USE of one as for its DEF)."""
    f = Fields(node, source)
    out: dict[str, Any] = {}
    values: dict[str, Any] = {}
    if keep_def(node):
        out["def_name"] = node.def_name
    app = f.node_("appearance")
    if app is not None and app.type in ("Appearance", "PBRAppearance"):
        out["appearance"] = app.type
        out["appearance_key"] = key(app)
        if keep_def(app):
            out["appearance_def"] = app.def_name
        a = f.sub(app)
        texture = a.node_("texture" if app.type == "Appearance" else "baseColorMap")
        # what the appearance model holds (as the loader sanitised it) is read there, not kept twice
        if app.type == "PBRAppearance":
            _written(a, {k: v for k, v in PBR_FIELDS.items() if k not in ("baseColor", "transparency", "roughness")},
                     "appearance", values)
        else:
            material = a.node_("material")
            if material is not None and material.type == "Material":
                out["material"] = True
                out["material_key"] = key(material)
                if keep_def(material):
                    out["material_def"] = material.def_name
                held = ("transparency",) if texture is not None else ("transparency", "diffuseColor")
                _written(a.sub(material), {k: v for k, v in MATERIAL_FIELDS.items() if k not in held}, "material",
                         values)
        if texture is not None and texture.type == "ImageTexture":
            out["texture_key"] = key(texture)
            if keep_def(texture):
                out["texture_def"] = texture.def_name
            _written(a.sub(texture), TEXTURE_FIELDS, "texture", values)
    geometry = f.node_("geometry")
    if geometry is not None:
        out["geometry"] = geometry.type
        if keep_def(geometry):
            out["geometry_def"] = geometry.def_name
        _written(f.sub(geometry), GEOMETRY_FIELDS.get(geometry.type, {}), "geometry", values)
    if values:
        out["values"] = values
    return out


GLOW_MAP = "emissiveColorMap"
"""How a note of an emissiveColorMap not loaded begins (after ``texture: ``)."""


def image_texture(node: Node | None, source: str, warn, resolve=None) -> dict | None:
    """An ImageTexture → the world format's texture, if its first url is a PNG/JPEG file found
    (else ``warn(node, "texture: …")`` and None: Webots would not load it). ``resolve(node, url)``
    → (the url the converted world names, or None, why): where the url leads (a PROTO's url is
    relative to the PROTO file, webots:// names the installation's file; the converter's); without
    it the url is relative to the world file and kept as written (backslashes made slashes, as
    Webots does)."""
    from pathlib import Path

    from sensorium.server.world.textures import TextureFileError, image_header, resolve_texture_url

    if node is None:
        return None
    if node.type != "ImageTexture":
        warn(node, f"texture: {node.type} is not an ImageTexture")
        return None
    f = Fields(node, source)
    urls = f.strings("url")
    if not urls:
        warn(node, "texture: ImageTexture without url")
        return None
    url = urls[0].replace("\\", "/")
    if resolve is not None:
        found, why = resolve(node, url)
        if found is None:
            warn(node, f"texture: {why}")
            return None
        url = found
    try:
        path = resolve_texture_url(url, Path(source).resolve().parent, allow_outside=True)
        image_header(path, url)
    except TextureFileError as exc:
        warn(node, f"texture: {exc}")
        return None
    filtering = f.integer("filtering", 4)
    return {"url": url, "repeat_s": f.flag("repeatS", True), "repeat_t": f.flag("repeatT", True),
            "filtering": filtering if 0 <= filtering <= 5 else 4}


def tex_coords(node: Node, f: Fields, n_index: int, warn) -> tuple[list[list[float]] | None, list[int] | None]:
    """An IndexedFaceSet's texture coordinates and one texCoord index per coordIndex entry
    (WbTriangleMesh): ``texCoordIndex`` if given (it must be as long as ``coordIndex``, else Webots
    warns and uses its default mapping), else ``coordIndex``; an index outside ``texCoord`` reads
    (0.5, 0.5), kept here as one extra coordinate. (None, None): the default mapping."""
    tnode = f.node_("texCoord")
    points = [list(p) for p in Fields(tnode, f.source).rows("point", 2, [])] if tnode is not None else []
    if not points:
        return None, None
    index = f.integers("texCoordIndex") or f.integers("coordIndex")
    if len(index) != n_index:
        warn(node, f"IndexedFaceSet: texCoordIndex has {len(index)} entries for {n_index} in coordIndex: "
                   "Webots' default texture mapping applies")
        return None, None
    n = len(points)
    if any(i >= n or i < 0 for i in index):      # (separators are -1 too; they never become corners)
        points.append([0.5, 0.5])
        index = [i if 0 <= i < n else n for i in index]
    return points, index


def _texture_transform(f: Fields, source: str, out: dict) -> None:
    node = f.node_("textureTransform")
    if node is None:
        return
    t = Fields(node, source)
    out["texture_transform"] = {"center": list(t.vec("center", (0.0, 0.0))), "rotation": t.num("rotation", 0.0),
                                "scale": list(t.vec("scale", (1.0, 1.0))),
                                "translation": list(t.vec("translation", (0.0, 0.0)))}


# ---------------------------------------------------------------- typo check

_SOLID = {"translation", "rotation", "children", "name", "model", "description", "contactMaterial",
          "immersionProperties", "boundingObject", "physics", "locked", "radarCrossSection", "recognitionColors",
          "translationStep", "rotationStep", "linearVelocity", "angularVelocity"}
_ROBOT = _SOLID | {"controller", "controllerArgs", "customData", "supervisor", "synchronization", "battery",
                   "cpuConsumption", "selfCollision", "window", "remoteControl", "showWindow", "data"}
_ROUND = {"bottom", "height", "radius", "side", "top", "subdivision"}
_LIGHT = {"ambientIntensity", "color", "intensity", "on", "castShadows"}
WEBOTS_FIELDS: dict[str, set[str]] = {
    "Solid": _SOLID, "Robot": _ROBOT,
    "Pose": {"translation", "rotation", "children", "translationStep", "rotationStep"},
    "Transform": {"translation", "rotation", "scale", "children", "translationStep", "rotationStep"},
    "Group": {"children"}, "Slot": {"type", "endPoint"},
    "Propeller": {"shaftAxis", "centerOfThrust", "thrustConstants", "torqueConstants", "fastHelixThreshold", "device",
                  "fastHelix", "slowHelix"},
    "Shape": {"appearance", "geometry", "castShadows", "isPickable"},
    "Box": {"size"}, "Sphere": {"radius", "subdivision", "ico"}, "Cylinder": _ROUND, "Capsule": _ROUND,
    "Plane": {"size"}, "Mesh": {"url", "ccw", "name", "materialIndex"},
    "ElevationGrid": {"height", "xDimension", "xSpacing", "yDimension", "ySpacing", "thickness"},
    "Cone": {"bottomRadius", "height", "side", "bottom", "subdivision"},
    "IndexedFaceSet": {"coord", "normal", "texCoord", "solid", "ccw", "convex", "normalPerVertex", "coordIndex",
                       "normalIndex", "texCoordIndex", "creaseAngle"},
    "Appearance": {"material", "texture", "textureTransform", "name"},
    "Material": {"ambientIntensity", "diffuseColor", "emissiveColor", "shininess", "specularColor", "transparency"},
    "PBRAppearance": {"baseColor", "baseColorMap", "transparency", "roughness", "roughnessMap", "metalness",
                      "metalnessMap", "IBLStrength", "normalMap", "normalMapFactor", "occlusionMap",
                      "occlusionMapStrength", "emissiveColor", "emissiveColorMap", "emissiveIntensity",
                      "textureTransform", "name"},
    "PointLight": _LIGHT | {"attenuation", "location", "radius"},
    "SpotLight": _LIGHT | {"attenuation", "location", "radius", "beamWidth", "cutOffAngle", "direction"},
    "DirectionalLight": _LIGHT | {"direction"},
    "DistanceSensor": _SOLID | {"lookupTable", "type", "numberOfRays", "aperture", "gaussianWidth", "resolution",
                                "redColorSensitivity"},
    "LightSensor": _SOLID | {"lookupTable", "colorFilter", "occlusion", "resolution"},
    "Lidar": _SOLID | {"tiltAngle", "horizontalResolution", "fieldOfView", "verticalFieldOfView", "numberOfLayers",
                       "near", "minRange", "maxRange", "type", "projection", "noise", "resolution",
                       "defaultFrequency", "minFrequency", "maxFrequency", "rotatingHead"},
    "LED": _SOLID | {"color", "gradual"},
    "PositionSensor": {"name", "noise", "resolution"},
    "RotationalMotor": {"name", "acceleration", "consumptionFactor", "controlPID", "minPosition", "maxPosition",
                        "maxVelocity", "multiplier", "sound", "muscles", "maxTorque"},
    "HingeJoint": {"jointParameters", "device", "endPoint"},
    "HingeJointParameters": {"position", "axis", "anchor", "minStop", "maxStop", "springConstant",
                             "dampingConstant", "staticFriction", "suspensionSpringConstant",
                             "suspensionDampingConstant", "suspensionAxis", "stopERP", "stopCFM"},
    "Coordinate": {"point"},
    "ImageTexture": {"url", "repeatS", "repeatT", "filtering"},
    "TextureTransform": {"center", "rotation", "scale", "translation"},
    "TextureCoordinate": {"point"},
}


def field_typos(node: Node) -> list[tuple[str, str]]:
    """(field, likely meant) for each field of a known node type that is not one of its Webots fields
    but is close to one: hand-edited worlds' typos, which Webots would reject."""
    import difflib

    known = WEBOTS_FIELDS.get(node.type)
    if known is None:
        return []
    out = []
    for name in node.fields:
        if name not in known:
            close = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.75)
            if close:
                out.append((name, close[0]))
    return out
