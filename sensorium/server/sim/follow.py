"""The Viewpoint's ``follow`` (Webots' WbViewpoint::updateFollowUp): a Viewpoint that follows a robot
or top-level solid by its name moves after each step as that node's translation moved, so pictures,
movies and the Supervisor's read of its ``position`` keep the followed node where the world framed it.

Webots' default ``followType``, "Tracking Shot", translates the view by the followed node's displacement
(its orientation kept); with ``followSmoothness`` under 0.05 at once, above through a spring, which is
taken here as at once (the view is where the spring comes to rest). The displacement counts from the
node's place in the world file, as Webots starts following at load, so the settling at load moves the
view too; a reset starts it again so (the robot back where the file puts it). A position set from
outside (``moveViewpoint``) follows on from there.
"Mounted Shot" and "Pan and Tilt Shot" are not followed: one line says so and the view stays.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

TRACKING = "Tracking Shot"


@dataclass
class ViewFollow:
    """What the Viewpoint follows and from where: the node (``robot`` index or top-level solid name),
    the view's ``base`` position and the node's translation ``ref`` it counts from, the position
    written last (a different one was set from outside) and the node's translation then (``at``)."""

    robot: int | None
    solid: str | None
    base: tuple[float, float, float]
    ref: tuple[float, float, float]
    last: tuple[float, float, float]
    at: tuple[float, float, float]
    # what the last update saw: the Viewpoint, the node's pose object and the field's list (every move makes a new pose and
    # every write a new list), so a step that moved neither costs two identity tests
    seen: tuple[Any, Any, Any] = field(default=(None, None, None), repr=False, compare=False)

    @classmethod
    def of(cls, sim: Any, warn: Any = None) -> ViewFollow | None:
        """The world's Viewpoint's follow, or None (no ``follow``, or a name no robot or top-level solid
        has: Webots' "invalid Solid name" warning, said through ``warn``)."""
        vp = next((s for s in sim.top_level.scenery if s.type == "Viewpoint"), None)
        name = vp.fields.get("follow", "") if vp is not None else ""
        if not name:
            return None
        kind = vp.fields.get("followType", TRACKING)
        written = sim.loaded.world            # the world file's places, before the settling at load
        index = next((k for k, r in enumerate(written.robots) if r.name == name), None)
        solid = None
        if index is not None:
            start = written.robots[index].pose.translation
        else:
            solid = next((s for s in written.solids if s.name == name), None)
            if solid is None:
                if warn is not None:
                    warn(f"Viewpoint follow {name!r}: no robot or top-level solid has that name; the view stays")
                return None
            start = solid.pose.translation
        if kind != TRACKING:
            if warn is not None:
                warn(f"Viewpoint followType {kind!r} is not followed (only {TRACKING!r}); the view stays")
            return None
        position = tuple(float(c) for c in vp.fields.get("position", (-10.0, 0.0, 0.0)))
        start = tuple(float(c) for c in start)
        return cls(index, None if solid is None else name, position, start, position, start)  # type: ignore[arg-type]

    def update(self, sim: Any) -> None:
        """After a step: the Viewpoint's position moved by the followed node's displacement."""
        vp = next(s for s in sim.top_level.scenery if s.type == "Viewpoint") if self.seen[0] is None else self.seen[0]
        now = (sim.scene.robot_poses[self.robot] if self.robot is not None
               else sim.scene.solid_poses.get(self.solid))
        if now is None:                     # the followed solid was removed: Webots stops following
            return
        field_now = vp.fields.get("position")
        if now is self.seen[1] and field_now is self.seen[2]:
            return
        at = tuple(float(c) for c in now.translation)
        written = tuple(float(c) for c in vp.fields.get("position", (-10.0, 0.0, 0.0)))
        if written != self.last:            # set from outside between steps: follow on from there
            self.base, self.ref = written, self.at  # type: ignore[assignment]
        new = tuple(b + (a - r) for b, a, r in zip(self.base, at, self.ref))
        if new != written:
            if sim.viewpoint_loaded is None:     # as moveViewpoint: a reset puts back the loaded fields
                sim.viewpoint_loaded = dict(vp.fields)
            vp.fields["position"] = list(new)
        self.last, self.at = new, at        # type: ignore[assignment]
        self.seen = (vp, now, vp.fields.get("position"))
