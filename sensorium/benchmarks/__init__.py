"""Sensorium's benchmark suite: ``sensorium bench`` (or ``python -m sensorium.benchmarks``).

One module per section, each ``run(cfg) -> Section``:

* :mod:`.accuracy`  — every knob that trades accuracy for speed, error vs an exact reference and time;
* :mod:`.scaling`   — time per step vs rays, triangles, lights, devices, robots, with the measured growth;
* :mod:`.peers`     — the same scene and rays through raw embreex, Open3D, MuJoCo, PyBullet, trimesh;
* :mod:`.transport` — lockstep round trips and steps/s over loopback against a raw pyzmq floor;
* :mod:`.memory`    — bytes per static triangle, transient memory and time per ray of large scans;
* :mod:`.limits`    — peak memory of worlds at the world-file limits, time to refuse oversize or damaged input;
* :mod:`.scaleout`  — vectorised Gymnasium env steps/s, sweep throughput on the process pool vs Ray;
* :mod:`.loading`   — loading a PROTO-heavy Webots world, per stage (expansion, templates, conversion, scene);
* :mod:`.cad`       — a robot of 30 mesh parts and swarms of mesh robots: resident and peak memory per stage, load time;
* :mod:`.images`    — a camera's and a range finder's picture vs raw embreex on the same rays;
* :mod:`.training`  — the batched vector env (many worlds in one simulation) vs MuJoCo Hopper, scaling, resets;
* :mod:`.radio`     — Emitter/Receiver traffic: time per delivered packet, radio and infra-red;

and :mod:`.report` writes ``benchmarks.md``, ``benchmarks.json`` and the PNG plots.
"""

SECTIONS = ("transport", "memory", "limits", "accuracy", "scaling", "scaleout", "loading", "cad", "images", "training", "radio", "peers")   # run order: peers last (its libraries start thread pools)
