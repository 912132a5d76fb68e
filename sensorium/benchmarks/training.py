"""Training at scale: the batched vector environment (many copies of a world in one simulation).

Env steps/s of ``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")`` for
ReachLight (256 copies) and LidarAvoid (64 copies, a 360-beam lidar), FAST and EXACT, against the
single environment and MuJoCo's Hopper-v5 (``pip install '.[bench-peers]'``; skipped with the reason
without it), all in one interleaved run; scaling with the number of copies (1 ... 1,024) with the
memory per copy; the cost of a reset per sub-environment. Needs the ``[gym]`` extra.

Throughput is given two ways: per wall second, and per CPU second of this process (``time.
process_time``): the environments run on one core, and on a shared machine the CPU figure is what
that core does whatever else runs; on a quiet machine the two agree. The ``workers=2`` rows (the
copies split over two worker processes, :mod:`sensorium.gym.workers`) count the workers' CPU too
(read from ``/proc/<pid>/stat``).
"""

from __future__ import annotations

import gc
import os
import time
import tracemalloc

import numpy as np

from .common import Config, Plot, Section, Series, Table, Target, median, process_cpu_s

REACH, LIDAR = "sensorium/ReachLight-v0", "sensorium/LidarAvoid-v0"
POLL_S = 200e-6                 # the workers rows' poll (workers=k's poll_s), measured against none


class _Runner:
    """One setting kept alive across rounds: an env (vector or single) and its random actions."""

    def __init__(self, gym, label: str, make, n: int, vector: bool):
        self.label, self.n, self.vector = label, n, vector
        self.env = make()
        self.env.reset(seed=0)
        self.env.action_space.seed(0)
        self.actions = [self.env.action_space.sample() for _ in range(64)]
        self.k = 0
        self.pids: list[int] = list(getattr(self.env, "pids", []))    # a workers env's processes
        self.wall: list[float] = []
        self.cpu: list[float] = []

    def cpu_s(self) -> float:
        """CPU seconds of this process and of the env's worker processes (if any)."""
        return time.process_time() + sum(map(process_cpu_s, self.pids))

    def run(self, seconds: float) -> None:
        env, acts = self.env, self.actions
        steps = 0
        t0, c0 = time.perf_counter(), self.cpu_s()
        while True:
            _, _, term, trunc, _ = env.step(acts[self.k % 64])
            self.k += 1
            steps += self.n
            if not self.vector and (term or trunc):
                env.reset()
            if time.perf_counter() - t0 >= seconds:
                break
        wall, cpu = time.perf_counter() - t0, self.cpu_s() - c0
        self.wall.append(steps / wall)
        self.cpu.append(steps / max(cpu, 1e-9))

    def close(self) -> None:
        self.env.close()


def _throughput(cfg: Config, sec: Section, gym) -> None:
    rounds = cfg.pick(5, 2)
    chunk = cfg.pick(1.5, 0.4)
    def batched(env_id: str, n: int, precision: str, threads: int = 1, workers: int = 1, **kw):
        return lambda: gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", precision=precision,
                                    threads=threads, workers=workers, **kw)

    makers = [
        ("ReachLight, batched x256, fast", batched(REACH, 256, "fast"), 256, True),
        ("ReachLight, batched x256, exact", batched(REACH, 256, "exact"), 256, True),
        ("LidarAvoid, batched x64, fast", batched(LIDAR, 64, "fast"), 64, True),
        ("LidarAvoid, batched x64, exact", batched(LIDAR, 64, "exact"), 64, True),
        ("LidarAvoid, batched x64, fast, casts on 2 threads", batched(LIDAR, 64, "fast", 2), 64, True),
        ("ReachLight, batched x256, fast, 2 worker processes", batched(REACH, 256, "fast", workers=2), 256, True),
        ("LidarAvoid, batched x64, fast, 2 worker processes", batched(LIDAR, 64, "fast", workers=2), 64, True),
        ("ReachLight, batched x256, fast, 2 worker processes, 0.2 ms poll",
         batched(REACH, 256, "fast", workers=2, poll_s=POLL_S), 256, True),
        ("LidarAvoid, batched x64, fast, 2 worker processes, 0.2 ms poll",
         batched(LIDAR, 64, "fast", workers=2, poll_s=POLL_S), 64, True),
        ("ReachLight, single env, fast", lambda: gym.make(REACH, precision="fast"), 1, False),
        ("LidarAvoid, single env, fast", lambda: gym.make(LIDAR, precision="fast"), 1, False),
    ]
    hopper_why = ""
    try:
        import mujoco  # noqa: F401

        gym.make("Hopper-v5").close()
        makers.append(("MuJoCo Hopper-v5 (physics), single env", lambda: gym.make("Hopper-v5"), 1, False))
    except Exception as exc:  # noqa: BLE001 - any missing piece (mujoco, imageio) skips the peer
        hopper_why = f"MuJoCo Hopper-v5 skipped: {type(exc).__name__}: {exc} (pip install '.[bench-peers]')"
        sec.findings.append(hopper_why)
    runners: list[_Runner] = []
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    try:
        for label, make, n, vec in makers:
            runners.append(_Runner(gym, label, make, n, vec))
        for r in runners:
            r.run(0.2)                                 # warm-up: first casts build the scenes
            r.wall.clear()
            r.cpu.clear()
        for _ in range(rounds):                        # the settings alternate: all see the same machine load
            for r in runners:
                r.run(chunk)
    finally:
        for r in runners:
            r.close()
    med = {r.label: (median(r.wall), median(r.cpu)) for r in runners}
    hop = med.get("MuJoCo Hopper-v5 (physics), single env")
    rows = []
    for r in runners:
        w, c = med[r.label]
        rows.append([r.label, r.n, f"{w:,.0f}", f"{c:,.0f}",
                     f"{w / hop[0]:.1f}x" if hop else "-", f"{c / hop[1]:.1f}x" if hop else "-"])
        cfg.log(f"  training: {r.label}: {w:,.0f} env steps/s ({c:,.0f} per CPU s)")
    sec.tables.append(Table("throughput", "Env steps/s, random actions (one process, one core; the worker rows two)", [
        "environment", "copies", "env steps / wall s", "env steps / CPU s", "vs Hopper (wall)", "vs Hopper (CPU)"],
        rows, notes=[
            f"Medians of {rounds} rounds; in each round every setting runs ~{chunk:g} s, the settings alternating "
            "so that all see the same machine load. An env step of ReachLight is 64 ms simulated (2 basic steps, 10 "
            "devices: 2 light sensors, 8 infra-red of 3 rays); of LidarAvoid 64 ms (a 360-beam lidar, 4 sonars, the "
            "32-ray clearance of its reward). Batched = `gymnasium.make_vec(id, num_envs=N, "
            "vectorization_mode=\"vector_entry_point\", threads=1)` (its casts on the calling thread: one core), "
            "with Gymnasium's NEXT_STEP autoresets included; the 2-thread row lets casts of >= 16,384 rays (the "
            "copies' lidar beams) be split over two threads, as the env does by default on a 2-core machine. "
            "The 2-worker rows: `make_vec(..., workers=2)`, the copies split over two worker processes "
            "(each a batched env of half the copies, casts on one thread), stepped side by side; their CPU "
            "column counts this process and both workers (/proc/<pid>/stat, 10 ms ticks). '0.2 ms poll': "
            "`poll_s=0.0002`, a worker polls that long for its next command before it sleeps.",
            "Hopper-v5: Gymnasium's MuJoCo Hopper, one env (physics, no rays). " + (hopper_why or "")]))
    sec.data["throughput"] = {k: {"wall": v[0], "cpu": v[1]} for k, v in med.items()}
    reach, lidar = med["ReachLight, batched x256, fast"], med["LidarAvoid, batched x64, fast"]
    reach_x, lidar_x = med["ReachLight, batched x256, exact"], med["LidarAvoid, batched x64, exact"]
    lidar_2 = med["LidarAvoid, batched x64, fast, casts on 2 threads"]
    reach_w, lidar_w = (med["ReachLight, batched x256, fast, 2 worker processes"],
                        med["LidarAvoid, batched x64, fast, 2 worker processes"])
    reach_wp, lidar_wp = (med["ReachLight, batched x256, fast, 2 worker processes, 0.2 ms poll"],
                          med["LidarAvoid, batched x64, fast, 2 worker processes, 0.2 ms poll"])
    sec.targets.append(Target("ReachLight, 256 copies, one core", ">= 30,000 env steps/s",
                              f"{reach[0]:,.0f} / wall s, {reach[1]:,.0f} / CPU s", reach[1] >= 30_000,
                              "judged on CPU seconds (one core's work on a shared machine)"))
    sec.targets.append(Target("LidarAvoid, 64 copies, one core", ">= 5,000 env steps/s",
                              f"{lidar[0]:,.0f} / wall s, {lidar[1]:,.0f} / CPU s", lidar[1] >= 5_000,
                              "judged on CPU seconds"))
    for name, v in (("ReachLight x256", reach), ("LidarAvoid x64", lidar)):
        if hop:
            sec.targets.append(Target(f"{name} vs MuJoCo Hopper-v5", ">= 5x", f"{v[1] / hop[1]:.1f}x (CPU), "
                                      f"{v[0] / hop[0]:.1f}x (wall)", v[1] / hop[1] >= 5.0, "same run, interleaved"))
        else:
            sec.targets.append(Target(f"{name} vs MuJoCo Hopper-v5", ">= 5x", "-", None, hopper_why))
    single = med["ReachLight, single env, fast"]
    sec.findings.append(
        f"Batched: ReachLight x256 {reach[1]:,.0f} env steps per CPU s ({reach[1] / single[1]:.0f}x one single env), "
        f"LidarAvoid x64 {lidar[1]:,.0f}; EXACT costs {100 * (1 - reach_x[1] / reach[1]):.0f} % (ReachLight) and "
        f"{100 * (1 - lidar_x[1] / lidar[1]):.0f} % (LidarAvoid) of FAST's throughput"
        + (f"; MuJoCo Hopper-v5 {hop[1]:,.0f} (a physics step, no sensors)." if hop else "."))

    sec.findings.append(
        f"LidarAvoid x64 with its casts allowed two threads: {lidar_2[0]:,.0f} env steps per wall s, "
        f"{lidar_2[1]:,.0f} per CPU s ({lidar_2[0] / lidar[0]:.2f}x / {lidar_2[1] / lidar[1]:.2f}x one thread): "
        "the copies' lidar beams (23,040 rays) are split over the threads, the rest of the step stays on one "
        "(the env's `threads` option; its default is the cores).")
    sec.findings.append(
        f"workers=2 (the copies in two worker processes): ReachLight x256 {reach_w[0]:,.0f} env steps per wall s "
        f"({reach_w[0] / reach[0]:.2f}x one process), LidarAvoid x64 {lidar_w[0]:,.0f} ({lidar_w[0] / lidar[0]:.2f}x); "
        f"per CPU s of the parent and both workers {reach_w[1]:,.0f} and {lidar_w[1]:,.0f} (each worker repeats the "
        f"batched step's fixed cost for half the copies, and the parent's hand-over is added). With a "
        f"{POLL_S * 1e3:.1f} ms poll (`poll_s`): {reach_wp[0]:,.0f} and {lidar_wp[0]:,.0f} env steps per wall s "
        f"({reach_wp[0] / reach[0]:.2f}x and {lidar_wp[0] / lidar[0]:.2f}x one process, {reach_wp[0] / reach_w[0]:.2f}x "
        f"and {lidar_wp[0] / lidar_w[0]:.2f}x the workers without it), per CPU s {reach_wp[1]:,.0f} and "
        f"{lidar_wp[1]:,.0f}. {os.cpu_count()} cores, "
        f"load average {load:.1f} when the run began: two workers gain wall time only where a second core is free.")
    _lidar_budget(cfg, sec, gym, hop[1] if hop else None)


def _bare_traversal(captured: tuple, repeats: int) -> float | None:
    """CPU seconds of one bare packet traversal of a captured lidar cast's rays: the static tier's
    FAST Embree scene, float32 rays, coherent packets of 16, only distances and triangles out (None
    without the packet path or where the cast's tier is anchored)."""
    from sensorium.server.raycast import packets

    rays, origins, directions, far, kind, skip = captured
    static = rays.static._static_tier(rays.movers._variant(kind, skip))
    if packets.library() is None or static is None or static.anchored:
        return None
    scene, _ = static.scene(False)
    if not isinstance(scene, packets.Scene):
        return None
    o32, d32 = origins.astype(np.float32), directions.astype(np.float32)
    far32 = np.broadcast_to(np.asarray(far, dtype=np.float32), (len(d32),)).copy()
    scene.run(o32, d32, far32, output=0, coherent=True)     # warm
    t0 = time.thread_time()
    for _ in range(repeats):
        scene.run(o32, d32, far32, output=0, coherent=True)
    return (time.thread_time() - t0) / repeats


def _lidar_budget(cfg: Config, sec: Section, gym, hopper_cpu_rate: float | None) -> None:
    """Where a LidarAvoid x64 step's CPU goes: the batched casts (``CopyRays.cast``: the packet
    traversal, the judging in C and the Python around them) against the rest of the step, and what 5x
    Hopper leaves per step. Measured in its own run (the wrapper's timer calls are not in the
    throughput rows above)."""
    from sensorium.server.raycast import packets
    from sensorium.server.raycast.copies import CopyRays

    env = gym.make_vec(LIDAR, num_envs=64, vectorization_mode="vector_entry_point", precision="fast", threads=1)
    cast = CopyRays.cast
    spent = [0.0, 0]
    beams: list = []   # one step's lidar cast (the copies' beams): (CopyRays, origins, directions, far, kind, skip)

    def timed(self, *args, **kw):
        if not beams and len(args[0]) >= 16384:
            skip = args[10] if len(args) > 10 else kw.get("skip_transparent", False)
            beams.append((self, np.array(args[0]), np.array(args[1]), args[3], args[4], bool(skip)))
        t0 = time.thread_time()
        try:
            return cast(self, *args, **kw)
        finally:
            spent[0] += time.thread_time() - t0
            spent[1] += 1

    try:
        env.reset(seed=0)
        env.action_space.seed(0)
        acts = [env.action_space.sample() for _ in range(64)]
        for k in range(50):
            env.step(acts[k % 64])
        CopyRays.cast = timed                                # type: ignore[method-assign]
        steps = cfg.pick(1000, 200)
        c0 = time.thread_time()
        for k in range(steps):
            env.step(acts[k % 64])
        step_s = (time.thread_time() - c0) / steps
    finally:
        CopyRays.cast = cast                                 # type: ignore[method-assign]
        env.close()
    cast_s = spent[0] / steps
    bare_s = _bare_traversal(beams[0], cfg.pick(200, 40)) if beams else None
    sec.data["lidar_budget"] = {"step_cpu_s": step_s, "casts_cpu_s": cast_s, "casts_per_step": spent[1] / steps,
                                "hopper_cpu_rate": hopper_cpu_rate, "bare_traversal_cpu_s": bare_s,
                                "beams": len(beams[0][2]) if beams else None}
    budget = "" if not hopper_cpu_rate else (
        f" 5x MuJoCo Hopper ({hopper_cpu_rate:,.0f} env steps per CPU s in the rows above) leaves "
        f"{64 / (5 * hopper_cpu_rate) * 1e3:.2f} ms per step of 64 copies: the casts alone take "
        f"{100 * cast_s * 5 * hopper_cpu_rate / 64:.0f} % of it.")
    if bare_s is not None:
        budget += (f" The bare traversal of the same step's {len(beams[0][2]):,} lidar beams (one call of Embree's "
                   f"coherent rtcIntersect16 packets over them, no judging, no Python around it) takes "
                   f"{bare_s * 1e3:.2f} ms" + ("" if not hopper_cpu_rate else
                                              f", {100 * bare_s * 5 * hopper_cpu_rate / 64:.0f} % of that budget") + ".")
    sec.findings.append(
        f"What bounds LidarAvoid x64 (FAST, one thread; a run of {steps:,} steps with the batched casts timed): "
        f"{step_s * 1e3:.2f} ms of CPU per env step, of which {cast_s * 1e3:.2f} ms ({100 * cast_s / step_s:.0f} %) "
        f"in the {spent[1] / steps:.0f} batched casts (lidar beams, sonars, the reward's clearance: the packet "
        f"traversal ({packets.status().split(' through ')[0]}), the judging in C and the Python around them), the rest the drive, "
        "device finishing, the task's reward and observations (C passes and numpy keeping the single env's "
        "bits)." + budget)


def _scaling(cfg: Config, sec: Section, gym) -> None:
    sizes = cfg.pick([1, 4, 16, 64, 256, 1024], [1, 16, 256])
    rows, rates, mems = [], [], []
    base_mem = None
    for n in sizes:
        gc.collect()
        tracemalloc.start()
        env = gym.make_vec(REACH, num_envs=n, vectorization_mode="vector_entry_point")
        env.reset(seed=0)
        env.step(env.action_space.sample())
        mem = tracemalloc.get_traced_memory()[0]
        tracemalloc.stop()
        env.action_space.seed(0)
        acts = [env.action_space.sample() for _ in range(8)]
        calls = max(3, cfg.pick(4096, 1024) // n)
        t0, c0 = time.perf_counter(), time.process_time()
        for k in range(calls):
            env.step(acts[k % 8])
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        t1, c1 = time.perf_counter(), time.process_time()
        env.reset(seed=1)
        reset_s, reset_cpu = time.perf_counter() - t1, time.process_time() - c1
        env.close()
        rate = calls * n / cpu
        if base_mem is None:
            base_mem = mem
        per_copy = (mem - base_mem) / (n - 1) if n > 1 else float("nan")
        rates.append(rate)
        mems.append(mem)
        rows.append([n, f"{calls * n / wall:,.0f}", f"{rate:,.0f}", f"{mem / 1e6:.1f}",
                     "-" if n == 1 else f"{per_copy / 1e3:.1f}", f"{reset_s / n * 1e3:.3f}",
                     f"{reset_cpu / n * 1e3:.3f}"])
        cfg.log(f"  training: ReachLight x{n}: {rate:,.0f} env steps per CPU s, {mem / 1e6:.1f} MB")
    sec.tables.append(Table("scaling", "ReachLight batched (fast): copies vs throughput, memory and reset", [
        "copies", "env steps / wall s", "env steps / CPU s", "memory (MB)", "per extra copy (kB)",
        "reset per sub-env (ms wall)", "reset per sub-env (ms CPU)"], rows, notes=[
            "Memory: Python-traced allocations (tracemalloc, numpy included) after building, resetting and one "
            "step; per extra copy = (memory(N) - memory(1)) / (N - 1). Embree's scenes are held once, whatever N.",
            "Reset: `reset(seed=...)` of every sub-env (world seeds, start poses, device state, then the warm-up "
            "steps batched) divided by the copies; the built scene is reused, nothing is rebuilt. Most of it "
            "is creating each device's noise stream for the new world seed (SHA-256 + PCG64 seeding), as the "
            "single environment does."]))
    sec.plots.append(Plot("scaling", "ReachLight batched: env steps per CPU s vs copies", "copies", "env steps / CPU s",
                          [Series("ReachLight fast", [float(n) for n in sizes], rates)], logx=True, logy=True))
    sec.data["scaling"] = {"sizes": sizes, "cpu_rate": rates, "memory": mems}
    reset_wall, reset_cpu = float(rows[-1][-2]), float(rows[-1][-1])
    sec.targets.append(Target("reset per sub-env (scene reused)", "< 1 ms",
                              f"{reset_cpu:.3f} ms CPU, {reset_wall:.3f} ms wall at {sizes[-1]} copies",
                              reset_cpu < 1.0, "reset(seed) / copies, judged on CPU seconds"))


def _single_reset(cfg: Config, sec: Section, gym) -> None:
    env = gym.make(REACH, precision="fast")
    env.reset(seed=0)
    times = []
    for i in range(cfg.pick(10, 3)):
        t0 = time.perf_counter()
        env.reset(seed=i)
        times.append(time.perf_counter() - t0)
    env.close()
    sec.data["single_reset_s"] = median(times)
    sec.findings.append(f"A single environment's reset rebuilds its simulation: {median(times) * 1e3:.1f} ms "
                        "(median) here; a batched sub-env's reset reuses the built scene (table above).")


def run(cfg: Config) -> Section:
    sec = Section("training", "Training at scale: many worlds in one simulation", intro=(
        "The batched vector environment steps N copies of a world in one simulation: the static world built "
        "once, every copy's rays in one cast per ray kind, every device model run once over all copies, each "
        "sub-environment bit-identical to the single environment with its seed (tests/test_gym_vector.py). "
        "Reproduce: `sensorium bench --only training`."))
    try:
        import gymnasium as gym

        import sensorium.gym  # noqa: F401  (registers the ids)
    except ImportError as exc:
        sec.findings.append(f"skipped: {exc} (pip install '.[gym]')")
        return sec
    _throughput(cfg, sec, gym)
    _scaling(cfg, sec, gym)
    _single_reset(cfg, sec, gym)
    return sec

