"""A careless controller of the vehicle library on tests/worlds/car_lights.yaml: NaN, infinite and
negative brake intensities, indicator periods of 0, negative, NaN, infinite and 1e-300 s, steering angles
NaN, infinite and 5e-324 rad, cruising speeds NaN and infinite. tests/c/car_hostile.c prints the same
lines (tests/test_vehicle_driver.py checks both)."""

import math

from vehicle import Car, Driver


def led(name):
    return car.getDevice(name).get()


def rear(name):
    return g(car.getDevice(name).getVelocity())


def g(x):
    return format(x, ".17g")


car = Car()
car.setBrakeIntensity(0.25)
car.setBrakeIntensity(math.nan)
print("brake_nan", g(car.getBrakeIntensity()), int(car.getBrakeLights()))
car.setBrakeIntensity(-0.5)
print("brake_negative", g(car.getBrakeIntensity()), int(car.getBrakeLights()), led("brake_lights"))
car.setBrakeIntensity(math.inf)
print("brake_inf", g(car.getBrakeIntensity()), int(car.getBrakeLights()), led("brake_lights"))
for period in (0.0, -1.0, math.nan, math.inf, -math.inf):
    car.setIndicatorPeriod(period)
print("period", g(car.getIndicatorPeriod()))
car.setIndicator(Driver.INDICATOR_RIGHT)
car.setIndicatorPeriod(1e-300)
car.step()
car.step()
print("tiny", g(car.getIndicatorPeriod()), led("right_indicators"), led("left_indicators"))
car.setIndicatorPeriod(0.34)
car.setCruisingSpeed(36)
car.setSteeringAngle(0.2)
for angle in (math.nan, math.inf, -math.inf):
    car.setSteeringAngle(angle)
car.setCruisingSpeed(math.nan)
car.setCruisingSpeed(-math.inf)
print("kept", g(car.getTargetCruisingSpeed()), g(car.getDevice("right_steer").getTargetPosition()),
      rear("right_rear_wheel"), rear("left_rear_wheel"))
car.setSteeringAngle(5e-324)
print("denormal", g(car.getRightSteeringAngle()), g(car.getLeftSteeringAngle()), rear("right_rear_wheel"),
      rear("left_rear_wheel"))
car.setSteeringAngle(math.pi / 2)                 # the front wheels' radii cancel: a differential's shares stay finite
print("right_angle", g(car.getRightSteeringAngle()), g(car.getLeftSteeringAngle()), rear("right_rear_wheel"),
      rear("left_rear_wheel"))
car.setSteeringAngle(5e-324)
for _ in range(20):
    car.step()
print("rolled", g(car.getWheelEncoder(Car.WHEEL_FRONT_RIGHT)), g(car.getWheelEncoder(Car.WHEEL_FRONT_LEFT)),
      int(math.isfinite(car.getCurrentSpeed())))
