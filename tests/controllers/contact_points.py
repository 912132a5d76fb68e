"""getContactPoints of tests/worlds/contact_points.wbt's nodes, and Webots' deprecated per-index functions
(tests/test_supervisor_contacts.py; tests/c/contact_points.c prints the same)."""
from controller import Supervisor

s = Supervisor()
dt = int(s.getBasicTimeStep())
s.step(dt)


def show(label, node, descendants):
    points = node.getContactPoints(descendants)
    print(label, len(points))
    for p in points:
        print(" ".join(f"{v:.4f}" for v in p.point), s.getFromId(p.node_id).getDef())


box, ball, cart = (s.getFromDef(name) for name in ("BOX", "BALL", "CART"))
show("box", box, False)
show("ball", ball, False)
show("cart own", cart, False)
show("cart all", cart, True)
cart.enableContactPointsTracking(dt, True)
print("count", cart.getNumberOfContactPoints(True), cart.getNumberOfContactPoints(False))
n = cart.getNumberOfContactPoints(True)
print("last", " ".join(f"{v:.4f}" for v in cart.getContactPoint(n - 1)), cart.getContactPointNode(n - 1).getDef())
print("past", " ".join(f"{v:.4f}" for v in cart.getContactPoint(n)), cart.getContactPointNode(n))
cart.disableContactPointsTracking()
box.getField("translation").setSFVec3f([1.0, 0.0, 0.55])
show("air", box, True)
print("same step", len(box.getContactPoints()))        # Webots' library answers a step's first query again
s.step(dt)
print("next step", len(box.getContactPoints()))        # asked again: in the air, falling
show("root", s.getRoot(), True)
