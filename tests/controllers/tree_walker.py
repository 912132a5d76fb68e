"""A Webots-style supervisor walking its robot's tree as Webots users write it (tests/test_supervisor_nested_joints.py
on tests/worlds/nested_joints.wbt): from its own node down every ``children`` and ``device`` field and each
joint's ``endPoint``, probing each node for those fields (``getField`` answers None where the node has none),
printing one line per node (depth, type, DEF) after the shoulder turned; then it asks the link's
``boundingObject`` (Webots has it, Sensorium does not serve it). Written as for Webots."""

from controller import Supervisor

robot = Supervisor()
timestep = int(robot.getBasicTimeStep())
robot.getDevice("shoulder").setPosition(0.5)
for _ in range(10):
    robot.step(timestep)


def walk(node, depth: int) -> None:
    params = node.getField("jointParameters")
    at = f" {params.getSFNode().getField('position').getSFFloat():.3f}" if params and params.getSFNode() else ""
    print(f"{depth} {node.getTypeName()} {node.getDef()}{at}")
    for name in ("children", "device"):
        field = node.getField(name)
        if field is not None:
            for i in range(field.getCount()):
                walk(field.getMFNode(i), depth + 1)
    end = node.getField("endPoint")
    if end is not None and end.getSFNode() is not None:
        walk(end.getSFNode(), depth + 1)


walk(robot.getSelf(), 0)
print("boundingObject", robot.getFromDef("LINK").getField("boundingObject"))
