"""A Connector and Brakes from Python (tests/worlds/connector.yaml): presence before and after the
first sampling period, the lock state, and the brakes' joints. The same sequence as
tests/c/connector_reader.c."""

from controller import Brake, Connector, Robot

robot = Robot()
dock, side, socket = robot.getDevice("dock"), robot.getDevice("side"), robot.getDevice("socket")
assert isinstance(dock, Connector) and isinstance(side, Connector)
for c in (dock, side, socket):
    c.enablePresence(32)
print("before", dock.getPresence(), dock.getPresenceSamplingPeriod(), int(dock.isLocked()))
robot.step(16)
print("at16", dock.getPresence(), side.getPresence(), socket.getPresence())
robot.step(16)
print("at32", dock.getPresence(), side.getPresence(), socket.getPresence())
dock.lock()
socket.lock()
print("locked", int(dock.isLocked()), int(socket.isLocked()))
robot.step(16)
dock.unlock()
print("unlocked", int(dock.isLocked()))
dock.disablePresence()
robot.step(32)
print("kept", dock.getPresence(), dock.getPresenceSamplingPeriod())


def name(device) -> str:
    return "none" if device is None else device.getName().replace(" ", "_")


arm, slide, loose = robot.getDevice("arm brake"), robot.getDevice("slide brake"), robot.getDevice("loose brake")
assert isinstance(arm, Brake)
print("arm", arm.getType(), name(arm.getMotor()), name(arm.getPositionSensor()))
print("slide", slide.getType(), name(slide.getMotor()), name(slide.getPositionSensor()))
print("loose", loose.getType(), name(loose.getMotor()), name(loose.getPositionSensor()))
print("back", name(robot.getDevice("arm").getBrake()), name(robot.getDevice("arm sensor").getBrake()),
      name(robot.getDevice("slide").getBrake()))
arm.setDampingConstant(2.0)
arm.setDampingConstant(3.0)
robot.step(16)
