"""A Webots-style randomising supervisor reaching the nodes inside what it imported (tests/
test_supervisor_inner_nodes.py on tests/worlds/supervisor_inner_nodes.wbt): a wall and a crate imported, the
wall's Shape reached through its children, its PBRAppearance's baseColor set and seen by the camera, its
transparency set to 1 (the wall hidden), 0.5 and 0 (shown again); an inner solid found by a dotted DEF, its
position read; the wall removed, its inner nodes then NULL by id. Written as for Webots; prints one line per
check (tests/c/supervisor_inner_nodes.c and supervisor_inner_nodes_cpp.cpp print the same)."""

from controller import Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
camera = robot.getDevice("cam")
camera.enable(timestep)
root = robot.getRoot().getField("children")


def centre() -> str:
    image = camera.getImage()
    k = 4 * (2 * camera.getWidth() + 2)
    return f"{image[k + 2]} {image[k + 1]} {image[k]}"


def numbers(values) -> str:
    return " ".join(f"{v:.6f}" for v in values)


root.importMFNodeFromString(-1, 'DEF BOX Solid { translation 2 0 0 name "wall" children [ Shape { appearance '
                                'PBRAppearance { baseColor 1 0 0 roughness 1 metalness 0 } geometry Box { size 0.1 '
                                '20 20 } } DEF INNER Solid { translation 0.3 -0.4 1.5 rotation 0 1 0 0.7 name "inner" '
                                'children [ DEF KNOB Shape { appearance Appearance { material Material { diffuseColor '
                                '0 0 1 } } geometry Sphere { radius 0.05 } } ] } ] }')
root.importMFNodeFromString(-1, 'DEF CRATE Solid { translation -1 3 0.5 rotation 0 0 1 0.5 name "crate" children [ '
                                'DEF LID Solid { translation 0.2 0.1 0.3 rotation 1 0 0 0.25 name "lid" } ] }')
robot.step(timestep)
box = robot.getFromDef("BOX")
children = box.getField("children")
shape, inner = children.getMFNode(0), children.getMFNode(1)
print("children", children.getCount(), shape.getTypeName(), inner.getTypeName())
found = robot.getFromDef("BOX.INNER")
print("inner", found.getDef(), found.getField("name").getSFString(), int(found.getId() == inner.getId()))
print("position", numbers(found.getPosition()))
print("lid", numbers(robot.getFromDef("CRATE.LID").getPosition()))
print("before", centre())
shape.getField("appearance").getSFNode().getField("baseColor").setSFColor([0.2, 0.6, 0.9])
robot.step(timestep)
print("after", centre())
transparency = shape.getField("appearance").getSFNode().getField("transparency")
for label, value in (("hidden", 1.0), ("half", 0.5), ("shown", 0.0)):
    transparency.setSFFloat(value)
    robot.step(timestep)
    print(label, centre())
knob = robot.getFromDef("BOX.INNER.KNOB")
ids = [inner.getId(), knob.getId()]
box.remove()
robot.step(timestep)
print("removed", int(robot.getFromId(ids[0]) is None), int(robot.getFromId(ids[1]) is None))
