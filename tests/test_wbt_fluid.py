"""A .wbt Fluid (Webots' water or air, which immersed solids float in: its boat and swimming-robot
worlds) was an unknown node: dropped with its shapes, and `validate` failed the world. It is now a
solid of its visual shapes, which cameras, lidars and infra-red sensors see; its boundingObject, the
volume solids are immersed in, is no obstacle: a robot drives through it, bounding rays pass it."""

from __future__ import annotations

from pathlib import Path

import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

HEADER = "#VRML_SIM R2023b utf8\n"
R, V, DT = 0.03, 5.0, 0.032          # wheel radius, wheel speed (rad/s), basic step (s)

WORLD = """WorldInfo { }
Solid { translation 0 0 -1 name "bottom" children [ DEF B Shape { geometry Plane { size 20 20 } } ] boundingObject USE B }
DEF WATER Fluid {
  translation 0 0 -0.5
  children [ DEF W Shape { appearance PBRAppearance { baseColor 0.2 0.4 0.9 } geometry Box { size 20 20 1 } } ]
  boundingObject USE W
  name "water"
  density 1000
  streamVelocity 0.1 0 0
}
Robot {
  translation 0 0 -0.05
  name "r"
  children [
    Pose { translation 0 0 0.05 children [ Shape { geometry Box { size 0.2 0.16 0.1 } } ] }
    HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0 0.1 0.03 }
      device [ RotationalMotor { name "left wheel motor" } ]
      endPoint Solid { translation 0 0.1 0.03 children [ Shape { geometry Cylinder { radius 0.03 height 0.01 } } ] } }
    HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0 -0.1 0.03 }
      device [ RotationalMotor { name "right wheel motor" } ]
      endPoint Solid { translation 0 -0.1 0.03 children [ Shape { geometry Cylinder { radius 0.03 height 0.01 } } ] } }
    DistanceSensor { translation 0.3 0 0.1 rotation 0 1 0 1.5708 name "down" type "generic"
      lookupTable [ 0 0 0, 2 2000 0 ] }
    Lidar { translation 0.3 0 0.1 rotation 0 1 0 1.5708 name "lidar" horizontalResolution 3 fieldOfView 0.02
      numberOfLayers 1 minRange 0.01 maxRange 5 }
  ]
  immersionProperties [ ImmersionProperties { fluidName "water" dragForceCoefficients 0.1 0 0 } ]
}
"""


def test_a_fluid_is_seen_by_visual_rays_and_no_obstacle(tmp_path: Path) -> None:
    p = tmp_path / "w.wbt"
    p.write_text(HEADER + WORLD)
    w = load_world(p)
    assert not w.report.losses
    (said,) = [x for x in w.warnings if "Fluid" in x]
    assert said.split(": ", 1)[1] == (
        "Fluid 'water': buoyancy, drag and its stream are not simulated (no physics); its shapes are kept as a solid "
        "that cameras, lidars and infra-red sensors see, its boundingObject (the fluid's volume) is no obstacle")
    (water,) = [s for s in w.world.solids if s.name == "water"]
    assert water.def_name == "WATER" and [s.seen_by for s in water.shapes] == ["visual"]

    sim = Simulation(w)
    r = sim.robot("r")
    down, lidar = r.device("down"), r.device("lidar")
    down.enable(32)
    lidar.enable(32)
    for m in ("left wheel motor", "right wheel motor"):
        r.motor(m).set_position(float("inf"))
        r.motor(m).set_velocity(V)
    n = 50
    sim.run(n)
    # the robot drove through the water's volume as through air: R·V per second, not stopped by it
    assert r.pose.translation[0] == pytest.approx(R * V * DT * n, abs=1e-9)
    # sensors at z = -0.05 + 0.1 = 0.05 looking down: the generic sensor's bounding ray passes the
    # water to the bottom (1.05 m: 1000 per metre), the lidar's visual ray meets its surface (0.05 m)
    assert down.value == pytest.approx(1050.0, abs=1e-6)
    assert lidar.range_image[0][1] == pytest.approx(0.05, abs=1e-6)
