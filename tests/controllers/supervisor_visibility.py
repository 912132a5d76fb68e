"""A Webots-style supervisor hiding the crate from its camera and lidar (tests/test_supervisor_visibility.py
on tests/worlds/supervisor_visibility.yaml): the centre beam and the centre pixel's red see the wall behind
it, the other camera still the red crate; shown again, the crate is back; a 'from' that is no camera,
lidar, range finder or Viewpoint is Webots' line. The same lines as tests/c/supervisor_visibility.c."""

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
lidar, cam, other = robot.getDevice("lidar"), robot.getDevice("cam"), robot.getDevice("other")
for device in (lidar, cam, other):
    device.enable(step)


def red(camera) -> int:
    return camera.imageGetRed(camera.getImage(), camera.getWidth(), 4, 3)


def centre() -> str:
    return f"{round(lidar.getRangeImage()[2])} {red(cam)}"


robot.step(step)
print("before", centre())
crate = robot.getFromDef("CRATE")
for device in (cam, lidar):
    crate.setVisibility(robot.getFromDevice(device), False)
robot.step(step)
print("hidden", centre())
print("other", red(other))
for device in (cam, lidar):
    crate.setVisibility(robot.getFromDevice(device), True)
robot.step(step)
print("again", centre())
crate.setVisibility(robot.getFromDef("CRATE"), False)          # the crate is no device: Webots' line
print("bad from")
