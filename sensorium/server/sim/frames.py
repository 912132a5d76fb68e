"""The world's ENU view (x east, y north, z up) the gym helpers and the sweep's summary rows work in.

A world in Webots' NUE convention (``world_info: {coordinate_system: NUE}``: x north, y up, z east)
is simulated in an ENU view of itself (the drives, contact and terrains: ``motion._TO_ENU``). The
helpers of :mod:`sensorium.gym` -- ``info["pose"]``, ``random_start``, ``clearance``, the ready-made
goals and the top-down ``render()`` -- read the same view: planar means the ground plane (normal to
the world's up axis), a pose is (east, north, yaw counter-clockwise about up from east), as REP 103
has it. :func:`enu_axes` turns the simulation's world-to-ENU permutation into the world axes that
are east, north and up, so a helper reads a world vector's ENU components by indexing: exactly
(no arithmetic), and in an ENU world the very values it always read.

A robot's heading is its drive's ``forward`` (:func:`drive_forward`; a robot built like Webots'
``four_wheels`` how-to drives along its own y, a y-up robot in a NUE world along its z or -z), as
the drives take it (sim/motion.py): ``info["pose"]``'s yaw, ``random_start``'s yaw and ``render()``'s
heading line all read :func:`heading`. A drive whose forward is its own x (the default) reads the
rotation's first column, the very values it always read.
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim.motion import _TO_ENU
from sensorium.server.world.poses import axis_angle_matrix, matrix_quaternion

__all__ = ["ENU_AXES", "to_enu", "enu_axes", "drive_forward", "heading", "planar_pose", "horizontal_directions",
           "own_up", "forward_turn", "upright_quaternion"]

ENU_AXES = (0, 1, 2)
"""An ENU world's east, north and up axes: its own x, y, z."""


def to_enu(world: wm.World) -> np.ndarray | None:
    """The simulation's world-to-ENU permutation matrix for the world's ``coordinate_system``
    (ENU = matrix @ world; None in an ENU world)."""
    return _TO_ENU[world.world_info.coordinate_system]


def enu_axes(world: wm.World) -> tuple[int, int, int]:
    """The world axes that are east, north and up (``ENU_AXES`` in an ENU world; in a NUE world
    (2, 0, 1): east is z, north x, up y): the rows of :func:`to_enu`."""
    turn = to_enu(world)
    if turn is None:
        return ENU_AXES
    east, north, up = (int(np.flatnonzero(row)[0]) for row in turn)
    return east, north, up


def drive_forward(robot: wm.Robot) -> np.ndarray | None:
    """The robot's drive's ``forward`` as a unit vector in its own frame, normalised as the drives
    normalise it (sim/motion.py); None when it is its own x (the default) or it has no drive."""
    drive = robot.differential_drive or robot.ackermann_drive or robot.mecanum_drive or robot.omni_drive
    forward = getattr(drive, "forward", None)
    if forward is None or tuple(forward) in ((1.0, 0.0), (1.0, 0.0, 0.0)):
        return None
    f = [float(v) for v in forward] + [0.0] * (3 - len(forward))
    norm = math.hypot(*f)
    return np.array([f[0] / norm, f[1] / norm, f[2] / norm])


def heading(rotation: np.ndarray, forward: np.ndarray | None) -> np.ndarray:
    """The world direction a robot at ``rotation`` ((3, 3), or (m, 3, 3) for m copies) drives along:
    its own x axis (``forward`` None: the rotation's first column, exactly) or ``rotation @ forward``,
    written out element-wise so that one robot and a batch of copies give the same bits."""
    if forward is None:
        return rotation[..., :, 0]
    return rotation[..., :, 0] * forward[0] + rotation[..., :, 1] * forward[1] + rotation[..., :, 2] * forward[2]


def planar_pose(axes: tuple[int, int, int], translation: np.ndarray, rotation: np.ndarray,
                forward: np.ndarray | None = None) -> tuple[float, float, float]:
    """(east, north, yaw) of a pose: its place on the ground plane and its heading (its drive's
    ``forward``, :func:`heading`; its own x axis by default) as an angle counter-clockwise about up
    from east."""
    e, n, _ = axes
    h = heading(rotation, forward)
    return float(translation[e]), float(translation[n]), math.atan2(h[n], h[e])


def horizontal_directions(axes: tuple[int, int, int], count: int) -> np.ndarray:
    """``count`` unit directions (world axes, (count, 3)) spread evenly over the ground plane, the
    first east, counter-clockwise seen from above."""
    angles = np.arange(count) * (2.0 * math.pi / count)
    dirs = np.zeros((count, 3))
    dirs[:, axes[0]] = np.cos(angles)
    dirs[:, axes[1]] = np.sin(angles)
    return dirs


def own_up(axes: tuple[int, int, int], rotation: np.ndarray) -> tuple[int, float]:
    """A robot's own up axis at ``rotation``: which of its own y (1) and z (2) axes is closer to the
    world's up, and its sign (+1 pointing up). Its own x is its forward, never up."""
    up = rotation[axes[2], :]                        # the world's up component of each own axis
    k = 1 if abs(up[1]) > abs(up[2]) else 2
    return k, (1.0 if up[k] >= 0.0 else -1.0)


def _level(axes: tuple[int, int, int], rotation: np.ndarray) -> np.ndarray:
    """Own frame -> a frame on level ground (ENU axes) with the robot's own x east: its up axis
    (:func:`own_up`) up, the third right-handed; the identity for a z-up robot."""
    k, s = own_up(axes, rotation)
    level = np.zeros((3, 3))
    level[0, 0] = 1.0
    level[2, k] = s
    level[1, 3 - k] = s if k == 2 else -s
    return level


def forward_turn(axes: tuple[int, int, int], rotation: np.ndarray, forward: np.ndarray | None) -> float:
    """The angle about up from the robot's own x axis to its drive's ``forward`` once it stands
    upright (:func:`upright_quaternion`; in an ENU world as ``random_start`` stands it, z up): a pose
    whose own x is at ``yaw - forward_turn`` heads at ``yaw``. 0 for ``forward`` None (its own x)."""
    if forward is None:
        return 0.0
    level = np.eye(3) if axes == ENU_AXES else _level(axes, rotation)
    f = level @ forward
    return math.atan2(f[1], f[0])


def upright_quaternion(axes: tuple[int, int, int], rotation: np.ndarray, yaw: float) -> tuple[float, float, float, float]:
    """The rotation (a quaternion, x y z w) of a robot whose pose has ``rotation`` turned upright
    and to ``yaw`` (counter-clockwise about up from east): its own x axis level at that heading
    (:func:`forward_turn` takes a drive's other forward there), and whichever of its own y and z
    axes is closer to the world's up (its up axis) along the world's up -- a NUE robot built y-up
    (Webots before R2022a) and one built z-up both stand."""
    level = _level(axes, rotation)
    turned = axis_angle_matrix((0.0, 0.0, 1.0), yaw) @ level      # in ENU axes
    world = np.empty((3, 3))
    world[list(axes), :] = turned                                  # back to the world's axes (exact)
    return matrix_quaternion(world)
