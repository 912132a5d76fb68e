"""A Webots-style supervisor randomising a PROTO obstacle (tests/test_supervisor_proto_regen.py on
tests/worlds/proto/supervisor_proto_regen.wbt): it sets the obstacle's size, moves it, sets its colour, adds a
post, makes it round and of stone, tries a size the world's limits refuse and resets the simulation, reading its
lidar's centre beam and the fields as it goes. Written as for Webots; prints one line per reading, as
tests/c/supervisor_proto_regen.c does."""

from controller import Supervisor


def g(x: float) -> str:
    return f"{x:.17g}"


def gs(xs) -> str:
    return " ".join(g(x) for x in xs)


robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
lidar = robot.getDevice("lidar")
lidar.enable(timestep)
robot.step(timestep)
obst = robot.getFromDef("OBST")
size = obst.getField("size")
print("before", f"{lidar.getRangeImage()[16]:.8g}", gs(size.getSFVec3f()))
first = obst.getId()
size.setSFVec3f([0.6, 0.4, 0.3])              # the obstacle is built again with that size
robot.step(timestep)
again = robot.getFromDef("OBST")
print("size", f"{lidar.getRangeImage()[16]:.8g}", gs(size.getSFVec3f()), "same", int(again.getId() == first),
      "def", again.getDef())
obst.getField("translation").setSFVec3f([1.5, 0.2, 0.0])
obst.getField("color").setSFColor([0.9, 0.1, 0.2])
robot.step(timestep)
print("moved", gs(obst.getPosition()))
posts = obst.getField("posts")
posts.insertMFFloat(-1, 0.5)
robot.step(timestep)
print("posts", posts.getCount(), g(posts.getMFFloat(0)))
obst.getField("round").setSFBool(True)
robot.step(timestep)
print("round", int(obst.getField("round").getSFBool()), g(posts.getMFFloat(0)))
material = obst.getField("material")
material.setSFString("stone")
robot.step(timestep)
print("material", material.getSFString())
size.setSFVec3f([4e9, 0.6, 0.6])              # beyond the world's limits: one line, nothing changed
robot.step(timestep)
print("refused", gs(size.getSFVec3f()))
robot.simulationReset()
robot.step(timestep)
print("reset", gs(obst.getField("translation").getSFVec3f()), g(size.getSFVec3f()[0]))
