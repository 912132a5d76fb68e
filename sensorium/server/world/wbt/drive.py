"""Motorised HingeJoint wheels → the world format's kinematic ``differential_drive``.

The kinematic drive turns the robot about its wheels' centre, x forward, wheels along the robot's y axis, and
a positive wheel speed drives forward. A Webots robot maps onto it when it clearly is such a robot:
every motorised hinge's axis along the robot's +y (or -y: a wheel mounted mirrored,
which a positive speed rolls backward, the drive's ``reversed_motors``; a skid-steer side all or none;
within WHEEL_AXES_TOL, 5e-3 rad: the drive rolls each wheel along its forward, so a wheel ε off it is
taken ε from where Webots' would roll, s·sin ε across over a path s) and wheels of one radius (a
wheel's round part the largest turning about its hinge's axis past its end point's own shapes when
larger than their first: :func:`rolling_part`, Tinkerbots' wheel two Solids along the slots), and either

* two wheels: both anchors on one line parallel to y, the wheels (their end points' origins) at
  two places along it; or
* several wheels per side (skid steer, a Pioneer 3-AT): each side's wheels on one line parallel to
  x, one line on either side of the robot's x axis.

The robot turns about its wheels' centre (the midpoint of the two wheels, or of the wheel lines at
the wheels' mean x), as Webots' physics turns it: a centre that is not under the robot's origin (a
Boe-Bot's axle is 2.5 cm ahead of it) is the drive's ``axle_center``.

A robot with steered wheels (a motorised hinge with a vertical axis, a Hinge2Joint's first axis: a
car) maps onto the kinematic ``ackermann_drive`` when its geometry is a car's as the world format
has it: two steering joints on one line parallel to y, symmetric about the robot's x axis,
turning about one vertical axis direction (+z: positive steers left, -z: right); driven wheels
(motorised hinges with their axis along +y) in pairs either side of the x axis, the front pair at
the steering joints' x, the rear pair on one line parallel to y behind them: the rear axle, whose
centre is the robot's origin in Webots' cars and may be ahead of or behind it (Webots'
``four_wheels`` how-to's ``ackerman`` has its origin at its body's centre): its x is the drive's
``rear_axle_offset`` and the wheelbase the steering joints' x less it. A car without driven rear
wheels (front-wheel drive) shows no rear axle: its origin is taken for the rear axle's centre.
Each axle's wheels of one radius.

A robot whose wheels all turn about another axis that is horizontal in its frame (perpendicular to
its z: Webots' ``four_wheels`` how-to turns its wheels about -x and drives along +y) is judged the
same way in the drive's own frame: x forward = axis × z (the way a positive wheel speed rolls the
wheel: its centre moves at ω·r·(axis × up)), y its left, z the robot's; the drive then says which
way is forward in the robot's frame (``forward``). A car's frame is its driven wheels' (their axis
taken within AXIS_TOL, as the car's other axes are).

Four wheels whose friction WorldInfo's ContactProperties makes asymmetric and turns
(``frictionRotation``: a KUKA youBot's mecanum rollers, which Webots simulates so) map onto the
kinematic ``mecanum_drive`` when they sit at the corners (±lx, ±ly) of a rectangle centred under
the origin, of one radius; a wheel's roller sign is minus the sign of its friction's turn: Webots'
contact frees a wheel along its cylinder's axis turned by -frictionRotation about the contact normal
(up into the wheel), so a wheel turned by -0.785 slides along (1, -1) and grips along (1, 1), sign +1
(the youBot's wheels turned by +0.785 are the ones its library's formulas give -1).

Three or more wheels, none steering, about axes horizontal in the robot's frame that are not all
along one line, each turning something round about its axis, their lowest points on one ground
(:func:`omni_wheels`: Webots' ``omni_wheels`` how-to, the ``four_wheels`` how-to's omni robot, a
Robotino) map onto the kinematic ``omni_drive``: each wheel where its round part meets its axis's
line, its axis and radius. Rollers (passive hinges across the wheel's axis, or asymmetric friction:
:func:`has_rollers`) do not decide it; wheels without them are said in one warning.

A robot built y-up in a NUE world (Webots before R2022a; convert.py's ``_robot_up``) is judged with its y
for its z throughout: its axes horizontal when perpendicular to its y, forward = axis × y (a 3-D
``forward``, its left y × forward), the drive's frame rows (forward, left, y) (:func:`drive_axes`);
its omni wheels' places and axes along its x and its left.

A robot built on its side (its own x, or in an ENU world its y, the world's up within 1 mrad: Tinkerbots'
base turned -pi/2 about y) is judged with that axis as up in the same way (convert.py's ``_robot_up``;
with x up, two-wheel and skid-steer wheels and one motor's axle only); its drive has no ``wheel_bottom``
(it keeps its height). A robot whose own -x, -y or -z is the world's up is judged with that end up
(:class:`Up`: forward = axis × -that axis). One motorised hinge carrying the wheels of both sides (:func:`one_motor_axle`:
Tinkerbots' vision_car) is a steered drive: one driven wheel midway between them, the robot's free
wheels keeping it straight.

Anything else gets one sentence saying which of these failed.
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.server.world.wbt.parser import Node

TOL = 1e-6
AXIS_TOL = 1e-4     # wheels' axes: Webots' PROTOs turn their joints' frames by 1.5708 or 3.14159 (not pi/2, pi)
# a two-wheel or skid-steer drive's wheels' axes, parallel or opposite: PROTO authors also write 1.57 for pi/2
# (7.96e-4 off), and robots built of blocks (Tinkerbots' Slots) compose several such turns: up to five of them
WHEEL_AXES_TOL = 5e-3


class Up(int):
    """A robot's own axis that stands up (0 x, 1 y, 2 z: an index, as a plain int is) and ``sign``, -1 when
    its negative end is the world's up (a robot built on its side the other way, or upside down): its
    wheels roll along axis × (−that axis)."""

    sign: float

    def __new__(cls, axis: int, sign: float = 1.0) -> Up:
        up = super().__new__(cls, axis)
        up.sign = sign
        return up


UP_Z = Up(2)     # a robot built z-up: the judgement's default


def up_vector(up: Up) -> np.ndarray:
    """The robot's up in its own frame: its ``up`` axis, negated when its sign is -1."""
    u = np.zeros(3)
    u[up] = up.sign
    return u


def wheel_radius(end: Node | None, conv) -> float | None:
    """Radius of a wheel end point: its boundingObject's (else its visual) cylinder or sphere."""
    part = _round_part(end, conv)
    return None if part is None else part[1]


def _round_part(end: Node | None, conv) -> tuple[str, float, float] | None:
    """(type, radius, height) of an end point's first cylinder, capsule or sphere (scaled; a
    sphere's height its diameter), its boundingObject's first, else its visual one's."""
    while end is not None and end.type == "Slot":      # Webots' cars hold their wheels in Slots
        end = conv.fields(end).node_("endPoint")
    if end is None:
        return None
    f = conv.fields(end)

    def find(node: Node | None, scale: float) -> tuple[str, float, float] | None:
        if node is None:
            return None
        conv.walk(node)
        if node.type in ("Cylinder", "Sphere", "Capsule"):
            nf = conv.fields(node)
            radius = nf.num("radius", 1.0) * scale
            return node.type, radius, (2.0 * radius if node.type == "Sphere" else nf.num("height", 2.0) * scale)
        nf = conv.fields(node)
        if node.type == "Shape":
            return find(nf.node_("geometry"), scale)
        if node.type in ("Pose", "Transform", "Group", "Solid"):
            if node.type == "Transform":
                scale *= nf.vec("scale", (1.0, 1.0, 1.0))[0]
            for child in nf.nodes("children"):
                r = find(child, scale)
                if r is not None:
                    return r
        return None

    bounding = find(f.node_("boundingObject"), 1.0)
    return bounding if bounding is not None and bounding[1] else find(end, 1.0)   # (a 0 radius: the visual's)


def rolls_about_its_axis(w: dict, conv, centred: bool = True) -> bool:
    """Whether a motorised hinge's end point turns something round as a wheel turns: its first
    cylinder or capsule (boundingObject first, as :func:`wheel_radius` looks) lies along the hinge's
    axis with its centre on it, or its first sphere is centred on the axis (within a quarter of the
    radius, 5° of tilt). An arm's link of a plain cylinder, standing across the axis or off it, does
    not: a robot with such an arm beside its wheels keeps its drive. ``centred`` False: the tilt
    only (a wheel's place is its Solid's where the joint's anchor is left at its default)."""
    end = conv.slotted(w["end"])
    if end is None:
        return False
    axis = np.asarray(w["axis"], dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    anchor = np.asarray(w["anchor"], dtype=np.float64)

    def judge(kind: str, radius: float, frame) -> bool:
        centre = np.asarray(frame.translation, dtype=np.float64)
        off = (centre - anchor) - axis * float(np.dot(centre - anchor, axis))
        if centred and float(np.linalg.norm(off)) > 0.25 * radius:
            return False
        if kind == "Sphere":
            return True
        along = np.asarray(frame.rotation, dtype=np.float64) @ np.array([0.0, 0.0, 1.0])
        return abs(float(np.dot(along, axis))) >= math.cos(math.radians(5.0)) * float(np.linalg.norm(along))

    found = _first_round_part(conv, end, w["frame"],
                              lambda kind, nf, frame: judge(kind, nf.num("radius", 1.0) * frame.scale, frame))
    return bool(found)


def holds_wheel(end: Node | None, conv) -> bool:
    """Whether a steering-like (vertical) hinge's end point is or carries a wheel: something round
    itself -- a sphere, or a cylinder or capsule no longer than twice its diameter (a compass
    needle's or a pointer's long thin rod is no wheel) --, or a hinge inside it whose end point is (a
    car's knuckle holding its wheel's joint). A pan head's or an arm's end point is neither."""
    part = _round_part(end, conv)
    if part is not None and part[2] <= 4.0 * part[1]:
        return True
    return _holds_wheel_joint(end, conv)


def spins_in_place(w: dict, conv) -> bool:
    """Whether a steering-like (vertical) hinge only spins what it holds where it is: its end point's
    first round part is a cylinder or capsule lying along the hinge's own axis, centred on it (a
    lidar's spinning head, a turntable: :func:`rolls_about_its_axis`), and it carries no hinge whose
    end point is round (no wheel's joint, as a BB-8's yaw hinge carries its ball's). Nothing it holds
    rolls on the ground, so it steers no wheel. A ball on the axis may be a steered ball wheel: not
    this."""
    end = conv.slotted(w["end"])
    if end is None or _first_round_part(conv, end, w["frame"], lambda kind, nf, frame: kind) not in ("Cylinder",
                                                                                                    "Capsule"):
        return False
    return rolls_about_its_axis(w, conv) and not _holds_wheel_joint(w["end"], conv)


def held_wheel(end: Node | None, conv) -> Node | None:
    """The node whose round part is the wheel a steering hinge's end point holds: the end point of the
    first hinge inside it with something round there (a tricycle's passive front wheel hinge), else the
    end point itself when its own round part is a wheel (:func:`holds_wheel`), else None."""
    found = _wheel_joint_end(end, conv)
    if found is not None:
        return found
    part = _round_part(end, conv)
    return end if part is not None and part[2] <= 4.0 * part[1] else None


def _holds_wheel_joint(end: Node | None, conv) -> bool:
    """Whether an end point holds a hinge whose end point has something round (a car's knuckle holding
    its wheel's joint)."""
    return _wheel_joint_end(end, conv) is not None


def _wheel_joint_end(node: Node | None, conv) -> Node | None:
    """The end point of the first hinge at or inside ``node`` (through Poses, Transforms, Groups, Solids
    and Slots, not past a hinge) whose end point has something round (:func:`wheel_radius`), else None."""
    if node is None:
        return None
    conv.walk(node)
    nf = conv.fields(node)
    if node.type in ("HingeJoint", "Hinge2Joint"):
        held = nf.node_("endPoint")
        return held if wheel_radius(held, conv) is not None else None
    if node.type in ("Pose", "Transform", "Group", "Solid", "Slot"):
        for child in [nf.node_("endPoint")] if node.type == "Slot" else nf.nodes("children"):
            found = _wheel_joint_end(child, conv)
            if found is not None:
                return found
    return None


def _axis_off_y(wheels: list[dict], tol: float, why: str) -> str:
    """The sentence for the first wheel whose axis is not the robot's +y (within ``tol``), else ""."""
    y = np.array([0.0, 1.0, 0.0])
    for w in wheels:
        a = w["axis"] / np.linalg.norm(w["axis"])
        if np.linalg.norm(a - y) > tol:
            return f"wheel axis of motor {w['motor']!r} is {np.round(a, 6).tolist()}, not the robot's +y ({why})"
    return ""


def drive_frame(wheels: list[dict], tol: float = TOL, up: Up = UP_Z,
                opposite: bool = False) -> tuple[np.ndarray | None, str]:
    """The rotation from the robot's frame to its drive's (rows: forward, left, up), or None when a
    wheel turns about the robot's +y within ``tol`` on a z-up robot (its frame is the drive's, as it
    always was) or there is no wheel; with the sentence saying why there is none when the wheels turn
    about different or non-horizontal axes. ``up``: the robot's own axis that is up, 2 its z, 1 its y
    (a robot built y-up in a NUE world, as Webots' were before R2022a). ``opposite``: a wheel turning
    about the opposite axis (within ``tol``: mounted mirrored) is along the same line, not different;
    the frame is then the +y wheel's (the robot's own), else the first wheel's."""
    y = np.array([0.0, 1.0, 0.0])
    axes = [w["axis"] / np.linalg.norm(w["axis"]) for w in wheels]
    if not axes or (up == 2 and up_vector(up)[2] > 0.0 and any(np.linalg.norm(a - y) <= tol for a in axes)):
        return None, ""
    a0 = axes[0]
    first = wheels[0]["motor"]
    name = "xyz"[up]
    if abs(a0[up]) > tol:
        plain = "neither the robot's +y nor " if up == 2 else ""
        return None, (f"wheel axis of motor {first!r} is {np.round(a0, 6).tolist()}, {plain}"
                      f"horizontal in its frame (perpendicular to its {name}, its up): the kinematic drive rolls on "
                      "wheels whose axis is horizontal")
    for w, a in zip(wheels[1:], axes[1:]):
        if np.linalg.norm(a - a0) > tol and not (opposite and np.linalg.norm(a + a0) <= tol):
            return None, (f"wheel axis of motor {w['motor']!r} is {np.round(a, 6).tolist()}, not "
                          f"{np.round(a0, 6).tolist()}, the axis of motor {first!r}"
                          + (" nor its opposite (the kinematic drive needs every axis along one line)" if opposite else
                             " (the kinematic drive needs every axis along one direction so that positive speeds drive "
                             "forward)"))
    a = a0.copy()
    a[up] = 0.0
    return drive_axes(np.cross(a, up_vector(up)), up), ""      # axis × up: where a positive speed rolls the wheel


def drive_axes(forward, up: Up = UP_Z) -> np.ndarray:
    """The rotation from the robot's frame to its drive's (rows: forward, left = up × forward, up) for
    a ``forward`` in the robot's frame (two values: in its x–y plane) and its up axis ``up`` (2 its
    z, 1 its y)."""
    f = np.zeros(3)
    f[:len(forward)] = forward
    f /= math.hypot(*f)
    u = up_vector(up)
    return np.array([f, np.cross(u, f), u])


def differential_drive(wheels: list[dict], conv, up: Up = UP_Z) -> tuple[dict | None, str]:
    """The kinematic drive of a robot's motorised hinges (two wheels, or several per side: skid
    steer), or (None, the sentence saying why not); ``up`` the robot's up axis (:func:`drive_frame`)."""
    if len(wheels) < 2:
        return None, f"{len(wheels)} motorised hinge joint; a drive needs two wheels or more, on both sides"
    # (axes within WHEEL_AXES_TOL of parallel or opposite: Webots' Moose turns its right wheels' frames by
    # 3.14159, not pi; Tinkerbots' slots by 1.57, not pi/2)
    wheels = [_rolled(w, conv) for w in wheels]
    frame, why = drive_frame(wheels, WHEEL_AXES_TOL, up, opposite=True)
    if why:
        return None, why
    wheels = _in_frame(wheels, frame)
    # a wheel about -y is mounted mirrored: a positive speed rolls it backward (Webots' physics rolls each
    # wheel about its own axis), so its speed counts negated (the drive's reversed_motors)
    mirrored = [w for w in wheels if np.linalg.norm(w["axis"] / np.linalg.norm(w["axis"]) + [0.0, 1.0, 0.0])
                <= WHEEL_AXES_TOL]
    off = _axis_off_y([w for w in wheels if not any(w is m for m in mirrored)], WHEEL_AXES_TOL,
                      "the kinematic drive needs every axis along +y or -y, the wheels on one line")
    if off:
        return None, off
    drive, why = _two_wheels(wheels, conv) if len(wheels) == 2 else _skid_steer(wheels, conv)
    if drive is not None and mirrored:
        reversed_motors = {w["motor"] for w in mirrored}
        left = [drive["left_motor"], *drive.get("skid_steer", {}).get("left", ())]
        right = [drive["right_motor"], *drive.get("skid_steer", {}).get("right", ())]
        for side, motors in (("left", left), ("right", right)):
            named = [m for m in motors if m in reversed_motors]
            if named and len(named) != len(motors):
                return None, (f"the {side} side's wheels {motors} turn about opposite axes, {named} mounted "
                              "mirrored and not the others: a skid-steer side's wheels roll as one")
        drive["reversed_motors"] = [m for m in (*left, *right) if m in reversed_motors]
    return _framed(drive, why, frame)


def rolling_part(w: dict, conv) -> tuple[float, np.ndarray, bool] | None:
    """(radius, centre in the robot's frame, whether it is the end point's own) of the round part a hinge's
    wheel rolls on the ground with: the largest of :func:`rolling_parts` (the lowest turning with the hinge:
    Tinkerbots' motor turns a 0.01 m sphere of its own and, two Solids further along the slots, the 0.02625 m
    wheel that meets the ground), the first of equals; None when nothing round turns so."""
    parts = rolling_parts(w, conv)
    return max(parts, key=lambda p: p[0]) if parts else None


def rolling_parts(w: dict, conv) -> list[tuple[float, np.ndarray, bool]]:
    """(radius, centre in the robot's frame, whether it is the end point's own) of each cylinder, capsule or
    sphere turning about a hinge's axis (:func:`rolls_about_its_axis`'s test: along it within 5°, centred on
    its line within a quarter of its radius) that its end point carries without another joint between (its
    children, Solids, Slots), in the world's order: the boundingObjects', else (none there) the shapes'."""
    end = conv.slotted(w["end"])
    if end is None:
        return []
    axis = np.asarray(w["axis"], dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    anchor = np.asarray(w["anchor"], dtype=np.float64)
    found: dict[bool, list[tuple[float, np.ndarray, bool]]] = {True: [], False: []}

    def part(node: Node, frame, own: bool, bounding: bool) -> None:
        nf = conv.fields(node)
        radius = nf.num("radius", 1.0) * frame.scale
        centre = np.asarray(frame.translation, dtype=np.float64)
        off = (centre - anchor) - axis * float(np.dot(centre - anchor, axis))
        if radius <= 0.0 or float(np.linalg.norm(off)) > 0.25 * radius:
            return
        if node.type != "Sphere":
            along = np.asarray(frame.rotation, dtype=np.float64) @ np.array([0.0, 0.0, 1.0])
            if abs(float(np.dot(along, axis))) < math.cos(math.radians(5.0)) * float(np.linalg.norm(along)):
                return
        found[bounding].append((radius, centre, own))

    def shapes(node: Node | None, frame, own: bool, bounding: bool) -> None:
        if node is None:
            return
        conv.walk(node)
        nf = conv.fields(node)
        if node.type in ("Cylinder", "Sphere", "Capsule"):
            part(node, frame, own, bounding)
        elif node.type == "Shape":
            shapes(nf.node_("geometry"), frame, own, bounding)
        elif node.type in ("Pose", "Transform", "Group") or (node.type == "Solid" and bounding):
            inner = frame if node.type == "Group" else conv.child_frame(node, frame)
            for child in nf.nodes("children"):
                shapes(child, inner, own, bounding)

    def solid(node: Node, frame, own: bool) -> None:
        inner = conv.child_frame(node, frame)
        shapes(conv.fields(node).node_("boundingObject"), inner, own, True)
        walk(conv.fields(node).nodes("children"), inner, own)

    def walk(children: list[Node], frame, own: bool) -> None:
        for child in children:
            conv.walk(child)
            cf = conv.fields(child)
            if child.type == "Solid":
                solid(child, frame, False)
            elif child.type == "Slot":
                held = conv.slotted(child)
                if held is not None and held.type == "Solid":
                    solid(held, frame, False)
            elif child.type in ("Pose", "Transform", "Group"):
                walk(cf.nodes("children"), frame if child.type == "Group" else conv.child_frame(child, frame), own)
            elif child.type == "Shape":
                shapes(child, frame, own, False)

    if end.type == "Solid":
        solid(end, w["frame"], True)
    return found[True] or found[False]


def _rolled(w: dict, conv) -> dict:
    """A wheel whose largest round part turning with its hinge (:func:`rolling_part`) lies past its end
    point's own shapes and is larger than its first round part: its radius that part's and its place
    that part's centre on the hinge's axis (a copy); else the wheel as it is (its end point's first round
    part, its place the end point's origin)."""
    rolled = rolling_part(w, conv)
    first = wheel_radius(w["end"], conv)
    if rolled is None or rolled[2] or (first is not None and rolled[0] <= first):
        return w
    axis = np.asarray(w["axis"], dtype=np.float64) / np.linalg.norm(w["axis"])
    anchor = np.asarray(w["anchor"], dtype=np.float64)
    return {**w, "radius": rolled[0], "centre": anchor + axis * float(np.dot(rolled[1] - anchor, axis))}


def _in_frame(wheels: list[dict], frame: np.ndarray | None) -> list[dict]:
    """The wheels' axes and places in the drive's frame (x forward, y left), copies (the same
    entries when the robot's frame is the drive's)."""
    if frame is None:
        return wheels
    return [{**w, "axis": frame @ w["axis"], "anchor": frame @ w["anchor"], "centre": frame @ w["centre"]}
            for w in wheels]


def _framed(drive: dict | None, why: str, frame: np.ndarray | None) -> tuple[dict | None, str]:
    """A drive judged in the drive's frame with its ``forward``, or the sentence saying in which
    frame the geometry it names was judged."""
    if frame is None:
        return drive, why
    if drive is None:
        fwd = [float(v) + 0.0 for v in np.round(frame[0, :2 if frame[2, 2] == 1.0 else 3], 6)]      # (no -0.0)
        return None, f"{why}; in the drive's frame: x forward along {fwd} in the robot's, y its left"
    # (x, y) for a z-up robot, as it always was; (x, y, z) for a y-up one, its up its y
    drive["forward"] = [float(v) + 0.0 for v in frame[0, :2 if frame[2, 2] == 1.0 else 3]]      # (no -0.0)
    return drive, ""


def _radius(wheels: list[dict], conv) -> tuple[float | None, str]:
    radii = [w["radius"] if "radius" in w else wheel_radius(w["end"], conv) for w in wheels]
    if any(r is None for r in radii):
        return None, "a wheel end point has no cylinder or sphere to take the wheel radius from"
    r0 = radii[0]
    assert r0 is not None
    for r in radii[1:]:
        assert r is not None
        if abs(r - r0) > TOL * max(r, r0):
            return None, f"the wheels have different radii ({', '.join(f'{x:g}' for x in radii if x is not None)})"
    return r0, ""


def _max_speed(wheels: list[dict], conv) -> float:
    """One maxVelocity for motors the drive moves as one (a car's two steering motors): the smaller."""
    speeds = {w["max_velocity"] for w in wheels}
    if len(speeds) > 1:
        conv.warn(wheels[0]["node"], f"motors have different maxVelocity {sorted(speeds)}: using the smaller")
    return min(speeds)


def _wheel_speeds(wheels: list[dict], conv, sides: tuple[list[dict], ...] = ()) -> dict:
    """The drive's ``max_wheel_speed`` (the smallest wheel's) and ``motor_max_speeds`` (each wheel whose
    own maxVelocity is more), as Webots clamps each motor to its own. ``sides``: a skid-steer drive's
    wheels of each side, which roll as one, so share the side's smallest (said at load)."""
    own = {w["motor"]: float(w["max_velocity"]) for w in wheels}
    for side in sides:
        speeds = {w["max_velocity"] for w in side}
        if len(speeds) > 1:
            conv.warn(side[0]["node"], f"the wheel motors of one side have different maxVelocity {sorted(speeds)}: the side rolls as "
                      "one, at the smaller")
        own.update({w["motor"]: float(min(speeds)) for w in side})
    low = min(own.values())
    out: dict = {"max_wheel_speed": low}
    if any(v != low for v in own.values()):
        out["motor_max_speeds"] = {name: v for name, v in own.items() if v != low}
    return out


def _two_wheels(wheels: list[dict], conv) -> tuple[dict | None, str]:
    a0, a1 = wheels[0]["anchor"], wheels[1]["anchor"]
    # (axes up to WHEEL_AXES_TOL apart put anchors on "one axle" that far off it per metre between them)
    near = TOL + WHEEL_AXES_TOL * abs(float(a0[1] - a1[1]))
    if abs(a0[0] - a1[0]) > near or abs(a0[2] - a1[2]) > near:
        return None, "the two wheel anchors are not on one axle parallel to the robot's y axis"
    # where the wheels are along the axle: their end points' origins (an anchor may be anywhere on it)
    a0, a1 = wheels[0]["centre"], wheels[1]["centre"]
    if abs(a0[1] - a1[1]) <= TOL:
        return None, "both wheels are at the same place on the axle"
    mid = (a0 + a1) / 2.0
    r0, why = _radius(wheels, conv)
    if r0 is None:
        return None, why
    left, right = (wheels[0], wheels[1]) if a0[1] > a1[1] else (wheels[1], wheels[0])
    return _centred({"wheel_radius": r0, "axle_length": float(abs(a0[1] - a1[1])),
                     **_wheel_speeds(wheels, conv), "left_motor": left["motor"],
                     "right_motor": right["motor"]}, mid[0], mid[1]), ""


def webots_kinematic_pair(wheels: list[dict], conv) -> dict | None:
    """The two wheels Webots moves a robot without Physics by (``WbKinematicDifferentialWheels``), as the
    drive's fields: ``left_motor``, ``right_motor``, ``wheel_radius``, ``axle_length`` and ``step_rule``
    ``mid_heading``; None when no pair qualifies (Webots then does not move the robot at all).

    The candidates are the robot's motorised HingeJoints with a Solid end point, in the world's order (here
    those not inside another candidate's end point: the robot's own joints). The first pair (i < j) taken is
    the first whose end points' boundingObjects hold a Cylinder (:func:`_biggest_cylinder`) of one radius > 0,
    the two at distances from the robot's origin (3-D, to the Pose, Transform or Solid holding each cylinder)
    within 1e-5 m of each other, their joints' axes parallel or opposite (a null cross product: a wheel mounted
    mirrored qualifies, its velocity then read as it is, not negated) and their anchors on a line along them. The
    axle is the sum of the two distances (not the wheels' separation: 2·√(0.026² + 0.02²) for an e-puck, whose
    wheels are 0.052 m apart), the radius the cylinders' (its field, as Webots reads it); the left wheel the one
    with the larger y in the robot's frame."""
    candidates = [w for w in wheels if w["node"].type == "HingeJoint"
                  and (end := conv.slotted(w["end"])) is not None and end.type == "Solid"]
    inner = set().union(*(_inside_ids(conv, w["end"]) for w in candidates)) if candidates else set()
    candidates = [w for w in candidates if id(w["node"]) not in inner]
    found = [_biggest_cylinder(w, conv) for w in candidates]

    def parallel(a, b) -> bool:
        a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
        return float(np.linalg.norm(np.cross(a, b))) <= 1e-9 * float(np.linalg.norm(a)) * max(float(np.linalg.norm(b)), 1.0)

    for i, wi in enumerate(candidates):
        if found[i] is None or found[i][0] <= 0.0:
            continue
        ri, pi = found[i]
        for j in range(i + 1, len(candidates)):
            wj = candidates[j]
            if found[j] is None or found[j][0] <= 0.0 or found[j][0] != ri:
                continue
            pj = found[j][1]
            di, dj = float(np.linalg.norm(pi)), float(np.linalg.norm(pj))
            if abs(di - dj) > 1e-5 or not parallel(wi["axis"], wj["axis"]) \
                    or not parallel(wi["axis"], np.asarray(wj["anchor"]) - np.asarray(wi["anchor"])):
                continue
            left, right = (wi, wj) if pi[1] > pj[1] else (wj, wi)
            return {"left_motor": left["motor"], "right_motor": right["motor"], "wheel_radius": float(ri),
                    "axle_length": di + dj, "step_rule": "mid_heading"}
    return None


def _inside_ids(conv, end: Node | None) -> set[int]:
    """The ids of the joints inside an end point (through its children and its joints' end points)."""
    out: set[int] = set()
    stack = [conv.slotted(end)] if end is not None else []
    while stack:
        node = stack.pop()
        if node is None:
            continue
        conv.walk(node)
        nf = conv.fields(node)
        for child in nf.nodes("children") if node.type in ("Pose", "Transform", "Group", "Solid", "Robot") else ():
            if child.type in ("HingeJoint", "Hinge2Joint", "SliderJoint", "BallJoint"):
                out.add(id(child))
                stack.append(conv.slotted(conv.fields(child).node_("endPoint")))
            else:
                stack.append(child)
    return out


def _biggest_cylinder(w: dict, conv) -> tuple[float, np.ndarray] | None:
    """(radius field, where its holding Pose, Transform or Solid is in the robot's frame) of the Cylinder
    Webots' kinematic rule finds in a wheel's end point's boundingObject: the node itself when a Cylinder,
    a Shape's Cylinder geometry, else of a Group's (a Pose's, a Transform's) children's the one of the
    largest radius (the first of equal ones); None without one."""
    end = conv.slotted(w["end"])

    def find(node: Node | None, frame) -> tuple[float, np.ndarray] | None:
        if node is None:
            return None
        conv.walk(node)
        nf = conv.fields(node)
        if node.type == "Cylinder":
            return nf.num("radius", 1.0), np.asarray(frame.translation, dtype=np.float64)
        if node.type == "Shape":
            geometry = nf.node_("geometry")
            return find(geometry, frame) if geometry is not None and geometry.type == "Cylinder" else None
        best = None
        if node.type in ("Pose", "Transform", "Group"):
            inner = frame if node.type == "Group" else conv.child_frame(node, frame)
            for child in nf.nodes("children"):
                got = find(child, inner)
                if got is not None and (best is None or got[0] > best[0]):
                    best = got
        return best

    end_frame = conv.child_frame(end, w["frame"])
    return find(conv.fields(end).node_("boundingObject"), end_frame)


def _centred(drive: dict, cx: float, cy: float) -> dict:
    """The drive with its ``axle_center`` when the wheels' centre is not under the robot's origin
    (Webots' robot turns about its wheels' centre wherever its origin is: a Boe-Bot's axle is
    2.5 cm ahead of it); a centre within TOL of the origin is the origin (the field left out)."""
    if abs(cx) > TOL or abs(cy) > TOL:
        drive["axle_center"] = [float(cx), float(cy)]
    return drive


def _skid_steer(wheels: list[dict], conv) -> tuple[dict | None, str]:
    """Several wheels per side on parallel axes (a Pioneer 3-AT): each side's wheels on one line
    parallel to x, one line either side of the robot's x axis; the robot turns about the middle of
    the two lines at the wheels' mean x (``axle_center`` when that is not the origin)."""
    centres = np.array([w["centre"] for w in wheels])
    left = [w for w, c in zip(wheels, centres) if c[1] > TOL]
    right = [w for w, c in zip(wheels, centres) if c[1] < -TOL]
    if len(left) + len(right) != len(wheels) or not left or not right:
        return None, (f"{len(wheels)} motorised wheels, not all on either side of the robot's x axis (a skid-steer "
                      "drive needs wheels on both sides and none on the axis)")
    yl, yr = (np.array([w["centre"][1] for w in side]) for side in (left, right))
    if np.ptp(yl) > TOL or np.ptp(yr) > TOL:
        return None, "the wheels of one side are not on one line parallel to the robot's x axis"
    r0, why = _radius(wheels, conv)
    if r0 is None:
        return None, why
    return _centred({"wheel_radius": r0, "axle_length": float(yl[0] - yr[0]),
                     **_wheel_speeds(wheels, conv, (left, right)),
                     "left_motor": left[0]["motor"], "right_motor": right[0]["motor"],
                     "skid_steer": {"left": [w["motor"] for w in left[1:]], "right": [w["motor"] for w in right[1:]]}},
                    float(centres[:, 0].mean()), float(yl[0] + yr[0]) / 2.0), ""


STEERING_UNLIMITED = 1.5
"""rad: the steering limit of a steering motor without position limits (the world format needs one
below pi/2, where the bicycle model's turn radius reaches 0)."""


def ackermann_drive(wheels: list[dict], conv, up: Up = UP_Z) -> tuple[dict | None, str]:
    """The kinematic Ackermann drive of a car's motorised hinges, or (None, the sentence why not);
    judged in the drive's frame, its driven wheels' axis along its y (see the module docstring)."""
    frame, why = drive_frame([w for w in wheels if not w["steers"]], AXIS_TOL, up)
    if why:
        return None, why
    drive, why = _ackermann(_in_frame(wheels, frame), conv)
    return _framed(drive, why, frame)


def _ackermann(wheels: list[dict], conv) -> tuple[dict | None, str]:
    steering = [w for w in wheels if w["steers"]]
    driven = [w for w in wheels if not w["steers"]]
    names = ", ".join(repr(w["motor"]) for w in steering)
    if len(steering) != 2:
        return None, (f"a car-like robot needs two steered front wheels, it has {len(steering)} steering motor(s) "
                      f"({names})")
    z = np.array([0.0, 0.0, 1.0])
    signs = []
    for w in steering:
        a = w["axis"] / np.linalg.norm(w["axis"])
        if np.linalg.norm(np.abs(a) - z) > AXIS_TOL:
            return None, (f"the steering axis of motor {w['motor']!r} is {np.round(a, 6).tolist()}, not vertical "
                          "(the robot's z axis)")
        signs.append(a[2] > 0)
    if signs[0] != signs[1]:
        return None, f"the steering motors {names} turn about opposite axes (one +z, one -z)"
    a0, a1 = steering[0]["anchor"], steering[1]["anchor"]
    if abs(a0[0] - a1[0]) > TOL or abs(a0[1] + a1[1]) > TOL or abs(a0[1]) <= TOL:
        return None, (f"the steering joints of {names} are not on one front axle parallel to the robot's y axis, "
                      "symmetric about its x axis")
    front_x = float(a0[0])
    right_steer, left_steer = (steering[0], steering[1]) if a0[1] < 0 else (steering[1], steering[0])
    off = _axis_off_y(driven, AXIS_TOL, "positive wheel speeds must drive forward")
    if off:
        return None, off
    front = [w for w in driven if abs(w["centre"][0] - front_x) <= TOL]
    rear = [w for w in driven if abs(w["centre"][0] - front_x) > TOL]
    rear_x = float(rear[0]["centre"][0]) if rear else 0.0
    rear_x = 0.0 if abs(rear_x) <= TOL else rear_x     # (on the origin within TOL: exactly, as it always was)
    if (len(front) not in (0, 2) or len(rear) not in (0, 2) or not driven
            or any(abs(w["centre"][0] - rear_x) > TOL for w in rear)):
        where = ", ".join(f"{w['motor']!r} at x={w['centre'][0]:g}" for w in driven) or "none"
        return None, (f"the driven wheels ({where}) are not a pair on the front axle (x={front_x:g}), a pair on one "
                      "rear axle parallel to the robot's y axis, or both")
    wheelbase = front_x - rear_x
    if wheelbase <= TOL:
        where = (f"the rear axle (x={rear_x:g}, its driven wheels')" if rear else
                 "the robot's origin (a car without driven rear wheels has its rear axle there)")
        return None, f"the steering joints are at x={front_x:g}, not ahead of {where}"
    out: dict = {"wheelbase": wheelbase, "track_front": float(abs(a0[1] - a1[1])),
                 "type": "4x4" if front and rear else "traction" if front else "propulsion",
                 "positive_steers": "left" if signs[0] else "right",
                 "right_steer": right_steer["motor"], "left_steer": left_steer["motor"]}
    radii = {}
    for axle, pair in (("front", front), ("rear", rear)):
        if not pair:
            continue
        c0, c1 = pair[0]["centre"], pair[1]["centre"]
        if abs(c0[1] + c1[1]) > TOL or abs(c0[1]) <= TOL:
            return None, f"the {axle} wheels are not either side of the robot's x axis at the same distance"
        r, why = _radius(pair, conv)
        if r is None:
            return None, f"{axle} wheels: {why}"
        radii[axle] = r
        right, left = (pair[0], pair[1]) if c0[1] < 0 else (pair[1], pair[0])
        out[f"right_{axle}_wheel"], out[f"left_{axle}_wheel"] = right["motor"], left["motor"]
        if axle == "rear":
            out["track_rear"] = float(abs(c0[1] - c1[1]))
    if "front" not in radii:            # the steered wheels' own end points (a Hinge2Joint's wheel)
        r, _ = _radius(steering, conv)
        radii["front"] = r if r is not None else radii["rear"]
    out["front_wheel_radius"], out["rear_wheel_radius"] = radii["front"], radii.get("rear", radii["front"])
    out.setdefault("track_rear", out["track_front"])
    out.update(_wheel_speeds(driven, conv))
    out["max_steering_speed"] = _max_speed(steering, conv)
    limits = [abs(v) for w in steering for v in w["limits"] if w["limits"] != (0.0, 0.0)]
    out["max_steering_angle"] = min([*limits, STEERING_UNLIMITED])
    if out["max_steering_angle"] == 0.0:
        return None, f"the steering motors {names} have a position limit of 0 (they cannot steer)"
    if rear_x != 0.0:                   # (on the origin: the key left out, the entry as it always was)
        out["rear_axle_offset"] = rear_x
    return out, ""


ENGINES = {"C": "combustion", "E": "electric", "P": "parallel hybrid", "S": "power-split hybrid"}
"""Webots' Car customData engine letters (its engineType field's values)."""


def car_engine(custom_data: str) -> str | None:
    """The engine type a Webots ``Car`` writes into its customData (its PROTO's engineType field, the
    eighth of the twenty values Webots' car library reads: wheelbase, tracks, radii, brake
    coefficient, damping, the engine letter, ...), or None when the data is no Car's (fewer than 20
    values, as the car library judges it)."""
    words = custom_data.split()
    if len(words) < 20 or not words[7]:
        return None
    try:
        [float(w) for w in words[:7] + words[8:18]]
        [int(w) for w in words[18:20]]
    except ValueError:
        return None
    return ENGINES.get(words[7][0], "combustion")


def free_car_wheels(car: dict | None, free: list[dict], conv, up: Up = UP_Z) -> set[int]:
    """A car's wheels without a motor (Webots' Car: a propulsion car's front wheels, the second axis of
    its steering Hinge2Joints; a traction car's rear ones, HingeJoints on the rear axle under its
    origin) become the drive's free wheels: each encoder on them gets ``free_wheel`` (and
    ``free_wheel_sign`` -1 when its axis is the car's right), a traction car the rear wheels' track
    and radius. ``free``: the robot's wheel axes with encoders and no motor; the ids of those that
    roll now (the others keep their line)."""
    if car is None or car["type"] == "4x4" or not free:
        return set()
    fwd = car.get("forward")
    frame = np.eye(3) if fwd is None else drive_axes(fwd, up)
    found: dict[str, tuple[dict, np.ndarray]] = {}      # right_front, ... -> (the axis, its centre in the drive's frame)
    for f in free:
        axis = frame @ (f["axis"] / np.linalg.norm(f["axis"]))
        if abs(abs(axis[1]) - 1.0) > AXIS_TOL:         # no wheel rolling along the car
            continue
        centre = frame @ f["centre"]
        if car["type"] == "propulsion" and f["steer"] in (car["right_steer"], car["left_steer"]):
            found["right_front" if f["steer"] == car["right_steer"] else "left_front"] = (f, axis)
        elif car["type"] == "traction" and f["steer"] is None and abs(centre[0]) <= TOL and abs(centre[1]) > TOL:
            key = "right_rear" if centre[1] < 0 else "left_rear"
            if key in found:            # two on one side: neither is the car's wheel
                return set()
            found[key] = (f, centre)
    if car["type"] == "traction":
        if set(found) != {"right_rear", "left_rear"}:
            return set()
        right, left = found["right_rear"], found["left_rear"]
        if abs(right[1][1] + left[1][1]) > TOL:
            return set()
        radius, _ = _radius([right[0], left[0]], conv)
        if radius is None:
            return set()
        car["track_rear"], car["rear_wheel_radius"] = float(left[1][1] - right[1][1]), radius
        found = {k: (f, frame @ (f["axis"] / np.linalg.norm(f["axis"]))) for k, (f, _) in found.items()}
    for key, (f, axis) in found.items():
        for sensor in f["sensors"]:
            sensor["free_wheel"] = key
            if axis[1] < 0:
                sensor["free_wheel_sign"] = -1
    return {id(f) for f, _ in found.values()}


# ---------------------------------------------------------------- mecanum wheels (a KUKA youBot)

MECANUM_ANGLE = math.pi / 4
"""rad: the rollers' angle the mecanum drive assumes (Webots' youBot turns its wheels' friction
directions by ±0.785398)."""


def contact_properties(conv) -> list[tuple[str, str, list[float], tuple[float, ...]]]:
    """The world's ContactProperties (the first top-level WorldInfo's ``contactProperties``, in
    order): (material1, material2, coulombFriction, frictionRotation) each, Webots' defaults filled in."""
    cached = getattr(conv, "_contact_properties", None)
    if cached is not None:
        return cached
    out: list[tuple[str, str, list[float], tuple[float, ...]]] = []
    info = next((n for n in conv.wbt.nodes if n.type == "WorldInfo"), None)
    if info is not None:
        for cp in conv.fields(info).nodes("contactProperties"):
            if cp.type != "ContactProperties":
                continue
            f = conv.fields(cp)
            out.append((f.string("material1", "default"), f.string("material2", "default"),
                        f.numbers("coulombFriction") or [1.0], f.vec("frictionRotation", (0.0, 0.0))))
    conv._contact_properties = out
    return out


def roller_turn(w: dict, conv) -> float | None:
    """How a wheel's rollers turn its friction, or None when it has no asymmetric friction: its end
    point's ``contactMaterial`` in the first ContactProperties naming it (as material1 or material2),
    whose ``coulombFriction`` is asymmetric for that solid (two different values; with three or four,
    material1's are the first two, with four material2's the last two) and whose ``frictionRotation``'s
    first value is not 0: that value (rad)."""
    end = conv.slotted(w["end"])
    if end is None or end.type != "Solid":
        return None
    material = conv.fields(end).string("contactMaterial", "default")
    for m1, m2, friction, rotation in contact_properties(conv):
        if material not in (m1, m2):
            continue
        if material == m1 and len(friction) >= 2:
            pair = friction[:2]
        elif len(friction) == 2 or len(friction) == 4:
            pair = friction[-2:]
        else:
            return None
        return float(rotation[0]) if pair[0] != pair[1] and rotation[0] != 0.0 else None
    return None


def mecanum_turns(wheels: list[dict], conv) -> list[float | None] | None:
    """Each wheel's :func:`roller_turn`, or None when no wheel has asymmetric friction (no mecanum
    robot)."""
    turns = [roller_turn(w, conv) for w in wheels]
    return turns if any(t is not None for t in turns) else None


def mecanum_drive(wheels: list[dict], turns: list[float | None], conv, up: Up = UP_Z) -> tuple[dict | None, str]:
    """The kinematic mecanum drive of four wheels whose friction is turned (:func:`mecanum_turns`),
    or (None, the sentence why not); judged in the drive's frame (x forward = the axis × up)."""
    frame, why = drive_frame(wheels, AXIS_TOL, up)
    if why:
        return None, why
    drive, why = _mecanum(_in_frame(wheels, frame), turns, conv)
    return _framed(drive, why, frame)


def _mecanum(wheels: list[dict], turns: list[float | None], conv) -> tuple[dict | None, str]:
    off = _axis_off_y(wheels, AXIS_TOL, "the mecanum drive needs every axis along +y so that positive speeds drive forward")
    if off:
        return None, off
    if len(wheels) != 4:
        return None, f"{len(wheels)} motorised wheels with turned friction (rollers); a mecanum drive has four"
    plain = [w["motor"] for w, t in zip(wheels, turns) if t is None]
    if plain:
        return None, (f"wheel {plain[0]!r} has no asymmetric friction turned by a ContactProperties' frictionRotation "
                      "(its rollers), as the other wheels have")
    centres = [w["centre"] for w in wheels]
    lx, ly = abs(float(centres[0][0])), abs(float(centres[0][1]))
    slots = {}
    for w, c, t in zip(wheels, centres, turns):
        if lx <= TOL or ly <= TOL or abs(abs(c[0]) - lx) > TOL or abs(abs(c[1]) - ly) > TOL:
            where = ", ".join(f"{o['motor']!r} at ({o['centre'][0]:g}, {o['centre'][1]:g})" for o in wheels)
            return None, (f"the wheels ({where}) are not at the corners (±lx, ±ly) of a rectangle centred under the "
                          "robot's origin")
        slots[("front" if c[0] > 0 else "rear", "left" if c[1] > 0 else "right")] = (w, t)
    if len(slots) != 4:
        return None, "two wheels are at the same corner of the robot"
    r0, why = _radius(wheels, conv)
    if r0 is None:
        return None, why
    order = [("front", "left"), ("front", "right"), ("rear", "left"), ("rear", "right")]
    rollers = [-1 if slots[k][1] > 0 else 1 for k in order]      # the youBot's: friction turned by +π/4 ↔ s = -1
    fl, fr, rl, rr = rollers
    if fl != rr or fr != rl or fl == fr:
        return None, (f"the rollers (friction turned by {', '.join(f'{slots[k][1]:g}' for k in order)} on the front "
                      "left, front right, rear left and rear right wheels) are not alike on diagonal wheels and "
                      "opposite on the front two")
    if fl == 1 and abs(lx - ly) <= TOL:
        return None, "the rollers all point at the robot's centre (lx = ly): such wheels cannot turn it"
    odd = [(w, t) for w, t in zip(wheels, turns) if t is not None and abs(abs(t) - MECANUM_ANGLE) > 0.01]
    if odd:
        w, t = odd[0]
        conv.warn(w["node"], f"mecanum wheel {w['motor']!r}: its friction is turned by {t:g} rad; the kinematic "
                             "drive takes its rollers at 45°")
    out: dict = {"wheel_radius": r0, "lx": lx, "ly": ly, **_wheel_speeds(wheels, conv),
                 "rollers": rollers}
    for (end_, side), key in zip(order, ("front_left", "front_right", "rear_left", "rear_right")):
        out[f"{key}_motor"] = slots[(end_, side)][0]["motor"]
    return out, ""


# ---------------------------------------------------------------- omni wheels (Webots' omni_wheels how-to, a Robotino)

ROLLER_COS = 0.1
"""|cos| between a passive hinge's axis and its wheel's below which the hinge is a roller (across the
wheel's axis; Webots' omni_wheels how-to has its rollers exactly across, 0)."""


GROUND_TOL = 1e-3
"""m: how far apart the omni wheels' lowest points may be and still stand on one ground plane."""


def omni_wheels(wheels: list[dict], conv, up: Up = UP_Z) -> bool:
    """Whether a robot's motorised hinges make an omni-wheel robot: three or more wheels, none
    steering, every axis horizontal in the robot's frame (perpendicular to its z) and not all along
    one line (parallel or opposite), each a wheel (something round at its end point turning about
    its axis: :func:`rolls_about_its_axis`) and their lowest points at one height (within
    GROUND_TOL): they stand on one ground. A two-wheel, skid-steer or mecanum robot has its axes
    along one line and a car steers, so none of them is one; mirrored axes (one side's wheels about
    -y) stay with the differential drive, which says why it cannot drive them; an arm's hinge beside
    two wheels is no wheel (nothing round turns about its axis, or it is not on the ground), and the
    differential drive takes the two. ``up``: the robot's up axis (2 its z, 1 its y: a y-up robot)."""
    if len(wheels) < 3 or any(w["steers"] for w in wheels):
        return False
    axes = [np.asarray(w["axis"], dtype=np.float64) / np.linalg.norm(w["axis"]) for w in wheels]
    if any(abs(a[up]) > AXIS_TOL for a in axes):
        return False
    if not any(abs(float(np.dot(a, axes[0]))) < 1.0 - TOL for a in axes[1:]):
        return False
    if not all(rolls_about_its_axis(w, conv) for w in wheels):
        return False
    bottoms = []
    for w in wheels:
        radius = wheel_radius(w["end"], conv)
        if radius is None:
            return False
        bottoms.append(float(_on_axis(w, conv)[up]) - radius)
    return max(bottoms) - min(bottoms) <= GROUND_TOL


def wheel_bottom(wheels: list[dict], conv, up: Up = UP_Z) -> float | None:
    """The drive's ``wheel_bottom``: the lowest bottom, along the robot's z (``up``: 1 along its y, a
    robot built y-up in a NUE world), of its wheels that do not
    steer (each one's round part's centre, where it is as the world loads, less its radius), or None
    without one whose radius is known. The robot settles on the ground with it at load. ``wheels``:
    motorised hinges, or a car's free wheels (no ``steers``: their rolling axes). A wheel whose larger round
    part turns with its hinge past its end point's own shapes (:func:`rolling_part`, as :func:`_rolled`
    takes it for the drive's radius) reaches down that part's bottom."""
    bottoms = []
    for w in wheels:
        radius = None if w.get("steers") else wheel_radius(w["end"], conv)
        if radius is not None:
            centre = round_centre(w, conv)
            bottom = float((w["centre"] if centre is None else centre)[up]) - radius
            rolled = rolling_part(w, conv) if "anchor" in w and "axis" in w else None
            if rolled is not None and not rolled[2] and rolled[0] > radius:
                bottom = float(rolled[1][up]) - rolled[0]
            bottoms.append(bottom)
    return min(bottoms) if bottoms else None


def axle_bottoms(car: dict, wheels: list[dict], conv, up: Up = UP_Z) -> dict[str, float]:
    """A car's wheels' lowest bottom (:func:`wheel_bottom`'s) on each axle, "rear" and "front", of
    ``wheels`` (its driven or its free ones), each wheel on the axle nearer its centre along x."""
    rear_x = float(car.get("rear_axle_offset", 0.0))
    middle = rear_x + 0.5 * float(car["wheelbase"])
    out: dict[str, float] = {}
    for w in wheels:
        bottom = wheel_bottom([w], conv, up)
        if bottom is not None:
            axle = "front" if float(w["centre"][0]) > middle else "rear"
            out[axle] = min(out.get(axle, bottom), bottom)
    return out


def _on_axis(w: dict, conv) -> np.ndarray:
    """Where a wheel rolls on the ground (above it): the centre of its round part (:func:`round_centre`,
    else its end point's origin) taken onto its axis's line, in the robot's frame."""
    axis = np.asarray(w["axis"], dtype=np.float64) / np.linalg.norm(w["axis"])
    anchor = np.asarray(w["anchor"], dtype=np.float64)
    centre = round_centre(w, conv)
    centre = np.asarray(w["centre"], dtype=np.float64) if centre is None else centre
    return anchor + axis * float(np.dot(centre - anchor, axis))


def round_centre(w: dict, conv) -> np.ndarray | None:
    """The centre, in the robot's frame, of the first cylinder, capsule or sphere of a wheel's end
    point (its boundingObject first, as :func:`wheel_radius` looks), or None."""
    end = conv.slotted(w["end"])
    if end is None:
        return None

    return _first_round_part(conv, end, w["frame"],
                             lambda kind, nf, frame: np.asarray(frame.translation, dtype=np.float64))


def _first_round_part(conv, end: Node, frame, leaf):
    """``leaf(type, its fields, its frame)`` of the first cylinder, capsule or sphere of a wheel's end
    point (placed at ``frame``), its boundingObject first, else its children; None when it has none. A
    leaf's answer ends the search, False included."""
    def find(node: Node | None, frame):
        if node is None:
            return None
        conv.walk(node)
        nf = conv.fields(node)
        if node.type in ("Cylinder", "Sphere", "Capsule"):
            return leaf(node.type, nf, frame)
        if node.type == "Shape":
            return find(nf.node_("geometry"), frame)
        if node.type in ("Pose", "Transform", "Group", "Solid"):
            inner = frame if node.type == "Group" else conv.child_frame(node, frame)
            for child in nf.nodes("children"):
                r = find(child, inner)
                if r is not None:
                    return r
        return None

    found = find(conv.fields(end).node_("boundingObject"), conv.child_frame(end, frame))
    return found if found is not None else find(end, frame)


def has_rollers(w: dict, conv) -> bool:
    """Whether a wheel shows its rollers: two or more HingeJoints without a motor in its end point
    whose axes lie across the wheel's (Webots' omni_wheels how-to: passive rollers that only its
    physics turns), or an asymmetric friction on its contact material (a ContactProperties'
    two ``coulombFriction`` values for it, as a Robotino's or a youBot's wheels have)."""
    end = conv.slotted(w["end"])
    if end is None:
        return False
    axis = np.asarray(w["axis"], dtype=np.float64) / np.linalg.norm(w["axis"])
    count = 0

    def walk(node: Node | None, frame) -> None:
        nonlocal count
        if node is None:
            return
        conv.walk(node)
        nf = conv.fields(node)
        if node.type == "HingeJoint":
            if not any(d.type == "RotationalMotor" for d in nf.nodes("device")):
                params = nf.node_("jointParameters")
                a = conv.fields(params).vec("axis", (1.0, 0.0, 0.0)) if params is not None else (1.0, 0.0, 0.0)
                turned = np.asarray(frame.rotation, dtype=np.float64) @ np.asarray(a, dtype=np.float64)
                n = float(np.linalg.norm(turned))
                if n > 0.0 and abs(float(np.dot(turned, axis))) <= ROLLER_COS * n:
                    count += 1
            return
        if node.type in ("Pose", "Transform", "Group", "Solid"):
            inner = frame if node.type == "Group" else conv.child_frame(node, frame)
            for child in nf.nodes("children"):
                walk(child, inner)

    walk(end, w["frame"])
    if count >= 2:
        return True
    if end.type != "Solid":
        return False
    material = conv.fields(end).string("contactMaterial", "default")
    for m1, m2, friction, _rotation in contact_properties(conv):
        if material not in (m1, m2):
            continue
        pair = friction[:2] if material == m1 and len(friction) >= 2 else friction[-2:] if len(friction) in (2, 4) else ()
        return len(pair) == 2 and pair[0] != pair[1]
    return False


def omni_drive(wheels: list[dict], conv, up: Up = UP_Z) -> tuple[dict | None, str]:
    """The kinematic omni drive of a robot's wheels (:func:`omni_wheels` said they make one), or
    (None, the sentence why not). Each wheel rolls on the ground where its round part is: the centre
    of its cylinder (or sphere) taken onto its axis's line, else the end point's origin; its radius
    that cylinder's. The wheels' places and axes are the robot's x and y; a y-up robot's (``up`` 1)
    along its x and its left, y × x = -z (its drive's ``forward`` its x, (1, 0, 0))."""
    frame = None if up == 2 else drive_axes((1.0, 0.0, 0.0), up)
    out = []
    for w in wheels:
        radius = wheel_radius(w["end"], conv)
        if radius is None:
            return None, f"wheel {w['motor']!r}: its end point has no cylinder or sphere to take the wheel radius from"
        axis = np.asarray(w["axis"], dtype=np.float64) / np.linalg.norm(w["axis"])
        on_axis = _on_axis(w, conv)
        if frame is not None:
            axis, on_axis = frame @ axis, frame @ on_axis
        out.append({"motor": w["motor"], "position": [float(on_axis[0]), float(on_axis[1])],
                    "axis": [float(axis[0]), float(axis[1])], "radius": float(radius)})
    rows = []
    for o in out:
        (ax, ay), (px, py) = o["axis"], o["position"]
        rows.append((ay, -ax, ay * -py - ax * px))
    s = np.linalg.svd(np.array(rows), compute_uv=False)
    if s[2] <= 1e-9 * max(float(s[0]), 1e-300):
        where = ", ".join(f"{o['motor']!r} at ({o['position'][0]:g}, {o['position'][1]:g}) about "
                          f"({o['axis'][0]:g}, {o['axis'][1]:g})" for o in out)
        return None, (f"the wheels ({where}) cannot move the robot in every direction: their rolling leaves a twist "
                      "free")
    drive: dict = {"wheels": out, **_wheel_speeds(wheels, conv)}
    if frame is not None:
        drive["forward"] = [1.0, 0.0, 0.0]
    return drive, ""


def track_drive(tracks: list[dict], conv, up: Up = UP_Z) -> tuple[dict | None, str]:
    """Two ``Track``s, a left and a right belt each driven by its LinearMotor, as the kinematic
    ``differential_drive`` they are (v = (vl + vr)/2, w = (vr - vl)/W, W between the belts' centre
    lines), or (None, the sentence saying why not). A belt at v m/s is a wheel of radius 1 m at
    v rad/s (``wheel_radius`` 1): the motor's position (m) is that wheel's angle, its maxVelocity
    (m/s) the wheel's. A positive velocity moves the robot along the Track's own +x (Webots' track
    sample drives forward so). ``tracks``: {"motor", "max_velocity", "node", "forward" (the Track's
    x in the robot's frame), "origin" (the Track's origin there)}; ``up`` as :func:`drive_frame`'s.
    The robot turns about the midpoint of the two tracks' origins."""
    if len(tracks) != 2:
        return None, f"{len(tracks)} Tracks with a motor; a tracked drive needs two, a left and a right one"
    axes = [np.asarray(t["forward"], dtype=np.float64) / np.linalg.norm(t["forward"]) for t in tracks]
    for t, a in zip(tracks, axes):
        if abs(a[up]) > AXIS_TOL:
            return None, (f"the belt of Track motor {t['motor']!r} runs along {np.round(a, 6).tolist()}, not "
                          f"horizontal in the robot's frame (perpendicular to its {'xyz'[up]})")
    if np.linalg.norm(axes[1] - axes[0]) > AXIS_TOL:
        return None, (f"the belts run along {np.round(axes[0], 6).tolist()} and {np.round(axes[1], 6).tolist()}, "
                      "not one direction (a tracked drive needs parallel belts moving the same way)")
    forward = axes[0].copy()
    forward[up] = 0.0
    frame = drive_axes(forward, up)
    places = [frame @ np.asarray(t["origin"], dtype=np.float64) for t in tracks]
    if abs(places[0][1] - places[1][1]) <= TOL:
        return None, "both Tracks are on one centre line (a tracked drive needs a left and a right belt)"
    (left, pl), (right, pr) = sorted(zip(tracks, places), key=lambda tp: -tp[1][1])
    drive = _centred({"wheel_radius": 1.0, "axle_length": float(pl[1] - pr[1]), **_wheel_speeds(tracks, conv),
                      "left_motor": left["motor"], "right_motor": right["motor"]},
                     float(pl[0] + pr[0]) / 2.0, float(pl[1] + pr[1]) / 2.0)
    along_x = up == 2 and float(np.linalg.norm(forward - np.array([1.0, 0.0, 0.0]))) <= AXIS_TOL
    return _framed(drive, "", None if along_x else frame)


def belt_bottom(track_frame, wheels: list[tuple[float, float, float]], up: Up = UP_Z) -> float | None:
    """A Track's lowest point along the robot's ``up`` axis: the lowest of its TrackWheels' circles,
    each (x, y, radius) in the Track's frame (a TrackWheel sits at (x, 0, y) there and turns in the
    Track's x-z plane, the belt around it); None without a TrackWheel. The belt's own thickness is
    not counted (Webots draws the belt's pads around the wheels)."""
    if not wheels:
        return None
    r = np.asarray(track_frame.rotation, dtype=np.float64)
    reach = track_frame.scale * math.hypot(float(r[up, 0]), float(r[up, 2]))   # a unit circle's half-height
    return min(float(track_frame.apply((x, 0.0, y))[up]) - radius * reach for x, y, radius in wheels)


# ---------------------------------------------------------------- steered wheels (a PR2's casters, a rover's corners)

def steered_drive(groups: list[tuple[dict | None, list[dict]]], steer_positions: dict[str, float], conv,
                  up: Up = UP_Z) -> tuple[dict | None, str]:
    """The kinematic steered-wheel drive of a robot whose driven wheels ride steering hinges of their
    own, or (None, the sentence why not). ``groups``: each steering hinge (None: the wheels that ride
    none, which keep their heading) with the driven wheels it turns; ``steer_positions``: each steering
    motor's position as the world loads. A steered wheel touches the ground under its steering axis
    (the hinge's anchor: a caster's two wheels, beside it, are taken there); an unsteered one where its
    round part is on its axis. Its heading at steering position 0 is where a positive speed rolls it,
    axis × up, less the hinge's turn as loaded; a hinge about up turns it left as its position grows
    (``steer_sign`` 1), one about down right (-1). ``up``: the robot's up axis (2 its z; 1 its y, a
    robot built y-up, whose places and headings are taken along its x and its left, y × x = -z, its
    drive's ``forward`` its x, (1, 0, 0), as :func:`omni_drive` takes them). A wheel marked ``"free"``
    (a tricycle's steered front wheel) becomes a wheel without motor; without an ``axis`` (no hinge of
    its own, its round part on the steering joint's end point) it rolls along the robot's forward."""
    frame = None if up == 2 else drive_axes((1.0, 0.0, 0.0), up)
    out = []
    rolling = []
    for steering, riding in groups:
        for w in riding:
            radius = wheel_radius(w["end"], conv)
            if radius is None:
                return None, (f"wheel {w.get('motor') or 'free'!r}: its end point has no cylinder or sphere to take "
                              "the wheel radius from")
            # a free wheel (a tricycle's front wheel, "free": True) with no hinge of its own rolls along forward
            axis = np.asarray(w["axis"] if w.get("axis") is not None else
                              (frame.T @ np.array([0.0, 1.0, 0.0]) if frame is not None else [0.0, 1.0, 0.0]),
                              dtype=np.float64)
            if frame is not None:
                axis = frame @ axis
            if abs(float(axis[2])) > AXIS_TOL * float(np.linalg.norm(axis)):
                return None, (f"wheel axis of motor {w['motor']!r} is {np.round(w['axis'], 6).tolist()}, not "
                              f"horizontal in the robot's frame (perpendicular to its {'xyz'[up]}): a steered wheel "
                              "rolls about a horizontal axis")
            wheel: dict = {"radius": float(radius)} if w.get("free") else {"motor": w["motor"], "radius": float(radius)}
            heading = math.atan2(-float(axis[0]), float(axis[1]))      # axis × up: (a_y, -a_x)
            if steering is None:
                at = _on_axis(w, conv)
            else:
                at = np.asarray(steering["anchor"], dtype=np.float64)
                sign = 1 if float(steering["axis"][up]) > 0.0 else -1
                heading -= sign * steer_positions.get(steering["motor"], 0.0)
                wheel["steer"] = steering["motor"]
                if sign < 0:
                    wheel["steer_sign"] = -1
            if frame is not None:
                at = frame @ at
            wheel["position"] = [float(at[0]), float(at[1])]
            if heading != 0.0:
                wheel["heading"] = math.remainder(heading, 2.0 * math.pi)
            out.append(wheel)
            if not w.get("free"):
                rolling.append(w)
    if len({tuple(w["position"]) for w in out}) < 2:
        return None, "the wheels all stand at one place"
    drive: dict = {"wheels": out, **_wheel_speeds(rolling, conv)}
    if frame is not None:
        drive["forward"] = [1.0, 0.0, 0.0]
    return drive, ""


def one_motor_axle(w: dict, free: list[dict], conv, up: Up = UP_Z) -> tuple[dict | None, str]:
    """The kinematic ``steered_drive`` of a robot whose only motorised hinge carries the wheels of both its
    sides (Tinkerbots' vision_car: one motor block whose hinge carries an axle and a wheel either side), or
    (None, the sentence why not). The hinge's axis is horizontal in the robot's frame (within
    WHEEL_AXES_TOL); its largest round parts turning about it (:func:`rolling_parts`, of one radius) stand at
    two places along it or more: turned together, they roll their midpoint at r·ω along axis × up and turn
    the robot nowhere, so the drive's one driven wheel stands there, heading 0 (the drive's forward that
    rolling direction). The robot's free hinges (no motor) whose round parts turn about their horizontal
    axes and meet the ground with them (bottoms within GROUND_TOL) are its free wheels, each where its round
    part is on its axis, heading along its rolling direction (0 or pi when within WHEEL_AXES_TOL of either: its
    axis taken parallel to the driven one, as a two-wheel drive's are); one of them at least off the driven axle's
    line, so that the wheels leave the robot one line of motion (straight along forward)."""
    axis = np.asarray(w["axis"], dtype=np.float64) / np.linalg.norm(w["axis"])
    if abs(float(axis[up])) > WHEEL_AXES_TOL:
        return None, (f"its axis {np.round(axis, 6).tolist()} is not horizontal in the robot's frame (perpendicular "
                      f"to its {'xyz'[up]})")
    parts = rolling_parts(w, conv)
    radius = max((p[0] for p in parts), default=0.0)
    anchor = np.asarray(w["anchor"], dtype=np.float64)
    along = sorted(float(np.dot(p[1] - anchor, axis)) for p in parts if p[0] >= radius * (1.0 - TOL))
    if radius <= 0.0 or along[-1] - along[0] <= TOL:
        return None, "its end point carries no two wheels at two places along its axis"
    u = up_vector(up)
    rolling = np.cross(axis, u)
    rolling[up] = 0.0
    frame = drive_axes(rolling, up)
    driven = frame @ (anchor + axis * (along[0] + along[-1]) / 2.0)
    bottom = float(np.dot(anchor + axis * along[0], u)) - radius
    wheels: list[dict] = [{"motor": w["motor"], "radius": radius, "position": [float(driven[0]), float(driven[1])]}]
    for f in free:
        fa = np.asarray(f["axis"], dtype=np.float64) / np.linalg.norm(f["axis"])
        part = rolling_part({**f, "axis": fa}, conv) if abs(float(fa[up])) <= WHEEL_AXES_TOL else None
        if part is None or abs(float(np.dot(part[1], u)) - part[0] - bottom) > GROUND_TOL:
            continue
        at = frame @ (f["anchor"] + fa * float(np.dot(part[1] - f["anchor"], fa)))
        a = frame @ fa
        heading = math.atan2(-float(a[0]), float(a[1]))         # axis × up: (a_y, -a_x)
        if abs(math.remainder(heading, math.pi)) <= WHEEL_AXES_TOL:    # parallel to the axle, as a drive's wheels
            heading = math.pi * round(heading / math.pi)
        wheels.append({"radius": part[0], "position": [float(at[0]), float(at[1])],
                       **({"heading": math.remainder(heading, 2.0 * math.pi)} if heading else {})})
    if not any(abs(o["position"][0] - wheels[0]["position"][0]) > TOL for o in wheels[1:]):
        return None, ("no free wheel meets the ground off its wheels' axle (its two wheels alone stand on one line: "
                      "nothing keeps the robot from tipping or turning)")
    drive: dict = {"wheels": wheels, "max_wheel_speed": float(w["max_velocity"]),
                   "forward": [float(v) for v in frame[0, :2 if frame[2, 2] == 1.0 else 3]]}
    return drive, ""
