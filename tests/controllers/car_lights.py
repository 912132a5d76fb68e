"""The vehicle library's answers from the world and the controller's own commands, as tests/c/car_lights.c
prints them (the same lines), on tests/worlds/car_lights.yaml (tests/test_vehicle_driver.py)."""

from vehicle import Car, Driver


def led(name):
    return car.getDevice(name).get()


def g(x):
    return format(x, ".17g")


car = Car()
print("start", car.getEngineType(), g(car.getIndicatorPeriod()), int(car.getBrakeLights()),
      int(car.getBackwardsLights()), car.getIndicator(), int(car.getHazardFlashers()))
car.setCruisingSpeed(36)
for _ in range(50):
    car.step()
print("rolled", g(car.getWheelEncoder(Car.WHEEL_FRONT_RIGHT)), g(car.getWheelEncoder(Car.WHEEL_FRONT_LEFT)),
      g(car.getWheelSpeed(Car.WHEEL_FRONT_RIGHT)), g(car.getWheelSpeed(Car.WHEEL_FRONT_LEFT)))
car.setBrakeIntensity(1.5)
print("brake", g(car.getBrakeIntensity()), int(car.getBrakeLights()), led("brake_lights"))
car.setBrakeIntensity(0.0)
print("released", g(car.getBrakeIntensity()), int(car.getBrakeLights()), led("brake_lights"))
car.setCruisingSpeed(-5)
print("reverse", int(car.getBackwardsLights()))
car.step()
print("reversing", int(car.getBackwardsLights()), led("backwards_lights"))
car.setCruisingSpeed(0)
car.step()
print("stopped", int(car.getBackwardsLights()), led("backwards_lights"))
car.setIndicatorPeriod(0.064)
car.setIndicator(Driver.INDICATOR_RIGHT)
out = ["blink", g(car.getIndicatorPeriod())]
for _ in range(8):
    t = car.getTime()
    car.step()
    out.append(f"{t:.3f}:{led('right_indicators')}{led('left_indicators')}")
print(*out)
car.setSteeringAngle(0.3)
car.setSteeringAngle(0.25)
kept = car.getIndicator()
car.setSteeringAngle(0.19)
out = ["auto", kept, car.getIndicator()]
car.enableIndicatorAutoDisabling(False)
car.setIndicator(Driver.INDICATOR_LEFT)
car.setSteeringAngle(0.5)
print(*out, car.getIndicator())
car.setIndicator(Driver.INDICATOR_OFF)
car.setHazardFlashers(True)
out = ["hazard", int(car.getHazardFlashers())]
for _ in range(4):
    t = car.getTime()
    car.step()
    out.append(f"{t:.3f}:{led('right_indicators')}{led('left_indicators')}")
print(*out)
car.setDippedBeams(True)
car.setAntifogLights(True)
car.enableLimitedSlipDifferential(False)
print("lights", int(car.getDippedBeams()), int(car.getAntifogLights()), led("front_lights"), led("rear_lights"),
      led("antifog_lights"), flush=True)
