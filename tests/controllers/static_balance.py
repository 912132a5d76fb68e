"""getStaticBalance of tests/worlds/static_balance.wbt's solids, before, during and after BOX's fall
(tests/test_supervisor_balance.py; tests/c/static_balance.c prints the same)."""
from controller import Supervisor

s = Supervisor()
dt = int(s.getBasicTimeStep())
s.step(dt)
box, outside, bare = (s.getFromDef(name) for name in ("BOX", "OUTSIDE", "BARE"))
print("balance", int(box.getStaticBalance()), int(outside.getStaticBalance()), int(bare.getStaticBalance()))
box.getField("translation").setSFVec3f([0.0, 0.0, 0.55])
print("air", int(box.getStaticBalance()))
for _ in range(20):
    s.step(dt)
print("landed", int(box.getStaticBalance()))
print("root", int(s.getRoot().getStaticBalance()))
