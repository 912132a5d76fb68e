"""Scale-out: Gymnasium environment steps/s for 1, 2, 4, 8 vectorised environments (sync vs async),
sweep throughput (simulated seconds per wall second) on the local process pool vs Ray with the same
CPUs, and what each engine costs per run and per sweep.

Needs the ``[gym]`` and ``[ray]`` extras; a part whose library is missing is reported as skipped.
Ray is started bound to 127.0.0.1 with ``num_cpus`` = this machine's CPUs and shut down afterwards.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from .common import Config, Plot, Section, Series, Table, interleaved, median, pct

ENV_ID = "sensorium/ReachLight-v0"


class _Loop:
    """One Gymnasium setting kept alive across rounds: a plain env or a vector env of ``n``."""

    def __init__(self, gym, mode: str, n: int, seed: int):
        self.mode, self.n = mode, n
        if mode == "single":
            self.env = gym.make(ENV_ID)
            self.space = self.env.action_space
        else:
            cls = gym.vector.AsyncVectorEnv if mode == "async" else gym.vector.SyncVectorEnv
            self.env = cls([lambda: gym.make(ENV_ID) for _ in range(n)])
            self.space = self.env.action_space
        self.env.reset(seed=seed)
        self.space.seed(seed)

    def steps_per_s(self, env_steps: int) -> float:
        """Random actions for about ``env_steps`` environment steps; env steps per second."""
        calls = max(1, env_steps // self.n)
        t0 = time.perf_counter()
        for _ in range(calls):
            _, _, term, trunc, _ = self.env.step(self.space.sample())
            if self.mode == "single" and (term or trunc):
                self.env.reset()
        return calls * self.n / (time.perf_counter() - t0)

    def close(self) -> None:
        self.env.close()


def _gym_part(cfg: Config, sec: Section) -> None:
    try:
        import gymnasium as gym

        import sensorium.gym  # noqa: F401  (registers the ids)
    except ImportError as exc:
        sec.findings.append(f"Gymnasium part skipped: {exc} (pip install 'sensorium[gym]').")
        return
    chunk = cfg.pick(64, 16)
    rounds = cfg.pick(5, 2)
    sizes = [1, 2, 4, 8]
    loops = [_Loop(gym, "single", 1, 0)] + [_Loop(gym, m, n, 0) for n in sizes for m in ("sync", "async")]
    rates: dict[tuple[str, int], list[float]] = {(lp.mode, lp.n): [] for lp in loops}
    try:
        for lp in loops:
            lp.steps_per_s(lp.n)                  # warm-up: first observation paths, subprocess start
        # rounds of short chunks, the settings alternating: all see the same (shared) machine load
        for _ in range(rounds):
            for lp in loops:
                rates[(lp.mode, lp.n)].append(lp.steps_per_s(chunk))
    finally:
        for lp in loops:
            lp.close()
    med = {k: median(v) for k, v in rates.items()}
    single = med[("single", 1)]
    rows = [["single (no vector env)", 1, f"{single:.0f}", "-"]]
    series: dict[str, list[float]] = {"sync": [], "async": []}
    for n in sizes:
        for mode in ("sync", "async"):
            r = med[(mode, n)]
            series[mode].append(r)
            cfg.log(f"  scaleout: {mode} x{n}: {r:.0f} env steps/s")
            rows.append([mode, n, f"{r:.0f}", f"{r / single:.2f}"])
    sec.tables.append(Table("vector_envs", f"Environment steps/s, {ENV_ID} (random actions; one env step = 64 ms "
                            "simulated = 2 basic steps, 10 devices)", ["vector env", "envs", "env steps/s", "vs single"],
                            rows, notes=[f"Medians of {rounds} rounds; in each round every setting runs ~{chunk} env "
                                         "steps, the settings alternating so that all see the same machine load. "
                                         "async = one subprocess per environment."]))
    sec.plots.append(Plot("vector_envs", "Env steps/s vs vectorised environments", "environments", "env steps/s",
                          [Series(k, [float(n) for n in sizes], v) for k, v in series.items()], logx=True, logy=False))
    # what the Gymnasium wrapper adds to the simulation it steps (alternated, same machine load)
    import numpy as np

    from sensorium.gym.tasks import reach_light

    env = reach_light()
    env.reset(seed=0)
    act = np.array([3.0, 3.0], dtype=np.float32)
    times = interleaved({"env": lambda: env.step(act), "sim": lambda: env.sim.run(env.steps_per_action)},
                        rounds=cfg.pick(200, 20))
    env_ms, sim_ms = median(times["env"]) * 1e3, median(times["sim"]) * 1e3
    env_q, sim_q = pct(times["env"], 25) * 1e3, pct(times["sim"], 25) * 1e3
    sec.tables.append(Table("wrapper", "Gymnasium wrapper overhead per env step", ["", "median (ms)", "25th pct (ms)"], [
        ["env.step (action, 2 basic steps, observation, reward, termination)", f"{env_ms:.2f}", f"{env_q:.2f}"],
        ["sim.run(2) alone", f"{sim_ms:.2f}", f"{sim_q:.2f}"],
        ["wrapper overhead", f"{env_ms - sim_ms:+.2f}", f"{env_q - sim_q:+.2f}"]],
        notes=["Driving straight from the world pose; both timed in alternation. On a loaded machine the 25th "
               "percentile is closer to the undisturbed cost than the median."]))
    sec.data["wrapper_ms"] = {"env_step": env_ms, "sim_run": sim_ms, "env_step_p25": env_q, "sim_run_p25": sim_q}
    sec.data["single_env_steps_per_s"] = single
    sec.data["vector"] = {k: dict(zip(sizes, v)) for k, v in series.items()}
    best = max(max(v) for v in series.values())
    sec.findings.append(f"Gymnasium: {single:.0f} env steps/s for one {ENV_ID} environment; "
                        f"the best vectorised setting reached {best:.0f} env steps/s "
                        f"({best / single:.1f}x) on {_cpus()} CPUs; the wrapper costs {env_q - sim_q:+.2f} ms "
                        f"per step over the bare simulation (25th percentiles).")
    sec.findings.append(f"What this means for you: a training run of 1 million env steps spends about "
                        f"{1e6 / best / 3600:.1f} h in the simulator at the best vectorised setting here "
                        f"({1e6 / single / 3600:.1f} h with one environment); the policy's own time comes on top.")


def _cpus() -> int:
    from sensorium.sweep.engines import default_workers

    return default_workers()


def _sweep_part(cfg: Config, sec: Section) -> None:
    from sensorium.sweep import run_sweep
    from sensorium.sweep.engines import available, init_ray
    from sensorium.sweep.run import run_one
    from sensorium.sweep.spec import RunSpec

    workers = _cpus()
    duration = cfg.pick(2000, 320)
    runs = cfg.pick(4, 2) * workers
    heavy = {"worlds": ["default"], "seeds": {"start": 0, "count": runs}, "duration_ms": duration,
             "controllers": ["circle"]}
    tiny_n = cfg.pick(8, 4) * workers
    tiny = {"worlds": ["default"], "seeds": {"start": 0, "count": tiny_n}, "duration_ms": 32, "controllers": ["idle"],
            "record": False}
    # the floor: one tiny run in this process (imports already done by a first call)
    run_one(RunSpec(0, "default", 0, (), "idle", 32, None))
    t0 = time.perf_counter()
    for i in range(5):
        run_one(RunSpec(i, "default", i, (), "idle", 32, None))
    in_process = (time.perf_counter() - t0) / 5
    engines = ["local"] + (["ray"] if available("ray") else [])
    rounds = cfg.pick(3, 1)
    started_ray = False
    startup: dict[str, float] = {}
    tiny_s: dict[str, list[float]] = {e: [] for e in engines}
    big_s: dict[str, list[float]] = {e: [] for e in engines}
    sim_s = 0.0

    def check(res, engine):
        bad = [r for r in res.rows if r["status"] != "ok"]
        if bad:
            raise RuntimeError(f"{engine}: run failed: {bad[0]['error']}")
        return res

    try:
        for engine in engines:                       # start each engine's workers once
            extra = 0.0
            if engine == "ray":
                import ray

                started_ray = not ray.is_initialized()
                t0 = time.perf_counter()
                init_ray(None, workers)
                extra = time.perf_counter() - t0
            first = check(run_sweep(tiny, None, engine=engine, workers=workers, progress=False), engine)
            startup[engine] = extra + first.wall_s
        # then alternate the engines, so that both see the same machine load (it is shared)
        for _ in range(rounds):
            for engine in engines:
                with tempfile.TemporaryDirectory() as tmp:
                    tiny_s[engine].append(check(run_sweep(tiny, None, engine=engine, workers=workers,
                                                          progress=False), engine).wall_s)
                    big = check(run_sweep(heavy, Path(tmp) / "out", engine=engine, workers=workers, progress=False,
                                          formats=("csv",)), engine)
                big_s[engine].append(big.wall_s)
                sim_s = big.sim_time_s
    finally:
        from sensorium.sweep.engines import shutdown_pools

        shutdown_pools()
        if started_ray:
            import ray

            ray.shutdown()
    rows = []
    results: dict[str, dict] = {}
    for engine in engines:
        tiny_wall, big_wall = median(tiny_s[engine]), median(big_s[engine])
        per_run = tiny_wall * workers / tiny_n
        thr = sim_s / big_wall
        results[engine] = {"startup_s": startup[engine], "tiny_sweep_s": tiny_s[engine], "per_run_s": per_run,
                           "throughput": thr, "big_wall_s": big_s[engine], "sim_s": sim_s}
        cfg.log(f"  scaleout: {engine}: {thr:.2f} simulated s / wall s, {per_run * 1000:.0f} ms per run")
        rows.append([engine, workers, f"{startup[engine]:.1f}", f"{tiny_wall:.2f}", f"{per_run * 1000:.0f}",
                     f"{big_wall:.1f}", f"{thr:.2f}"])
    sec.tables.append(Table("sweep_engines", "Sweep engines on this machine", [
        "engine", "workers", "first sweep incl. startup (s)", f"{tiny_n} one-step runs (s)",
        "cost per run (ms CPU)", f"{runs} x {duration / 1000:g} s arena runs (s)", "simulated s per wall s"], rows, notes=[
        f"One-step runs: the arena world, 32 ms, no recording; cost per run = wall x workers / runs. The same run "
        f"in this process takes {in_process * 1000:.0f} ms: the rest is the engine's per-run overhead.",
        "Arena runs: both robots driving circles, every topic recorded to MCAP (all devices measured every step).",
        "Both engines keep their workers between sweeps of one Python process: the first column is paid once "
        "(`sensorium sweep` pays it on every command).",
        f"Medians of {rounds} rounds; the engines alternate within a round so that both see the same machine load.",
    ]))
    sec.data["sweep"] = results
    sec.data["in_process_run_s"] = in_process
    if "ray" in results:
        lo, ra = results["local"], results["ray"]
        sec.findings.append(
            f"Sweeps: {lo['throughput']:.2f} (pool) vs {ra['throughput']:.2f} (Ray) simulated s per wall s on "
            f"{workers} CPUs; per-run cost {lo['per_run_s'] * 1000:.0f} ms (pool) vs {ra['per_run_s'] * 1000:.0f} ms (Ray) "
            f"against {in_process * 1000:.0f} ms in-process; first sweep incl. startup {lo['startup_s']:.1f} s (pool) vs "
            f"{ra['startup_s']:.1f} s (Ray).")
        best = max(lo["throughput"], ra["throughput"])
        sec.findings.append(
            f"What this means for you: on this {workers}-CPU machine a sweep of 100 arena runs of 60 simulated "
            f"seconds takes about {100 * 60 / best / 60:.0f} min "
            + ("with either engine (within 10 % of each other here)"
               if min(lo["throughput"], ra["throughput"]) >= 0.9 * best
               else f"with the faster engine here ({'pool' if best == lo['throughput'] else 'Ray'})")
            + "; Ray pays off when a sweep spans several machines, the process pool on one.")


def run(cfg: Config) -> Section:
    sec = Section("scaleout", "Scale-out: vectorised Gymnasium environments and sweeps on Ray", intro=(
        "How many environment steps per second Gymnasium's vector environments get out of this machine, and "
        "what running many simulations costs on the local process pool and on Ray with the same CPUs "
        "(`sensorium sweep`). Reproduce: `sensorium bench --only scaleout`."))
    _gym_part(cfg, sec)
    _sweep_part(cfg, sec)
    return sec
