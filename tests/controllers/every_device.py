"""Every Webots device class through Webots' Python API (the twin of tests/c/every_device.c: the same
lines, doubles as the 16 hex digits of their bits): the device list in Webots' order with node types
and models, every simulated device's reading after one step, every listed-only device's "no value"
answers, an emitter's packet, waiting for user input, joystick and mouse."""

import math
import struct

from controller import (
    GPS,
    LED,
    Accelerometer,
    Altimeter,
    Brake,
    Compass,
    Connector,
    Display,
    DistanceSensor,
    Emitter,
    Gyro,
    InertialUnit,
    Lidar,
    LightSensor,
    Motor,
    PositionSensor,
    Radar,
    Receiver,
    Robot,
    Skin,
    Speaker,
    TouchSensor,
    VacuumGripper,
)


def h(x):
    """A double as the 16 hex digits of its bits (NaN: 7ff8000000000000)."""
    return f"{struct.unpack('<Q', struct.pack('<d', x))[0]:016x}"


def hs(values):
    return "none" if values is None else ",".join(h(v) for v in values)


def b(x):
    return int(bool(x))


robot = Robot()
for i in range(robot.getNumberOfDevices()):
    dev = robot.getDeviceByIndex(i)
    print("device", i, dev.getName(), dev.getNodeType(), dev.getModel() or "-")

get = robot.getDevice
gps, acc, alt, compass, gyro, imu = get("gps"), get("accelerometer"), get("altimeter"), get("compass"), get("gyro"), get("imu")
ds, lidar, light, encoder, bumper = get("ds"), get("lidar"), get("light"), get("left encoder"), get("bumper")
emitter, receiver, led = get("emitter"), get("receiver"), get("led")
assert isinstance(gps, GPS) and isinstance(acc, Accelerometer) and isinstance(alt, Altimeter)
assert isinstance(compass, Compass) and isinstance(gyro, Gyro) and isinstance(imu, InertialUnit)
assert isinstance(ds, DistanceSensor) and isinstance(lidar, Lidar) and isinstance(light, LightSensor)
assert isinstance(encoder, PositionSensor) and isinstance(bumper, TouchSensor) and isinstance(led, LED)
assert isinstance(emitter, Emitter) and isinstance(receiver, Receiver)
for sensor in (gps, acc, alt, compass, gyro, imu, ds, lidar, light, encoder, bumper, receiver):
    sensor.enable(16)
print("before", hs(gps.getValues()), h(alt.getValue()), hs(imu.getQuaternion()))
print("send", emitter.send("hello"), emitter.send([1.5, -2.0]), emitter.getChannel(), h(emitter.getRange()),
      emitter.getBufferSize())
led.set(2)
robot.step(16)
print("gps", hs(gps.getValues()), h(gps.getSpeed()), hs(gps.getSpeedVector()), gps.getCoordinateSystem())
print("accelerometer", hs(acc.getValues()), len(acc.getLookupTable()))
print("altimeter", h(alt.getValue()))
print("compass", hs(compass.getValues()))
print("gyro", hs(gyro.getValues()))
print("imu", hs(imu.getRollPitchYaw()), hs(imu.getQuaternion()), h(imu.getNoise()))
print("ds", h(ds.getValue()), ds.getType())
print("lidar", hs(lidar.getRangeImage()))
print("light", h(light.getValue()))
print("encoder", h(encoder.getValue()))
print("bumper", h(bumper.getValue()), bumper.getType(), hs(bumper.getValues()))
print("led", led.get())
print("receiver", receiver.getQueueLength(), receiver.getChannel(), h(receiver.getSignalStrength()),
      hs(receiver.getEmitterDirection()))
wheel = get("left wheel motor")
assert isinstance(wheel, Motor)
print("wheel", h(wheel.getMaxVelocity()), wheel.getType(), h(wheel.getTorqueFeedback()))

# listed, not simulated: Webots' "no value", one warning per device
radar, brake, connector, display = get("radar"), get("brake"), get("connector"), get("display")
skin, speaker, gripper = get("skin"), get("speaker"), get("gripper")
linear, arm = get("linear motor"), get("arm motor")
assert isinstance(radar, Radar) and isinstance(brake, Brake) and isinstance(connector, Connector)
assert isinstance(display, Display) and isinstance(skin, Skin) and isinstance(speaker, Speaker)
assert isinstance(gripper, VacuumGripper) and isinstance(linear, Motor) and isinstance(arm, Motor)
radar.enable(16)                    # simulated: no target yet (none before the first value), its world range
print("radar", radar.getNumberOfTargets(), len(radar.getTargets()), b(math.isnan(radar.getMaxRange())))
print("brake", brake.getType(), b(brake.getMotor() is None))
print("connector", connector.getPresence(), b(connector.isLocked()))
display.drawText("hi", 0, 0)
print("display", display.getWidth(), display.getHeight())
print("skin", skin.getBoneCount(), b(skin.getBoneName(0) == ""))
Speaker.playSound(speaker, speaker, "beep.wav", 1.0, 1.0, 0.0, False)   # simulated: no such file, one line
print("speaker", b(speaker.isSpeaking()), b(speaker.getEngine() == "pico"))
gripper.enablePresence(16)          # simulated: no value yet (false), the pump off as the world has it
print("gripper", b(gripper.getPresence()), b(gripper.isOn()))
linear.setVelocity(1.0)
print("linear", linear.getType(), h(linear.getVelocity()))
print("arm", arm.getType(), h(arm.getTargetPosition()))
for name in ("camera", "range finder", "pen"):       # present whatever their state of simulation
    assert get(name) is not None

print("joystick", b(robot.getJoystick().isConnected()), robot.getJoystick().getPressedButton())
robot.getMouse().enable(16)
state = robot.getMouse().getState()
print("mouse", b(math.isnan(state.u)), b(state.left))
print("battery", b(math.isnan(robot.batterySensorGetValue())))
t0 = robot.getTime()
event = robot.waitForUserInputEvent(Robot.EVENT_KEYBOARD | Robot.EVENT_MOUSE_CLICK, 100)
print("wait", event, round((robot.getTime() - t0) * 1000))
