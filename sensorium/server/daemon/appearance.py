"""The Supervisor's Shape nodes and what is inside them (sans-IO): a shape's ``appearance``
(``Appearance`` with its ``material`` Material and ``texture`` ImageTexture, or ``PBRAppearance``
with its ``baseColorMap``) and its ``geometry``.

Numbered by nested.py after every other nested node (so no other id moves). Their fields read what
the world file wrote (``schemas.world.ShapeNode``; Webots' defaults for what it leaves out), the
values sensors see where the world's model has them (a colour, transparency and roughness as the
loader sanitised them), or what a Supervisor set since. A Supervisor sets a Material's
``diffuseColor``, ``emissiveColor`` and ``transparency``, a PBRAppearance's ``baseColor``,
``roughness``, ``metalness``, ``transparency``, ``emissiveColor`` and ``emissiveIntensity``: the scene takes the new
appearance for that one shape (``Scene.set_appearance``), so every sensor sees it at its next
measurement as if the world file had said it (a transparency crossing 0 or 1 too: which rays see
the shape and its shadows follows). Everything else is read-only.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sensorium.schemas import world as wm
from sensorium.server.daemon.mf_items import item_position
from sensorium.server.world.textures import TextureFileError, TextureLimitError, read_checked_image
from sensorium.server.world.wbt.fields import GEOMETRY_FIELDS, MATERIAL_FIELDS, PBR_FIELDS, TEXTURE_FIELDS

TYPES = frozenset({"Shape", "Appearance", "PBRAppearance", "Material", "ImageTexture", "Box", "Sphere", "Cylinder",
                   "Capsule", "Cone", "Plane", "Mesh", "IndexedFaceSet", "ElevationGrid"})
"""The node types served here (what Webots' node of each type lacks: no pose, no children)."""

GEOMETRY_TYPES = {wm.Box: "Box", wm.Sphere: "Sphere", wm.Cylinder: "Cylinder", wm.Capsule: "Capsule", wm.Cone: "Cone",
                  wm.Plane: "Plane", wm.Mesh: "Mesh", wm.Triangles: "IndexedFaceSet",
                  wm.ElevationGrid: "ElevationGrid"}

SETTABLE = {"Material": frozenset({"diffuseColor", "emissiveColor", "transparency"}),
            "PBRAppearance": frozenset({"baseColor", "roughness", "metalness", "transparency", "emissiveColor",
                                        "emissiveIntensity"}),
            "ImageTexture": frozenset({"repeatS", "repeatT", "filtering"})}
"""The SF fields a Supervisor sets here (an ImageTexture's ``url`` is an MF field: :func:`change_url`);
the rest of these nodes is read-only."""

MAX_URLS = 64
"""The most items an ImageTexture's ``url`` holds after a Supervisor's change (Webots reads the first)."""

MAX_URL_CHARS = 4096
"""The longest url item a Supervisor sets (a file path's most on Linux); a refusal quotes only its start."""


def _quoted(url: str) -> str:
    """A url as a refusal line quotes it: whole up to 80 characters, else its start and its length."""
    return repr(url) if len(url) <= 80 else f"{url[:60]!r}... ({len(url):,} characters)"

# the written field names of a YAML geometry model (no .wbt node): Webots' field -> the model's attribute
_MODEL_GEOMETRY = {"size": "size", "radius": "radius", "height": "height", "bottomRadius": "bottom_radius",
                   "subdivision": "subdivision"}

Getter = Callable[[Any, Any], Any]
Setter = Callable[[Any, Any, Any], None] | None


@dataclass(frozen=True, slots=True)
class ShapeRef:
    """A served Shape, or a node inside it: the scene's shape index, the ``.wbt`` node's DEFs and
    written values (None: a YAML shape, served from its ``appearance``), and which node it is."""

    index: int
    node: wm.ShapeNode | None
    role: str            # "Shape", "appearance", "material", "texture", "geometry"
    type: str            # its Webots type (PBRAppearance, Box, ...)
    peers: tuple[int, ...] = ()   # the shapes whose node this is too (a DEF and its USEs), itself included


def served(shape: Any, wbt: bool) -> bool:
    """Whether a shape of a robot or solid is a Shape node here: one the ``.wbt`` import describes
    (``node``), or in a YAML world one that visual rays see (a bounding-only shape is Webots'
    boundingObject, no child)."""
    if getattr(shape, "node", None) is not None:
        return True
    return not wbt and shape.seen_by != "bounding"


def inside(shape: Any, index: int) -> list[tuple[str, str, str, str]]:
    """The nodes inside a served Shape, parents first: (role, type, DEF, the field of its parent
    holding it); the appearance's children follow it, then the geometry."""
    node: wm.ShapeNode | None = getattr(shape, "node", None)
    out: list[tuple[str, str, str, str]] = []
    app = shape.appearance
    kind = node.appearance if node is not None else ("PBRAppearance" if app is not None else None)
    if kind is not None:
        out.append(("appearance", kind, (node.appearance_def if node else None) or "", "appearance"))
        if node is not None and node.material:
            out.append(("material", "Material", node.material_def or "", "material"))
        textured = (app is not None and app.texture is not None) or (node is not None and (
            node.texture_def is not None or node.texture_key >= 0 or any(k.startswith("texture.") for k in node.values)))
        if textured:
            out.append(("texture", "ImageTexture", (node.texture_def if node else None) or "",
                        "texture" if kind == "Appearance" else "baseColorMap"))
    geometry = node.geometry if node is not None and node.geometry else GEOMETRY_TYPES.get(type(shape.geometry), "")
    if geometry:
        out.append(("geometry", geometry, (node.geometry_def if node else None) or "", "geometry"))
    return out


def _seen(ref: ShapeRef, loaded: wm.Appearance | None, name: str) -> Any:
    """A field's value as the world's model has it (what sensors see, as the loader sanitised it);
    None where the model does not hold that field."""
    if loaded is None:
        return None
    if ref.type == "PBRAppearance":
        held = {"baseColor": loaded.base_color, "transparency": loaded.transparency, "roughness": loaded.roughness,
                "emissiveIntensity": loaded.emissive_intensity}
    else:      # a Material: its transparency; its diffuse colour unless a texture replaces it by white
        held = {"transparency": loaded.transparency}
        if loaded.texture is None:
            held["diffuseColor"] = loaded.base_color
    v = held.get(name)
    return [float(x) for x in v] if isinstance(v, tuple | list) else v


def _value(sim: Any, ref: ShapeRef, name: str, default: Any) -> Any:
    """A field's value now: as a Supervisor set it, else as the world loaded it, else Webots' default."""
    key = f"{ref.role}.{name}"
    changed = sim.scene.appearance_values.get(ref.index, {})
    if key in changed:
        return changed[key]
    if name == "emissiveColor" and ref.role in ("appearance", "material"):
        glow = sim.scene.glow_of(ref.index)     # a Charger's colour now (WbCharger writes the field)
        if glow is not None:
            return [float(v) for v in glow]
    seen = _seen(ref, sim.scene.loaded_model(ref.index).appearance, name) if ref.role in ("appearance", "material") \
        else None
    if seen is not None:
        return seen
    written: Any = ref.node.values.get(key, default) if ref.node is not None else default
    if ref.node is None and ref.role == "geometry":       # a YAML shape: its model's
        model = sim.scene.loaded_model(ref.index).geometry
        written = getattr(model, _MODEL_GEOMETRY.get(name, ""), None)
        written = default if written is None else written
    elif ref.node is None and ref.role == "texture":
        t = sim.scene.loaded_model(ref.index).appearance.texture
        written = {"url": [t.url], "repeatS": t.repeat_s, "repeatT": t.repeat_t, "filtering": t.filtering}[name]
    if ref.role == "geometry" and name == "subdivision" or ref.role == "texture" and name == "filtering":
        return int(written)
    return list(written) if isinstance(written, tuple) else written


def _what(ref: ShapeRef, def_name: str, node_id: int) -> str:
    return f"{ref.type} {def_name!r} (node {node_id})" if def_name else f"{ref.type} (node {node_id})"


def _setter(ref: ShapeRef, name: str, kind: str) -> Setter:
    if name not in SETTABLE.get(ref.type, ()):
        return None
    if ref.type == "ImageTexture":
        return _texture_setter(ref, name, kind)

    def set_value(sim: Any, node: Any, value: Any) -> None:
        where = f"field {name!r} ({kind}) of {_what(ref, node.def_name, node.id)}"
        values = value if isinstance(value, list) else [value]
        if name == "emissiveIntensity":      # a multiplier (WbPbrAppearance: any value >= 0)
            if float(value) < 0.0:
                raise ValueError(f"{where}: the value must be >= 0, got {value!r} (Webots resets it to 1 with a "
                                 "warning); nothing changed")
        elif not all(0.0 <= float(v) <= 1.0 for v in values):
            raise ValueError(f"{where}: {'each component' if kind == 'SFColor' else 'the value'} must be in [0, 1], "
                             f"got {value!r} (Webots resets it with a warning); nothing changed")
        scene = sim.scene
        shapes = ref.peers or (ref.index,)
        for k in shapes:        # the shape, and those that USE the same node
            current = scene.shape_model(k).appearance
            update: dict[str, Any] = {}
            if name == "transparency":
                update["transparency"] = float(value)
            elif name == "baseColor" or (name == "diffuseColor" and current is not None and current.texture is None):
                update["base_color"] = tuple(float(v) for v in values)
            elif name == "roughness":
                update["roughness"] = float(value)
            elif name == "emissiveColor":
                update["emissive_color"] = tuple(float(v) for v in values)
            elif name == "emissiveIntensity":
                update["emissive_intensity"] = float(value)
            if update and current is not None:      # (metalness: not rendered here, kept)
                scene.set_appearance(k, current.model_copy(update=update))
            scene.appearance_values.setdefault(k, {})[f"{ref.role}.{name}"] = \
                [float(v) for v in values] if kind == "SFColor" else float(value)

    return set_value


# ------------------------------------------------------------------------------ an ImageTexture's fields

def _texture_value(scene: Any, k: int, name: str, default: Any) -> Any:
    """Shape ``k``'s ImageTexture field now: as a Supervisor set it, else as the world file wrote it."""
    changed = scene.appearance_values.get(k, {})
    if f"texture.{name}" in changed:
        return changed[f"texture.{name}"]
    node = getattr(scene.loaded_model(k), "node", None)
    if node is not None:
        return node.values.get(f"texture.{name}", default)
    t = scene.loaded_model(k).appearance.texture
    return {"url": [t.url], "repeatS": t.repeat_s, "repeatT": t.repeat_t, "filtering": t.filtering}.get(name, default)


def _retextured(scene: Any, k: int, url: str | None) -> wm.Appearance | None:
    """Shape ``k``'s appearance with its base map naming ``url`` (None: no texture, as Webots draws an
    ImageTexture it has no image for: an Appearance shows its Material's diffuseColor, a
    PBRAppearance its baseColor), as the world file's loader would have made it."""
    current = scene.shape_model(k).appearance
    if current is None:
        return None
    loaded = scene.loaded_model(k).appearance
    node = getattr(scene.loaded_model(k), "node", None)
    kind = node.appearance if node is not None else "PBRAppearance"
    update: dict[str, Any] = {}
    if url is None:
        update.update(texture=None, roughness_map=None, occlusion_map=None)
        if kind == "Appearance" and node is not None and node.material:
            changed = scene.appearance_values.get(k, {})
            diffuse = changed.get("material.diffuseColor") or (
                loaded.base_color if loaded.texture is None else node.values.get("material.diffuseColor", (0.8, 0.8, 0.8)))
            update["base_color"] = tuple(float(v) for v in diffuse)
    else:
        update["texture"] = wm.Texture(url=url, repeat_s=bool(_texture_value(scene, k, "repeatS", True)),
                                       repeat_t=bool(_texture_value(scene, k, "repeatT", True)),
                                       filtering=int(_texture_value(scene, k, "filtering", 4)))
        if current.texture is None:     # the PBR maps read with the base map: the world file's
            update.update(roughness_map=loaded.roughness_map, occlusion_map=loaded.occlusion_map)
        if kind == "Appearance":
            update["base_color"] = (1.0, 1.0, 1.0)        # a texture replaces the diffuse colour by white
    return current.model_copy(update=update)


def _world_url(scene: Any, url: str) -> str | None:
    """The file a texture url the world file itself writes (a ``webots://`` url, one in a PROTO file)
    was read from, so that such a url reads as at load; None for any other url."""
    for k in range(len(scene.shapes)):
        model = scene.loaded_model(k)
        node, app = getattr(model, "node", None), model.appearance
        if node is not None and app is not None and app.texture is not None:
            written = node.values.get("texture.url")
            if written and str(written[0]).replace("\\", "/") == url:
                return app.texture.url
    return None


class _Unreadable(Exception):
    """A url whose image is not read (not found, not an image, not local): Webots sets the field, warns and
    draws the shape without its texture."""


def _installed_url(scene: Any, url: str) -> str:
    """The file a ``webots://`` url names in the Webots installation (``--webots-home``/``WEBOTS_HOME``)
    or the ``--proto-path`` folders, found as a world file's are: Webots reads any such url a Supervisor
    sets (its how-to ``texture_change`` swaps two of its textures). Not found there: _Unreadable (naming
    the places tried)."""
    from sensorium.server.world.proto import ProtoError, ProtoSearch, asset_roots, resolve_url

    search = ProtoSearch.create(scene.base_dir)
    try:
        path = resolve_url(url, scene.base_dir / "world.wbt", search).resolve()
    except ProtoError as exc:
        raise _Unreadable(f"texture file {exc.message}") from None
    except (OSError, ValueError) as exc:
        raise _Unreadable(f"{_quoted(url)} cannot be resolved ({exc})") from None
    if not any(path.is_relative_to(root) for root in asset_roots(search)):
        raise _Unreadable(f"{_quoted(url)} names a file outside the Webots installation and the --proto-path folders")
    return str(path)


def _retexture(sim: Any, ref: ShapeRef, where: str, url: str | None) -> list[str]:
    """Every shape holding the texture takes ``url`` (checked as a world file's textures are). A url whose
    image is not read (missing, not a PNG/JPEG, outside the world's folder, a download) leaves them
    untextured, as Webots draws a texture it cannot load: its one line returned. An image over the world's
    texture limits: ValueError (one line), nothing changed."""
    scene = sim.scene
    shapes = ref.peers or (ref.index,)
    name = url
    given: dict = {}
    lines: list[str] = []
    if url is not None:
        try:
            known = _world_url(scene, url)
            if known is None and url.startswith("webots://"):
                known = _installed_url(scene, url)
            if known is None and "://" in url:
                raise _Unreadable(f"{_quoted(url)}: only local image files are read here, named relative to the "
                                  "world file's folder, or webots:// urls of the Webots installation (no downloads)")
            name = known or url
            before = scene.textures.pixels(without=shapes) if scene.textures is not None else 0
            # (the file as it is now, read once: the image checked is the image shown, whatever happens to
            # the file after; the same image as held is not held twice: TextureSampler)
            file, _, decoded = read_checked_image(
                name, scene.base_dir, sim.limits, pixels_before=before,
                allow_outside=known is not None or bool(getattr(sim, "allow_outside_meshes", False)))
            given = {name: (file, decoded)}
        except TextureLimitError as exc:
            raise ValueError(f"{where}: {str(exc).replace(repr(name), _quoted(name))}; nothing changed") from None
        except (TextureFileError, _Unreadable) as exc:
            problem = str(exc).replace(repr(name), _quoted(name)) if isinstance(exc, TextureFileError) else str(exc)
            lines.append(f"{where}: {problem}; the shape is drawn without its texture (as Webots draws an image it "
                         "cannot load)")
            name = None
    for k in shapes:        # (an image whose pixel format has alpha: the shape casts no shadow, as Webots draws it)
        new = _retextured(scene, k, name)
        if new is not None:
            scene.set_texture(k, new, given)
    return lines


def change_url(sim: Any, ref: ShapeRef, node: Any, op: str, index: Any, value: Any) -> list[str]:
    """Webots' ``setMFString``/``insertMFString``/``removeMF`` on an ImageTexture's ``url``: when the list
    changes (an item set to another value, one inserted or removed: Webots' ``updateUrl``), the image its
    first item names is read from its file as it is now (relative to the world file's folder, within the
    world's texture limits) and every shape holding the texture shows it from the next step, as if the
    world file had named it; an empty url (or none) leaves the shapes untextured, as Webots. A url whose
    image is not read (missing, not an image, a download) is set all the same and leaves the shapes
    untextured, as Webots does: its one line returned. Bad input (not a string, too long, an item out of
    range) and an image over the texture limits: ValueError (one line naming the node, the field and the
    problem), nothing changed."""
    where = f"field 'url' (MFString) of {_what(ref, node.def_name, node.id)}"
    items = [str(v) for v in _value(sim, ref, "url", ())]
    count = len(items)
    if op != "remove" and not isinstance(value, str):
        raise ValueError(f"{where}: takes a string, got {value!r}; nothing changed")
    if op != "remove" and len(value) > MAX_URL_CHARS:
        raise ValueError(f"{where}: takes a url of at most {MAX_URL_CHARS:,} characters, got {_quoted(value)}; "
                         "nothing changed")
    at = item_position(where, op, index, count)
    new = list(items)
    if op == "insert":
        if count >= MAX_URLS:
            raise ValueError(f"{where}: it holds {count} urls, the most kept here; nothing changed")
        new.insert(at, value.replace("\\", "/"))
    elif op == "remove":
        del new[at]
    else:
        new[at] = value.replace("\\", "/")
    lines: list[str] = []
    if new != items:        # Webots' updateUrl: any change of the list (not the same value set again) reads the image
        first = new[0] if new else ""
        lines = _retexture(sim, ref, where, first if first.strip() else None)
    for k in ref.peers or (ref.index,):
        sim.scene.appearance_values.setdefault(k, {})["texture.url"] = list(new)
    return lines


def _texture_setter(ref: ShapeRef, name: str, kind: str) -> Setter:
    """``repeatS``/``repeatT`` (the wrap infra-red sensors and cameras read) and ``filtering`` (kept and
    read back; it changes Webots' rendering only, never a texel read)."""
    def set_value(sim: Any, node: Any, value: Any) -> None:
        where = f"field {name!r} ({kind}) of {_what(ref, node.def_name, node.id)}"
        if name == "filtering" and (isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 5):
            raise ValueError(f"{where}: must be a whole number from 0 to 5, got {value!r} (Webots resets it to 4 "
                             "with a warning); nothing changed")
        scene = sim.scene
        for k in ref.peers or (ref.index,):
            current = scene.shape_model(k).appearance
            if name != "filtering" and current is not None and current.texture is not None:
                attr = "repeat_s" if name == "repeatS" else "repeat_t"
                scene.set_texture(k, current.model_copy(update={
                    "texture": current.texture.model_copy(update={attr: bool(value)})}))
            scene.appearance_values.setdefault(k, {})[f"texture.{name}"] = int(value) if name == "filtering" \
                else bool(value)

    return set_value


def fields(ref: ShapeRef, child: Callable[[str], int]) -> dict[str, tuple[str, Getter, Setter]]:
    """A served node's fields: (type, getter, setter or None). ``child(field)``: the id of the node
    in its SFNode field (0: NULL)."""
    def node_field(name: str) -> tuple[str, Getter, Setter]:
        return ("SFNode", lambda sim, node: child(name), None)

    if ref.role == "Shape":
        return {"appearance": node_field("appearance"), "geometry": node_field("geometry"),
                "castShadows": ("SFBool", lambda sim, node: bool(sim.scene.loaded_model(ref.index).cast_shadows), None)}
    table = {"material": MATERIAL_FIELDS, "texture": TEXTURE_FIELDS}.get(ref.role) or (
        PBR_FIELDS if ref.type == "PBRAppearance" else {} if ref.role == "appearance"
        else GEOMETRY_FIELDS.get(ref.type, {}))
    out: dict[str, tuple[str, Getter, Setter]] = {}
    for name, (kind, default) in table.items():
        out[name] = (kind, lambda sim, node, name=name, default=default: _value(sim, ref, name, default),
                     _setter(ref, name, kind))
    if ref.type == "Appearance":
        out.update(material=node_field("material"), texture=node_field("texture"))
    elif ref.type == "PBRAppearance":
        out["baseColorMap"] = node_field("baseColorMap")
    return out
