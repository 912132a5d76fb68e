"""Lights carried by robots in the batched simulation: each copy's at that copy's robot pose.

The single simulation's light arrays (``lights_from_models(scene.sensor_lights())``) list the world's
lights and the solids' (fixed here: the batched simulation never moves a solid), then every robot's
lights that are on, robot after robot, each placed by ``place_light(model, robot pose ∘ identity)``.
Copy c's arrays are the same list with copy c's robot poses: the fixed lights shared by every copy,
the carried ones placed per copy with the same numpy calls on stacks (``Pose.compose`` with the
identity, then ``location @ R.T + t`` and ``direction @ R.T``, each a matmul of the same shapes), so
the bits are the single simulation's. A light riding a joint (``on_joint``) is placed on its copy's
link: its robot's pose ∘ the joint's displacement there (batched_joints.py's ``link_rot`` /
``link_pos``, Pose.compose's products stacked), then as above; a spot light's light-sensor axis there is
turned by the displacement alone (scene.py's ``link_aimed``).

A robot's LEDs' lights (``robot_led_lights``: in the robot's frame, listed after its own lights, as
the single scene lists them) are carried the same way and are on in a copy exactly while that copy's
LED is, in its colour (``BatchedSimulation.set_led``): the copies whose LEDs are alike (:meth:`CarriedLights.key`)
share the single simulation's arrays of the lights that are on, light sensors' rows grouped by it.

Light sensors take :class:`RowLights`: per sensor row, its copy's positions and directions (the
math of devices/light.py broadcasts them as it broadcasts shared ones), a spot light's axis as the
single simulation's ``Scene.sensor_lights`` gives it (``light_sensor_direction``, when set, stays in
world axes). Cameras shade a copy's rows with that copy's
:class:`~sensorium.server.devices.light.LightArrays` (:meth:`CarriedLights.arrays`), built from the
same ``Light`` values as the single camera's (``Scene.world_lights``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import light as light_math
from sensorium.server.sim.batched_joints import compose_stacked
from sensorium.server.sim.scene import for_light_sensors, light_from_model, link_aimed, place_light, robot_led_lights
from sensorium.server.world.geometry import Pose

__all__ = ["CarriedLights", "RowLights", "copy_world_lights", "has_carried_lights"]

_EYE = np.eye(3)
_ZERO = np.zeros(3)


@dataclass(frozen=True)
class RowLights(light_math.LightArrays):
    """:class:`~sensorium.server.devices.light.LightArrays` with ``position`` and ``direction`` per row
    (S, n, 3): each sensor's copy's lights, as devices/light.py's ``light_terms``,
    ``occlusion_segments_many`` and ``irradiance_from_terms`` read them. Made from the shared arrays
    (validated and normalised there) and directions normalised per row by :meth:`CarriedLights.rows`,
    so nothing is checked or reshaped again here."""

    def __post_init__(self) -> None:
        pass


def has_carried_lights(robot: wm.Robot) -> bool:
    """Whether a robot carries lights: its own or its LEDs'."""
    return bool(robot.lights) or any(getattr(d, "lights", None) for d in robot.devices)


class CarriedLights:
    """The world's fixed lights (shared) and its robots' lights that are on (placed per copy), each
    robot's own lights then its LEDs' (``robot_led_lights``, in the robot's frame), which are on in a
    copy exactly while that copy's LED is, in its colour (:meth:`switch`)."""

    def __init__(self, world: wm.World, fixed_models: list, copies: int = 1):
        on = [m for m in fixed_models if m.on]
        self._fixed = [light_from_model(m) for m in on]                        # as cameras see them
        sensor_fixed = [light_from_model(for_light_sensors(m)) for m in on]   # as light sensors see them
        carried: list[tuple[int, object]] = []
        switch: list[int] = []           # per carried light: its LED's column, -1 for a robot's own light
        self.leds: dict[tuple[int, str], int] = {}     # (robot slot, LED name) -> its column
        for i, r in enumerate(world.robots):
            own = [(i, m) for m in r.lights if m.on]
            carried += own
            switch += [-1] * len(own)
            for name, models in robot_led_lights(r):
                switch += [len(self.leds)] * len(models)
                self.leds[(i, name)] = len(self.leds)
                carried += [(i, m) for m in models]
        self.switch = np.array(switch, dtype=np.int64)
        self.switched = bool(self.leds)
        # per copy and LED: on, and the colour its lights take (WbLed); none is on before a set
        self.led_on = np.zeros((copies, len(self.leds)), dtype=bool)
        self.led_color = np.zeros((copies, len(self.leds), 3))
        self._groups: dict[bytes, tuple[np.ndarray, light_math.LightArrays, list, np.ndarray]] = {}
        self._carried = [light_from_model(m) for _, m in carried]
        sensor_carried = [light_from_model(for_light_sensors(m)) for _, m in carried]
        self._sensor_carried = sensor_carried
        self._sensor_fixed = sensor_fixed
        self.slots = np.array([i for i, _ in carried], dtype=np.int64)
        self.count = len(carried)
        # the carried lights' fields in their robot's frame: which of them move (Webots: a directional
        # light's direction stays in world axes wherever it is attached; for light sensors, so does a spot
        # light's light_sensor_direction)
        self._located = np.array([hasattr(m, "location") for _, m in carried], dtype=bool)
        self._aimed = np.array([m.type == "SpotLight" for _, m in carried], dtype=bool)
        self._sensor_aimed = np.array([m.type == "SpotLight" and m.light_sensor_direction is None for _, m in carried],
                                      dtype=bool)
        self._local_pos = np.array([lt.position for lt in self._carried], dtype=np.float64).reshape(-1, 3)
        self._local_dir = np.array([lt.direction for lt in self._carried], dtype=np.float64).reshape(-1, 3)
        self._sensor_dir = np.array([lt.direction for lt in sensor_carried], dtype=np.float64).reshape(-1, 3)
        # the light sensors' arrays: constants (poses aside)
        self.shared = light_math.LightArrays.from_lights(sensor_fixed + sensor_carried)
        self.cast_shadows = np.array([bool(m.cast_shadows) for m in on] + [bool(m.cast_shadows) for _, m in carried],
                                     dtype=bool)
        self._oriented = self.shared.kind != light_math.LightKind.POINT
        self._n_fixed = len(self._fixed)
        # the joint each carried light rides (``on_joint``; None: its robot's body), its column once bound
        self._joints = [getattr(m, "on_joint", None) for _, m in carried]
        self._link: np.ndarray | None = None           # per carried light: its joint's column, -1 none
        self._link_rot = self._link_pos = None          # (copies, joints, ...) displacements (batched_joints.py)
        # on a link, a spot light's light-sensor axis turns with the joint (scene.link_aimed)
        self._sensor_turned = np.array([m.type == "SpotLight" and m.light_sensor_direction is not None
                                        and j is not None for (_, m), j in zip(carried, self._joints)], dtype=bool)

    def bind_joints(self, joints) -> None:
        """The copies' joints (:class:`~sensorium.server.sim.batched_joints.BatchedJoints`) whose links
        carry lights: each such light is placed at its robot's pose ∘ its joint's displacement."""
        if any(j is not None for j in self._joints):
            self._link = np.array([-1 if j is None else joints.of(int(i), j) for i, j in zip(self.slots, self._joints)],
                                  dtype=np.int64)
            self._link_rot, self._link_pos = joints.link_rot, joints.link_pos

    # ------------------------------------------------------------------ LEDs
    def switch_led(self, slot: int, name: str, copies: np.ndarray, on: bool, color: tuple[float, float, float]) -> None:
        """LED ``name`` of robot ``slot`` in ``copies`` set: its lights on or off, in ``color``."""
        col = self.leds.get((slot, name))
        if col is None:
            return
        self.led_on[copies, col] = on
        self.led_color[copies, col] = color
        if len(self._groups) > 256:        # a gradual LED can take 16M colours: the cache stays small
            self._groups.clear()

    def _visible(self, copy: int) -> np.ndarray:
        """Which carried lights are on in ``copy``: the robots' own, and the lights of its LEDs that are on."""
        sw = self.switch
        return (sw < 0) | self.led_on[copy, np.maximum(sw, 0)]

    def key(self, copy: int) -> bytes:
        """A copy's LED state (which are on, their colours): copies of one key light alike."""
        return self.led_on[copy].tobytes() + self.led_color[copy].tobytes()

    def group(self, copy: int) -> tuple[np.ndarray, light_math.LightArrays, list, np.ndarray]:
        """The carried lights on in ``copy`` (indices), the light sensors' arrays of them with the fixed
        ones (the single simulation's ``lights_from_models(sensor_lights())``: the same ``Light``
        values in the same order), the camera's ``Light`` values of them and which cast shadows."""
        k = self.key(copy)
        got = self._groups.get(k)
        if got is None:
            sel = np.flatnonzero(self._visible(copy))
            colors = [None if self.switch[j] < 0 else tuple(float(v) for v in self.led_color[copy, self.switch[j]])
                      for j in range(len(self.switch))]
            sensor = [lt if colors[j] is None else replace(lt, color=colors[j])
                      for j, lt in enumerate(self._sensor_carried)]
            camera = [lt if colors[j] is None else replace(lt, color=colors[j]) for j, lt in enumerate(self._carried)]
            arrays = light_math.LightArrays.from_lights(self._sensor_fixed + [sensor[j] for j in sel])
            got = self._groups[k] = (sel, arrays, [camera[j] for j in sel],
                                        self.cast_shadows[self._n_fixed:][sel])
        return got

    def shadows(self, copy: int, fixed: np.ndarray) -> np.ndarray:
        """Which of ``copy``'s lights (fixed ones, then its carried ones that are on) cast shadows."""
        if not self.switched:
            return self.cast_shadows
        return np.concatenate([fixed, self.group(copy)[3]])

    def placed(self, rot: np.ndarray, pos: np.ndarray, copies: np.ndarray, sensors: bool = False
               ) -> tuple[np.ndarray, np.ndarray]:
        """The carried lights' positions and raw (unnormalised) directions in the world of each of
        ``copies`` (k,): (k, m, 3) each, as ``place_light`` gives them for that copy's robot poses
        (``sensors``: the directions as ``for_light_sensors`` then gives them)."""
        local_dir, aimed = (self._sensor_dir, self._sensor_aimed) if sensors else (self._local_dir, self._aimed)
        k = len(copies)
        R = rot[copies[:, None], self.slots[None, :]]                 # (k, m, 3, 3)
        t = pos[copies[:, None], self.slots[None, :]]
        linked = None
        if self._link is not None:    # on a link: robot pose ∘ its displacement (Pose.compose), as the scene frames it
            linked = np.flatnonzero(self._link >= 0)
            cols = self._link[linked]
            Ld = self._link_rot[copies[:, None], cols[None, :]]       # (k, m', 3, 3)
            Lt = self._link_pos[copies[:, None], cols[None, :]]
            R = R.copy()
            t = t.copy()
            R[:, linked], t[:, linked] = compose_stacked(R[:, linked], t[:, linked], Ld, Lt)
        Rc = np.matmul(R, _EYE)                                       # frame ∘ identity (Pose.compose)
        tc = np.matmul(R, _ZERO) + t
        Rt = Rc.transpose(0, 1, 3, 2)
        where = np.broadcast_to(self._local_pos[None, :, None, :], (k, self.count, 1, 3))
        aim = np.broadcast_to(local_dir[None, :, None, :], (k, self.count, 1, 3))
        p = np.matmul(where, Rt)[:, :, 0, :] + tc                     # location @ R.T + t (Pose.apply)
        d = np.matmul(aim, Rt)[:, :, 0, :]                            # direction @ R.T (Pose.apply_dirs)
        p = np.where(self._located[None, :, None], p, self._local_pos[None])
        d = np.where(aimed[None, :, None], d, local_dir[None])
        if sensors and linked is not None and self._sensor_turned.any():
            # its light-sensor axis turned by the joint's displacement only (scene.link_aimed: apply_dirs)
            turned = np.flatnonzero(self._sensor_turned[linked])
            j = linked[turned]
            axis = np.broadcast_to(local_dir[j][None, :, None, :], (k, len(j), 1, 3))
            d[:, j] = np.matmul(axis, Ld[:, turned].transpose(0, 1, 3, 2))[:, :, 0, :]
        return p, d

    def rows(self, rot: np.ndarray, pos: np.ndarray, copies: np.ndarray) -> RowLights:
        """Every light of each row's copy (``copies``: a copy per row), fixed then carried, as light
        sensors see them. With LEDs' lights, the rows' copies share one LED state (:meth:`key`)."""
        S = len(copies)
        p, d = self.placed(rot, pos, copies, sensors=True)
        shared = self.shared
        if self.switched:
            sel, shared, _, _ = self.group(int(copies[0]))
            p, d = p[:, sel], d[:, sel]
            oriented = self._oriented[self._n_fixed:][sel]
        else:
            oriented = self._oriented[self._n_fixed:]
        norm = np.linalg.norm(d, axis=2)                              # LightArrays' normalisation, per row
        d = np.where(oriented[None, :, None], d / np.where(norm > 0.0, norm, 1.0)[:, :, None], d)
        position = np.concatenate([np.broadcast_to(shared.position[None, :self._n_fixed], (S, self._n_fixed, 3)), p],
                                  axis=1)
        direction = np.concatenate([np.broadcast_to(shared.direction[None, :self._n_fixed], (S, self._n_fixed, 3)),
                                    d], axis=1)
        return RowLights(shared.kind, position, direction, shared.attenuation, shared.intensity,
                         shared.ambient_intensity, shared.color, shared.beam_width, shared.cut_off_angle)

    def arrays(self, rot: np.ndarray, pos: np.ndarray, copy: int) -> light_math.LightArrays:
        """Copy ``copy``'s lights as the single simulation's arrays: the same ``Light`` values."""
        p, d = self.placed(rot, pos, np.array([copy], dtype=np.int64))
        if self.switched:
            sel, _, carried, _ = self.group(copy)
        else:
            sel, carried = np.arange(self.count), self._carried
        moved = [replace(lt, position=tuple(float(v) for v in p[0, k]), direction=tuple(float(v) for v in d[0, k]))
                 for k, lt in zip(sel.tolist(), carried)]
        return light_math.LightArrays.from_lights(self._fixed + moved)


def copy_world_lights(sim, copy: int) -> list:
    """``Scene.world_lights`` of copy ``copy`` of a batched simulation: the fixed lights' models, then
    every robot's lights placed at that copy's robot poses (what a task reads, e.g. a light's place)."""
    out = list(sim.scene.world_lights())
    carried = sim.carried
    for slot, robot in enumerate(sim.world.robots):
        models = list(robot.lights)
        for name, lights in robot_led_lights(robot):
            col = carried.leds[(slot, name)]
            on, color = bool(carried.led_on[copy, col]), tuple(float(v) for v in carried.led_color[copy, col])
            models += [m.model_copy(update={"on": on, "color": color}) if on else m for m in lights]
        if models:
            frame = sim.pose(copy, slot).compose(Pose.identity())
            for m in models:
                joint = getattr(m, "on_joint", None)
                if joint is None:
                    out.append(place_light(m, frame))
                    continue
                k = sim.joints.of(slot, joint)     # on a link: where this copy's joint holds it (Scene.world_lights)
                moved = Pose(sim.joints.link_rot[copy, k], sim.joints.link_pos[copy, k])
                out.append(link_aimed(place_light(m, sim.pose(copy, slot).compose(moved).compose(Pose.identity())),
                                      moved))
    return out
