"""A swarm world for the scaling tests and measurements: ``n`` MiniPuck robots (tests/protos/minipuck,
our own e-puck-like PROTO: a cylinder body, 8 infra-red sensors in housings, 8 light sensors, 3
ground sensors, wheels with encoders, LEDs) each with a 52 x 39 camera on its front, in a walled
square arena with a light, at jittered grid positions (seeded) so robots see and sense each other.

    python tests/_swarm.py N OUT.wbt      # writes the world (its PROTO path points at tests/protos)
"""

from __future__ import annotations

import math
import random
import sys
from pathlib import Path

PROTOS = Path(__file__).resolve().parent / "protos" / "minipuck"



def camera(far: float = 2.0, housing: bool = False) -> str:
    """The robot's 52 x 39 camera (``far`` 0: unbounded, Webots' default), with a small housing of its
    own behind its lens (``housing``: a device with shapes, whose rays ride the robot's body)."""
    box = ('children [ Pose { translation -0.004 0 0 children [ Shape { geometry Box { size 0.006 0.01 0.008 } } ] } ] '
           if housing else "")
    return (f'Camera {{ translation 0.03 0 -0.02 name "camera" width 52 height 39 fieldOfView 0.84 near 0.005 far {far:g} '
            f"{box}}}")


def swarm_wbt(n: int, seed: int = 7, spacing: float = 0.12, cameras: bool = True, far: float = 2.0,
              housing: bool = False) -> str:
    """The text of a world with ``n`` robots on a grid of pitch ``spacing`` (jittered, random headings),
    each with a camera (see :func:`camera`) unless ``cameras`` is False."""
    rng = random.Random(seed)
    side = max(1, math.ceil(math.sqrt(n)))
    half = 0.5 * side * spacing + 0.1
    lines = [
        "#VRML_SIM R2023b utf8",
        f'EXTERNPROTO "{(PROTOS / "MiniPuck.proto").as_posix()}"',
        "WorldInfo { basicTimeStep 32 }",
        f'Solid {{ name "floor" children [ Shape {{ geometry DEF FLOOR Plane {{ size {2 * half:.3f} {2 * half:.3f} }} }} ] '
        "boundingObject USE FLOOR }",
        "PointLight { location 0 0 1 attenuation 0 0 1 }",
    ]
    for k, (x, y, sx, sy) in enumerate([(half, 0, 0.02, 2 * half), (-half, 0, 0.02, 2 * half),
                                        (0, half, 2 * half, 0.02), (0, -half, 2 * half, 0.02)]):
        lines.append(f'Solid {{ translation {x:.4f} {y:.4f} 0.05 name "wall{k}" children [ DEF W{k} Shape {{ '
                     f"geometry Box {{ size {sx:.4f} {sy:.4f} 0.1 }} }} ] boundingObject USE W{k} }}")
    for i in range(n):
        gx, gy = i % side, i // side
        x = (gx - 0.5 * (side - 1)) * spacing + rng.uniform(-0.015, 0.015)
        y = (gy - 0.5 * (side - 1)) * spacing + rng.uniform(-0.015, 0.015)
        yaw = rng.uniform(-math.pi, math.pi)
        slot = f" extensionSlot [ {camera(far, housing)} ]" if cameras else ""
        lines.append(f'MiniPuck {{ translation {x:.4f} {y:.4f} 0 rotation 0 0 1 {yaw:.4f} name "puck{i}"{slot} }}')
    return "\n".join(lines) + "\n"


def write_swarm(n: int, path: Path, **kw) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(swarm_wbt(n, **kw))
    return path


if __name__ == "__main__":   # N OUT.wbt [FAR [housing]]
    print(write_swarm(int(sys.argv[1]), Path(sys.argv[2]), far=float(sys.argv[3]) if len(sys.argv) > 3 else 2.0,
                      housing=len(sys.argv) > 4 and sys.argv[4] == "housing"))
