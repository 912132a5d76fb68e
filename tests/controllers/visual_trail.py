"""Webots' draw-trail pattern (tests/test_supervisor_visuals.py on tests/worlds/visual_trail.wbt), written
as for Webots: a previous trail removed, a Shape holding an IndexedLineSet of N points imported at the
root, then each step the target moved on its circle and its position written into the trail's points and
line indices; the points, indices and a few inserted and removed items read back. Prints the lines
tests/c/visual_trail.c prints."""

import math

from controller import Supervisor

N = 60
STEPS = 50
robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
old = robot.getFromDef("TRAIL")
if old is not None:
    old.remove()
robot.getRoot().getField("children").importMFNodeFromString(
    -1, "DEF TRAIL Shape { appearance Appearance { material Material { diffuseColor 0 1 0 emissiveColor 0 1 0 } } "
        "geometry DEF TRAIL_LINE_SET IndexedLineSet { coord Coordinate { point [ " + ", ".join(["0 0 0"] * N)
        + " ] } coordIndex [ " + " ".join(["0 0 -1"] * N) + " ] } }")
trail = robot.getFromDef("TRAIL")
line_set = robot.getFromDef("TRAIL_LINE_SET")
coord = line_set.getField("coord").getSFNode()
points = coord.getField("point")
indices = line_set.getField("coordIndex")
print("nodes", trail.getTypeName(), line_set.getTypeName(), coord.getTypeName(),
      int(line_set.getParentNode().getId() == trail.getId()), points.getCount(), indices.getCount())
material = trail.getField("appearance").getSFNode().getField("material").getSFNode()
print("material", material.getTypeName(), " ".join(f"{v:g}" for v in material.getField("diffuseColor").getSFColor()),
      f"{material.getField('shininess').getSFFloat():g}")
target = robot.getFromDef("TARGET")
translation = target.getField("translation")
seen = []
for k in range(STEPS):
    a = 0.1 * k
    translation.setSFVec3f([math.cos(a), 3 + math.sin(a), 0.1])
    robot.step(timestep)
    p = target.getPosition()
    seen.append(list(p))
    points.setMFVec3f(k, p)
    if k > 0:                                      # the segment from the point before to this one
        indices.setMFInt32(3 * (k - 1), k - 1)
        indices.setMFInt32(3 * (k - 1) + 1, k)
print("same", int(all(points.getMFVec3f(k) == seen[k] for k in range(STEPS))), int(points.getMFVec3f(STEPS) == [0, 0, 0]))
print("points", " ".join(f"{v:.17g}" for k in range(STEPS) for v in points.getMFVec3f(k)))
print("indices", " ".join(str(indices.getMFInt32(i)) for i in range(3 * STEPS)))
points.insertMFVec3f(0, [9.0, 8.0, 7.0])
points.removeMF(-1)
indices.insertMFInt32(-1, 5)
print("edited", points.getCount(), " ".join(f"{v:g}" for v in points.getMFVec3f(0)),
      " ".join(f"{v:g}" for v in points.getMFVec3f(1)), indices.getCount(), indices.getMFInt32(-1))
points.setMFVec3f(N, [0.0, 0.0, 0.0])            # out of bounds: one line, nothing changed
indices.setMFInt32(0, -7)                        # not an index: one line
print("kept", points.getCount(), indices.getMFInt32(0))
trail.remove()
robot.step(timestep)
print("removed", int(robot.getFromDef("TRAIL") is None), int(robot.getFromDef("TRAIL_LINE_SET") is None))
