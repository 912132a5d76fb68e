"""An e-puck-like two-wheel robot written as a .wbt world of our own, for the drive tests that judge how the
import reads its wheels (Webots' kinematic rule without Physics, wheels mounted mirrored): its body a
cylinder, each wheel a motorised HingeJoint whose end point's boundingObject is a cylinder of radius R."""

from __future__ import annotations

import math
from pathlib import Path

R, Y, STEP = 0.02, 0.026, 32              # wheel radius, its distance along the axle, basic step (ms)
T = STEP / 1000.0
X0, Y0, H0 = 0.1, -0.2, 0.3               # where the robot starts, its heading


def wheel(name: str, x: float, y: float, axis: str = "0 1 0") -> str:
    """A wheel at (x, y, R) in the robot's frame turning about ``axis``: its motor ``name`` (maxVelocity 20)
    and position sensor ``name sensor``."""
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {axis} anchor {x} {y} {R} }}\n'
            f'  device [ RotationalMotor {{ name "{name}" maxVelocity 20 }} PositionSensor {{ name "{name} sensor" }} ]\n'
            f'  endPoint Solid {{ translation {x} {y} {R} children [ DEF W Pose {{ rotation 1 0 0 1.5708 children [\n'
            f'    Shape {{ geometry Cylinder {{ radius {R} height 0.003 }} }} ] }} ] boundingObject USE W }} }}\n')


def robot_world(path: Path, wheels: str, physics: bool) -> Path:
    """The world at ``path``: robot "bot" at (X0, Y0) heading H0 with ``wheels`` (:func:`wheel`'s), with a
    Physics node or without."""
    path.write_text(f'#VRML_SIM R2023b utf8\nWorldInfo {{ basicTimeStep {STEP} }}\n'
                    f'Robot {{ name "bot" translation {X0} {Y0} 0 rotation 0 0 1 {H0} children [\n'
                    '  DEF BODY Pose { translation 0 0 0.025 children [ Shape { geometry Cylinder { radius 0.037 '
                    'height 0.045 } } ] }\n' + wheels
                    + '] boundingObject USE BODY' + (' physics Physics { }' if physics else '') + ' }\n')
    return path


def heading(rotation) -> float:
    """The yaw of a 3x3 rotation about z."""
    return math.atan2(rotation[1, 0], rotation[0, 0])
