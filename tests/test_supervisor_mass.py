"""Masses and the Supervisor's getCenterOfMass: the .wbt import reads each Solid's Physics (mass, or
density × the boundingObject's volume; centerOfMass, or the boundingObject's centroid) and the server
answers the mass-weighted centre of a Solid and the Solids inside it, in world coordinates now."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_supervisor import A, Live

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.wbt import wbt_convert

QUARTER = math.pi / 2
WORLD = f"""#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 32 }}
DEF BRICK Solid {{
  translation 0 0 1
  rotation 0 0 1 {QUARTER!r}
  name "brick"
  children [
    DEF WEIGHT Solid {{
      translation 0 0 0.5
      name "weight"
      boundingObject Box {{ size 0.1 0.1 0.1 }}
      physics Physics {{ mass 1 centerOfMass [ 0.2 0 0 ] }}
    }}
  ]
  boundingObject Pose {{ translation 0.1 0 0 children [ Box {{ size 0.1 0.2 0.3 }} ] }}
  physics Physics {{ density 500 }}
}}
DEF CUBE Solid {{
  translation 4 0 1
  name "cube"
  boundingObject IndexedFaceSet {{
    coord Coordinate {{ point [ 0 0 0, 0.2 0 0, 0.2 0.2 0, 0 0.2 0, 0 0 0.2, 0.2 0 0.2, 0.2 0.2 0.2, 0 0.2 0.2 ] }}
    coordIndex [ 0 3 2 1 -1 4 5 6 7 -1 0 1 5 4 -1 1 2 6 5 -1 2 3 7 6 -1 3 0 4 7 -1 ]
  }}
  physics Physics {{ }}
}}
DEF BARE Solid {{ translation 6 0 0 name "bare" }}
DEF BOT Robot {{
  translation 1 2 0
  rotation 0 0 1 {QUARTER!r}
  name "bot"
  supervisor TRUE
  controller "<extern>"
  children [
    DEF BALL Solid {{
      translation 0.5 0 0.1
      name "ball"
      boundingObject Sphere {{ radius 0.1 }}
      physics Physics {{ mass 3 }}
    }}
    DEF PLAIN Solid {{ translation 0 0 0.3 name "plain" }}
    DEF MAST Pose {{ translation 0 0 0.2 }}
    HingeJoint {{
      jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 0.1 0.05 }}
      device [ RotationalMotor {{ name "left wheel" }} ]
      endPoint Solid {{
        translation 0 0.1 0.05
        rotation 1 0 0 {QUARTER!r}
        name "left"
        children [ DEF WHEEL Shape {{ geometry Cylinder {{ radius 0.05 height 0.02 }} }} ]
        boundingObject USE WHEEL
      }}
    }}
    HingeJoint {{
      jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 -0.1 0.05 }}
      device [ RotationalMotor {{ name "right wheel" }} ]
      endPoint Solid {{
        translation 0 -0.1 0.05
        rotation 1 0 0 {QUARTER!r}
        name "right"
        children [ USE WHEEL ]
        boundingObject USE WHEEL
      }}
    }}
  ]
  boundingObject Box {{ size 0.2 0.2 0.1 }}
  physics Physics {{ mass 1 }}
}}
"""


@pytest.fixture()
def world(tmp_path):
    path = tmp_path / "mass.wbt"
    path.write_text(WORLD)
    return path


def _live(path) -> Live:
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "bot"})
    return lv


def bot(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/bot/robot/{item}", args)


def com(lv: Live, name: str) -> list[float]:
    return bot(lv, "get_node_center_of_mass", {"node": bot(lv, "get_from_def", {"name": name})["node"]})["value"]


def placed(lv: Live, name: str, local) -> np.ndarray:
    """A point given in the named node's frame, in the world where the node is now."""
    pose = bot(lv, "get_node_pose", {"node": bot(lv, "get_from_def", {"name": name})["node"]})
    return np.array(pose["position"]) + np.array(pose["orientation"]).reshape(3, 3) @ np.asarray(local, float)


def test_masses_from_mass_density_centre_and_a_closed_mesh(world):
    solids = {s.name: s for s in load_world(world).world.solids}
    brick = solids["brick"]
    assert brick.mass.kg == pytest.approx(500 * 0.1 * 0.2 * 0.3, rel=1e-12)     # density × the Box's volume
    assert brick.mass.center == pytest.approx((0.1, 0.0, 0.0), abs=1e-15)      # the bounding object's centroid
    weight = brick.children[0].mass
    assert (weight.kg, tuple(weight.center)) == (1.0, (0.2, 0.0, 0.0))       # centerOfMass as written
    cube = solids["cube"].mass                                                 # Webots' default density: 1000
    assert cube.kg == pytest.approx(1000 * 0.2 ** 3, rel=1e-12)
    assert cube.center == pytest.approx((0.1, 0.1, 0.1), abs=1e-15)
    assert solids["bare"].mass is None


def test_center_of_mass_of_a_robot_and_its_solids(world):
    lv = _live(world)
    # the robot's 1 kg Box at its origin, the ball's 3 kg at (0.5, 0, 0.1); the wheels have no Physics
    expected = placed(lv, "BOT", (3 * 0.5 / 4, 0.0, 3 * 0.1 / 4))
    assert com(lv, "BOT") == pytest.approx(list(expected), abs=1e-12)
    assert com(lv, "BOT")[:2] == pytest.approx([1.0, 2.0 + 0.375], abs=1e-12)    # turned a quarter turn about z
    assert com(lv, "BALL") == pytest.approx(list(placed(lv, "BOT", (0.5, 0.0, 0.1))), abs=1e-12)


def test_center_of_mass_of_a_solid_with_a_child(world):
    lv = _live(world)
    # brick: 3 kg at (0.1, 0, 0); its child WEIGHT: 1 kg at (0.2, 0, 0.5) in the brick's frame
    expected = placed(lv, "BRICK", ((3 * 0.1 + 0.2) / 4, 0.0, 0.5 / 4))
    assert com(lv, "BRICK") == pytest.approx(list(expected), abs=1e-12)
    assert com(lv, "WEIGHT") == pytest.approx(list(placed(lv, "BRICK", (0.2, 0.0, 0.5))), abs=1e-12)


def test_without_physics_zero_and_no_solid_nan(world):
    lv = _live(world)
    assert com(lv, "BARE") == [0.0, 0.0, 0.0]        # Webots: a NULL physics answers the zero vector
    assert com(lv, "PLAIN") == [0.0, 0.0, 0.0]
    assert all(math.isnan(v) for v in com(lv, "MAST"))                 # no Solid: NaN (Webots)
    assert all(math.isnan(v) for v in bot(lv, "get_node_center_of_mass", {"node": 0})["value"])   # the root


def test_the_center_of_mass_follows_a_driving_and_a_moved_robot(world):
    lv = _live(world)
    before = np.array(com(lv, "BOT"))
    robot = lv.sim.robot("bot")
    for name in ("left wheel", "right wheel"):
        robot.motor(name).set_position(math.inf)
        robot.motor(name).set_velocity(4.0)
    for _ in range(10):
        lv.step(A, "bot")
    after = np.array(com(lv, "BOT"))
    assert after == pytest.approx(list(placed(lv, "BOT", (0.375, 0.0, 0.075))), abs=1e-12)
    moved = after - before
    assert np.hypot(*moved[:2]) == pytest.approx(4.0 * 0.05 * 10 * 0.032, rel=1e-9)   # v = ω r, straight ahead
    for name in ("left wheel", "right wheel"):
        robot.motor(name).set_velocity(0.0)
    node = bot(lv, "get_from_def", {"name": "BOT"})["node"]
    bot(lv, "set_field", {"node": node, "field": "translation", "value": [-3.0, 0.5, 0.0]})
    lv.step(A, "bot")
    assert com(lv, "BOT") == pytest.approx(list(placed(lv, "BOT", (0.375, 0.0, 0.075))), abs=1e-12)
    assert com(lv, "BOT")[:2] == pytest.approx([-3.0, 0.5 + 0.375], abs=1e-9)


def test_bad_physics_values_are_reset_with_one_line(tmp_path):
    path = tmp_path / "bad.wbt"
    path.write_text('#VRML_SIM R2023b utf8\nSolid {\n  name "s"\n  boundingObject Box { size 1 1 1 }\n'
                    '  physics Physics {\n    density -5\n  }\n}\n'
                    'Solid {\n  translation 3 0 0\n  name "t"\n  physics Physics { mass -2 density -1 }\n}\n')
    done = wbt_convert(path)
    lines = [w for w in done.warnings if "Physics" in w]
    assert lines[0] == f"{path}:6:5: Physics.density: -5 is not > 0; using 1000 (as Webots does)"
    assert done.data["solids"][0]["mass"] == {"kg": 1000.0, "center": [0.0, 0.0, 0.0]}
    # mass -2, density -1: the density is reset to 1000 first (Webots' order), then the mass to -1;
    # with no boundingObject there is no volume: no mass, said once
    assert any(w.startswith(f"{path}:12:") and "Physics.density: -1" in w for w in lines), lines
    assert any(w.startswith(f"{path}:12:") and "Physics.mass: -2" in w for w in lines), lines
    assert any("no volume here" in w for w in lines), lines
    assert "mass" not in done.data["solids"][1]


def test_extra_centres_are_said(tmp_path):
    path = tmp_path / "centres.wbt"
    path.write_text('#VRML_SIM R2023b utf8\nSolid {\n  name "c"\n'
                    '  physics Physics { mass 1 centerOfMass [ 0 0 1, 0 0 2 ] }\n}\n')
    done = wbt_convert(path)
    assert any(w.startswith(f"{path}:4:") and "Physics.centerOfMass: 2 items" in w for w in done.warnings)
    assert done.data["solids"][0]["mass"] == {"kg": 1.0, "center": [0.0, 0.0, 1.0]}


# ---------------------------------------------------------------------- mesh files in a bounding object

# a unit cube about its centre: quads counter-clockwise seen from outside (as the IndexedFaceSet above)
CUBE_CORNERS = np.array([[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)])[[0, 1, 3, 2, 4, 5, 7, 6]]
CUBE_QUADS = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
CUBE = [CUBE_CORNERS[[q[0], q[k], q[k + 1]]] for q in CUBE_QUADS for k in (1, 2)]
# the tetrahedron O, X, Y, Z: volume 1/6, centroid (1/4, 1/4, 1/4); faces wound outward
TETRA_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def write_stl(path, triangles) -> None:
    lines = ["solid part"]
    for tri in triangles:
        n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
        lines += [f"facet normal {n[0]} {n[1]} {n[2]}", "outer loop", *(f"vertex {x} {y} {z}" for x, y, z in tri),
                  "endloop", "endfacet"]
    path.write_text("\n".join([*lines, "endsolid part", ""]))


def test_the_cube_is_wound_outward():
    """(The test's own cube: the sum of its signed tetrahedra from the origin is +1.)"""
    assert sum(float(np.dot(a, np.cross(b, c))) / 6.0 for a, b, c in CUBE) == pytest.approx(1.0, abs=1e-15)


def _mesh_world(tmp_path, body: str):
    write_stl(tmp_path / "cube.stl", CUBE)
    write_stl(tmp_path / "inward.stl", [t[::-1] for t in CUBE])
    write_stl(tmp_path / "open.stl", [t for t in CUBE if not (t[:, 2] == 0.5).all()])     # its +z face left out
    (tmp_path / "tetra.obj").write_text(TETRA_OBJ)
    path = tmp_path / "meshes.wbt"
    path.write_text("#VRML_SIM R2023b utf8\n" + body)
    return load_world(path)


def test_a_closed_mesh_weighs_density_times_its_volume_about_its_centroid(tmp_path):
    loaded = _mesh_world(tmp_path, f"""
Solid {{ name "cube" boundingObject Mesh {{ url "cube.stl" }} physics Physics {{ density 500 }} }}
Solid {{
  name "tetra"
  boundingObject Pose {{ translation 1 2 3 rotation 0 0 1 {QUARTER!r} children [ Mesh {{ url "tetra.obj" }} ] }}
  physics Physics {{ }}
}}
Solid {{
  name "big tetra"
  boundingObject Transform {{ scale 2 2 2 children [ Shape {{ geometry Mesh {{ url "tetra.obj" }} }} ] }}
  physics Physics {{ }}
}}
""")
    solids = {s.name: s for s in loaded.world.solids}
    assert solids["cube"].mass.kg == pytest.approx(500.0, rel=1e-12)          # 500 kg/m³ × 1 m³
    assert solids["cube"].mass.center == pytest.approx((0.0, 0.0, 0.0), abs=1e-15)
    tetra = solids["tetra"].mass                                                # 1000 kg/m³ × 1/6 m³
    assert tetra.kg == pytest.approx(1000.0 / 6.0, rel=1e-12)
    assert tetra.center == pytest.approx((1.0 - 0.25, 2.0 + 0.25, 3.0 + 0.25), abs=1e-12)   # turned a quarter about z
    big = solids["big tetra"].mass                                              # scale 2: 8/6 m³ about (1/2, 1/2, 1/2)
    assert big.kg == pytest.approx(8000.0 / 6.0, rel=1e-12)
    assert big.center == pytest.approx((0.5, 0.5, 0.5), abs=1e-12)
    assert all(s.pending_mass is None for s in solids.values())
    assert not [w for w in loaded.warnings if "Mesh" in w or "mesh" in w], loaded.warnings


def test_a_box_and_a_mesh_weigh_together(tmp_path):
    """A 1 m³ Box at the origin and the 1 m³ cube mesh 2 m along x: 2 m³ about (1, 0, 0); a given mass
    keeps that centre, a given centre that mass."""
    bounding = ('boundingObject Group { children [ Box { size 1 1 1 } '
                'Pose { translation 2 0 0 children [ Mesh { url "cube.stl" } ] } ] }')
    loaded = _mesh_world(tmp_path, f"""
Solid {{ name "density" {bounding} physics Physics {{ }} }}
Solid {{ name "mass" {bounding} physics Physics {{ mass 3 }} }}
Solid {{ name "centre" {bounding} physics Physics {{ centerOfMass [ 0 0 0.5 ] }} }}
""")
    solids = {s.name: s.mass for s in loaded.world.solids}
    assert solids["density"].kg == pytest.approx(2000.0, rel=1e-12)
    assert solids["density"].center == pytest.approx((1.0, 0.0, 0.0), abs=1e-12)
    assert (solids["mass"].kg, solids["mass"].center) == (3.0, pytest.approx((1.0, 0.0, 0.0), abs=1e-12))
    assert (solids["centre"].kg, solids["centre"].center) == (pytest.approx(2000.0, rel=1e-12), (0.0, 0.0, 0.5))


def test_an_open_mesh_weighs_what_webots_formula_gives_and_an_inward_one_1_kg(tmp_path):
    """Webots weighs a mesh's triangles as wound (ODE's dMassSetTrimesh), open or not: the cube without
    its top face still passes x e_x's flux of 1 m³, but z²/2 e_z's only through its bottom (-1/8): its
    centre is at z -1/8. Wound inward its mass is negative: Webots counts it 1 kg at its origin (at its
    1000 kg/m³ reference, 1/1000 m³ beside the Box's 1 m³), with one warning."""
    loaded = _mesh_world(tmp_path, """
Solid { name "open" boundingObject Mesh { url "open.stl" } physics Physics { } }
Solid {
  name "inward"
  boundingObject Group { children [ Mesh { url "inward.stl" } Pose { translation 2 0 0 children [ Box { size 1 1 1 } ] } ] }
  physics Physics { density 300 }
}
""")
    solids = {s.name: s.mass for s in loaded.world.solids}
    assert solids["open"].kg == pytest.approx(1000.0, rel=1e-12)
    assert solids["open"].center == pytest.approx((0.0, 0.0, -0.125), abs=1e-12)
    assert solids["inward"].kg == pytest.approx(300.0 * 1.001, rel=1e-12)
    assert solids["inward"].center == pytest.approx((2.0 / 1.001, 0.0, 0.0), abs=1e-12)
    said = [w for w in loaded.warnings if "inward.stl" in w]
    assert len(said) == 1 and "counts 1 kg at its origin" in said[0], loaded.warnings
    assert said[0].startswith(f"{tmp_path / 'meshes.wbt'}:4:1: Solid (solids[1].pending_mass.meshes[0]): mesh 'inward.stl'")
    assert not [w for w in loaded.warnings if "open.stl" in w], loaded.warnings


def test_the_center_of_mass_of_a_solid_with_a_mesh(tmp_path):
    """getCenterOfMass of a turned solid weighing a Box and a mesh, and of a robot carrying it."""
    loaded = _mesh_world(tmp_path, f"""
DEF LOAD Solid {{
  translation 8 0 1
  rotation 0 0 1 {QUARTER!r}
  name "load"
  boundingObject Group {{ children [ Box {{ size 1 1 1 }} Pose {{ translation 2 0 0 children [ Mesh {{ url "cube.stl" }} ] }} ] }}
  physics Physics {{ density 500 }}
}}
DEF BOT Robot {{
  name "bot" supervisor TRUE controller "<extern>"
  children [ DEF PART Solid {{ translation 0 0 1 name "part" boundingObject Mesh {{ url "tetra.obj" }} physics Physics {{ }} }} ]
  boundingObject Box {{ size 0.1 0.1 0.1 }}
  physics Physics {{ mass {1000.0 / 6.0!r} }}
}}
""")
    lv = Live(Simulation(loaded))
    lv.ok(A, "attach", {"robot": "bot"})
    assert com(lv, "LOAD") == pytest.approx([8.0, 1.0, 1.0], abs=1e-12)          # (1, 0, 0) turned a quarter
    assert com(lv, "PART") == pytest.approx([0.25, 0.25, 1.25], abs=1e-12)
    assert com(lv, "BOT") == pytest.approx([0.125, 0.125, 0.625], abs=1e-12)       # two equal masses


def test_a_solid_a_supervisor_imports_weighs_its_mesh(tmp_path):
    loaded = _mesh_world(tmp_path, 'DEF BOSS Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    lv = Live(Simulation(loaded))
    lv.ok(A, "attach", {"robot": "boss"})
    lv.ok(A, "/boss/robot/import_node_from_string", {
        "node": 0, "field": "children", "position": -1,
        "node_string": 'DEF LOADED Solid { translation 5 0 0 name "l" boundingObject Pose { translation 0 0 1 '
                       'children [ Mesh { url "tetra.obj" } ] } physics Physics { } }'})
    lv.step(A, "boss")
    node = lv.ok(A, "/boss/robot/get_from_def", {"name": "LOADED"})["node"]
    assert lv.ok(A, "/boss/robot/get_node_center_of_mass", {"node": node})["value"] == \
        pytest.approx([5.25, 0.25, 1.25], abs=1e-12)


def test_the_import_records_what_the_loader_completes(tmp_path):
    write_stl(tmp_path / "cube.stl", CUBE)
    path = tmp_path / "pending.wbt"
    path.write_text('#VRML_SIM R2023b utf8\nSolid {\n  name "m"\n'
                    '  boundingObject Group { children [ Box { size 1 2 1 } Mesh { url "cube.stl" } ] }\n'
                    '  physics Physics { density 10 }\n}\n')
    done = wbt_convert(path)
    entry = done.data["solids"][0]
    assert "mass" not in entry
    assert entry["pending_mass"] == {"volume": 2.0, "centroid": [0.0, 0.0, 0.0], "density": 10.0,
                                     "meshes": [{"mesh": {"type": "mesh", "url": "cube.stl", "scale": [1.0, 1.0, 1.0]},
                                                 "pose": {"translation": [0.0, 0.0, 0.0]}}]}
    assert not [w for w in done.warnings if "Mesh" in w], done.warnings
    assert load_world(path).world.solids[0].mass.kg == pytest.approx(30.0, rel=1e-12)


def test_mass_and_pending_mass_together_are_refused(tmp_path):
    path = tmp_path / "both.yaml"
    path.write_text("solids:\n- name: s\n  mass: {kg: 1.0}\n"
                    "  pending_mass: {volume: 1.0, meshes: [{mesh: {type: mesh, url: cube.stl}}]}\n")
    with pytest.raises(WorldError) as err:
        load_world(path)
    assert "give either mass or pending_mass" in str(err.value)


def test_a_yaml_world_gives_masses(tmp_path):
    path = tmp_path / "w.yaml"
    path.write_text("robots:\n- name: r\n  supervisor: true\n  pose: {translation: [1.0, 0.0, 0.0]}\n"
                    "  mass: {kg: 2.0, center: [0.1, 0.0, 0.0]}\n"
                    "solids:\n- name: s\n  def_name: S\n  pose: {translation: [0.0, 3.0, 0.0]}\n"
                    "  mass: {kg: 1.0, center: [0.0, 0.0, 0.5]}\n"
                    "  children:\n  - {name: c, pose: {translation: [1.0, 0.0, 0.0]}, mass: {kg: 3.0}}\n")
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "r"})
    me = lv.ok(A, "/r/robot/get_self")["node"]
    assert lv.ok(A, "/r/robot/get_node_center_of_mass", {"node": me})["value"] == pytest.approx([1.1, 0.0, 0.0])
    solid = lv.ok(A, "/r/robot/get_from_def", {"name": "S"})["node"]
    assert lv.ok(A, "/r/robot/get_node_center_of_mass", {"node": solid})["value"] == \
        pytest.approx([0.75, 3.0, 0.125])          # (1 kg at (0, 3, 0.5) + 3 kg at (1, 3, 0)) / 4


ARM_WORLD = """#VRML_SIM R2023b utf8
Robot {
  name "arm" controller "<extern>" supervisor TRUE
  children [
    HingeJoint {
      jointParameters HingeJointParameters { axis 0 0 1 anchor 0 0 0.2 }
      device [ RotationalMotor { name "pan" maxVelocity 100 } ]
      endPoint DEF LINK Solid {
        translation 0.1 0 0.2
        name "link"
        boundingObject Box { size 0.2 0.02 0.02 }
        physics Physics { mass 3 centerOfMass [ 0.1 0 0 ] }
      }
    }
  ]
  boundingObject Box { size 0.1 0.1 0.1 }
  physics Physics { mass 1 }
}
"""


def test_the_center_of_mass_follows_a_turned_joint(tmp_path):
    """A 3 kg link whose centre is 0.2 m out from a vertical hinge through (0, 0, 0.2), on a 1 kg base:
    (0.15, 0, 0.15), and a quarter turn later (0, 0.15, 0.15)."""
    path = tmp_path / "arm.wbt"
    path.write_text(ARM_WORLD)
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "arm"})
    me = lv.ok(A, "/arm/robot/get_self")["node"]
    link = lv.ok(A, "/arm/robot/get_from_def", {"name": "LINK"})["node"]
    assert lv.ok(A, "/arm/robot/get_node_center_of_mass", {"node": me})["value"] == \
        pytest.approx([0.15, 0.0, 0.15], abs=1e-12)
    lv.sim.robot("arm").motor("pan").set_position(QUARTER)
    for _ in range(20):                     # 100 rad/s and Webots' 10 rad/s^2 ramp: there well before
        lv.step(A, "arm")
    assert lv.sim.robot("arm").motor("pan").position == QUARTER
    assert lv.ok(A, "/arm/robot/get_node_center_of_mass", {"node": me})["value"] == \
        pytest.approx([0.0, 0.15, 0.15], abs=1e-12)
    assert lv.ok(A, "/arm/robot/get_node_center_of_mass", {"node": link})["value"] == \
        pytest.approx([0.0, 0.2, 0.2], abs=1e-12)


def test_a_bounding_sphere_of_radius_0_is_webots_unit_sphere_for_mass_and_fall(tmp_path):
    """Webots resets a non-positive Sphere radius to 1 (the node's own rule, a bounding object too): the
    solid weighs 1000 × 4/3 π, falls onto the floor like a unit ball and answers its centre."""
    path = tmp_path / "radius0.wbt"
    path.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n'
                    'Solid {\n  translation 0 0 -0.5\n  name "floor"\n  boundingObject Box { size 10 10 1 }\n}\n'
                    'DEF BALL Solid {\n  translation 2 0 3\n  name "ball"\n'
                    '  boundingObject Sphere { radius 0 }\n  physics Physics { }\n}\n'
                    'Robot { translation -3 0 0 name "bot" supervisor TRUE controller "<extern>" }\n')
    done = wbt_convert(path)
    assert done.warnings == [f"{path}:11:27: Sphere.radius: 0 is not > 0; using 1 (as Webots does)"]
    ball = {s.name: s for s in load_world(path).world.solids}["ball"]
    assert ball.mass.kg == pytest.approx(1000 * 4 / 3 * math.pi, rel=1e-12)
    assert tuple(ball.mass.center) == (0.0, 0.0, 0.0)
    lv = _live(path)
    lv.step(A, "bot")
    assert com(lv, "BALL") == pytest.approx([2.0, 0.0, 1.0], abs=1e-12)    # resting on the floor's top, z = 0
