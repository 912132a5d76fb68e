"""World files: the pydantic models that are the contract for YAML/JSON worlds.

Field names are Webots' field names in snake_case, defaults are Webots' node defaults, and the
sanitising rules are Webots' (devices.md §2.1, §3.1, §4.1) except where the project decided to
reject instead (attenuation ``0 0 0``, unknown sensor types). Sanitising that changes a value is
reported as a warning by the loader; anything ambiguous or meaningless is an error.

Conventions: world z-up, devices FLU (x forward, y left, z up); lengths in metres, angles in
radians, time in integer milliseconds.
"""

from __future__ import annotations

import itertools
import math
import types
import typing
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainSerializer,
    SerializationInfo,
    ValidationInfo,
    ValidatorFunctionWrapHandler,
    WrapValidator,
    field_validator,
    model_validator,
)

Vec3 = tuple[float, float, float]


Color = Vec3


def _unit_colors(v: Color | list[Color]) -> Color | list[Color]:
    """A colour, or each of a list of colours, with every component within [0, 1]."""
    for c in v if isinstance(v, list) else [v]:
        if min(c) < 0 or max(c) > 1:
            raise ValueError(f"colour components must be within [0, 1], got {[float(x) for x in c]}")
    return v


def _nonzero_direction(v: Vec3) -> Vec3:
    if math.hypot(*v) == 0:
        raise ValueError("direction must not be the zero vector")
    return v


_SCALARS = {float, int, str, type(None)}


def _not_a_number(value: Any, tp: Any) -> tuple[Any] | None:
    """``(v,)`` for the first bool in ``value`` where the annotation ``tp`` wants a number, else
    None. Pydantic's lax mode reads ``true`` as 1: a YAML ``basic_time_step: true`` became a 1 ms
    step without a word. (A string that spells a number stays one: YAML 1.1 reads ``1e-3``, without
    a dot, as a string, and pydantic's reading of it is the number meant.)"""
    if tp is float or tp is int:
        return (value,) if isinstance(value, bool) else None
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin is Annotated:
        return _not_a_number(value, args[0])
    if origin is typing.Union or origin is types.UnionType:
        kinds = [a for a in args if a is not type(None)]
        return _not_a_number(value, kinds[0]) if len(kinds) == 1 else None   # (X | None only)
    if origin not in (tuple, list) or not isinstance(value, (list, tuple)) or not args:
        return None
    if origin is list or (len(args) == 2 and args[1] is Ellipsis):
        types_in = set(map(type, value))            # a long run of numbers (heights, vertices): types at C speed
        rows = types_in <= {list, tuple} and set(map(type, itertools.chain.from_iterable(value))) <= _SCALARS
        if bool not in types_in and (types_in <= _SCALARS or rows):
            return None                             # no bool in it, none deeper
        return next((bad for v in value if (bad := _not_a_number(v, args[0])) is not None), None)
    return next((bad for v, a in zip(value, args) if (bad := _not_a_number(v, a)) is not None), None)


class Strict(BaseModel):
    """Base: unknown keys are errors, NaN/inf rejected everywhere, models immutable, and a bool where
    a number is due is refused (not read as 0 or 1)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)

    @model_validator(mode="before")
    @classmethod
    def _numbers_are_numbers(cls, data: Any) -> Any:
        if isinstance(data, dict):
            fields = cls.model_fields
            for name, value in data.items():
                field = fields.get(name)
                if field is not None and (bad := _not_a_number(value, field.annotation)) is not None:
                    raise ValueError(f"{name}: expected a number, got {bad[0]!r}")
        return data


class Pose(Strict):
    """Translation plus either a Webots axis-angle rotation or a quaternion (ROS order x, y, z, w)."""

    translation: Vec3 = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float, float] | None = Field(
        default=None, description="Webots axis-angle: axis x, y, z then angle (rad)"
    )
    quaternion: tuple[float, float, float, float] | None = Field(
        default=None, description="unit quaternion in ROS order x, y, z, w"
    )

    @model_validator(mode="after")
    def _one_rotation(self) -> Pose:
        if self.rotation is not None and self.quaternion is not None:
            raise ValueError("give either 'rotation' (axis-angle) or 'quaternion', not both")
        if self.rotation is not None and math.hypot(*self.rotation[:3]) == 0.0 and self.rotation[3] != 0.0:
            raise ValueError("rotation axis must not be zero")
        if self.quaternion is not None and math.hypot(*self.quaternion) == 0.0:
            raise ValueError("quaternion must not be zero")
        return self


# ---------------------------------------------------------------- geometry

class Box(Strict):
    type: Literal["box"]
    size: Vec3 = (2.0, 2.0, 2.0)

    @field_validator("size")
    @classmethod
    def _positive(cls, v: Vec3) -> Vec3:
        if min(v) <= 0:
            raise ValueError("every box size component must be > 0")
        return v


class Sphere(Strict):
    type: Literal["sphere"]
    radius: float = Field(default=1.0, gt=0)
    subdivision: int = Field(default=3, ge=0, le=6, description="icosphere level of the triangle mesh")


class Cylinder(Strict):
    """Axis along local z, centred on the origin, closed caps (Webots R2022+)."""

    type: Literal["cylinder"]
    radius: float = Field(default=1.0, gt=0)
    height: float = Field(default=2.0, gt=0)
    subdivision: int = Field(default=36, ge=3, le=1024, description="facets around the axis")


class Capsule(Strict):
    """Cylinder of ``height`` along local z with hemispherical ends of ``radius``."""

    type: Literal["capsule"]
    radius: float = Field(default=1.0, gt=0)
    height: float = Field(default=2.0, gt=0)
    subdivision: int = Field(default=12, ge=2, le=256, description="facets per quarter circle")


class Cone(Strict):
    """Webots' Cone: axis along local z, apex at z = +height/2, base disc at z = −height/2. Seen by
    visual rays only (Webots does not accept a Cone in a boundingObject)."""

    type: Literal["cone"]
    bottom_radius: float = Field(default=1.0, gt=0)
    height: float = Field(default=2.0, gt=0)
    subdivision: int = Field(default=36, ge=3, le=1024, description="sides of the tessellation (FAST)")


class Plane(Strict):
    """Normal along local +z. ``size`` null means infinite.

    As in Webots, bounding-object rays see every plane as infinite and two-sided; visual rays see
    it one-sided (from +z) and finite when ``size`` is given.
    """

    type: Literal["plane"]
    size: tuple[float, float] | None = (1.0, 1.0)

    @field_validator("size")
    @classmethod
    def _positive(cls, v: tuple[float, float] | None) -> tuple[float, float] | None:
        if v is not None and min(v) <= 0:
            raise ValueError("plane size components must be > 0 (use null for an infinite plane)")
        return v


class Rows:
    """Rows of numbers (a mesh's vertices or faces) held as one read-only numpy array of shape
    (n, width): 8 bytes a number instead of a Python object and a list slot each. It reads as the
    list of tuples it stands for (``len``, indexing and iteration give tuples of Python numbers,
    ``==`` compares values), and ``np.asarray`` gives the array itself, without a copy. Float rows
    are float64, index rows int64 (object only for an index beyond 64 bits, which the loader refuses
    by value)."""

    __slots__ = ("array",)

    def __init__(self, array: np.ndarray):
        array = np.asarray(array)
        array.flags.writeable = False       # (the caller's array itself: handed over, never copied)
        self.array = array

    def __len__(self) -> int:
        return len(self.array)

    def __bool__(self) -> bool:
        return len(self.array) > 0

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return Rows(self.array[i])
        return tuple(self.array[i].tolist())

    def __iter__(self) -> typing.Iterator[tuple[Any, ...]]:
        return map(tuple, self.array.tolist())

    def __array__(self, dtype: Any = None, copy: bool | None = None) -> np.ndarray:
        if dtype is None or np.dtype(dtype) == self.array.dtype:
            return self.array.copy() if copy else self.array
        return self.array.astype(dtype)

    def tolist(self) -> list[list[Any]]:
        return self.array.tolist()

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Rows):
            return self.array.shape == other.array.shape and bool(np.array_equal(self.array, other.array))
        if isinstance(other, list | tuple):
            return len(other) == len(self) and all(a == tuple(b) for a, b in zip(self, other, strict=True))
        return NotImplemented

    def __hash__(self) -> int:
        return hash((self.array.shape, self.array.dtype.str, self.array.tobytes()))

    def __repr__(self) -> str:
        return f"Rows({self.array.shape[0]} x {self.array.shape[1] if self.array.ndim == 2 else 0}, {self.array.dtype})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (Rows, (self.array,))


def _as_rows(width: int, kind: type, min_length: int, max_length: int
             ) -> typing.Callable[[Any, ValidatorFunctionWrapHandler], Any]:
    """A field of rows of ``width`` numbers of ``kind`` (float or int) validated into ``Rows``. Rows
    given as a numpy array of that dtype and shape (a .wbt IndexedFaceSet's, as converted), or as
    lists of plain numbers (a YAML/JSON world), are checked in one numpy pass (finite, within the
    field's length bounds) and kept as one array; anything else goes through pydantic's own
    validation of the list type, whose errors (path, message) are the field's errors as before."""
    dtype = np.float64 if kind is float else np.int64
    scalars = {float, int} if kind is float else {int}

    def fast(value: Any) -> np.ndarray | None:
        if isinstance(value, Rows):
            return value.array
        if isinstance(value, np.ndarray):
            if value.dtype != dtype or value.ndim != 2 or value.shape[1] != width:
                return None
            arr = value
        elif isinstance(value, list):
            if value and not (set(map(type, value)) <= {list, tuple} and set(map(len, value)) == {width}
                              and set(map(type, itertools.chain.from_iterable(value))) <= scalars):
                return None
            try:
                arr = np.array(value, dtype=dtype)
            except (OverflowError, ValueError):
                return None
            if arr.ndim != 2:
                arr = arr.reshape(-1, width)    # (no rows)
        else:
            return None
        if kind is float and not np.isfinite(arr).all():
            return None
        return arr

    def validate(value: Any, handler: ValidatorFunctionWrapHandler) -> Any:
        arr = fast(value)
        if arr is not None and min_length <= len(arr) <= max_length:
            return Rows(arr)
        if isinstance(value, Rows):         # (out of bounds: pydantic says so, as for a list)
            value = value.array
        if isinstance(value, np.ndarray):
            value = value.tolist()
        out = handler(value)
        try:
            return Rows(np.array(out, dtype=dtype).reshape(-1, width))
        except OverflowError:               # an index beyond 64 bits: kept, refused by value later
            return Rows(np.array(out, dtype=object).reshape(-1, width))

    return validate


def _rows_out(value: Any, info: SerializationInfo) -> Any:
    """``Rows`` written back as lists of numbers (``model_dump``: tuples, as the list type's own)."""
    if isinstance(value, Rows):
        return value.tolist() if info.mode_is_json() else list(value)
    return value


# each a list type (its JSON schema, its errors) held as Rows; the bounds are the list's, given to both
Vertices = Annotated[list[Vec3], Field(max_length=1_000_000), WrapValidator(_as_rows(3, float, 0, 1_000_000)),
                     PlainSerializer(_rows_out)]
Faces = Annotated[list[tuple[int, int, int]], Field(min_length=1, max_length=2_000_000),
                  WrapValidator(_as_rows(3, int, 1, 2_000_000)), PlainSerializer(_rows_out)]
TexCoords = Annotated[list[tuple[float, float]], Field(max_length=1_000_000),
                      WrapValidator(_as_rows(2, float, 0, 1_000_000)), PlainSerializer(_rows_out)]
TexFaces = Annotated[list[tuple[int, int, int]], Field(max_length=2_000_000),
                     WrapValidator(_as_rows(3, int, 0, 2_000_000)), PlainSerializer(_rows_out)]


class Triangles(Strict):
    """Triangles given inline (Webots' IndexedFaceSet, triangulated): vertex coordinates and index
    triples into them, in the shape's frame."""

    type: Literal["triangles"]
    vertices: Vertices
    faces: Faces
    tex_coords: TexCoords | None = Field(
        default=None,
        description="texture coordinates (s, t), t up as in Webots' TextureCoordinate; none: Webots' default "
                    "mapping from the bounding box")
    tex_coord_faces: TexFaces | None = Field(
        default=None,
        description="per face, the tex_coords index of each corner (Webots' texCoordIndex); none: the faces' indices")


class Mesh(Strict):
    """Triangle mesh file (STL, OBJ, PLY, glTF, OFF, COLLADA .dae); path relative to the world file. A
    COLLADA file is placed as Webots places it: scaled by its ``<unit>``, its ``<up_axis>`` turned to +z."""

    type: Literal["mesh"]
    url: str
    scale: Vec3 = (1.0, 1.0, 1.0)
    material_index: int = Field(default=-1, ge=-1, le=1_000_000, description=(
        "COLLADA (Webots' Mesh.materialIndex): only the triangles of this material, the file's materials "
        "numbered in the order of their ids (then a default one for triangles bound to none); OBJ (ours: "
        "what a CadShape's materials become): the material names its faces use, sorted (then a default one "
        "for faces without); -1: all"))
    name: str = Field(default="", max_length=4096, description=(
        "COLLADA only (Webots' Mesh.name): only the triangles of the geometry of this name (else id); \"\": all"))


class ElevationGrid(Strict):
    """A height field (Webots' ElevationGrid, R2022a+): ``x_dimension`` × ``y_dimension`` points,
    the grid spanning local x and y from the origin (``x_spacing``, ``y_spacing`` apart), heights
    along +z, row-major (``height[j * x_dimension + i]`` is the point at ``(i·x_spacing,
    j·y_spacing)``). Each cell is two triangles split along its diagonal from ``(i, j)`` to
    ``(i + 1, j + 1)``, as Webots renders it; rays see those triangles exactly."""

    type: Literal["elevation_grid"]
    height: tuple[float, ...] = Field(max_length=16_000_000, description="x_dimension × y_dimension heights, "
                                      "row-major: x fastest, the first at the local origin")
    x_dimension: int = Field(ge=2, le=1_000_000, description="points along x")
    x_spacing: float = Field(default=1.0, gt=0, description="distance between points along x (m)")
    y_dimension: int = Field(ge=2, le=1_000_000, description="points along y")
    y_spacing: float = Field(default=1.0, gt=0, description="distance between points along y (m)")
    thickness: float = Field(default=0.0, ge=0, description="Webots' physics depth below the lowest "
                             "point; read and kept, rays see the surface")

    @model_validator(mode="after")
    def _height_count(self) -> ElevationGrid:
        need = self.x_dimension * self.y_dimension
        if len(self.height) != need:
            raise ValueError(f"height has {len(self.height):,} values; x_dimension × y_dimension = "
                             f"{self.x_dimension:,} × {self.y_dimension:,} = {need:,} are needed")
        return self


Geometry = Annotated[Box | Sphere | Cylinder | Capsule | Cone | Plane | Triangles | Mesh | ElevationGrid,
                     Field(discriminator="type")]


class Texture(Strict):
    """An image on a surface (Webots' ImageTexture): a PNG or JPEG file, path relative to the world
    file (confined to its folder like meshes). Infra-red sensors read the texel under each hit,
    nearest texel, alpha ignored (Webots' pickColor); cameras see through transparent texels
    (alpha times 1 - transparency, as Webots' shaders). A bare string is taken as the url."""

    url: str = Field(min_length=1)
    repeat_s: bool = True
    repeat_t: bool = True
    filtering: int = Field(default=4, ge=0, le=5, description="Webots' rendering filter; sensors read the nearest texel")


class TextureTransform(Strict):
    """Webots' TextureTransform (X3D order: translation, then rotation and scale about center)."""

    center: tuple[float, float] = (0.0, 0.0)
    rotation: float = 0.0
    scale: tuple[float, float] = (1.0, 1.0)
    translation: tuple[float, float] = (0.0, 0.0)


def _texture_from_url(v: object) -> object:
    return {"url": v} if isinstance(v, str) else v


TextureField = Annotated[Texture | None, BeforeValidator(_texture_from_url)]


class Appearance(Strict):
    """What infra-red sensors see (PBRAppearance fields). No appearance means white (red = 1).

    With a ``texture`` the colour is ``base_color × (1 − transparency) × texel`` (Webots multiplies
    a PBRAppearance's baseColor by its baseColorMap; a textured Appearance's diffuse colour is
    replaced by white). ``roughness_map``/``occlusion_map`` (red channel) are read only where
    ``texture`` is set, as in Webots. Cameras add ``emissive_color`` to the light a surface sends
    (Webots' Material ``emissiveColor``; a PBRAppearance's ``emissiveColor`` times ``emissive_intensity``
    where WREN's forward shader draws it: a translucent shape, or an opaque one while no light that is on
    casts shadows)."""

    base_color: Vec3 = (1.0, 1.0, 1.0)
    emissive_color: Vec3 = (0.0, 0.0, 0.0)
    transparency: float = Field(default=0.0, ge=0.0, le=1.0)
    roughness: float = Field(default=0.0, ge=0.0, le=1.0)
    texture: TextureField = None
    roughness_map: TextureField = None
    occlusion_map: TextureField = None
    texture_transform: TextureTransform | None = None
    emissive_intensity: float = Field(default=1.0, ge=0.0, description="Webots' PBRAppearance emissiveIntensity: "
                                      "cameras multiply the emissive colour (or emissive_map texel) by it on a "
                                      "translucent shape, and on an opaque one while no light that is on casts "
                                      "shadows (WREN's shadow-volume shader leaves it out); not read with phong")
    emissive_map: TextureField = Field(default=None, description="Webots' PBRAppearance emissiveColorMap: cameras "
                                       "take its texel, as stored (no sRGB decoding), for the emissive colour, as "
                                       "WREN's PBR shaders do; read with or without a texture")
    phong: bool = Field(default=False, description="drawn as Webots draws an Appearance node (its Phong shader): "
                        "cameras multiply the emissive colour by the texture's colour too (a PBRAppearance's "
                        "emissive colour is added as it is)")

    _unit = field_validator("base_color", "emissive_color")(_unit_colors)


SeenBy = Literal["both", "bounding", "visual"]

NodeValue = float | tuple[float, float, float] | tuple[float, float] | tuple[str, ...] | bool


class InnerDef(Strict):
    """A DEF name written in a PROTO's body, for the Supervisor's getFromProtoDef (README "Supervisor"). On
    the node it names (a robot's `nodes` entry, a solid inside a top-level solid, a shape or one of its
    nodes: ``role``): which PROTO instance's scope finds it; on a robot or top-level solid, with ``why``, a
    DEF of an instance inside it that names a node Sensorium does not serve (a Physics node, ...)."""

    scope: int = Field(ge=-1, description="the PROTO instance: -1 the robot or top-level solid holding the node, "
                       "else (in a robot) the index of the instance's entry in the robot's `nodes`, (in a top-level "
                       "solid) the `proto_scope` of the nested solid that is the instance")
    name: str = Field(min_length=1, max_length=4096, description="the DEF name")
    role: Literal["", "appearance", "material", "texture", "geometry"] = Field(
        default="", description="on a shape: which of its nodes ('' the Shape itself)")
    why: str = Field(default="", max_length=512, description="on the robot or top-level solid: why the DEF'd node is "
                     "no Supervisor node here ('' on the node itself)")


_INNER_DEFS = "the DEF names of PROTO bodies this node answers getFromProtoDef for (see InnerDef)"

_WRITTEN_AT = ("where the world file (or the node string it was imported from) writes this node: [line, column] (a "
               "PROTO instance: where the instance is written); none for a node a PROTO's body made. A Supervisor's "
               "exportString finds its text there")


def _written_at() -> Any:
    return Field(default=None, min_length=2, max_length=2, description=_WRITTEN_AT)


_SEQ = ("inside a top-level solid holding Poses or Groups (`poses`): its file order there (larger: written later), "
        "which orders its parent's children (Supervisor getMFNode); none otherwise")


_MADE_AT = ("where the PROTO body that made this node writes it: [line, column] in that body's text (as its template "
            "generated it; a PROTO instance inside a body: where the instance is written there); none for a node the "
            "world file writes. A Supervisor's exportString finds its text there")


def _made_at() -> Any:
    return Field(default=None, min_length=2, max_length=2, description=_MADE_AT)


class ShapeNode(Strict):
    """A ``.wbt`` Shape as a Supervisor serves it (README "Supervisor"): its DEFs, its appearance
    node's type, and the written values of its appearance's, material's, texture's and geometry's
    fields (Webots' defaults for the ones left out). What sensors see is the shape's ``appearance``;
    these are what a Supervisor reads back."""

    def_name: str | None = Field(default=None, min_length=1)
    parent: int = Field(default=-1, ge=-1, description="on a robot: the index in the robot's `nodes` of the node "
                        "holding it (-1: the robot); on a solid: the index in its solid's `poses` of the Pose or "
                        "Group holding it (-1: the solid)")
    seq: int | None = Field(default=None, ge=1, description=_SEQ)
    after: int = Field(default=-1, ge=-1, description="its place among its parent's children: on a robot, the "
                       "index of the last `nodes` entry written before it; on a solid, how many of the solid's "
                       "children solids come before it, minus one")
    appearance: Literal["Appearance", "PBRAppearance"] | None = None
    appearance_def: str | None = Field(default=None, min_length=1)
    appearance_proto: str | None = Field(default=None, min_length=1, description="an appearance PROTO instance "
                                         "(PaintedWood, ...): the PROTO's name")
    appearance_interface: list[ProtoLevel] = Field(default=[], max_length=16, description="its PROTO's interface, as a "
                                                   "nested node's `interface`")
    appearance_key: int = Field(default=-1, ge=-1, description="shapes whose appearance is one world-file node "
                                "(its DEF and USEs) share this number; a Supervisor's change reaches them all")
    material: bool = Field(default=False, description="an Appearance with a Material node")
    material_key: int = Field(default=-1, ge=-1, description="the same for its Material node")
    material_def: str | None = Field(default=None, min_length=1)
    texture_def: str | None = Field(default=None, min_length=1)
    texture_key: int = Field(default=-1, ge=-1, description="the same for its ImageTexture node")
    geometry: str = Field(default="", max_length=64, description="the geometry node's type (Box, Mesh, ...)")
    geometry_def: str | None = Field(default=None, min_length=1)
    values: dict[str, NodeValue] = Field(default={}, max_length=64, description="the written values: "
                                         "'<node>.<field>' (node: appearance, material, texture, geometry)")
    inner_defs: list[InnerDef] = Field(default=[], max_length=64, description=_INNER_DEFS)
    written_at: list[Annotated[int, Field(ge=1)]] | None = _written_at()
    made_at: list[Annotated[int, Field(ge=1)]] | None = _made_at()
    piece: bool = Field(default=False, description="a further piece of the shape before it: a mesh the .wbt import "
                        "split around its robot's devices (README 'Worlds') is one Shape node to a "
                        "Supervisor, its first piece's")

_CAST_SHADOWS = ("Webots' Shape.castShadows: false lets cameras' shadow rays through this shape (it still hides "
                 "what is behind it, and other rays see it)")


class Shape(Strict):
    """A geometry as seen by rays: bounding-object rays (generic/sonar/laser distance sensors,
    light occlusion), visual rays (infra-red distance sensors, lidar), or both."""

    geometry: Geometry
    appearance: Appearance | None = None
    seen_by: SeenBy = "both"
    cast_shadows: bool = Field(default=True, description=_CAST_SHADOWS)
    node: ShapeNode | None = Field(default=None, description="the .wbt Shape node a Supervisor serves (its DEF, "
                                   "its appearance's fields as written); none: served from `appearance`")

    @model_validator(mode="after")
    def _cone_seen(self) -> Shape:
        _check_cone_seen(self.geometry, self.seen_by)
        return self


def _check_cone_seen(geometry: object, seen_by: str) -> None:
    if isinstance(geometry, Cone) and seen_by == "bounding":
        raise ValueError("a cone is seen by visual rays only (Webots accepts no Cone in a boundingObject): "
                         "seen_by bounding would hide it (use visual or both)")


_ON_JOINT = ("on a robot: the motor (RotationalMotor or LinearMotor, not a drive's) whose joint this rides on, "
             "the innermost one; it moves with that joint (README 'Joints'). Left out: the robot's body")


class Part(Shape):
    """One shape of a body made of several shapes, placed by ``pose`` in its owner's frame."""

    name: str | None = None
    pose: Pose = Pose()
    on_joint: str | None = Field(default=None, min_length=1, description=_ON_JOINT)
    of_device: str | None = Field(
        default=None, min_length=1,
        description="on a robot: the device whose own Solid this shape belongs to (a sensor's housing); that "
                    "device's infra-red rays and lidar beams do not see it, as in Webots")
    in_solid: int = Field(
        default=-1, ge=-1, le=1 << 20,
        description="on a robot: the index in the robot's `nodes` of the Solid (or device) this shape belongs to, "
                    "the nearest one holding it (-1: the robot itself); the Supervisor's contact points name it")
    unseen_by: list[str] = Field(
        default=[], max_length=256,
        description="on a robot: devices whose visual rays (infra-red, lidar, camera, range finder) do not see this "
                    "shape although it is not theirs: the triangles of a mesh around a device that face away from it, "
                    "which Webots culls (the .wbt import splits such a mesh)")


# ---------------------------------------------------------------- lights


# Webots' ranges of the lights' number fields (WbLight, WbPointLight, WbSpotLight): a world file's value
# outside is reset by the loader with a warning as Webots does (loader.sanitize, to Webots' reset value),
# except radius (a schema error here); the Supervisor's setters refuse one (daemon/supervisor.py). The colour
# must be within [0, 1] like every colour of a YAML world (Webots clamps it, as the .wbt converter does).
LIGHT_RANGES: dict[str, tuple[float, float]] = {
    "ambient_intensity": (0.0, 1.0),
    "intensity": (0.0, math.inf),
    "radius": (0.0, math.inf),
    "beam_width": (0.0, math.pi / 2),
    "cut_off_angle": (0.0, math.pi / 2),
}


def _range_text(lo: float, hi: float) -> str:
    def num(v: float) -> str:
        return "pi/2" if v == math.pi / 2 else f"{v:g}"
    return f">= {num(lo)}" if hi == math.inf else f"within [{num(lo)}, {num(hi)}]"


def light_value_problem(field: str, value: object) -> str | None:
    """What is wrong with ``value`` for light field ``field`` (snake_case) against Webots' range, or
    None: a number outside ``LIGHT_RANGES``, a colour component outside [0, 1]."""
    if field == "color":
        try:
            _unit_colors(tuple(value))  # type: ignore[arg-type]   # one colour (a list is a list of colours)
        except ValueError as exc:
            return str(exc)
        return None
    bounds = LIGHT_RANGES.get(field)
    if bounds is None or not isinstance(value, int | float) or bounds[0] <= value <= bounds[1]:
        return None
    return f"must be {_range_text(*bounds)}, got {value}"


def _range_doc(field: str) -> str:
    return f"{_range_text(*LIGHT_RANGES[field])} (outside: reset with a warning, as Webots)"


class LightNode(Strict):
    """A ``.wbt`` light inside a robot or solid as a Supervisor serves it (README "Supervisor"): where it
    sits among its parent's children and its ``location``/``direction`` fields as written (in its parent's
    frame); the light's own ``location``/``direction`` are those placed in its robot's or solid's frame."""

    parent: int = Field(default=-1, ge=-1, description="on a robot: the index in the robot's `nodes` of the node "
                        "holding it (-1: the robot); on a solid: the index in its solid's `poses` of the Pose or "
                        "Group holding it (-1: the solid)")
    seq: int | None = Field(default=None, ge=1, description=_SEQ)
    after: int = Field(default=-1, ge=-1, description="its place among its parent's children, as a Shape's `after`")
    frame: Pose = Field(default=Pose(), description="its parent's frame in the robot's or solid's frame: "
                        "`location` and `direction` are the fields placed by it")
    linear: list[float] | None = Field(default=None, min_length=9, max_length=9,
                                       description="under a scaled Transform: the scale its parent's frame applies "
                                       "before `frame` (row-major, in that frame's axes), so that `location` is "
                                       "placed at frame(linear · location); None: unscaled")
    aim: Pose | None = Field(default=None, description="a spot light's: the rotation turning `direction` into "
                             "`light_sensor_direction` (the nearest Pose's or Solid's own); None: it has none")
    location: Vec3 | None = Field(default=None, description="the field as written (its parent's frame)")
    direction: Vec3 | None = Field(default=None, description="the field as written (its parent's frame)")
    written_at: list[Annotated[int, Field(ge=1)]] | None = _written_at()
    made_at: list[Annotated[int, Field(ge=1)]] | None = _made_at()
    body: bool = Field(default=False, description="written by a PROTO's body, not the world file (a "
                       "Supervisor cannot remove it: Webots' node internal to a PROTO)")
    inner_defs: list[InnerDef] = Field(default=[], max_length=64, description="its DEFs in PROTO bodies "
                                       "(getFromProtoDef), as a nested node's")


class _Light(Strict):
    name: str | None = None
    def_name: str | None = Field(default=None, min_length=1, description="Webots DEF name (Supervisor getFromDef)")
    ambient_intensity: float = Field(default=0.0, description=_range_doc("ambient_intensity"))
    intensity: float = Field(default=1.0, description=_range_doc("intensity"))
    color: Color = Field(default=(1.0, 1.0, 1.0), description="each component within [0, 1]")
    on: bool = True
    cast_shadows: bool = False  # rendering only in Webots; kept for file compatibility
    on_joint: str | None = Field(
        default=None, min_length=1,
        description="on a robot's `lights` only: the motor (RotationalMotor or LinearMotor, not a drive's) whose "
                    "joint carries this light, the innermost one; it moves with that joint (README 'Joints'). An "
                    "LED's lights ride with the LED (its own `on_joint`). Left out: the robot's body")
    node: LightNode | None = Field(default=None, description="a .wbt light inside a robot or solid: the "
                                   "Supervisor node it is (none: the light is no node of its own)")

    _unit = field_validator("color")(_unit_colors)


class _Attenuated(_Light):
    attenuation: Vec3 = (1.0, 0.0, 0.0)
    location: Vec3 = (0.0, 0.0, 0.0)
    radius: float = Field(default=100.0, ge=LIGHT_RANGES["radius"][0],
                          description="cameras: no direct light from it on a surface farther than this (m; Webots' "
                          "renderer); light sensors ignore it (Webots)")

    @field_validator("attenuation")
    @classmethod
    def _attenuation(cls, v: Vec3) -> Vec3:
        if min(v) < 0:
            raise ValueError("attenuation components must be >= 0")
        if v == (0.0, 0.0, 0.0):
            raise ValueError("attenuation 0 0 0 would give infinite irradiance; use 1 0 0 for none")
        return v


class PointLight(_Attenuated):
    type: Literal["PointLight"]


class SpotLight(_Attenuated):
    type: Literal["SpotLight"]
    direction: Vec3 = (0.0, 0.0, -1.0)
    beam_width: float = Field(default=1.570796, description=_range_doc("beam_width") + "; above cut_off_angle: "
                              "set to it with a warning")
    cut_off_angle: float = Field(default=0.785398, description=_range_doc("cut_off_angle"))
    light_sensor_direction: Vec3 | None = Field(
        default=None, description="the beam axis light sensors use, in world axes, fixed (Webots' LightSensor turns "
        "`direction` by the own rotation of the nearest enclosing Pose or Solid only, cameras by every enclosing "
        "frame); unset: `direction` placed as cameras see it, except a light of a nested solid (`children`): "
        "`direction` turned by that solid's own pose rotation. The .wbt import sets it for a spot light inside Poses")

    _nonzero = field_validator("direction")(_nonzero_direction)

    @field_validator("light_sensor_direction")
    @classmethod
    def _sensor_axis(cls, v: Vec3 | None) -> Vec3 | None:
        return None if v is None else _nonzero_direction(v)


class DirectionalLight(_Light):
    type: Literal["DirectionalLight"]
    direction: Vec3 = (0.0, 0.0, -1.0)

    _nonzero = field_validator("direction")(_nonzero_direction)


Light = Annotated[PointLight | SpotLight | DirectionalLight, Field(discriminator="type")]


# ---------------------------------------------------------------- solids

class Mass(Strict):
    """Webots' Physics of a Solid, a Robot or a device, as the Supervisor's getCenterOfMass reads it: its mass
    and its centre of mass in its own frame (the .wbt import resolves Webots' rules: a mass, or density ×
    the boundingObject's volume; centerOfMass, or the boundingObject's centroid). Nothing is pushed here."""

    kg: float = Field(gt=0.0, description="the mass (kg)")
    center: Vec3 = Field(default=(0.0, 0.0, 0.0), description="the centre of mass in the node's frame (m)")


class MassMesh(Strict):
    """A mesh file in the ``boundingObject`` of a Physics node: its volume and centroid count as Webots counts
    them (ODE's dMassSetTrimesh on its triangles as the file winds them), read with the file by the loader."""

    mesh: Mesh = Field(description="the file as a shape names it, its scale that of the Transforms above it")
    pose: Pose = Field(default=Pose(), description="the mesh's frame in the node's frame")


class PendingMass(Strict):
    """A Physics node whose mass or centre of mass needs the volume of mesh files in its ``boundingObject``:
    what the .wbt import knows of it. The loader reads the files and sets the node's ``mass`` from it by
    Webots' rules (the same density over every bounding shape), then drops it."""

    kg: float | None = Field(default=None, gt=0.0, description="Physics.mass when > 0; none: density × the "
                             "bounding object's volume")
    density: float = Field(default=1000.0, gt=0.0, description="Physics.density (kg/m³), used when kg is none")
    center: Vec3 | None = Field(default=None, description="Physics.centerOfMass in the node's frame; none: the "
                                "bounding object's centroid")
    volume: float = Field(default=0.0, ge=0.0, description="the volume of its other bounding shapes (m³)")
    centroid: Vec3 = Field(default=(0.0, 0.0, 0.0), description="their centroid in the node's frame (m)")
    meshes: list[MassMesh] = Field(min_length=1, max_length=100_000, description="its mesh files")


_MASS = ("Webots' Physics node: its mass and centre of mass (Supervisor getCenterOfMass: this node's and those "
         "of the nodes inside it with one, in world coordinates); none: no Physics (getCenterOfMass reads 0 0 0)")
_PENDING_MASS = ("a Physics whose mass or centre needs the volume of mesh files (the .wbt import's): the loader "
                 "reads them and sets `mass`; leave out `mass` with it")


def _one_mass(mass: Mass | None, pending: PendingMass | None) -> None:
    if mass is not None and pending is not None:
        raise ValueError("pending_mass: give either mass or pending_mass (which the loader makes the mass), not both")


_SCALE = ("a Transform's scale as the world file writes it (a zero component: 1, as Webots resets it), which a "
          "Supervisor's getField reads; none: 1 1 1 (and for every other node)")


class SolidPose(Strict):
    """A ``.wbt`` Pose, Transform or Group inside a solid as a Supervisor serves it (README
    "Supervisor"): getFromDef, its parent's children, its ``translation`` and ``rotation`` (read here), its
    world pose. The shapes, lights and solids inside it are its solid's, placed through it as the world loads."""

    type: Literal["Pose", "Transform", "Group"]
    def_name: str | None = Field(default=None, min_length=1)
    parent: int = Field(default=-1, ge=-1, description="the index of the Pose or Group holding it in the same "
                        "`poses` (an earlier entry); -1: the solid")
    seq: int = Field(ge=1, description=_SEQ)
    pose: Pose | None = Field(default=None, description="its frame in the solid's frame as the world loads; none "
                              "for a Group")
    scale: Vec3 | None = Field(default=None, description=_SCALE)
    inner_defs: list[InnerDef] = Field(default=[], max_length=64, description=_INNER_DEFS)
    written_at: list[Annotated[int, Field(ge=1)]] | None = _written_at()
    made_at: list[Annotated[int, Field(ge=1)]] | None = _made_at()


class Solid(Strict):
    """A static object (movable by a supervisor; carried by a VacuumGripper when it has ``physics``), seen
    by rays through its shapes.

    ``geometry`` (with ``appearance``/``seen_by``) is the solid's own shape at its origin;
    ``shapes`` adds further shapes each with its own offset; ``children`` are solids fixed to this
    one (poses relative to it, nested to any depth, moving with it); ``lights`` are lights fixed to
    it (``location`` and a SpotLight's ``direction`` in its frame; a DirectionalLight's direction
    stays in world axes, as in Webots).
    """

    name: str = Field(min_length=1)
    def_name: str | None = Field(default=None, min_length=1, description="Webots DEF name (Supervisor getFromDef)")
    pose: Pose = Pose()
    geometry: Geometry | None = None
    appearance: Appearance | None = None
    seen_by: SeenBy = "both"
    cast_shadows: bool = Field(default=True, description=_CAST_SHADOWS)
    shapes: list[Part] = []
    children: list[Solid] = []
    lights: list[Light] = []
    model: str = Field(default="", max_length=4096, description="Webots model (a recognised object's model)")
    recognition_colors: list[Color] = Field(
        default=[], max_length=1024, description="Webots recognitionColors: cameras with a Recognition node report "
        "this solid (with its children); top-level solids only")

    radar_cross_section: float = Field(
        default=0.0, ge=0.0, description="Webots radarCrossSection (m²): > 0 makes the solid a Radar target (a "
        "nested one too: at its own origin, its own shapes and those of the solids inside it as its box)")
    connectors: list[Connector] = Field(
        default=[], max_length=1024, description="Webots Connectors on this solid (a passive object a robot's "
        "connector docks with), each pose in the solid's frame: robots' connectors see them; they read nothing")
    inner_defs: list[InnerDef] = Field(default=[], max_length=1024, description=_INNER_DEFS + "; on a top-level "
                                       "solid, those of its PROTO instances' DEFs that name no node here (`why`)")
    proto_scope: int | None = Field(default=None, ge=0, description="a PROTO instance inside a top-level solid: its "
                                    "number there (InnerDef.scope)")
    poses: list[SolidPose] = Field(default=[], max_length=100_000, description="the Poses, Transforms and Groups "
                                   "inside it (not inside its children solids), in file order: Supervisor nodes")
    in_pose: int = Field(default=-1, ge=-1, description="a solid inside a solid: the index in its parent's `poses` "
                         "of the Pose or Group holding it (-1: the parent solid itself)")
    seq: int | None = Field(default=None, ge=1, description=_SEQ)

    written_at: list[Annotated[int, Field(ge=1)]] | None = _written_at()
    made_at: list[Annotated[int, Field(ge=1)]] | None = _made_at()
    physics: bool = Field(default=False, description="Webots: the solid has a Physics node. Nothing is pushed here "
                          "(no dynamics); a top-level solid with physics settles at load on what is under it (as "
                          "Webots' physics drops it), a VacuumGripper carries only such a solid, and one it lets go or "
                          "a Supervisor imports falls under the world's gravity onto what is under it over the next "
                          "steps (no solid falls at any other time)")
    mass: Mass | None = Field(default=None, description=_MASS)
    pending_mass: PendingMass | None = Field(default=None, description=_PENDING_MASS)

    _unit = field_validator("recognition_colors")(_unit_colors)

    @model_validator(mode="after")
    def _recognised_at_the_top(self) -> Solid:
        _one_mass(self.mass, self.pending_mass)
        _check_cone_seen(self.geometry, self.seen_by)
        for i, con in enumerate(self.connectors):
            if con.on_joint is not None:
                raise ValueError(f"connectors[{i}] ({con.name}): a solid has no joints (leave out on_joint)")
        for i, p in enumerate(self.poses):
            if p.parent >= i:
                raise ValueError(f"poses[{i}]: parent {p.parent} is not an earlier entry of `poses`")
        held = [("children", i, c.in_pose) for i, c in enumerate(self.children)]
        held += [("shapes", i, s.node.parent) for i, s in enumerate(self.shapes) if s.node is not None]
        held += [("lights", i, lt.node.parent) for i, lt in enumerate(self.lights) if lt.node is not None]
        for where, i, parent in held:
            if parent >= len(self.poses):
                raise ValueError(f"{where}[{i}]: its Pose {parent} is not in `poses` ({len(self.poses)} entries)")
        for i, child in enumerate(self.children):
            if child.recognition_colors:
                raise ValueError(f"children[{i}] ({child.name}): recognition_colors are read on top-level solids "
                                 "and robots only (give them to the top-level solid)")
        return self


# ---------------------------------------------------------------- devices

LookupRow = tuple[float, float, float]  # input, output, relative noise


class _Device(Strict):
    name: str = Field(min_length=1)
    model: str = Field(default="", max_length=4096, description="Webots model (Device.getModel)")
    pose: Pose = Pose()
    on_joint: str | None = Field(default=None, min_length=1, description=_ON_JOINT)


class LightSensor(_Device):
    device: Literal["LightSensor"]
    lookup_table: list[LookupRow] = [(0.0, 0.0, 0.0), (1.0, 1000.0, 0.0)]
    color_filter: Color = (1.0, 1.0, 1.0)
    occlusion: bool = False
    resolution: float = -1.0


class DistanceSensor(_Device):
    device: Literal["DistanceSensor"]
    lookup_table: list[LookupRow] = [(0.0, 0.0, 0.0), (0.1, 1000.0, 0.0)]
    type: Literal["generic", "infra-red", "infrared", "sonar", "laser"] = "generic"
    number_of_rays: int = 1
    aperture: float = 1.5708
    gaussian_width: float = 1.0
    resolution: float = -1.0
    red_color_sensitivity: float = 1.0

    @field_validator("type", mode="before")
    @classmethod
    def _lower(cls, v: object) -> object:
        return v.lower() if isinstance(v, str) else v


class Lidar(_Device):
    device: Literal["Lidar"]
    tilt_angle: float = 0.0
    horizontal_resolution: int = Field(default=512, ge=1, le=1 << 16)
    field_of_view: float = Field(default=1.5708, gt=0.0, le=2 * math.pi)
    vertical_field_of_view: float = 0.2
    number_of_layers: int = Field(default=4, ge=1, le=4096)
    near: float = Field(default=0.01, ge=0.0)
    min_range: float = Field(default=0.01, ge=0.0)
    max_range: float = Field(default=1.0, gt=0.0)
    type: Literal["fixed", "rotating"] = "fixed"
    projection: Literal["cylindrical", "planar"] = "cylindrical"
    noise: float = Field(default=0.0, ge=0.0)
    resolution: float = -1.0
    default_frequency: float = Field(default=10.0, gt=0.0)
    min_frequency: float = Field(default=1.0, gt=0.0)
    max_frequency: float = Field(default=25.0, gt=0.0)

    @model_validator(mode="after")
    def _consistent(self) -> Lidar:
        if self.projection == "planar" and self.field_of_view > math.pi:
            raise ValueError("a planar lidar's field_of_view must be <= pi")
        return self


class PositionSensor(_Device):
    """A joint's encoder (Webots PositionSensor on a HingeJoint or SliderJoint): the position, in
    radians (metres on a slider), of the joint turned by ``motor``: a drive's wheel or steering
    motor, or a RotationalMotor/LinearMotor of the robot moved kinematically. ``pose`` is unused."""

    device: Literal["PositionSensor"]
    motor: str | None = Field(default=None, min_length=1,
                              description="name of the robot's motor whose joint it measures; left out: a "
                                          "sensor on a joint nothing turns here (it reads ``position``)")
    position: float = Field(default=0.0, allow_inf_nan=False,
                            description="without a motor: the joint's position it reads (Webots jointParameters "
                                        "position: rad, m on a slider), a free wheel's at the start; unused with a "
                                        "motor (the motor's own)")
    free_wheel: Literal["right_front", "left_front", "right_rear", "left_rear"] | int | None = Field(
        default=None, description="the encoder of a wheel of the robot's ackermann_drive that has no motor (Webots' "
        "Car: the front wheels of a propulsion car, the rear ones of a traction car), or the index of a free wheel "
        "(no motor) in its steered_drive's wheels (a tricycle's front wheel): it reads ``position`` plus the "
        "angle the wheel has rolled, its contact point's travel along its rolling direction over its radius")
    free_wheel_sign: Literal[1, -1] = Field(
        default=1, description="1: the wheel's joint axis is the car's left, so rolling forward reads increasing; "
                               "-1: its right (rolling forward reads decreasing)")
    noise: float = Field(default=0.0, ge=0.0, description="standard deviation of Gaussian noise (rad)")
    resolution: float = -1.0


LedLight = Annotated[PointLight | SpotLight, Field(discriminator="type")]


class LED(_Device):
    """Webots LED: ``set(i)`` lights colour ``i`` (1-based, 0 = off) of ``color``; a ``gradual`` LED
    takes a 0xRRGGBB value instead when ``color`` is empty (``color: []``: an RGB LED), else an
    intensity 0..255 of its first colour (a monochrome LED; the default colour is red, as in Webots). Its ``lights`` (Webots' PointLight/SpotLight children of the LED)
    are on exactly while the LED is (value != 0) and take its colour (WbLed): light sensors and cameras
    see them then; their own ``on`` and ``color`` are overridden (off and black until the first
    ``set``, and again after a reset)."""

    device: Literal["LED"]
    color: list[Color] = Field(default=[(1.0, 0.0, 0.0)], max_length=1024)
    gradual: bool = False
    lights: list[LedLight] = Field(
        default=[], description="point and spot lights switched by the LED, in its own frame (`location` and a "
        "SpotLight's `direction` relative to the LED's `pose`); their `on` and `color` are the LED's")

    _unit = field_validator("color")(_unit_colors)


class Pen(_Device):
    """Webots Pen: at each basic step while ``write`` is on, ink on the first visual shape its
    ray meets (from the pen's origin along its -z axis, nearer than ``max_distance``; 0 or less:
    unlimited), in that shape's paint texture, which infra-red sensors read (README "Textures and
    line following"). ``ink_density`` outside [0, 1] is clamped with a warning, as Webots does."""

    device: Literal["Pen"]
    ink_color: Color = (0.0, 0.0, 0.0)
    ink_density: float = 0.5
    lead_size: float = Field(default=0.002, ge=0.0, description="m, the width of the pen's tip")
    max_distance: float = Field(default=0.0, description="m; <= 0: unlimited range")
    write: bool = Field(default=True, description="writing from the first step (wb_pen_write switches it)")

    _unit = field_validator("ink_color")(_unit_colors)


class GPS(_Device):
    """Webots GPS: the device's position (local coordinates, or WGS84 latitude / longitude /
    altitude, per ``world_info.gps_coordinate_system``), its speed and speed vector."""

    device: Literal["GPS"]
    type: Literal["satellite", "laser"] = Field(default="satellite", description="ignored, as in Webots")
    accuracy: float = Field(default=0.0, ge=0.0, description="standard deviation (m) of the position noise")
    noise_correlation: float = Field(default=0.0, ge=0.0, le=1.0,
                                     description="how much the noise of one second ago remains (Gauss-Markov)")
    resolution: float = Field(default=-1.0, description="m; -1 = infinite")
    speed_noise: float = Field(default=0.0, ge=0.0, description="relative standard deviation of the speed")
    speed_resolution: float = Field(default=-1.0, description="m/s; -1 = infinite")


class InertialUnit(_Device):
    """Webots InertialUnit: the device's orientation (quaternion; roll, pitch, yaw in the world's
    coordinate system's convention)."""

    device: Literal["InertialUnit"]
    noise: float = Field(default=0.0, ge=0.0, description="σ of each Gaussian angle, as a fraction of π")
    resolution: float = -1.0
    x_axis: bool = True
    y_axis: bool = True
    z_axis: bool = True


class Compass(_Device):
    """Webots Compass: the world's north (ENU: +y, NUE: +x) in the device frame, through the lookup
    table per axis (empty table: the unit vector itself)."""

    device: Literal["Compass"]
    lookup_table: list[LookupRow] = Field(default=[], max_length=4096)
    resolution: float = -1.0
    x_axis: bool = True
    y_axis: bool = True
    z_axis: bool = True


class Accelerometer(_Device):
    """Webots Accelerometer on a kinematic robot: the specific force (m/s²) in the device frame from
    the motion's second difference and the world's gravity (README "What is simulated")."""

    device: Literal["Accelerometer"]
    lookup_table: list[LookupRow] = Field(default=[], max_length=4096)
    resolution: float = -1.0
    x_axis: bool = True
    y_axis: bool = True
    z_axis: bool = True


class Gyro(_Device):
    """Webots Gyro on a kinematic robot: the angular velocity (rad/s) in the device frame."""

    device: Literal["Gyro"]
    lookup_table: list[LookupRow] = Field(default=[], max_length=4096)
    resolution: float = -1.0
    x_axis: bool = True
    y_axis: bool = True
    z_axis: bool = True


class Altimeter(_Device):
    """Webots Altimeter: the device's height along the world's up axis (m)."""

    device: Literal["Altimeter"]
    accuracy: float = Field(default=0.0, ge=0.0, description="standard deviation (m) of Gaussian noise")
    resolution: float = -1.0


class TouchSensor(_Device):
    """Webots TouchSensor. ``bumper`` with bounding shapes of its own (the robot's shapes whose
    ``of_device`` names it: a .wbt TouchSensor's boundingObject): 1 when they touch a solid or
    another robot at the end of the step (within 1e-6 m, as kinematic contact sees them), else 0;
    ``bumper`` without: 1 while the robot's body pushes against a solid or another robot (kinematic
    contact clipped its motion in the last basic step), else 0; a touch on any basic step since the
    last reading reads 1, as Webots keeps it until read (README "Bumpers"). ``force`` and
    ``force-3d`` need physics: they read NaN (Webots' "no value"), said once when the world loads."""

    device: Literal["TouchSensor"]
    type: Literal["bumper", "force", "force-3d"] = "bumper"
    lookup_table: list[LookupRow] = Field(default=[(0.0, 0.0, 0.0), (5000.0, 50000.0, 0.0)], max_length=4096)
    resolution: float = -1.0


class Lens(Strict):
    """Webots' Lens node in a Camera's or RangeFinder's ``lens`` field: Brown's radial (k1, k2) and
    tangential (p1, p2) distortion about ``center`` (image units: (0.5, 0.5) is the image's centre,
    x across, y down), as Webots' shader applies it to a planar image, or to each cube-face
    sub-image of a spherical or cylindrical one (README "Lens distortion").
    A ``center`` component outside [0, 1] is reset with a warning, as Webots does."""

    center: tuple[float, float] = (0.5, 0.5)
    radial_coefficients: tuple[float, float] = (0.0, 0.0)
    tangential_coefficients: tuple[float, float] = (0.0, 0.0)


class _Imager(_Device):
    """What Webots' RangeFinder and Camera share: the image's size and projection, the near plane,
    the lens."""

    device: str
    field_of_view: float = Field(default=0.785398, gt=0.0, le=2 * math.pi)
    width: int = Field(default=64, ge=1, le=1 << 16)
    height: int = Field(default=64, ge=1, le=1 << 16)
    projection: Literal["planar", "cylindrical", "spherical"] = "planar"
    near: float = Field(default=0.01, ge=0.0)
    lens: Lens | None = Field(default=None, description="Webots' Lens node (NULL: none); a spherical or cylindrical image's cube faces each take it")
    _what: ClassVar[str]

    @model_validator(mode="after")
    def _planar_fov(self) -> _Imager:
        if self.projection == "planar" and self.field_of_view >= math.pi:
            raise ValueError(f"a planar {self._what}'s field_of_view must be < pi")
        return self


class RangeFinder(_Imager):
    """Webots RangeFinder (a depth camera): ``width`` × ``height`` ranges, by exact rays through the
    pixel centres. ``planar``: the depth along the device's +x axis (Webots' z-buffer distance to
    the image plane); ``cylindrical``/``spherical``: the distance along each pixel's ray. Values
    outside [min_range, max_range) and no hit read +inf (README "Cameras and range finders")."""

    device: Literal["RangeFinder"]
    min_range: float = Field(default=0.01, ge=0.0)
    max_range: float = Field(default=1.0, gt=0.0)
    noise: float = Field(default=0.0, ge=0.0, description="σ of the Gaussian noise as a fraction of max_range")
    resolution: float = -1.0
    motion_blur: float = Field(default=0.0, ge=0.0, description="ms a pixel takes to reach 99.5% of a new range "
                               "(Webots' motionBlur): each image mixes its values with the previous image's, the "
                               "previous one weighing 0.005^(sampling period / motion_blur), before the noise; an "
                               "infinite value (new or previous) is not mixed; 0: off")
    _what: ClassVar[str] = "range finder"


class Recognition(Strict):
    """Webots' Recognition node in a Camera's ``recognition`` field: the camera reports the solids
    (and robots) that have ``recognition_colors`` and that it sees (README "Recognition")."""

    max_range: float = Field(default=100.0, ge=0.0, description="m: objects farther are not recognised")
    max_objects: int = Field(default=-1, ge=-1, description="-1 or 0: no limit (as Webots); else the biggest on the image")
    occlusion: int = Field(default=1, ge=0, le=2, description="0 none, 1 the centre's ray, 2 any pixel of the image")
    frame_color: Color = (1.0, 0.0, 0.0)
    frame_thickness: int = Field(default=1, ge=0)
    segmentation: bool = False


class Zoom(Strict):
    """Webots' Zoom node in a Camera's ``zoom`` field: the range a controller's ``setFov`` may
    take (Webots' defaults 0.5 and 1.5 rad); the image itself is the camera's ``field_of_view``
    until a controller zooms (README "Cameras and range finders")."""

    min_field_of_view: float = Field(default=0.5, ge=0.0, allow_inf_nan=False)
    max_field_of_view: float = Field(default=1.5, ge=0.0, allow_inf_nan=False)

    @model_validator(mode="after")
    def _ordered(self) -> Zoom:
        if self.min_field_of_view > self.max_field_of_view:
            raise ValueError(f"zoom: min_field_of_view ({self.min_field_of_view:g}) is above max_field_of_view "
                             f"({self.max_field_of_view:g})")
        return self


class Focus(Strict):
    """Webots' Focus node in a Camera's ``focus`` field: its focal length and the focal distance a
    controller's ``setFocalDistance`` may set within [min, max] (Webots' defaults 0); the image shows
    no depth of field (one load warning: README "Cameras and range finders")."""

    focal_distance: float = Field(default=0.0, ge=0.0, allow_inf_nan=False)
    focal_length: float = Field(default=0.0, ge=0.0, allow_inf_nan=False)
    min_focal_distance: float = Field(default=0.0, ge=0.0, allow_inf_nan=False)
    max_focal_distance: float = Field(default=0.0, ge=0.0, allow_inf_nan=False)


class Camera(_Imager):
    """Webots Camera: a ``width`` × ``height`` BGRA image by exact rays through the pixels (four per
    pixel with ``anti_aliasing``), shaded with the LightSensor's lighting, textures, transparency,
    shadows of the lights that cast them, the background colour (README "Cameras and range finders")."""

    device: Literal["Camera"]
    far: float = Field(default=0.0, ge=0.0, description="0: no far clipping plane")
    exposure: float = Field(default=1.0, ge=0.0)
    anti_aliasing: bool = False
    noise: float = Field(default=0.0, ge=0.0, le=1.0, description="σ of the per-channel Gaussian noise, in [0, 1] units")
    recognition: Recognition | None = None
    zoom: Zoom | None = Field(default=None, description="Webots' Zoom node (NULL: none): the range setFov() may take")
    focus: Focus | None = Field(default=None, description="Webots' Focus node (NULL: none): focal length, the range "
                                "setFocalDistance() may take; no depth of field rendered")
    motion_blur: float = Field(default=0.0, ge=0.0, description="ms a pixel takes to reach 99.5% of a new colour "
                               "(Webots' motionBlur): each image mixes its radiance with the previous image's, the "
                               "previous one weighing 0.005^(sampling period / motion_blur); 0: off")
    noise_mask_url: str = Field(default="", description="Webots' noiseMaskUrl: a PNG or JPEG (relative to the world "
                                "file) mixed over each image by its alpha, shifted by a random offset per image "
                                "(planar cameras only); empty: none")
    _what: ClassVar[str] = "camera"

    @model_validator(mode="after")
    def _noise_mask_planar(self) -> Camera:
        if self.noise_mask_url and self.projection != "planar":
            raise ValueError(f"noise_mask_url: Webots applies a noise mask to planar cameras only, this one is "
                             f"{self.projection}")
        return self


def _minus_one_or_positive(name: str, v: float) -> float:
    if v != -1 and not v > 0:
        raise ValueError(f"{name} must be -1 (unlimited) or > 0, got {v}")
    return v


def _medium(v: object) -> object:
    if isinstance(v, str):
        v = v.lower()
        return "infra-red" if v == "infrared" else v
    return v


Medium = Annotated[Literal["radio", "serial", "infra-red"], BeforeValidator(_medium)]


class _Radio(_Device):
    """What Webots' Emitter and Receiver share: the medium (``radio`` and ``serial`` ignore
    obstacles; ``infra-red`` is blocked by bounding objects and has a cone), the channel (-1:
    every channel), ``allowed_channels`` (empty: any), the transmission buffer in bytes (-1:
    unlimited), Webots' baud rate and byte size."""

    type: Medium = "radio"
    aperture: float = Field(default=-1.0, description="infra-red cone opening (rad) around the device's x axis; -1: "
                                                      "every direction")
    channel: int = Field(default=0, ge=-1, le=(1 << 31) - 1)
    baud_rate: int = Field(default=-1, ge=-1, le=(1 << 31) - 1, description="bits per second; -1: unlimited")
    byte_size: int = Field(default=8, ge=8, le=(1 << 31) - 1, description="bits per byte on the wire")
    buffer_size: int = Field(default=-1, ge=-1, le=(1 << 31) - 1, description="bytes; -1: unlimited")
    allowed_channels: list[int] = Field(default=[], max_length=4096)

    @field_validator("aperture")
    @classmethod
    def _aperture(cls, v: float) -> float:
        if v != -1 and not 0.0 <= v <= 2 * math.pi:
            raise ValueError(f"aperture must be -1 or within [0, 2*pi], got {v}")
        return v

    @field_validator("baud_rate", "buffer_size")
    @classmethod
    def _unlimited_or_positive(cls, v: int, info: ValidationInfo) -> int:
        return int(_minus_one_or_positive(str(info.field_name), v))

    @model_validator(mode="after")
    def _allowed(self) -> _Radio:
        if self.allowed_channels and self.channel not in self.allowed_channels:
            raise ValueError(f"channel {self.channel} is not one of allowed_channels {self.allowed_channels}")
        return self


class Emitter(_Radio):
    """Webots Emitter: packets a controller sends reach the enabled receivers of other robots on the
    same medium and channel within ``range`` (m, -1: unlimited; ``set_range`` is capped at
    ``max_range``), at the next basic step; infra-red ones only inside its cone and with no bounding
    object in between (README "Emitter and Receiver")."""

    device: Literal["Emitter"]
    range: float = Field(default=-1.0, description="m; -1: unlimited")
    max_range: float = Field(default=-1.0, description="m, the largest range set_range may set; -1: unlimited")

    @field_validator("range", "max_range")
    @classmethod
    def _range(cls, v: float, info: ValidationInfo) -> float:
        return _minus_one_or_positive(str(info.field_name), v)

    @model_validator(mode="after")
    def _within_max(self) -> Emitter:
        if self.max_range != -1 and (self.range == -1 or self.range > self.max_range):
            raise ValueError(f"range {self.range} exceeds max_range {self.max_range}")
        return self


class Receiver(_Radio):
    """Webots Receiver: queues the packets of emitters on its medium and channel while enabled; the
    controller reads them at the receiver's sampling period, each with the signal strength 1/r²
    and the emitter's direction in the receiver frame (Gaussian noise per Webots' fields)."""

    device: Literal["Receiver"]
    signal_strength_noise: float = Field(default=0.0, ge=0.0, description="relative σ of the signal strength")
    direction_noise: float = Field(default=0.0, ge=0.0, description="σ of each direction component, times the distance")


class Motor(_Device):
    """A Webots motor's fields (snake_case, Webots' defaults) and its joint's initial ``position``.

    A motor that is not one of the robot's drive motors moves its joint kinematically, as Webots
    does without physics (WbMotor's kinematic control, sim/joints.py): towards ``target`` at up to
    ``max_velocity``, its speed changing by at most ``acceleration`` (or, -1, ``max_torque``/``max_force``)
    per second; ``min_position`` = ``max_position`` = 0 means no limits. Its PositionSensor reads the
    position; the shapes and devices that name it in ``on_joint`` move with it: a hinge turns them by
    ``position - initial position`` about ``axis`` through ``anchor``, a slider moves them by that much
    along ``axis`` (README 'Joints'). ``axis`` and ``anchor`` are in the robot frame with every joint at
    its initial position (where the world file places everything); ``on_joint`` of a motor: the joint
    this joint rides on (an arm's elbow on its shoulder)."""

    max_velocity: float = Field(default=10.0, ge=0.0, description="rad/s (m/s for a LinearMotor)")
    min_position: float = Field(default=0.0, description="rad (m); min = max = 0: no limits")
    max_position: float = 0.0
    acceleration: float = Field(default=-1.0, description="rad/s² (m/s²); -1: the available torque (force)")
    position: float = Field(default=0.0, description="the joint's initial position (its jointParameters' "
                                                     "position), where the motor starts and holds")
    axis: Vec3 | None = Field(default=None, description="the joint's axis, robot frame (see the class); left "
                              "out: Webots' default, 1 0 0 for a hinge, 0 0 1 for a slider")
    anchor: Vec3 = Field(default=(0.0, 0.0, 0.0), description="a hinge's axis passes through it (robot frame, m); "
                         "unused by a slider")
    multiplier: float = Field(default=1.0, description="scales every position and velocity command this motor takes "
                              "(Webots' coupled motors: a command to one motor named 'group::part' reaches every "
                              "joint motor of the robot named 'group::...', each scaled by its own multiplier); "
                              "0 is reset to 1, as Webots does")

    @property
    def joint_axis(self) -> Vec3:
        """The joint's axis, Webots' default when left out (HingeJointParameters: x; JointParameters: z)."""
        if self.axis is not None:
            return self.axis
        return (0.0, 0.0, 1.0) if isinstance(self, LinearMotor) else (1.0, 0.0, 0.0)

    @model_validator(mode="after")
    def _motor_limits(self) -> Motor:
        if self.acceleration < 0.0 and self.acceleration != -1.0:
            raise ValueError("acceleration must be >= 0, or -1 (limited by the available torque or force)")
        if self.min_position > self.max_position:
            raise ValueError(f"min_position {self.min_position} > max_position {self.max_position}")
        if self.axis is not None and math.hypot(*self.axis) == 0.0:
            raise ValueError("axis must not be zero")
        if (self.min_position or self.max_position) and not self.min_position <= self.position <= self.max_position:
            raise ValueError(f"position {self.position} outside [min_position, max_position] = "
                             f"[{self.min_position}, {self.max_position}]")
        return self


def coupling_group(name: str) -> str | None:
    """The coupled-motor group a motor's name puts it in (Webots' WbMotor::inferMotorCouplings): the
    part before ``::`` of a name made of exactly two parts (``"gripper::left"`` → ``"gripper"``);
    None for any other name."""
    parts = name.split("::")
    return parts[0] if len(parts) == 2 else None


class RotationalMotor(Motor):
    """A RotationalMotor. An entry named like one of the robot's ``differential_drive``/``ackermann_drive``
    motors *is* that drive motor, at this index of the device list (a drive motor without an entry
    comes after the listed devices; the drive's own fields are used, not these). Any other is a
    HingeJoint's motor moved kinematically (see the base class). ``pose`` is unused."""

    device: Literal["RotationalMotor"]
    max_torque: float = Field(default=10.0, ge=0.0, description="N·m: the kinematic acceleration bound "
                                                                "(acceleration -1, or above it)")


class LinearMotor(Motor):
    """A LinearMotor; positions in metres. An entry named like one of the robot's ``differential_drive``
    motors *is* that drive motor, as a RotationalMotor entry is (a tracked robot's: its belt at v m/s is
    a wheel of radius 1 at v rad/s; controllers see a LinearMotor, as in Webots). Any other is a
    SliderJoint's motor moved kinematically (see the base class). ``pose`` is unused."""

    device: Literal["LinearMotor"]
    max_force: float = Field(default=10.0, ge=0.0, description="N: the kinematic acceleration bound "
                                                               "(acceleration -1, or above it)")


class Radar(_Device):
    """Webots Radar: the targets (solids and robots with ``radar_cross_section`` > 0) in its frustum
    around its x axis, between ``min_range`` and ``max_range``, whose echo reaches
    ``min_detectable_signal`` by the radar equation: each one's distance, received power (dBm),
    radial speed and azimuth (README "Radar"). Webots' defaults (Radar.wrl); a value Webots resets
    (WbRadar's update functions) is reset with its warning when the world loads."""

    device: Literal["Radar"]
    min_range: float = Field(default=1.0, description="m, >= 0")
    max_range: float = Field(default=50.0, description="m, > min_range")
    horizontal_field_of_view: float = Field(default=0.78, description="rad, in (0, pi)")
    vertical_field_of_view: float = Field(default=0.1, description="rad, in (0, pi/2)")
    min_absolute_radial_speed: float = Field(default=0.0, description="m/s; 0: no limit")
    min_radial_speed: float = Field(default=0.0, description="m/s; min and max both 0: no limits")
    max_radial_speed: float = Field(default=0.0, description="m/s, > min_radial_speed; min and max both 0: no limits")
    cell_distance: float = Field(default=0.0, description="m: targets nearer in distance merge; 0: none")
    cell_speed: float = Field(default=0.0, description="m/s: and nearer in speed (0: distance only)")
    range_noise: float = Field(default=0.0, description="σ of the distance (m)")
    speed_noise: float = Field(default=0.0, description="σ of the speed (m/s)")
    angular_noise: float = Field(default=0.0, description="σ of the azimuth (rad)")
    antenna_gain: float = Field(default=20.0, description="dBi")
    frequency: float = Field(default=24.0, description="GHz, >= 0")
    transmitted_power: float = Field(default=20.0, description="dBm")
    min_detectable_signal: float = Field(default=-100.0, description="dBm")
    occlusion: bool = Field(default=False, description="a target hidden behind another shape is not seen")


class Connector(_Device):
    """Webots Connector: a docking device whose presence sensor reads 1 while a compatible peer
    connector (another robot's) sits at its origin within ``distance_tolerance``, its x axis facing
    this one's within ``axis_tolerance`` and its z axis at one of ``number_of_rotations`` angles within
    ``rotation_tolerance`` (WbConnector's rule, each connector judging with its own tolerances), else
    0, and -1 for a passive connector. ``lock``/``unlock`` set ``is_locked``; nothing is physically
    joined here (README "Connector and Brake"). Webots' defaults (Connector.wrl)."""

    device: Literal["Connector"]
    type: Literal["symmetric", "active", "passive"] = Field(
        default="symmetric", description="symmetric docks with symmetric, active with passive (same model)")
    is_locked: bool = Field(default=False, description="the lock state at start (a passive connector: false)")
    auto_lock: bool = Field(default=False, description="a locked connector attaches when a peer becomes present "
                            "(no physical link here)")
    unilateral_lock: bool = Field(default=True, description="kept for Webots; no physical link here")
    unilateral_unlock: bool = Field(default=True, description="kept for Webots; no physical link here")
    distance_tolerance: float = Field(default=0.01, ge=0.0, allow_inf_nan=False,
                                      description="m: the origins at most this far apart")
    axis_tolerance: float = Field(default=0.2, ge=0.0, le=math.pi, description="rad: the x axes opposed within it")
    rotation_tolerance: float = Field(default=0.2, ge=0.0, le=math.pi,
                                      description="rad: the z axes within it of an allowed docking rotation")
    number_of_rotations: int = Field(default=4, ge=0, le=1 << 20,
                                     description="allowed docking rotations in a full turn; 0: any rotation")
    snap: bool = Field(default=True, description="kept for Webots; nothing is moved here")
    tensile_strength: float = Field(default=-1.0, description="N, -1: unbreakable; kept for Webots (no forces here)")
    shear_strength: float = Field(default=-1.0, description="N, -1: unbreakable; kept for Webots (no forces here)")

    @model_validator(mode="after")
    def _passive_unlocked(self) -> Connector:
        if self.type == "passive" and self.is_locked:
            raise ValueError("a passive connector cannot be locked: is_locked must be false (Webots)")
        for f in ("tensile_strength", "shear_strength"):
            v = getattr(self, f)
            if v < 0.0 and v != -1.0:
                raise ValueError(f"{f} must be >= 0, or -1 (unbreakable), got {v}")
        return self


class Brake(_Device):
    """Webots Brake on a joint: ``getType`` is its joint's (rotational for a HingeJoint, linear for a
    SliderJoint), ``getMotor``/``getPositionSensor`` the devices of the same joint, named here.
    ``setDampingConstant`` is accepted and has no effect (no physics). ``pose`` is unused."""

    device: Literal["Brake"]
    joint_type: Literal["rotational", "linear"] = Field(
        default="rotational", description="its joint's kind (a SliderJoint's brake: linear); with ``motor``, the "
                                          "motor's (a LinearMotor: linear)")
    motor: str | None = Field(default=None, min_length=1, description="the robot's motor on the same joint")
    position_sensor: str | None = Field(default=None, min_length=1,
                                        description="the robot's PositionSensor on the same joint")


UNSIMULATED_DEVICE_TYPES = (
    "Microphone", "Radio", "Skin",
)
"""Webots device node types that Sensorium lists but does not simulate yet (UnsimulatedDevice)."""


class Display(_Device):
    """Webots Display: an image of ``width`` x ``height`` pixels its controller draws on (lines,
    shapes, text, images, an attached camera's image under it), published as
    ``/<robot>/<display>/image`` (README "The Display"). Webots' Display.wrl defaults; a size below 1
    is set to 1 by Webots (WbRenderingDevice::updateWidth/updateHeight)."""

    device: Literal["Display"]
    width: int = Field(default=64, ge=1, le=1 << 16, description="pixels (wb_display_get_width)")
    height: int = Field(default=64, ge=1, le=1 << 16, description="pixels (wb_display_get_height)")
    screen_shape: int | None = Field(default=None, ge=0, description=(
        "the robot's shape (index in its shapes) whose ImageTexture shows the display's image, as Webots "
        "replaces the texture of the Shape its Display's first child is or holds; None: no such shape"))
    screen_maps: list[Literal["texture", "emissive_map"]] | None = Field(default=None, max_length=2, description=(
        "the screen shape's maps the image replaces, each an ImageTexture of its appearance with a url or "
        "none (texture: an Appearance's texture or a PBRAppearance's baseColorMap; emissive_map: its "
        "emissiveColorMap), as WbDisplay replaces each; None: texture, and emissive_map when the "
        "appearance has one"))


class VacuumGripper(_Device):
    """Webots VacuumGripper: a suction pump (``is_on``, wb_vacuum_gripper_turn_on/off) whose presence
    sensor reads whether it holds a solid: pump on, its own bounding shapes (the robot's shapes with
    ``of_device`` naming it) touched a top-level solid with ``physics``, which it then carries until
    the pump is off (README "VacuumGripper and Speaker"). Webots' VacuumGripper.wrl defaults; no forces
    here, so the strengths and ``contact_points`` are kept for the record and read by nothing."""

    device: Literal["VacuumGripper"]
    is_on: bool = Field(default=False, description="the pump is on at the start (Webots' isOn)")
    tensile_strength: float = Field(default=-1.0, description="N; -1: infinite (Webots' tensileStrength)")
    shear_strength: float = Field(default=-1.0, description="N; -1: infinite (Webots' shearStrength)")
    contact_points: int = Field(default=3, ge=1, le=1 << 30, description="Webots' contactPoints")

    @model_validator(mode="after")
    def _strengths(self) -> VacuumGripper:
        for key in ("tensile_strength", "shear_strength"):
            v = getattr(self, key)
            if not (v >= 0.0 or v == -1.0) or math.isinf(v):
                raise ValueError(f"{key} {v} must be >= 0 or -1 (infinite)")
        return self


class Speaker(_Device):
    """Webots Speaker: plays sound files and speaks text; headless, it produces no audio, but which
    sounds are playing and whether it is speaking follow the simulated time (README "The
    Speaker"). Webots' Speaker node has no fields of its own."""

    device: Literal["Speaker"]




class UnsimulatedDevice(_Device):
    """A Webots device that Sensorium does not simulate: present in the robot's device list (its
    index, type, name and model are Webots'), its functions answer Webots' "no value" (NaN, NULL, 0)
    with one warning per device. Only ``device``, ``name``, ``model`` and ``pose`` are accepted: the
    device's other Webots fields come with its model (the .wbt converter leaves them out)."""

    device: Literal[UNSIMULATED_DEVICE_TYPES]  # type: ignore[valid-type]


Device = Annotated[LightSensor | DistanceSensor | Lidar | PositionSensor | LED | GPS | InertialUnit | Compass
                   | Accelerometer | Gyro | Altimeter | TouchSensor | Emitter | Receiver | RotationalMotor | LinearMotor
                   | Pen | RangeFinder | Camera | Radar | Display | VacuumGripper | Speaker | Connector | Brake
                   | UnsimulatedDevice,
                   Field(discriminator="device")]

DEVICE_TYPES = ("LightSensor", "DistanceSensor", "Lidar", "PositionSensor", "LED", "GPS", "InertialUnit", "Compass",
                "Accelerometer", "Gyro", "Altimeter", "TouchSensor", "Emitter", "Receiver", "RotationalMotor",
                "LinearMotor", "Pen", "RangeFinder", "Camera", "Display", "Radar", "VacuumGripper", "Speaker", "Connector", "Brake",
                *UNSIMULATED_DEVICE_TYPES)
"""Every Webots device node type a robot's ``devices`` list accepts."""


# ---------------------------------------------------------------- motion

class SkidSteer(Strict):
    """The other motorised wheels of a skid-steer robot (a Pioneer 3-AT's back wheels), by side:
    each side rolls at the mean of its wheels' speeds (``left_motor`` and these on the left)."""

    left: list[str] = Field(default_factory=list, max_length=16)
    right: list[str] = Field(default_factory=list, max_length=16)


def _forward_field() -> Any:
    return Field(default=(1.0, 0.0), description="the drive's forward in the robot's frame, (x, y) or (x, y, z): "
                 "the drive's geometry is along it, its left (up × forward) and up, up the robot's own axis that "
                 "stands up (its z; a robot built y-up in a NUE world: its y, and forward (x, 0, z)); positive "
                 "wheel speeds of a two-wheel, skid-steer, car or mecanum drive drive it along forward, the wheels' "
                 "axis along its left (default x forward, wheels along y; a Webots robot whose wheels turn about "
                 "its x axis drives along y, or along z when built y-up)")


def _wheel_bottom_field() -> Any:
    return Field(default=None, description="m, the height of the robot's lowest wheel's bottom from its origin along "
                 "its z, its up (a robot built y-up in a NUE world: its y) (its axle's height less its radius; negative: "
                 "below the origin; 0: the origin is where the wheels touch the ground). Given (the .wbt import gives it "
                 "from the wheels' joints and shapes for a Robot with physics), "
                 "the robot is lowered or raised at load, and where a Supervisor puts it, as Webots' physics drops it, "
                 "until that point touches the ground under its origin (README \"Settling on the ground\"); none: it "
                 "keeps the height it is placed at")


def _motor_max_speeds_field() -> Any:
    return Field(default={}, max_length=16, description="rad/s by wheel motor name: a wheel motor's own maxVelocity "
                 "where it differs from max_wheel_speed (Webots' Elisa-3: 133.33 left, 140 right); each motor clamps "
                 "to its own and its controller's warning names it; a motor not named here has max_wheel_speed")


def _maxima_are_numbers(v: Any) -> Any:
    """A bool where a maxVelocity is due is refused (not read as 0 or 1)."""
    if isinstance(v, dict):
        for name, value in v.items():
            if isinstance(value, bool):
                raise ValueError(f"{name!r}: expected a number, got {value!r}")
    return v


def _check_motor_max_speeds(maxima: dict[str, float], wheels: list[str], where: str) -> None:
    """Each named motor is one of the drive's ``wheels``, each maximum a positive number."""
    for name, value in maxima.items():
        if name not in wheels:
            raise ValueError(f"motor_max_speeds: {name!r} is not one of the {where} ({', '.join(map(repr, wheels))})")
        if not value > 0:
            raise ValueError(f"motor_max_speeds[{name!r}]: a maxVelocity must be a number > 0, got {value!r}")


def wheel_max_speed(drive: Any, motor: str) -> float:
    """A wheel motor's maxVelocity (rad/s): its own ``motor_max_speeds`` entry, else the drive's
    ``max_wheel_speed``."""
    return float(drive.motor_max_speeds.get(motor, drive.max_wheel_speed))


Forward = tuple[float, float] | tuple[float, float, float]
"""A drive's ``forward``: (x, y) in the robot's frame, or (x, y, z) (a robot built y-up)."""


def _nonzero_forward(v: Forward) -> Forward:
    if math.hypot(*v) == 0:
        raise ValueError("forward must not be the zero vector")
    return v


class ConveyorBelt(Strict):
    """A robot's belt that carries what lies on it (Webots' ``ConveyorBelt``: one ``Track`` whose
    LinearMotor moves the belt's contact surface): its top face, a ``length`` x ``width`` rectangle
    centred at ``top`` in the robot's frame, moving along ``direction`` (the Track's +x; ``along`` when
    not given) at the motor's velocity. The .wbt import writes one for each Box in the boundingObject of
    a single motorised Track."""

    motor: str = Field(min_length=1, description="the robot's LinearMotor that moves the belt (m/s)")
    top: Vec3 = Field(description="the top face's centre in the robot's frame")
    along: Vec3 = Field(description="unit: the face's side nearest the belt's direction of travel, robot frame")
    across: Vec3 = Field(description="unit: the face's other side's direction, robot frame")
    direction: Vec3 | None = Field(default=None, description="unit: the belt's direction of travel at a positive "
                                   "velocity, robot frame, when it is not `along` (a face turned on its Track)")
    length: float = Field(gt=0, description="the face's extent along `along` (m)")
    width: float = Field(gt=0, description="the face's extent along `across` (m)")


class DifferentialDrive(Strict):
    """Kinematic wheeled drive (no physics, no collision response): the robot moves in the world
    xy-plane from its wheel motors, controlled with Webots' motor API. Two wheels, or several per
    side (``skid_steer``: a side rolls at the mean of its wheels' speeds, no slip)."""

    wheel_radius: float = Field(default=0.0205, gt=0)
    axle_length: float = Field(default=0.052, gt=0, description="distance between the wheels (the wheel lines)")
    max_wheel_speed: float = Field(default=6.28, gt=0, description="rad/s, Webots maxVelocity")
    motor_max_speeds: dict[str, float] = _motor_max_speeds_field()
    _maxima_numbers = field_validator("motor_max_speeds", mode="before")(_maxima_are_numbers)
    left_motor: str = Field(default="left wheel motor", min_length=1)
    right_motor: str = Field(default="right wheel motor", min_length=1)
    skid_steer: SkidSteer | None = Field(default=None, description="more wheels per side (skid steer)")
    reversed_motors: list[str] = Field(
        default_factory=list, max_length=32, description="the wheel motors whose wheel rolls backward for a positive "
        "speed (mounted mirrored: its hinge axis opposite the others', as Webots users build one side and negate its "
        "speed in the controller): each one's speed counts negated in the drive's motion; its encoder still reads "
        "the motor's own position. A skid-steer side's wheels roll as one: all of a side's or none")
    forward: Forward = _forward_field()
    wheel_bottom: float | None = _wheel_bottom_field()
    axle_center: tuple[float, float] = Field(
        default=(0.0, 0.0), description="m, where the robot turns: the point midway between the wheel lines (the "
        "wheels' centre) from the robot's origin, along forward and its left; (0, 0): under the origin. Elsewhere "
        "(a Boe-Bot's axle 2.5 cm ahead of its origin) the centre follows the drive's arc and the origin, rigidly "
        "attached to it, turns about it")
    step_rule: Literal["arc", "mid_heading"] = Field(
        default="arc", description="how a basic step moves the robot: arc, the exact arc of the step's constant wheel "
        "speeds; mid_heading, Webots' rule for a robot without Physics (WbKinematicDifferentialWheels): a straight "
        "segment of length v·dt along the heading at mid-step (heading + ω·dt/2), then the heading turned by ω·dt, "
        "about the robot's origin (axle_center (0, 0))")

    @property
    def motor_names(self) -> tuple[list[str], list[str]]:
        """(left side's motors, right side's motors), first the ``left_motor``/``right_motor``."""
        extra = self.skid_steer or SkidSteer()
        return [self.left_motor, *extra.left], [self.right_motor, *extra.right]

    @property
    def side_signs(self) -> tuple[float, float]:
        """(left, right): -1.0 for a side whose wheels are ``reversed_motors``, else 1.0."""
        left, right = self.motor_names
        return (-1.0 if left[0] in self.reversed_motors else 1.0, -1.0 if right[0] in self.reversed_motors else 1.0)

    _forward_nonzero = field_validator("forward")(_nonzero_forward)

    @model_validator(mode="after")
    def _distinct(self) -> DifferentialDrive:
        if self.left_motor == self.right_motor:
            raise ValueError(f"left_motor and right_motor are both {self.left_motor!r}: the left and right wheels "
                             "each need a motor of its own name (Webots warns of the repeated name, and getDevice "
                             "gives the first)")
        left, right = self.motor_names
        names = [*left, *right]
        if len(set(names)) != len(names):
            raise ValueError(f"every wheel motor needs its own name, got {names}")
        _check_motor_max_speeds(self.motor_max_speeds, names, "drive's wheel motors")
        for name in self.reversed_motors:
            if name not in names:
                raise ValueError(f"reversed_motors: {name!r} is not one of the drive's wheel motors "
                                 f"({', '.join(map(repr, names))})")
        for side, motors in zip(("left", "right"), self.motor_names):
            # a side's wheels roll as one (their mean), stepped as one state in the batched simulation
            named = [m for m in motors if m in self.reversed_motors]
            if named and len(named) != len(motors):
                raise ValueError(f"reversed_motors: the {side} side's wheels {motors} roll as one, so name all of "
                                 f"them or none, got {named}")
        if self.step_rule == "mid_heading" and any(self.axle_center):
            raise ValueError(f"step_rule mid_heading turns the robot about its origin (Webots' kinematic rule), so "
                             f"axle_center must be (0, 0), got {list(self.axle_center)}")
        for side, motors in zip(("left", "right"), self.motor_names):
            # a side's wheels roll as one (their mean), stepped as one state in the batched simulation
            if len({wheel_max_speed(self, m) for m in motors}) > 1:
                raise ValueError(f"motor_max_speeds: the {side} side's wheels {motors} must share one maxVelocity "
                                 "(a skid-steer side rolls as one)")
        return self


class AckermannDrive(Strict):
    """Kinematic car-like drive (Webots' Car/AckermannVehicle geometry, no engine, no slip, no
    physics): two front wheels steered by position-controlled motors, driven wheels by velocity or
    position control, the car turning about a centre on its rear axle's line (x forward, y left;
    ``forward`` another direction of the robot's frame, its left then up × forward: the geometry
    below is in those axes). The rear axle's centre is the robot's origin (Webots' car PROTOs), or
    ``rear_axle_offset`` from it along forward (a robot whose origin is its body's centre: the
    origin then moves on its own circle about the turn centre). The car follows the bicycle model:
    its turn radius about the rear axle's centre is ``wheelbase`` times the mean of the front
    wheels' cotangents (exact for Ackermann angles), its speed the driven wheels' rolling speeds
    over their distances from the turn centre. Motor names default to Webots' vehicle library's."""

    wheelbase: float = Field(gt=0, description="m, rear axle to front axle")
    track_front: float = Field(gt=0, description="m, between the front wheels")
    track_rear: float = Field(gt=0, description="m, between the rear wheels")
    front_wheel_radius: float = Field(gt=0, description="m")
    rear_wheel_radius: float = Field(gt=0, description="m")
    type: Literal["traction", "propulsion", "4x4"] = Field(
        default="propulsion", description="which wheels have motors (Webots): traction the front ones, propulsion the "
        "rear ones, 4x4 all four")
    max_wheel_speed: float = Field(default=100.0, gt=0, description="rad/s, the wheel motors' maxVelocity")
    motor_max_speeds: dict[str, float] = _motor_max_speeds_field()
    _maxima_numbers = field_validator("motor_max_speeds", mode="before")(_maxima_are_numbers)
    max_steering_angle: float = Field(default=0.6, gt=0, lt=math.pi / 2, description="rad, the steering motors' "
                                      "maxPosition (and -minPosition): Webots clamps set_position to it")
    max_steering_speed: float = Field(default=10.0, gt=0, description="rad/s, the steering motors' maxVelocity")
    positive_steers: Literal["right", "left"] = Field(
        default="right", description="where a positive steering motor position turns the car (Webots' Driver: right)")
    right_steer: str = Field(default="right_steer", min_length=1)
    left_steer: str = Field(default="left_steer", min_length=1)
    right_front_wheel: str = Field(default="right_front_wheel", min_length=1)
    left_front_wheel: str = Field(default="left_front_wheel", min_length=1)
    right_rear_wheel: str = Field(default="right_rear_wheel", min_length=1)
    left_rear_wheel: str = Field(default="left_rear_wheel", min_length=1)
    forward: Forward = _forward_field()
    wheel_bottom: float | None = _wheel_bottom_field()
    rear_axle_offset: float = Field(default=0.0, description="m, where the rear axle's centre is along forward from "
                                    "the robot's origin (negative: behind it); 0, the origin on the rear axle, as "
                                    "Webots' car PROTOs have it")
    axle_bottoms: tuple[float, float] | None = Field(
        default=None, description="m, (rear, front): each axle's wheels' bottom from the origin along its z when the "
        "robot is upright, given when they differ (wheels of two sizes, as Webots' Tractor's 0.6 and 0.38 m, or "
        "axles at two heights; the .wbt import gives it for a Robot with physics): with ``wheel_bottom`` the car "
        "settles leaning about its y until both axles' wheels touch the ground (README \"Settling on the ground\")")
    engine_type: Literal["combustion", "electric", "parallel hybrid", "power-split hybrid"] = Field(
        default="combustion", description="Webots' Car engineType: what the vehicle library's getEngineType answers "
        "(no engine is simulated)")

    _forward_nonzero = field_validator("forward")(_nonzero_forward)

    @property
    def driven(self) -> list[tuple[str, str]]:
        """(field, motor name) of the wheels with motors, in Webots' order (right before left)."""
        front = [("right_front_wheel", self.right_front_wheel), ("left_front_wheel", self.left_front_wheel)]
        rear = [("right_rear_wheel", self.right_rear_wheel), ("left_rear_wheel", self.left_rear_wheel)]
        return front if self.type == "traction" else rear if self.type == "propulsion" else front + rear

    @property
    def motor_fields(self) -> list[tuple[str, str]]:
        """(field, motor name) of every motor of the drive: the two steering motors, the driven wheels."""
        return [("right_steer", self.right_steer), ("left_steer", self.left_steer), *self.driven]

    @model_validator(mode="after")
    def _distinct(self) -> AckermannDrive:
        names = [m for _, m in self.motor_fields]
        if len(set(names)) != len(names):
            raise ValueError(f"every motor of the drive needs its own name, got {names}")
        _check_motor_max_speeds(self.motor_max_speeds, [m for _, m in self.driven], "car's driven wheel motors")
        return self


MECANUM_WHEELS = ("front_left", "front_right", "rear_left", "rear_right")
"""A mecanum drive's wheels, in the order of its ``rollers``."""


class MecanumDrive(Strict):
    """Kinematic omnidirectional drive on four mecanum wheels (a KUKA youBot's base; no physics, no
    slip): the wheels at (±``lx``, ±``ly``) from the robot's origin (x forward, y left; ``forward``
    another direction of the robot's frame), their rollers at 45°. A wheel at (x, y) with roller sign
    s turning at ω rolls the robot with r·ω = vx + s·vy + (s·x − y)·ωz; the robot's velocity (vx, vy,
    ωz) over a step is the least-squares solution for the four wheels' speeds (exact when they agree).
    ``rollers`` gives s for the front left, front right, rear left and rear right wheels: diagonal
    wheels alike, the two front ones opposite; the default is the youBot's (its library's base_move
    formulas), with which every wheel at +ω drives forward at r·ω, (+, −, −, +)·ω on (front right,
    front left, rear right, rear left) strafes left at r·ω, and (−, +, −, +) on (front left, front
    right, rear left, rear right) turns left at r·ω/(lx + ly)."""

    wheel_radius: float = Field(gt=0, description="m")
    lx: float = Field(gt=0, description="m, half the wheelbase: the wheels' distance ahead of and behind the origin")
    ly: float = Field(gt=0, description="m, half the track: the wheels' distance either side of the origin")
    max_wheel_speed: float = Field(default=14.81, gt=0, description="rad/s, the wheel motors' maxVelocity")
    motor_max_speeds: dict[str, float] = _motor_max_speeds_field()
    _maxima_numbers = field_validator("motor_max_speeds", mode="before")(_maxima_are_numbers)
    front_left_motor: str = Field(default="wheel2", min_length=1)
    front_right_motor: str = Field(default="wheel1", min_length=1)
    rear_left_motor: str = Field(default="wheel4", min_length=1)
    rear_right_motor: str = Field(default="wheel3", min_length=1)
    rollers: tuple[int, int, int, int] = Field(
        default=(-1, 1, 1, -1), description="roller sign s of the front left, front right, rear left, rear right "
        "wheels (r·ω = vx + s·vy + (s·x − y)·ωz): diagonal wheels alike, the front two opposite; the default is "
        "the youBot's")
    forward: Forward = _forward_field()
    wheel_bottom: float | None = _wheel_bottom_field()

    _forward_nonzero = field_validator("forward")(_nonzero_forward)

    @property
    def motor_fields(self) -> list[tuple[str, str]]:
        """(field, motor name) of the four wheels, in the order of ``rollers``."""
        return [(f"{w}_motor", getattr(self, f"{w}_motor")) for w in MECANUM_WHEELS]

    @model_validator(mode="after")
    def _valid(self) -> MecanumDrive:
        names = [m for _, m in self.motor_fields]
        if len(set(names)) != len(names):
            raise ValueError(f"every wheel motor needs its own name, got {names}")
        _check_motor_max_speeds(self.motor_max_speeds, names, "drive's wheel motors")
        fl, fr, rl, rr = self.rollers
        if any(s not in (-1, 1) for s in self.rollers) or fl != rr or fr != rl or fl == fr:
            raise ValueError(f"rollers {list(self.rollers)} (front left, front right, rear left, rear right): each is "
                             "1 or -1, diagonal wheels alike and the two front wheels opposite (else the wheels "
                             "cannot strafe or turn)")
        if fl == 1 and self.lx == self.ly:
            raise ValueError(f"rollers {list(self.rollers)} with lx = ly: such wheels cannot turn the robot (their "
                             "rollers all point at its centre)")
        return self


class OmniWheel(Strict):
    """One wheel of an omni drive: where it touches the ground, the axis it turns about, its radius
    and motor (in the robot's frame: x forward, y left, z up; with the drive's ``forward`` another
    direction, along it and its left, up × forward)."""

    motor: str = Field(min_length=1, description="its RotationalMotor's name")
    position: tuple[float, float] = Field(description="m, (x, y) of the wheel in the robot's frame: where it rolls "
                                          "on the ground")
    axis: tuple[float, float] = Field(description="its hinge axis in the ground plane, (x, y) in the robot's frame "
                                      "(any length but 0): a positive speed rolls the wheel along axis × up")
    radius: float = Field(gt=0, description="m")

    @field_validator("axis")
    @classmethod
    def _nonzero_axis(cls, v: tuple[float, float]) -> tuple[float, float]:
        if v[0] == 0.0 and v[1] == 0.0:
            raise ValueError("axis must not be the zero vector")
        return v


class OmniDrive(Strict):
    """Kinematic omnidirectional drive on omni wheels (three 120° apart as in Webots' ``omni_wheels``
    how-to or a Festo Robotino, four at a square's corners, ...; no physics): each wheel's rollers let
    it slip freely along its axis a, and it rolls without slip along d = a × up, so a wheel at p turning
    at ω drives the robot's twist (vx, vy, ωz) with d · (v + ωz × p) = r·ω. The twist over a step is the
    least-squares solution for the wheels' speeds: exact when they agree with one twist, their best fit
    when they do not (a real robot's wheels would slip). The wheels must fix the twist: their rows
    (d, d · (up × p)) span three dimensions (not all axes parallel)."""

    wheels: list[OmniWheel] = Field(min_length=3, max_length=16)
    wheel_bottom: float | None = _wheel_bottom_field()
    max_wheel_speed: float = Field(default=10.0, gt=0, description="rad/s, the wheel motors' maxVelocity")
    motor_max_speeds: dict[str, float] = _motor_max_speeds_field()
    _maxima_numbers = field_validator("motor_max_speeds", mode="before")(_maxima_are_numbers)
    forward: Forward = _forward_field()

    _forward_nonzero = field_validator("forward")(_nonzero_forward)

    @property
    def motor_fields(self) -> list[tuple[str, str]]:
        """(field, motor name) of the wheels, in their order."""
        return [(f"wheels[{i}].motor", w.motor) for i, w in enumerate(self.wheels)]

    @model_validator(mode="after")
    def _valid(self) -> OmniDrive:
        names = [w.motor for w in self.wheels]
        if len(set(names)) != len(names):
            raise ValueError(f"every wheel motor needs its own name, got {names}")
        _check_motor_max_speeds(self.motor_max_speeds, names, "drive's wheel motors")
        rows = []
        for w in self.wheels:
            n = math.hypot(*w.axis)
            dx, dy = w.axis[1] / n, -w.axis[0] / n
            rows.append((dx, dy, dx * -w.position[1] + dy * w.position[0]))
        s = [float(x) for x in np.linalg.svd(np.array(rows), compute_uv=False)]
        if s[2] <= 1e-9 * max(s[0], 1e-300):
            raise ValueError("the wheels cannot move the robot in every direction (their axes are all parallel, or "
                             "their rolling directions leave a twist free): an omni drive needs wheels whose "
                             "rolling fixes vx, vy and the turn rate")
        return self


class SteeredWheel(Strict):
    """One wheel of a steered-wheel drive: its rolling motor, the steering motor that turns it about the
    up axis (none: it keeps its heading), where it touches the ground and its radius (in the robot's frame:
    x forward, y left, z up; with the drive's ``forward`` another direction, along it and its left)."""

    motor: str | None = Field(default=None, min_length=1, description="its rolling RotationalMotor's name; none: a "
                              "free wheel (a tricycle's steered front wheel, a caster) that rolls with the robot and "
                              "only keeps it from sliding across its heading")
    steer: str | None = Field(default=None, min_length=1, description="the RotationalMotor of the hinge that "
                              "steers it (one of the robot's devices, moved as any joint is); none: its heading "
                              "is fixed")
    position: tuple[float, float] = Field(description="m, (x, y) where it touches the ground (a steered wheel: on "
                                          "its steering axis)")
    radius: float = Field(gt=0, description="m")
    heading: float = Field(default=0.0, ge=-2 * math.pi, le=2 * math.pi, description="rad, the direction a positive "
                           "speed rolls it at steering position 0, from forward towards the left (pi: its hinge "
                           "axis points right)")
    steer_sign: Literal[1, -1] = Field(default=1, description="1: a positive steering position turns it to the left "
                                       "(a steering hinge about up); -1: to the right (about down)")


class SteeredDrive(Strict):
    """Kinematic drive on wheels that each roll along their own heading, steered or not (a PR2's four
    casters, a rover's steered corners, a swerve base; no physics, no slip): wheel i at p_i = (x_i, y_i)
    with heading h_i (its fixed ``heading`` plus ``steer_sign`` times its steering motor's position that
    step) turning at ω_i moves its ground point at r_i·ω_i·(cos h_i, sin h_i). The body twist (vx, vy, ωz)
    over a step is the least-squares fit of those velocities to v + ωz × p_i (the 2N rows (1, 0, -y_i) and
    (0, 1, x_i)): exact when the wheels agree with one twist, their best fit when they do not (a real
    robot's wheels would slip or scuff). A free wheel (no ``motor``) only forbids sliding across its heading:
    with free wheels the body moves along the twists every wheel's no-slip-across row allows (one line of
    twists, as a tricycle's), at the speed where the driven wheels' rims' speeds along their headings sum to
    their motors' (a tricycle: the bicycle model, v = r·ω and ωz = v·tan δ / L about the rear axle's centre).
    The wheels must stand at two places at least, one of them driven."""

    wheels: list[SteeredWheel] = Field(min_length=2, max_length=16)
    wheel_bottom: float | None = _wheel_bottom_field()
    max_wheel_speed: float = Field(default=10.0, gt=0, description="rad/s, the rolling motors' maxVelocity")
    motor_max_speeds: dict[str, float] = _motor_max_speeds_field()
    _maxima_numbers = field_validator("motor_max_speeds", mode="before")(_maxima_are_numbers)
    forward: Forward = _forward_field()

    _forward_nonzero = field_validator("forward")(_nonzero_forward)

    @property
    def motor_fields(self) -> list[tuple[str, str]]:
        """(field, motor name) of the rolling motors, in the wheels' order (the steering motors are the
        robot's joint motors, not the drive's)."""
        return [(f"wheels[{i}].motor", w.motor) for i, w in enumerate(self.wheels) if w.motor is not None]

    @model_validator(mode="after")
    def _valid(self) -> SteeredDrive:
        names = [w.motor for w in self.wheels if w.motor is not None]
        if not names:
            raise ValueError("no wheel has a motor: a steered drive needs one driven wheel at least")
        if len(set(names)) != len(names):
            raise ValueError(f"every wheel motor needs its own name, got {names}")
        _check_motor_max_speeds(self.motor_max_speeds, names, "drive's wheel motors")
        steers = [w.steer for w in self.wheels if w.steer is not None]
        both = sorted(set(steers) & set(names))
        if both:
            raise ValueError(f"motor {both[0]!r} both rolls and steers a wheel")
        if len({w.position for w in self.wheels}) < 2:
            raise ValueError("the wheels all stand at one place: their velocities leave the turn rate free (a "
                             "steered drive needs wheels at two places at least)")
        return self


# ---------------------------------------------------------------- robots and world

class ProtoField(Strict):
    """One interface field of a PROTO instance as the Supervisor reads it (README "Supervisor")."""

    # its numbers are read back, never simulated: the world's number bounds (limits.check_work) leave
    # them out, so a PROTO parameter of 1e12 or 1e-40 that nothing here uses loads as in Webots
    not_simulated: ClassVar[bool] = True
    name: str = Field(min_length=1, max_length=256)
    type: Literal["SFBool", "SFInt32", "SFFloat", "SFVec2f", "SFVec3f", "SFRotation", "SFColor", "SFString", "SFNode",
                  "MFBool", "MFInt32", "MFFloat", "MFVec2f", "MFVec3f", "MFRotation", "MFColor", "MFString", "MFNode"]
    value: bool | int | float | str | list[bool] | list[int] | list[float] | list[str] | list[list[float]] | None = Field(
        default=None, description="the instance's value or the PROTO's default; none: not kept (a node-typed "
        "field, or more than 4096 items)")
    base: str | None = Field(default=None, min_length=1, description="the base node's field the value passes to "
                             "through IS unchanged (a Supervisor sets the interface field through it)")


class ProtoLevel(Strict):
    """One PROTO of an instance's chain: the instance's own PROTO, then the one its body instantiates
    (a derived PROTO's parent), ... (Webots' getProto(), getParent())."""

    name: str = Field(min_length=1, max_length=256)
    fields: list[ProtoField] = Field(default=[], max_length=1024)
    derived: bool = Field(default=False, description="its body is an instance of another PROTO (isDerived), the "
                          "next level, or one past the 16 kept (getParent then answers NULL)")


_INTERFACE = ("a PROTO instance's interface: its PROTO's fields with the instance's values, then each PROTO it is "
              "built on (Supervisor getField, getProto)")


class NestedNode(Strict):
    """A node inside a robot as the Supervisor walks it (README "Supervisor"): a ``.wbt`` robot's
    Solids, devices, Poses, Transforms, Groups, Slots and joints below it, depth first in file order
    (its shapes, lights and geometries are no nodes here). Written by the ``.wbt`` import; a YAML
    robot without ``nodes`` has one node per device, a child of the robot at the device's pose."""

    type: str = Field(min_length=1, max_length=64, description="Webots' base node type (Solid, Pose, Camera, "
                      "HingeJoint, ...)")
    proto: str | None = Field(default=None, min_length=1, description="a PROTO instance: the PROTO's name")
    interface: list[ProtoLevel] = Field(default=[], max_length=16, description=_INTERFACE)
    def_name: str | None = Field(default=None, min_length=1, description="Webots DEF name (Supervisor getFromDef; "
                                 "a PROTO's internal nodes have none: Webots does not find them by DEF)")
    name: str | None = Field(default=None, description="a Solid's or device's name field")
    parent: int = Field(default=-1, ge=-1, description="index of its parent in the robot's `nodes` (an earlier "
                        "entry); -1: the robot")
    field: Literal["children", "endPoint", "device", "device2", "device3"] = Field(
        default="children", description="the parent's field that holds it")
    pose: Pose | None = Field(default=None, description="its frame in the robot's frame as the world loads; "
                              "none for a node that is no Pose (Group, joints, motors, position sensors)")
    scale: Vec3 | None = Field(default=None, description=_SCALE)
    device: str | None = Field(default=None, min_length=1, description="the robot's device this node is "
                               "(Supervisor getFromDevice)")
    joint_parameters: bool = Field(default=False, description="a HingeJoint or SliderJoint whose world file gives "
                                   "its jointParameters node (a Supervisor reads its position there)")
    joint_parameters_def: str | None = Field(default=None, min_length=1, description="that jointParameters node's "
                                             "DEF name (Supervisor getFromDef, as Webots' ziegler_nichols how-to "
                                             "finds it to set its position)")
    axis: Vec3 | None = Field(default=None, description="a HingeJoint's or SliderJoint's axis in the robot's frame as "
                              "the world loads (its jointParameters' axis, else Webots' default), whatever its devices: "
                              "getUrdf writes it for joints no motor turns too; none for other nodes")
    anchor: Vec3 | None = Field(default=None, description="a HingeJoint's anchor in the robot's frame as the world "
                                "loads (its axis passes through it); none for other nodes")
    inner_defs: list[InnerDef] = Field(default=[], max_length=64, description=_INNER_DEFS)
    written_at: list[Annotated[int, Field(ge=1)]] | None = _written_at()
    made_at: list[Annotated[int, Field(ge=1)]] | None = _made_at()
    mass: Mass | None = Field(default=None, description=_MASS + "; a Solid or device only")
    pending_mass: PendingMass | None = Field(default=None, description=_PENDING_MASS)

    @model_validator(mode="after")
    def _one_physics(self) -> NestedNode:
        _one_mass(self.mass, self.pending_mass)
        return self


class CarriedTarget(Strict):
    """A Solid inside a robot with a radar cross section (Webots: any Solid with ``radarCrossSection``
    > 0 is a Radar target, nested ones too): radars detect it apart from its robot, at its own origin,
    its own shapes (and those of the solids inside it) being its box (README "Radar")."""

    name: str = Field(min_length=1, description="the Solid's name (a device's name when the Solid is a device)")
    pose: Pose = Field(default=Pose(), description="its origin in the robot frame as the world loads")
    on_joint: str | None = Field(default=None, min_length=1, description=_ON_JOINT)
    radar_cross_section: float = Field(gt=0.0, description="Webots radarCrossSection (m²)")
    shapes: list[int] = Field(
        default=[], max_length=100_000, description="indices in the robot's `shapes` of its own shapes and those of "
        "the solids inside it: its box (its bounding ones; none of those: its bounding sphere), which do not hide it "
        "from an occlusion ray. None: its origin is a point target")

    @field_validator("shapes")
    @classmethod
    def _indices(cls, v: list[int]) -> list[int]:
        if any(i < 0 for i in v):
            raise ValueError("shape indices are >= 0")
        return v


class Carrier(Strict):
    """The robot a robot rides on (Webots: a Robot with a controller or devices in another robot's children,
    as the radar robot in highway_overtake's car): its pose is the carrier's composed with ``frame`` every
    step, fixed there (no joint between them)."""

    robot: str = Field(min_length=1, description="the carrying robot's name")
    frame: Pose = Field(default=Pose(), description="this robot's frame in the carrier's")
    parent: Pose | None = Field(default=None, description="the frame of its parent in the carrier's (the Poses "
                                "between them), where its translation and rotation fields are; None: the carrier")


class Robot(Strict):
    name: str = Field(min_length=1)
    def_name: str | None = Field(default=None, min_length=1, description="Webots DEF name (Supervisor getFromDef)")
    pose: Pose = Pose()
    controller: str = Field(
        default="<extern>", min_length=1, max_length=255,
        description='"<extern>": driven by a controller you start (sensorium controller, a client); while no '
                    'synchronous controller is attached the server waits for one. "<none>": never controlled, '
                    "never waited for (its motors keep their initial state). A name (Webots' controller field, "
                    "e.g. \"e-puck_avoid_collision\"): `sensorium run` starts the project's controllers/NAME/ "
                    "for it; `sensorium serve` treats it as \"<extern>\"")
    controller_args: list[Annotated[str, Field(max_length=4096)]] = Field(
        default=[], max_length=1024, description="Webots controllerArgs: the arguments `sensorium run` gives the "
        "controller (its argv after the program)")

    @field_validator("controller")
    @classmethod
    def _controller_name(cls, v: str) -> str:
        """Webots' special values, or the name of a folder under the project's controllers/."""
        if v.startswith("<"):
            if v not in ("<extern>", "<none>", "<generic>"):
                raise ValueError(f'controller {v!r}: "<extern>", "<none>", "<generic>" or a controller\'s name')
        elif v in (".", "..") or any(c in v for c in "/\\\0"):
            raise ValueError(f"controller {v!r}: a controller's name is a folder name under controllers/ "
                             "(no '/', '\\', '.' or '..')")
        return v

    synchronization: bool = True
    supervisor: bool = Field(default=False, description="its controller may use the Supervisor services (Webots)")
    battery: list[Annotated[float, Field(ge=0.0, allow_inf_nan=False)]] = Field(
        default=[], max_length=3, description="Webots battery: [current energy (J), maximum energy (J), recharge "
        "speed (W)]; empty: no battery (its battery sensor reads NaN). The energy drops by cpu_consumption each "
        "step (README 'Battery and Charger'); a Charger needs all three values")
    cpu_consumption: float = Field(default=10.0, ge=0.0, allow_inf_nan=False,
                                   description="Webots cpuConsumption (W): the battery's drain")
    custom_data: str = Field(default="", max_length=1 << 20, description="Webots customData (get/setCustomData)")
    model: str = Field(default="", max_length=4096, description="Webots model (getModel)")
    self_collision: bool = False
    carried_by: Carrier | None = Field(
        default=None, description="the robot this one rides on, fixed in its frame (a .wbt Robot nested in "
        "another's children); its own pose is then where the carrier puts it")
    body: Shape | None = None
    shapes: list[Part] = Field(default=[], description="further body shapes, each with its pose in the robot frame")
    lights: list[Light] = Field(
        default=[], description="lights carried by the robot (location and a SpotLight's direction in its frame)")
    differential_drive: DifferentialDrive | None = None
    ackermann_drive: AckermannDrive | None = Field(default=None, description="a car-like robot (steered front wheels); "
                                                   "a robot has one drive at most")
    mecanum_drive: MecanumDrive | None = Field(default=None, description="an omnidirectional robot on four mecanum "
                                               "wheels (a KUKA youBot); a robot has one drive at most")
    omni_drive: OmniDrive | None = Field(default=None, description="an omnidirectional robot on three or more omni "
                                         "wheels (Webots' omni_wheels how-to, a Robotino); a robot has one drive at most")
    steered_drive: SteeredDrive | None = Field(default=None, description="a robot on wheels that each steer (a PR2's "
                                               "casters, a rover's corners); a robot has one drive at most")
    belts: list[ConveyorBelt] = Field(default=[], max_length=1024, description="conveyor belts on the robot: "
                                      "each carries the solids with physics lying on its top face")
    devices: list[Device] = Field(default=[], description="in Webots' tree order (the order of the device "
                                  "indices); every Webots device type is accepted, those not simulated as present")
    recognition_colors: list[Color] = Field(
        default=[], max_length=1024, description="Webots recognitionColors: other robots' cameras with a Recognition "
        "node report this robot")
    radar_cross_section: float = Field(
        default=0.0, ge=0.0, description="Webots radarCrossSection (m²): > 0 makes the robot a Radar target")
    radar_targets: list[CarriedTarget] = Field(
        default=[], max_length=10_000, description="the Solids inside the robot that are Radar targets of their own "
        "(Webots' radar sample: a small target box on each robot); the .wbt import writes them")

    nodes: list[NestedNode] = Field(
        default=[], max_length=200_000, description="the nodes inside the robot a Supervisor walks (getFromDef, "
        "getFromDevice, children, parents, world poses); written by the .wbt import; empty: one per device")
    inner_defs: list[InnerDef] = Field(default=[], max_length=1024, description="the DEF names of its PROTO "
                                       "instances' bodies that name no node here, with why (InnerDef)")
    mass: Mass | None = Field(default=None, description=_MASS)
    pending_mass: PendingMass | None = Field(default=None, description=_PENDING_MASS)

    _unit = field_validator("recognition_colors")(_unit_colors)

    @model_validator(mode="after")
    def _one_drive(self) -> Robot:
        _one_mass(self.mass, self.pending_mass)
        given = [k for k in ("differential_drive", "ackermann_drive", "mecanum_drive", "omni_drive", "steered_drive")
                 if getattr(self, k) is not None]
        if len(given) > 1:
            raise ValueError(f"a robot has one drive at most: give one of differential_drive, ackermann_drive, "
                             f"mecanum_drive, omni_drive and steered_drive, not {' and '.join(given)}")
        if self.steered_drive is not None:
            rotational = {d.name for d in self.devices if isinstance(d, RotationalMotor)}
            for i, w in enumerate(self.steered_drive.wheels):
                if w.steer is not None and w.steer not in rotational:
                    raise ValueError(f"steered_drive.wheels[{i}].steer: {w.steer!r} is not one of the robot's "
                                     "RotationalMotor devices (a steering hinge's motor, moved as a joint)")
        for i, t in enumerate(self.radar_targets):
            bad = [k for k in t.shapes if k >= len(self.shapes)]
            if bad:
                raise ValueError(f"radar_targets[{i}] ({t.name}): shape index {bad[0]} is past the robot's "
                                 f"{len(self.shapes)} shapes")
        for d in self.devices:
            if isinstance(d, PositionSensor) and isinstance(d.free_wheel, int):
                steered = self.steered_drive
                if steered is None:
                    raise ValueError(f"PositionSensor {d.name!r}: free_wheel {d.free_wheel} needs the robot's "
                                     "steered_drive")
                if d.motor is not None:
                    raise ValueError(f"PositionSensor {d.name!r}: give motor or free_wheel, not both")
                if not 0 <= d.free_wheel < len(steered.wheels) or steered.wheels[d.free_wheel].motor is not None:
                    raise ValueError(f"PositionSensor {d.name!r}: free_wheel {d.free_wheel} is no wheel without motor "
                                     f"in the steered_drive's {len(steered.wheels)} wheels")
            elif isinstance(d, PositionSensor) and d.free_wheel is not None:
                car = self.ackermann_drive
                if car is None:
                    raise ValueError(f"PositionSensor {d.name!r}: free_wheel {d.free_wheel!r} needs the robot's "
                                     "ackermann_drive")
                if d.motor is not None:
                    raise ValueError(f"PositionSensor {d.name!r}: give motor or free_wheel, not both")
                if any(field == f"{d.free_wheel}_wheel" for field, _ in car.driven):
                    raise ValueError(f"PositionSensor {d.name!r}: free_wheel {d.free_wheel!r} has a motor in this "
                                     f"{car.type} car (name its motor instead)")
        linear = {d.name for d in self.devices if isinstance(d, LinearMotor)}
        for i, b in enumerate(self.belts):
            if b.motor not in linear:
                raise ValueError(f"belts[{i}].motor: {b.motor!r} is not one of the robot's LinearMotor devices")
        for i, node in enumerate(self.nodes):
            if node.parent >= i:
                raise ValueError(f"nodes[{i}] ({node.type}): parent {node.parent} must be an earlier node's index "
                                 "(or -1: the robot)")
        return self

    @property
    def drive_motors(self) -> list[tuple[str, str]]:
        """(field path inside the robot, motor name) of every motor of the robot's drive."""
        if self.differential_drive is not None:
            left, right = self.differential_drive.motor_names
            out = [("differential_drive.left_motor", left[0]), ("differential_drive.right_motor", right[0])]
            out += [(f"differential_drive.skid_steer.left[{i}]", m) for i, m in enumerate(left[1:])]
            return out + [(f"differential_drive.skid_steer.right[{i}]", m) for i, m in enumerate(right[1:])]
        if self.ackermann_drive is not None:
            return [(f"ackermann_drive.{f}", m) for f, m in self.ackermann_drive.motor_fields]
        if self.mecanum_drive is not None:
            return [(f"mecanum_drive.{f}", m) for f, m in self.mecanum_drive.motor_fields]
        if self.omni_drive is not None:
            return [(f"omni_drive.{f}", m) for f, m in self.omni_drive.motor_fields]
        if self.steered_drive is not None:
            return [(f"steered_drive.{f}", m) for f, m in self.steered_drive.motor_fields]
        return []


class WorldInfo(Strict):
    name: str = "world"
    basic_time_step: int = Field(default=32, ge=1, le=60_000, description="milliseconds")
    random_seed: int = Field(default=0, ge=0, lt=2**63)
    contact: bool = Field(default=True, description="kinematic contact: a robot's body stops at solids and other "
                                                    "robots' bodies (README 'Kinematic contact'); false = pass through")
    coordinate_system: Literal["ENU", "NUE"] = Field(
        default="ENU", description="world axes: ENU = x east, y north, z up; NUE = x north, y up, z east. "
        "Only the up axis matters here: differential drives move in the plane normal to it")
    gravity: float = Field(default=9.81, ge=0.0, le=1000.0, description="m/s², what an accelerometer at rest reads")
    gps_coordinate_system: Literal["local", "WGS84"] = Field(
        default="local", description="what a GPS reads: local coordinates (m) or WGS84 latitude, longitude (degrees), "
        "altitude (m)")
    gps_reference: Vec3 = Field(default=(0.0, 0.0, 0.0), description="local: added to the position; WGS84: the "
                                "latitude, longitude (degrees) and altitude (m) of the world's origin")
    ink_evaporation: float = Field(default=0.0, ge=0.0, description="1/s: pen ink fades as exp(-ink_evaporation·t) "
                                   "(Webots' inkEvaporation); 0 = never")


class Background(Strict):
    """Webots' Background node: what a camera sees where no shape is (``skyColor``'s first colour,
    which Webots clears the HDR image with reverse tone mapped: at exposure 1 it shows as itself)."""

    sky_color: Color = (0.0, 0.0, 0.0)

    _unit = field_validator("sky_color")(_unit_colors)


class Fog(Strict):
    """Webots' Fog node: camera images blend each surface with ``color`` by its distance from the
    camera (README "Cameras and range finders"); the background, range images, lidars and distance
    sensors are not fogged. A ``visibility_range`` of 0 disables it (Webots)."""

    color: Color = (1.0, 1.0, 1.0)
    visibility_range: float = Field(default=0.0, ge=0.0, description="metres; 0 disables the fog (Webots)")
    fog_type: Literal["LINEAR", "EXPONENTIAL", "EXPONENTIAL2"] = Field(
        default="LINEAR", description="how the blend grows with the distance d (V the visibility range): LINEAR "
        "by d/V, EXPONENTIAL by 1 - exp(-d/V), EXPONENTIAL2 by 1 - exp(-(d/V)^2), each raised to 2.2 (Webots)")

    _unit = field_validator("color")(_unit_colors)


class TopNode(Strict):
    """One top-level node of a ``.wbt`` world, in file order (the Supervisor's root ``children``):
    a node Sensorium simulates counts the robots, solids and top-level lights it became (their
    places in ``robots``, ``solids`` and ``lights`` follow the file); any other node (``WorldInfo``,
    ``Viewpoint``, ``Background``, ...) keeps its type and DEF name only."""

    type: str = Field(min_length=1, description="Webots node type (a PROTO instance: its base type)")
    proto: str | None = Field(default=None, min_length=1, description="a PROTO instance: the PROTO's name "
                              "(Supervisor getTypeName; getBaseTypeName is type)")
    interface: list[ProtoLevel] = Field(default=[], max_length=16, description=_INTERFACE)
    def_name: str | None = Field(default=None, min_length=1, description="Webots DEF name (Supervisor getFromDef)")
    fields: dict[str, float | str | list[float] | list[list[float]]] = Field(
        default={}, description="a node not simulated (Viewpoint, Background): the world file's values of the fields "
        "the Supervisor reads (README 'Supervisor')")
    robots: int = Field(default=0, ge=0, description="robots this node became")
    solids: int = Field(default=0, ge=0, description="top-level solids this node became")
    lights: int = Field(default=0, ge=0, description="top-level lights this node became")


class Charger(Strict):
    """Webots' Charger: the top-level solid ``solid`` (its position) recharges the battery of one robot at a
    time whose position comes within ``radius`` of its own (README 'Battery and Charger')."""

    solid: str = Field(min_length=1, description="the name of the top-level solid that is the Charger")
    battery: list[Annotated[float, Field(ge=0.0, allow_inf_nan=False)]] = Field(
        default=[], max_length=3, description="[current energy (J), maximum energy (J), energy upload speed (W)]; "
        "fewer than three values: the Charger does nothing, as in Webots")
    radius: float = Field(default=0.04, ge=0.0, allow_inf_nan=False,
                          description="the distance (m) between its position and a robot's that starts a charge")
    emissive_color: Vec3 = Field(default=(0.0, 1.0, 0.0), description="the emissive colour its glowing shapes "
                                 "take when it is full (Webots' Charger.emissiveColor)")
    gradual: bool = Field(default=True, description="true: the glowing shapes' emissive colour goes from their own "
                          "to emissive_color with the energy; false: their own until full, then emissive_color")
    glow_shapes: int = Field(default=1, ge=0, description="how many of its solid's first shapes glow so (a .wbt "
                             "Charger: the shapes of its first child, as Webots)")
    glow_lights: int = Field(default=0, ge=0, description="how many of its solid's first lights take that colour as "
                             "their color (a .wbt Charger: the lights of its first child, as Webots)")
    glow_solids: int = Field(default=0, ge=0, description="how many of its solid's first children solids glow so, "
                             "every shape and light in them (a .wbt Charger: the solids in its first child, which "
                             "Webots searches as groups)")

    _unit = field_validator("emissive_color")(_unit_colors)


class World(Strict):
    """A whole world file.

    Checks that relate several fields (sorted lookup tables, unique names, mesh files that exist)
    live in ``sensorium.server.world.loader.check_world`` so that each problem gets its exact path.
    """

    world_info: WorldInfo = WorldInfo()
    solids: list[Solid] = []
    lights: list[Light] = []
    robots: list[Robot] = []
    chargers: list[Charger] = Field(default=[], description="Webots' Charger nodes (each names its solid)")
    background: Background = Background()
    fog: Fog | None = Field(default=None, description="Webots' Fog node (the first one of a .wbt world)")
    top_nodes: list[TopNode] = Field(
        default=[], description="a .wbt world's top-level nodes in file order (Supervisor root children); empty: "
        "WorldInfo, Viewpoint, the robots, solids and lights (README 'Supervisor')")


def json_schema() -> dict:
    """JSON Schema of a world file, as committed in ``schemas/json/world.schema.json``."""
    schema = World.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "Sensorium world file"
    return schema
