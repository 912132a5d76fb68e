"""Typed access to the fields of a parsed .wbt node, and node-to-model pieces that need no context:
geometry, appearance, lights, devices. Defaults are those of Webots' reference manual; a field of
the wrong shape is an error naming file, line and column."""

from __future__ import annotations

from typing import Any

from sensorium.server.world.wbt.parser import Node, WbtSyntaxError


class Fields:
    """Typed getters on one node; errors point at the field (or the node when it is absent)."""

    def __init__(self, node: Node, source: str):
        self.node = node
        self.source = source

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
        out = []
        for v in self.numbers(name):
            if v != int(v):
                raise self.error(name, f"expected integers, got {v}")
            out.append(int(v))
        return out

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
        flat = self.numbers(name)
        if len(flat) % width:
            raise self.error(name, f"expected groups of {width} numbers, got {len(flat)} numbers")
        return [tuple(flat[i:i + width]) for i in range(0, len(flat), width)]


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
        out["attenuation"] = list(f.vec("attenuation", (1.0, 0.0, 0.0)))
        out["location"] = list(f.vec("location", (0.0, 0.0, 0.0)))
        out["radius"] = f.num("radius", 100.0)
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
                "color_filter": list(f.vec("colorFilter", (1.0, 1.0, 1.0))), "occlusion": f.flag("occlusion", False),
                "resolution": f.num("resolution", -1.0)}
    if t == "Lidar":
        return {"device": t, "tilt_angle": f.num("tiltAngle", 0.0),
                "horizontal_resolution": f.integer("horizontalResolution", 512),
                "field_of_view": f.num("fieldOfView", 1.5708),
                "vertical_field_of_view": f.num("verticalFieldOfView", 0.2),
                "number_of_layers": f.integer("numberOfLayers", 4), "near": f.num("near", 0.01),
                "min_range": f.num("minRange", 0.01), "max_range": f.num("maxRange", 1.0),
                "type": f.string("type", "fixed"), "projection": f.string("projection", "cylindrical"),
                "noise": f.num("noise", 0.0), "resolution": f.num("resolution", -1.0),
                "default_frequency": f.num("defaultFrequency", 10.0), "min_frequency": f.num("minFrequency", 1.0),
                "max_frequency": f.num("maxFrequency", 25.0)}
    if t == "RangeFinder":
        projection = f.string("projection", "planar")
        if f.flag("spherical", False) and projection == "planar":    # deprecated in R2023 (WbRangeFinder::init)
            projection = "cylindrical"
        return {"device": t, "field_of_view": f.num("fieldOfView", 0.785398), "width": f.integer("width", 64),
                "height": f.integer("height", 64), "projection": projection, "near": f.num("near", 0.01),
                "min_range": f.num("minRange", 0.01), "max_range": f.num("maxRange", 1.0),
                "noise": f.num("noise", 0.0), "resolution": f.num("resolution", -1.0)}
    if t == "Camera":
        projection = f.string("projection", "planar")
        if f.flag("spherical", False) and projection == "planar":    # deprecated in R2023
            projection = "spherical"
        out = {"device": t, "field_of_view": f.num("fieldOfView", 0.785398), "width": f.integer("width", 64),
               "height": f.integer("height", 64), "projection": projection, "near": f.num("near", 0.01),
               "far": f.num("far", 0.0), "exposure": f.num("exposure", 1.0),
               "anti_aliasing": f.flag("antiAliasing", False), "noise": f.num("noise", 0.0)}
        rec = f.node_("recognition")
        if rec is not None:
            rf = Fields(rec, f.source)
            out["recognition"] = {"max_range": rf.num("maxRange", 100.0), "max_objects": rf.integer("maxObjects", -1),
                                  "occlusion": rf.integer("occlusion", 1), "frame_color": list(rf.vec("frameColor", (1.0, 0.0, 0.0))),
                                  "frame_thickness": rf.integer("frameThickness", 1),
                                  "segmentation": rf.flag("segmentation", False)}
        return out
    if t == "PositionSensor":
        return {"device": t, "noise": f.num("noise", 0.0), "resolution": f.num("resolution", -1.0)}
    if t == "LED":
        colours = f.rows("color", 3, [(1.0, 0.0, 0.0)])
        return {"device": t, "color": [list(c) for c in colours], "gradual": f.flag("gradual", False)}
    raise AssertionError(t)


def pen(f: Fields) -> dict:
    """A Pen's fields in the world format's names (Webots' defaults; its colour clamped to [0, 1]
    as an SFColor is, its density left to the loader's Webots clamping)."""
    colour = [min(max(c, 0.0), 1.0) for c in f.vec("inkColor", (0.0, 0.0, 0.0))]
    return {"ink_color": colour, "ink_density": f.num("inkDensity", 0.5), "lead_size": max(f.num("leadSize", 0.002), 0.0),
            "max_distance": f.num("maxDistance", 0.0), "write": f.flag("write", True)}


DEVICE_NAMES = {"DistanceSensor": "distance sensor", "LightSensor": "light sensor", "Lidar": "lidar",
                "RangeFinder": "range-finder", "Camera": "camera",
                "PositionSensor": "position sensor", "LED": "led", "RotationalMotor": "rotational motor"}


# ---------------------------------------------------------------- appearance

def appearance(node: Node | None, source: str, warn, resolve=None) -> dict | None:
    """Appearance / PBRAppearance → the world format's appearance (what infra-red sensors read).

    As Webots' pickColor: a PBRAppearance is ``baseColor × (1 − transparency)`` times its
    ``baseColorMap`` texel (roughness and occlusion maps read where the base map is); an Appearance
    with a loaded ``texture`` reads white × ``(1 − transparency)`` × texel (WbAppearance::diffuseColor
    replaces the material's colour by white), without one its material's diffuseColor. A texture
    that cannot be loaded here (missing file, not PNG/JPEG, webots:// or remote url) is noted with
    ``warn(node, "texture: <why>")`` and read as Webots reads a texture it could not load.
    ``resolve(node, url) -> (url or None, why)``: where a url of a PROTO file or ``webots://`` is
    (the converter's asset resolution); without it urls are relative to ``source``."""
    if node is None:
        return None
    f = Fields(node, source)
    if node.type == "PBRAppearance":
        out: dict[str, Any] = {"base_color": list(f.vec("baseColor", (1.0, 1.0, 1.0))),
                               "transparency": f.num("transparency", 0.0), "roughness": f.num("roughness", 0.0)}
        base = image_texture(f.node_("baseColorMap"), source, warn, resolve)
        if base is not None:
            out["texture"] = base
            for field, key in (("roughnessMap", "roughness_map"), ("occlusionMap", "occlusion_map")):
                extra = image_texture(f.node_(field), source, warn, resolve)
                if extra is not None:
                    out[key] = extra
            _texture_transform(f, source, out)
        return out
    if node.type == "Appearance":
        material = f.node_("material")
        texture = image_texture(f.node_("texture"), source, warn, resolve)
        out = {"base_color": [1.0, 1.0, 1.0]}
        if material is not None:
            m = Fields(material, source)
            if texture is None:
                out["base_color"] = list(m.vec("diffuseColor", (0.8, 0.8, 0.8)))
            out["transparency"] = m.num("transparency", 0.0)
        if texture is not None:
            out["texture"] = texture
            _texture_transform(f, source, out)
        return out
    warn(node, f"appearance {node.type}: not built in (a PROTO?); taken as white")
    return None


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
