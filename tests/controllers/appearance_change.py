"""A Webots-style supervisor changing a wall's colour and its camera seeing it (tests/test_supervisor_appearance.py
on tests/worlds/appearance_change.wbt): the wall's Shape reached through its solid's children, its
PBRAppearance through the Shape's appearance field, its baseColor set; a Material found by DEF. Written as for
Webots; prints the lines tests/c/appearance_change.c prints."""

from controller import Node, Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
camera = robot.getDevice("cam")
camera.enable(timestep)


def centre() -> str:
    image = camera.getImage()
    k = 4 * (2 * camera.getWidth() + 2)
    return f"{image[k + 2]} {image[k + 1]} {image[k]}"


def numbers(values) -> str:
    return " ".join(f"{v:g}" for v in values)


robot.step(timestep)
print("before", centre())
shape = robot.getFromDef("WALL").getField("children").getMFNode(0)
appearance = shape.getField("appearance").getSFNode()
box = shape.getField("geometry").getSFNode()
print("nodes", shape.getTypeName(), appearance.getTypeName(), appearance.getDef(), box.getTypeName(),
      int(appearance.getType() == Node.PBR_APPEARANCE), int(box.getType() == Node.BOX),
      int(appearance.getParentNode().getId() == shape.getId()))
print("size", numbers(box.getField("size").getSFVec3f()))
color = appearance.getField("baseColor")
print("color", numbers(color.getSFColor()), f"{appearance.getField('metalness').getSFFloat():g}")
color.setSFColor([0.3, 0.6, 0.9])
robot.step(timestep)
print("after", centre(), numbers(color.getSFColor()))
material = robot.getFromDef("PANEL_MATERIAL")
ball = robot.getFromDef("PANEL").getField("children").getMFNode(1)
reached = ball.getField("appearance").getSFNode().getField("material").getSFNode()
print("reached", int(reached.getId() == material.getId()), int(material.getType() == Node.MATERIAL),
      reached.getBaseTypeName())
diffuse = material.getField("diffuseColor")
print("material", material.getTypeName(), numbers(diffuse.getSFColor()),
      f"{material.getField('transparency').getSFFloat():g}")
diffuse.setSFColor([0.5, 0.25, 0.125])
robot.step(timestep)
print("material", numbers(diffuse.getSFColor()))
