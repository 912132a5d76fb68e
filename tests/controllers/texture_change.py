"""A Webots-style supervisor changing a wall's texture and its camera seeing it (tests/test_supervisor_texture.py,
which writes the world and its images): the ImageTexture found by DEF, its url set, emptied, given again and set to
a file that does not exist (set, with one warning line: the wall is drawn untextured, as in Webots). Written as for Webots; prints the lines
tests/c/texture_change.c prints."""

from controller import Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
camera = robot.getDevice("cam")
camera.enable(timestep)


def centre() -> str:
    image = camera.getImage()
    k = 4 * (4 * camera.getWidth() + 4)
    return f"{image[k + 2]} {image[k + 1]} {image[k]}"


robot.step(timestep)
url = robot.getFromDef("TEX").getField("url")
first = centre()
print("before", url.getMFString(0), first)
url.setMFString(0, "b.png")
robot.step(timestep)
print("set", url.getMFString(0), int(centre() != first))
url.removeMF(0)
robot.step(timestep)
print("removed", url.getCount(), centre())
url.insertMFString(0, "a.png")
robot.step(timestep)
print("inserted", url.getMFString(0), centre())
url.setMFString(0, "nope.png")
robot.step(timestep)
print("missing", url.getMFString(0), centre())
