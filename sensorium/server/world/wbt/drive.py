"""Two motorised HingeJoint wheels → the world format's kinematic ``differential_drive``.

The kinematic drive turns the robot about its origin, x forward, wheels on the robot's y axis, and
a positive wheel speed drives forward. A Webots robot maps onto it when it clearly is such a robot:
exactly two motorised hinges, both axes along the robot's +y, both anchors on one line parallel to
y, the two wheels (their end points' origins) on either side of the robot's origin (their midpoint
under it), and wheels of one radius. Anything else gets one
sentence saying which of these failed.
"""

from __future__ import annotations

import numpy as np

from sensorium.server.world.wbt.parser import Node

TOL = 1e-6


def wheel_radius(end: Node | None, conv) -> float | None:
    """Radius of a wheel end point: its boundingObject's (else its visual) cylinder or sphere."""
    if end is None:
        return None
    f = conv.fields(end)

    def find(node: Node | None, scale: float) -> float | None:
        if node is None:
            return None
        conv.walk(node)
        if node.type in ("Cylinder", "Sphere", "Capsule"):
            return conv.fields(node).num("radius", 1.0) * scale
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

    return find(f.node_("boundingObject"), 1.0) or find(end, 1.0)


def differential_drive(wheels: list[dict], conv) -> tuple[dict | None, str]:
    if len(wheels) != 2:
        return None, f"{len(wheels)} motorised hinge joints; a differential drive needs exactly two wheels"
    y = np.array([0.0, 1.0, 0.0])
    for w in wheels:
        a = w["axis"] / np.linalg.norm(w["axis"])
        if np.linalg.norm(a - y) > TOL:
            return None, (f"wheel axis of motor {w['motor']!r} is {np.round(a, 6).tolist()}, not the robot's +y "
                          "(the kinematic drive needs both axes along +y so that positive speeds drive forward)")
    a0, a1 = wheels[0]["anchor"], wheels[1]["anchor"]
    if abs(a0[0] - a1[0]) > TOL or abs(a0[2] - a1[2]) > TOL:
        return None, "the two wheel anchors are not on one axle parallel to the robot's y axis"
    # where the wheels are along the axle: their end points' origins (an anchor may be anywhere on it)
    a0, a1 = wheels[0]["centre"], wheels[1]["centre"]
    if abs(a0[1] - a1[1]) <= TOL:
        return None, "both wheels are at the same place on the axle"
    mid = (a0 + a1) / 2.0
    if abs(mid[0]) > TOL or abs(mid[1]) > TOL:
        return None, (f"the axle midpoint is at x={mid[0]:g}, y={mid[1]:g} in the robot frame, not under the robot's "
                      "origin (the kinematic drive turns about the origin)")
    r0, r1 = (wheel_radius(w["end"], conv) for w in wheels)
    if r0 is None or r1 is None:
        return None, "a wheel end point has no cylinder or sphere to take the wheel radius from"
    if abs(r0 - r1) > TOL * max(r0, r1):
        return None, f"the wheels have different radii ({r0:g} and {r1:g})"
    left, right = (wheels[0], wheels[1]) if a0[1] > a1[1] else (wheels[1], wheels[0])
    speeds = {w["max_velocity"] for w in wheels}
    if len(speeds) > 1:
        conv.warn(wheels[0]["node"], f"wheel motors have different maxVelocity {sorted(speeds)}: using the smaller")
    return {"wheel_radius": r0, "axle_length": float(abs(a0[1] - a1[1])), "max_wheel_speed": min(speeds),
            "left_motor": left["motor"], "right_motor": right["motor"]}, ""
