"""Packet traversal: Embree's ``rtcIntersect16`` instead of embreex's one ``rtcIntersect1`` per ray.

A small C file (``packets.c``) is compiled once per machine with the system C compiler into a cache
folder and loaded with ctypes; it opens the Embree library embreex itself loaded (embreex's wheel
carries Embree 4, whose ``rtcIntersect16`` embreex does not expose) and traces a batch in packets
of 16. Same library, same scenes, same float32 rays:

* incoherent packets (EXACT, scattered sensor rays) give embreex's answers bit for bit
  (tests/test_packets.py: plain and robust scenes, rays aimed at vertices and edges); measured on
  the warehouse lidar (131,072 rays, 110k triangles, one thread) ~1.2-1.3x embreex's rays/s;
* coherent packets (a FAST lidar scan: rays from one origin) traverse each node once per packet,
  ~3.4x embreex's rays/s, and differ from it only for rays within float32 rounding of an edge or a
  vertex: the neighbouring triangle of the same surface (within 32 float32 ulps of the distance)
  or, in FAST's plain (not watertight) scene, the other side of the edge (0 of the 131,072
  warehouse beams; ~1 % of rays aimed exactly at vertices and edges).

The same helper judges the hits of a pass where trace.py/refine.py would in numpy
(``sp_fast_pass``, ``sp_exact_pass``; see the engine docstring): compiled with
``-ffp-contract=off`` and without fast-math, each operation rounds as numpy's does, so the answers
are the numpy path's bit for bit (tests/test_native_judging.py).

Debian bookworm packages Embree 3.13 (libembree3-3): not needed, as embreex's Embree 4 offers the
same packet entry points.

Where there is no C compiler, no embreex-loaded Embree 4 library, or ``SENSORIUM_PACKETS=0``, the
engine casts through embreex as before (only slower); :func:`status` says which and why.
``SENSORIUM_EMBREE_LIB`` names another Embree 4 library, ``SENSORIUM_CACHE_DIR`` the cache folder.
"""

from __future__ import annotations

import ctypes
import gc
import hashlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import numpy as np

from sensorium.server.raycast import blocks

_SOURCE = Path(__file__).with_name("packets.c")
_lock = threading.Lock()
_state: dict = {}          # "lib": the loaded helper, or "why": the reason there is none; "embree": its path
_SCRATCH = 2048           # casts of up to this many rays write into a per-thread scratch buffer


def _cache_dir() -> Path:
    env = os.environ.get("SENSORIUM_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "sensorium"


def _embree_library() -> str | None:
    """The Embree 4 library embreex loaded (so both paths run the very same code), else the one
    its wheel carries, else a system one; ``SENSORIUM_EMBREE_LIB`` first."""
    env = os.environ.get("SENSORIUM_EMBREE_LIB")
    if env:
        return env
    import embreex
    from embreex import rtcore  # noqa: F401 - loads the library

    try:
        with open("/proc/self/maps") as maps:
            for line in maps:
                path = line.rstrip("\n").split(" ")[-1]
                if os.path.basename(path).startswith("libembree4"):
                    return path
    except OSError:
        pass
    here = Path(embreex.__file__).resolve().parent
    for folder in (here.parent / "embreex.libs", here / ".dylibs", here.parent / "embreex.dylibs", here):
        found = sorted(folder.glob("libembree4*")) if folder.is_dir() else []
        if found:
            return str(found[0])
    from ctypes.util import find_library

    return find_library("embree4")


def _compile(out: Path) -> str | None:
    """Compile packets.c into ``out`` (atomically: other processes may build the same file at the
    same time); the reason on failure."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        return "no C compiler (cc) on PATH"
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".so", dir=out.parent)
    os.close(fd)
    # no fused multiply-adds and no fast-math: the judging in C rounds every operation as numpy does
    cmd = [*cc.split(), "-O2", "-ffp-contract=off", "-fno-fast-math", "-shared", "-fPIC", "-pthread", "-o", tmp,
           str(_SOURCE), "-lm"]
    if sys.platform.startswith("linux"):
        cmd.append("-ldl")
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        if done.returncode != 0:
            lines = (done.stderr or done.stdout).strip().splitlines()
            return f"compiling packets.c failed: {lines[-1] if lines else done.returncode}"
        os.replace(tmp, out)
        return None
    except (OSError, subprocess.SubprocessError) as exc:
        return f"compiling packets.c failed: {exc}"
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def build_key() -> str:
    """The cached library's key: the source, the machine, its C library and Python. Not the kernel
    (``platform.platform()`` names it): a library built into an image (docker/Dockerfile) is found
    by the containers that run it on other kernels."""
    abi = f"{sys.platform}-{platform.machine()}-{'-'.join(platform.libc_ver())}-{sys.version}"
    return hashlib.sha256(_SOURCE.read_bytes() + abi.encode()).hexdigest()[:16]


def _load() -> None:
    if os.environ.get("SENSORIUM_PACKETS", "1") == "0":
        _state["why"] = "off (SENSORIUM_PACKETS=0)"
        return
    embree = _embree_library()
    if not embree:
        _state["why"] = "no Embree 4 library found beside embreex"
        return
    key = build_key()
    lib_path = None
    for folder in (_cache_dir(), Path(tempfile.gettempdir()) / f"sensorium-{os.getuid() if hasattr(os, 'getuid') else 0}"):
        path = folder / f"packets-{key}.so"
        if path.is_file():
            lib_path = path
            break
        try:
            why = _compile(path)
        except OSError as exc:   # an unwritable cache folder: try the next
            why = f"cannot write {folder}: {exc.strerror}"
        if why is None:
            lib_path = path
            break
        if why.startswith(("no C compiler", "compiling")):
            break
    if lib_path is None:
        _state["why"] = why
        return
    lib = ctypes.CDLL(str(lib_path))
    lib.sp_open.restype = ctypes.c_char_p
    lib.sp_open.argtypes = [ctypes.c_char_p]
    missing = lib.sp_open(embree.encode())
    if missing is not None:
        _state["why"] = f"{embree}: {missing.decode()} not found"
        return
    vp, sz, i = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int
    lib.sp_new_device.restype = vp
    lib.sp_release_device.argtypes = [vp]
    lib.sp_new_scene.restype = vp
    lib.sp_new_scene.argtypes = [vp, i, sz, vp, sz, vp, sz, vp, sz, vp, i]
    lib.sp_release_scene.argtypes = [vp]
    lib.sp_intersect.restype = None
    lib.sp_intersect.argtypes = [vp, sz, vp, sz, vp, vp, i, i]
    d = ctypes.c_double
    lib.sp_exact_pass.restype = None
    lib.sp_exact_pass.argtypes = [vp, vp, sz, vp, sz, vp, vp, vp, vp, sz, vp, vp, sz, vp, d, vp, vp, vp, vp]
    lib.sp_fast_pass.restype = sz
    f, i64 = ctypes.c_float, ctypes.c_int64
    lib.sp_fast_pass.argtypes = [vp, vp, sz, i, vp, sz, vp, i, f, vp, vp, f, i, vp, sz, vp, vp, vp, d, vp, d, i, vp, i64,
                                 i, i, vp, vp, vp, vp, i, sz, vp]
    lib.sp_set_worker_cpus.restype = i
    lib.sp_set_worker_cpus.argtypes = [sz, vp]
    lib.sp_probe_worker_cpus.restype = i
    lib.sp_probe_worker_cpus.argtypes = []
    cpus = blocks.process_cpus()        # sp_fast_pass's threads keep them, as the block workers do
    lib.sp_set_worker_cpus(len(cpus), (ctypes.c_int32 * max(1, len(cpus)))(*cpus))
    lib.sp_lidar_scan.restype = None
    lib.sp_lidar_scan.argtypes = [sz, vp, vp, d, f, vp, vp, vp, vp, vp]
    lib.sp_to_frame.restype = None
    lib.sp_to_frame.argtypes = [sz, vp, vp, vp, vp]
    lib.sp_cone.restype = sz
    lib.sp_cone.argtypes = [sz, vp, vp, d, vp]
    lib.sp_analytic.restype = None
    lib.sp_analytic.argtypes = [vp, sz, vp, vp, vp, vp, vp, vp, vp]
    lib.sp_sensor_rays.restype = None
    lib.sp_sensor_rays.argtypes = [sz, sz, sz] + [vp] * 12
    lib.sp_plane1.restype = sz
    lib.sp_plane1.argtypes = [sz, vp, sz, vp, i, d, i, vp, vp, vp, d, vp, d, i, vp, vp, vp, i, i64, vp, i64, i64, vp,
                              vp, vp]
    lib.sp_arc_steps.restype = sz
    lib.sp_arc_steps.argtypes = [sz, vp, vp, vp, vp, vp, d, vp, vp, vp, vp, vp]
    lib.sp_drive_moves.restype = sz
    lib.sp_drive_moves.argtypes = [sz, vp, vp, vp, vp, vp, vp, vp, vp, d, vp, vp, vp, vp, vp]
    lib.sp_cos_sin.restype = sz
    lib.sp_cos_sin.argtypes = [sz, vp, vp, vp]
    lib.sp_box3.restype = None
    lib.sp_box3.argtypes = [sz, vp, vp]
    lib.sp_inside_shells.restype = sz
    lib.sp_inside_shells.argtypes = [sz, vp, sz, vp, vp, d, sz, vp, vp, vp, vp, vp, vp, vp, i, vp, vp]
    lib.sp_copy_pairs.restype = sz
    lib.sp_copy_pairs.argtypes = [sz, sz, sz, vp, vp, vp, vp, vp, vp, vp, d, vp, d, vp, vp, i64, vp, i64, vp, vp]
    lib.sp_copy_cast.restype = i64
    lib.sp_copy_cast.argtypes = [vp]
    lib.sp_copy_finish.restype = i64
    lib.sp_copy_finish.argtypes = [vp]
    lib.sp_contact_near.restype = sz
    lib.sp_drive_wheels.restype = sz
    lib.sp_lidar_beams.restype = None
    lib.sp_lidar_beams.argtypes = [sz, sz, vp, vp, vp, vp, vp, vp, vp, vp]
    lib.sp_drive_wheels.argtypes = [sz, sz, sz, vp, vp, vp, vp, vp, d, vp, vp, vp, vp, vp, vp, vp, vp]
    lib.sp_contact_near.argtypes = [sz, sz, sz, vp, vp, vp, vp, vp, vp, vp, vp, vp, vp, vp, vp, vp, vp, d, d, vp, vp,
                                    vp]
    # the batched step's passes (DriveStep, lookup, atan2, the sonars, AvoidObstacles, the due scan,
    # the observation clip) and the batched kinematic devices' libm passes
    for name, restype, argtypes in (
            ("sp_drive_step", sz, [sz, vp, sz, vp, sz, sz, sz, d, d, d, i, vp, vp]),
            ("sp_pose_scatter", None, [sz, sz, vp, vp, vp, vp, vp, vp, vp, vp]),
            ("sp_lookup", None, [sz, vp, sz, vp, vp, vp, vp, vp]),
            ("sp_atan2", None, [sz, vp, sz, vp, sz, vp, sz]),
            ("sp_cross_norm", None, [sz, vp, vp, vp]),
            ("sp_sonar_nearest", None, [sz, sz, vp, vp, vp, d, vp]),
            ("sp_clearance_gaps", None, [sz, sz, vp, d, d, vp]),
            ("sp_avoid_reward", None, [sz, vp, sz, sz, vp, d, d, vp, d, d, d, vp]),
            ("sp_avoid_outcome", i, [sz, sz, vp, d, d, vp, sz, sz, sz, vp, d, d, d, d, d, vp, vp, vp]),
            ("sp_box_clip32", None, [sz, vp, f, f, vp]),
            ("sp_due", sz, [sz, sz, vp, vp, vp, vp, vp]),
            ("sp_roll_pitch_yaw", None, [sz, vp, i, vp]),
            ("sp_half_angles", sz, [sz, vp, vp]),
            ("sp_correlation_ratios", sz, [sz, vp, vp, vp]),
            ("sp_gyro", None, [sz, vp, d, vp]),
            ("sp_constrained_twists", sz, [sz, sz, vp, vp, vp, vp, vp, vp, sz, vp, vp])):
        func = getattr(lib, name)
        func.restype, func.argtypes = restype, argtypes
    _state["lib"] = lib
    _state["embree"] = embree


def library():
    """The loaded helper (built on first use), or None."""
    if not _state:
        with _lock:
            if not _state:
                try:
                    _load()
                except Exception as exc:  # noqa: BLE001 - any failure: the embreex path, with the reason
                    _state.clear()
                    _state["why"] = f"{type(exc).__name__}: {exc}"
    return _state.get("lib")


def status() -> str:
    """One line: which traversal casts the rays, and why."""
    if library() is not None:
        return f"Embree packets of 16 (rtcIntersect16) through {_state['embree']}"
    return f"embreex, one ray per call ({_state.get('why', 'packets unavailable')})"


def _ptr(a: np.ndarray | None) -> int | None:
    return None if a is None else a.ctypes.data


def padded(a: np.ndarray, dtype) -> np.ndarray:
    """``a`` as a C-contiguous array of ``dtype`` that a :class:`Scene` shares with Embree instead of
    copying it (Embree reads the last vertex with a 16-byte load: 16 bytes readable past the end)."""
    a = np.asarray(a)
    out = np.empty(a.size + 16 // np.dtype(dtype).itemsize, dtype=dtype)[:a.size].reshape(a.shape)
    out[...] = a
    return out


def _shareable(a: np.ndarray) -> bool:
    """True if ``a`` is a view with 16 bytes of its own buffer past its end (see :func:`padded`)."""
    b = a.base
    return (isinstance(b, np.ndarray) and a.flags.c_contiguous and b.flags.c_contiguous
            and b.ctypes.data <= a.ctypes.data and a.ctypes.data + a.nbytes + 16 <= b.ctypes.data + b.nbytes)


class Device:
    """An Embree device of the packet path."""

    def __init__(self) -> None:
        self.lib = library()
        self.handle = self.lib.sp_new_device()
        if not self.handle:
            # Debian's Embree 3 holds about 1,000 devices at once in a process; simulations no longer
            # used but not yet collected (reference cycles) still hold theirs: collect them, try again
            gc.collect()
            self.handle = self.lib.sp_new_device()
        if not self.handle:
            raise RuntimeError("Embree could not create another device (rtcNewDevice failed): each live "
                               "Simulation holds one, and Embree 3 allows about 1,000 in one process")

    def __del__(self) -> None:
        if getattr(self, "handle", None):
            self.lib.sp_release_device(self.handle)
            self.handle = None


class Scene:
    """A committed Embree scene (geometry 0: ``V``, ``F``; geometry 1, when given: ``V1``, ``F1``) with
    embreex's ``EmbreeScene.run(..., output=1)`` contract."""

    def __init__(self, device: Device, robust: bool, V: np.ndarray, F: np.ndarray, V1=None, F1=None) -> None:
        self.lib, self.device = device.lib, device   # the device outlives its scenes
        v0, f0 = np.ascontiguousarray(V, dtype=np.float32), np.ascontiguousarray(F, dtype=np.int32)
        v1 = None if V1 is None else np.ascontiguousarray(V1, dtype=np.float32)
        f1 = None if F1 is None else np.ascontiguousarray(F1, dtype=np.int32)
        # geometry 0's arrays shared with Embree where they allow it (the tier's, made with
        # `padded`: no second copy of the vertices and faces per scene), else copied; kept alive here
        shared = int(v0 is V and f0 is F and _shareable(v0) and _shareable(f0))
        self._shared = (v0, f0) if shared else ()
        self.handle = self.lib.sp_new_scene(device.handle, int(robust), len(v0), _ptr(v0), len(f0), _ptr(f0),
                                            0 if v1 is None else len(v1), _ptr(v1), 0 if f1 is None else len(f1),
                                            _ptr(f1), shared)
        if not self.handle:
            raise RuntimeError("Embree could not build the scene")
        self._local = threading.local()   # per thread: scratch buffer, last directions array

    def __del__(self) -> None:
        if getattr(self, "handle", None):
            self.lib.sp_release_scene(self.handle)
            self.handle = None

    def run(self, origins: np.ndarray, directions: np.ndarray, dists=None, output=1, coherent=False) -> dict:
        """Nearest hits (see embreex): ``origins`` (n,3) float32, possibly one broadcast row;
        ``directions`` (n,3) float32; ``dists`` the far limits: None (1e37), a number or an (n,)
        array (not written: the distances come back in a new array). ``output`` 0: only "tfar" and
        "primID". A small cast's fixed cost is mostly the ctypes pointers: a few rays use a
        per-thread scratch buffer whose address is known, and the directions array of the last call
        (a lidar's kept beams) keeps its address too."""
        n = len(directions)
        d = directions if directions.flags.c_contiguous and directions.dtype == np.float32 else \
            np.ascontiguousarray(directions, dtype=np.float32)
        one = origins.strides[0] == 0 and origins.dtype == np.float32
        words = 8 * n if output else 2 * n
        local = self._local
        if d is getattr(local, "d", None):
            d_ptr = local.d_ptr
        else:
            local.d, local.d_ptr = d, d_ptr = d, d.ctypes.data
        small = n <= _SCRATCH
        if small:   # outputs and the one origin in the thread's scratch buffer, copied out after
            buf = getattr(local, "buf", None)
            if buf is None:
                arr = np.empty(8 * _SCRATCH + 4, dtype=np.float32)
                local.buf = buf = (arr, arr.ctypes.data)
            out, out_ptr = buf[0][:words], buf[1]
        else:
            out = np.empty(words, dtype=np.float32)
            out_ptr = out.ctypes.data
        if one and small:
            buf[0][words:words + 3] = origins[0]
            o_ptr, stride = out_ptr + 4 * words, 0
        elif one:
            o_ptr, stride = origins.ctypes.data, 0
        else:
            o = np.ascontiguousarray(origins, dtype=np.float32)
            o_ptr, stride = o.ctypes.data, 3
        tfar = out[:n]
        tfar[:] = 1e37 if dists is None else dists
        if n:
            self.lib.sp_intersect(self.handle, n, o_ptr, stride, d_ptr, out_ptr, 1 if output else 0, 1 if coherent else 0)
        if small:
            out = out.copy()
            tfar = out[:n]
        res = {"tfar": tfar, "primID": out[n:2 * n].view(np.int32)}
        if output:
            res.update(geomID=out[2 * n:3 * n].view(np.int32), u=out[3 * n:4 * n], v=out[4 * n:5 * n],
                       Ng=out[5 * n:].reshape(n, 3))
        return res


class CopyJob(ctypes.Structure):
    """``struct sp_copy_job`` of packets.c: one batched cast's arguments, scratch and results for
    ``sp_copy_cast`` / ``sp_copy_finish`` (copies.py's lean path; every field 8 bytes)."""

    _fields_ = [(name, ctypes.c_double if kind == "d" else ctypes.c_int64 if kind == "i" else ctypes.c_void_p)
                for name, kind in (
                    ("n", "i"), ("O", "p"), ("D", "p"), ("d32", "p"), ("d32_buf", "p"), ("near", "d"), ("far", "p"),
                    ("far_value", "d"), ("distance_only", "i"), ("coherent", "i"), ("threads", "i"), ("n_rows", "i"),
                    ("rows", "p"),
                    ("plane", "i"), ("axis", "i"), ("c", "d"), ("visual", "i"), ("pt", "p"), ("nz", "p"), ("sized", "i"),
                    ("ax", "p"), ("ay", "p"), ("half", "p"), ("sid", "i"),
                    ("scene", "p"), ("T", "p"), ("radius", "d"), ("n_shells", "i"), ("shell_c", "p"),
                    ("shell_bound", "p"),
                    ("lim", "p"), ("far32", "p"), ("st_t", "p"), ("st_s", "p"), ("st_n", "p"), ("special", "p"),
                    ("t", "p"), ("s", "p"), ("nrm", "p"),
                    ("C", "i"), ("R", "i"), ("run", "i"), ("copy", "p"), ("rot", "p"), ("pos", "p"), ("anchor", "p"),
                    ("r2", "p"), ("present", "p"), ("centre", "p"), ("excl", "p"), ("excl_value", "i"), ("mnt", "p"),
                    ("mnt_value", "i"), ("out_ray", "p"), ("out_body", "p"),
                    ("big", "d"), ("eps64", "d"), ("plane_hits", "i"), ("n_hit", "i"), ("n_special", "i"),
                    ("into_out", "i"), ("n_pairs", "i"))]


class TierArrays(ctypes.Structure):
    """``struct sp_tier`` of packets.c: pointers to a tier's arrays (see :func:`tier_arrays`)."""

    _fields_ = [(name, ctypes.c_void_p) for name in (
        "normal", "g1", "g2", "h_min", "V", "F", "tri_slot", "tri_shape", "tri_owner", "c_code", "c_r", "c_h",
        "c_rot", "c_pos", "c_shape", "c_isolated")] + [("eps", ctypes.c_double), ("ng_max", ctypes.c_double),
                                                       ("guarded", ctypes.c_int64)] + [
        (name, ctypes.c_void_p) for name in ("ring_vptr", "ring_tri", "guard_ptr", "guard_idx")] + [
        ("n_tri", ctypes.c_int64), ("prism_triangles", ctypes.c_int64), ("grow", ctypes.c_double),
        ("bare", ctypes.c_void_p)]


def tier_arrays(tier, exact: bool):
    """(struct, address, arrays kept alive) describing ``tier`` (a :class:`.tiers._Tier`) to the
    judging passes of packets.c; ``exact``: with the float64 refinement data it reads (the dual
    basis, the vertex rings, the guards' lists). The tier's own arrays, never copies: each already
    has the dtype C reads (a mismatch is a bug, not a conversion that would double the memory)."""
    keep = []

    def ptr(a, dtype):
        if a.dtype != dtype or not a.flags.c_contiguous:
            raise TypeError(f"tier array of {a.dtype} {a.shape} where packets.c reads contiguous {np.dtype(dtype)}")
        keep.append(a)
        return a.ctypes.data

    f64, i32, i64 = np.float64, np.int32, np.int64
    isolated = np.ascontiguousarray(tier.c_isolated, dtype=np.uint8)   # one byte per curved shape
    keep.append(isolated)
    st = TierArrays(
        normal=ptr(tier.normal, f64), V=ptr(tier.V, f64), F=ptr(tier.F, i32), tri_slot=ptr(tier.tri_slot, i32),
        tri_shape=ptr(tier.tri_shape, i64), tri_owner=ptr(tier.tri_owner, i32),
        c_code=ptr(tier.c_code, i64), c_r=ptr(tier.c_r, f64), c_h=ptr(tier.c_h, f64),
        c_rot=ptr(tier.c_rot, f64), c_pos=ptr(tier.c_pos, f64), c_shape=ptr(tier.c_shape, i64),
        c_isolated=isolated.ctypes.data, eps=tier.eps, ng_max=tier.ng_max,
        guarded=int(exact and tier.guard is not None))
    if exact:
        from sensorium.server.raycast.guards import PRISM_TRIANGLES

        st.g1, st.g2, st.h_min = ptr(tier.g1, f64), ptr(tier.g2, f64), ptr(tier.h_min, f64)
        st.ring_vptr, st.ring_tri = ptr(tier.ring.vptr, i64), ptr(tier.ring.tri_of, i32)
        st.n_tri, st.prism_triangles, st.grow = len(tier.F), PRISM_TRIANGLES, tier.eps + 8.0 * tier.res
        guard = tier.guard
        if guard is not None:
            st.guard_ptr, st.guard_idx = ptr(guard[1], i64), ptr(guard[2], i64)
            bare = tier.bare_scene()
            keep.append(bare)
            st.bare = bare.handle
    return st, ctypes.addressof(st), keep


_tls = threading.local()


class Scratch:
    """A thread's buffers for the judging passes of small casts (up to ``_SCRATCH`` rays): outputs
    and one-origin rows at addresses known once, so a call converts no array to a pointer."""

    def __init__(self) -> None:
        n = _SCRATCH
        self.t, self.s, self.n = np.empty(n), np.empty(n, dtype=np.int64), np.empty((n, 3))
        self.sp, self.rows = np.empty(n, dtype=np.uint8), np.empty(n, dtype=np.int64)
        self.o1, self.origin = np.empty(3, dtype=np.float32), np.empty(3)
        self.p_t, self.p_s, self.p_n, self.p_sp, self.p_rows, self.p_o1, self.p_origin = (
            a.ctypes.data for a in (self.t, self.s, self.n, self.sp, self.rows, self.o1, self.origin))


def scratch() -> Scratch:
    """This thread's :class:`Scratch`."""
    sc = getattr(_tls, "scratch", None)
    if sc is None:
        sc = _tls.scratch = Scratch()
    return sc


SCRATCH = _SCRATCH


def _pair_buffers(size: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Two int64 buffers of at least ``size`` entries (and their addresses) that a pair-listing
    pass writes before its answer is copied out: this thread's, reused call after call up to
    ``_PAIR_BUFFER`` entries (a 64-copy lidar scan's fresh (rays x slots) arrays, 0.7 MB, cost
    ~30 us a call in page faults), fresh ones beyond."""
    if size > _PAIR_BUFFER:
        a, b = np.empty(size, dtype=np.int64), np.empty(size, dtype=np.int64)
        return a, b, a.ctypes.data, b.ctypes.data
    got = getattr(_tls, "pairs", None)
    if got is None or len(got[0]) < size:
        m = max(size, 4096)
        a, b = np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int64)
        got = _tls.pairs = (a, b, a.ctypes.data, b.ctypes.data)
    return got


_PAIR_BUFFER = 1 << 20


def address(a: np.ndarray) -> int:
    """``a.ctypes.data`` (~1 us), remembered for the last few small arrays this thread passed (a
    lidar's beams, cast scan after scan); those arrays are kept alive meanwhile."""
    if a.nbytes > 65536:   # large arrays: not kept (the conversion is small beside their cast)
        return a.ctypes.data
    cache = getattr(_tls, "addresses", None)
    if cache is None:
        cache = _tls.addresses = {}
    got = cache.get(id(a))
    if got is not None and got[0] is a:
        return got[1]
    p = a.ctypes.data
    if len(cache) >= 8:
        cache.clear()
    cache[id(a)] = (a, p)
    return p


def cone_rows(D: np.ndarray, v: np.ndarray, thr: float) -> np.ndarray | None:
    """Indices of the rows of the (n,3) float64 directions D with D . v >= thr (one pass in C), or
    None without the helper."""
    lib = library()
    if lib is None or D.dtype != np.float64 or not D.flags.c_contiguous:
        return None
    n = len(D)
    sc = scratch()
    sc.origin[:] = v
    if len(sc.rows) < n:   # grown to the largest batch seen (a lidar's): no new pages per scan
        sc.rows = np.empty(n, dtype=np.int64)
        sc.p_rows = sc.rows.ctypes.data
    k = lib.sp_cone(n, address(D), sc.p_origin, float(thr), sc.p_rows)
    return sc.rows[:k].copy()


def to_frame_rows(x: np.ndarray, rows: np.ndarray, R: np.ndarray) -> np.ndarray | None:
    """``exact._to_frame(x.take(rows, axis=0), R)`` in one C pass (the same sums, the same bits), or
    None without the helper."""
    lib = library()
    if lib is None or x.dtype != np.float64 or not x.flags.c_contiguous or rows.dtype != np.int64:
        return None
    out = np.empty((len(rows), 3))
    rr = np.ascontiguousarray(rows)
    Rc = np.ascontiguousarray(R, dtype=np.float64)
    lib.sp_to_frame(len(rows), address(x), rr.ctypes.data, Rc.ctypes.data, out.ctypes.data)
    return out


def _check_buffer(func: str, a: np.ndarray, dtype, shape: tuple, writes: bool = False) -> None:
    """TypeError unless ``a`` is the C-contiguous ``dtype`` array of ``shape`` the C pass ``func``
    reads (or, ``writes``, writes: then also writable)."""
    want = np.dtype(dtype)
    if a.dtype == want and a.shape == shape and a.flags.c_contiguous and (a.flags.writeable or not writes):
        return
    if writes:
        raise TypeError(f"{func}: writes contiguous {want} {shape}, not {a.dtype} {a.shape}"
                        + ("" if a.flags.writeable else " (read-only)"))
    raise TypeError(f"{func}: {a.dtype} {a.shape} where it reads contiguous {want} {shape}")


def lidar_scan(dist: np.ndarray, lo: float, hi: float, ranges: np.ndarray, columns=None, xyz: np.ndarray | None = None,
               factor: np.ndarray | None = None, threads: int = 1) -> bool:
    """A fixed lidar's range image and point coordinates from its beams' distances in one C pass
    (``sp_lidar_scan``): ``ranges`` (n,) float32 receives ``ranges_from_hits`` without noise or
    resolution (``factor``: a planar lidar's depth factors), ``xyz`` (n, 3) float32, when given,
    ``point_xyz`` of those ranges along ``columns`` (three (n,) float64 columns); the same bits.
    Large scans in blocks on ``threads`` threads (the GIL is released during each call). False
    without the helper (nothing written)."""
    lib = library()
    if lib is None:
        return False
    n = len(dist)
    arrays = [dist, factor, ranges, xyz, *(columns if xyz is not None else (None, None, None))]
    for a, dtype, shape, writes in zip(arrays, (np.float64, np.float64, np.float32, np.float32, np.float64, np.float64,
                                                np.float64), ((n,), (n,), (n,), (n, 3), (n,), (n,), (n,)),
                                       (False, False, True, True, False, False, False)):
        if a is not None:
            _check_buffer("lidar_scan", a, dtype, shape, writes)
    p_d, p_f, p_r, p_x, p_cx, p_cy, p_cz = (None if a is None else a.ctypes.data for a in arrays)
    hi32 = float(np.float32(hi))

    def part(sl: slice) -> None:
        a, m = sl.start, sl.stop - sl.start
        lib.sp_lidar_scan(m, p_d + 8 * a, None if p_f is None else p_f + 8 * a, lo, hi32,
                          *((None, None, None) if p_x is None else (p_cx + 8 * a, p_cy + 8 * a, p_cz + 8 * a)),
                          p_r + 4 * a, None if p_x is None else p_x + 12 * a)

    blocks.run(part, blocks.split(n, threads, 1 << 16), threads)
    return True


def copy_pairs(O: np.ndarray, D: np.ndarray, copy: np.ndarray, centre: np.ndarray, r2: np.ndarray,
               present: np.ndarray, lo, far, excl, mount, dist: np.ndarray, run: int = 0
               ) -> tuple[np.ndarray, np.ndarray] | None:
    """The broad phase of :meth:`.copies.CopyRays.cast` in one C pass (``sp_copy_pairs``): the
    (ray, copy * R + slot) pairs whose ray comes within the bounding sphere (``centre`` (C, R, 3),
    ``r2`` (R,)) of a present slot of its own copy, its excluded and mount slots left out, listed
    slot by slot and ray by ray as the numpy path (``copies._pairs``) lists them; or None without
    the helper. ``lo``, ``excl``, ``mount``: scalars or (n,) arrays; ``far`` the rays' far limits
    (a scalar or (n,)) and ``dist`` (n,) their static hits: each ray's limit is
    ``np.minimum(far, dist)``, made in the pass (no (n,) temporary). ``run`` > 0: the rays come in
    runs of ``run`` consecutive rays sharing one origin and one copy (the last may be shorter):
    the same pairs, with each run's origin worked out once (a run the spheres are far from is
    passed over whole)."""
    lib = library()
    if lib is None:
        return None
    n = len(O)
    R = int(r2.shape[0])
    f64, i64 = np.float64, np.int64
    O, D = np.ascontiguousarray(O, dtype=f64), np.ascontiguousarray(D, dtype=f64)
    copy = np.ascontiguousarray(copy, dtype=i64)
    centre = np.ascontiguousarray(centre, dtype=f64)
    r2 = np.ascontiguousarray(r2, dtype=f64)
    present = np.ascontiguousarray(present, dtype=np.uint8)
    dist = np.ascontiguousarray(dist, dtype=f64)
    if dist.shape != (n,):
        raise TypeError(f"copy_pairs: static hits of shape {dist.shape} for {n} rays")
    lim = None
    if isinstance(far, np.ndarray) and far.ndim:
        lim = np.ascontiguousarray(far, dtype=f64)
        if lim.shape != (n,):
            raise TypeError(f"copy_pairs: limits of shape {lim.shape} for {n} rays")
    lo_a = np.ascontiguousarray(lo, dtype=f64) if isinstance(lo, np.ndarray) else None
    ex_a = np.ascontiguousarray(excl, dtype=i64) if isinstance(excl, np.ndarray) else None
    mn_a = np.ascontiguousarray(mount, dtype=i64) if isinstance(mount, np.ndarray) else None
    out_ray, out_body, p_ray, p_body = _pair_buffers(n * R)
    p_O, p_D, p_copy, p_centre, p_r2, p_present, p_dist = _small_addresses((O, D, copy, centre, r2, present, dist))
    k = lib.sp_copy_pairs(n, R, max(0, int(run)), p_O, p_D, p_copy, p_centre, p_r2, p_present, _ptr(lo_a),
                          0.0 if lo_a is not None else float(lo), _ptr(lim), 0.0 if lim is not None else float(far),
                          p_dist, _ptr(ex_a), 0 if ex_a is not None else int(excl), _ptr(mn_a),
                          0 if mn_a is not None else int(mount), p_ray, p_body)
    return out_ray[:k].copy(), out_body[:k].copy()


def sensor_rays(copies: np.ndarray, slots: np.ndarray, rot: np.ndarray, pos: np.ndarray, pi: np.ndarray,
                local_rot: np.ndarray, local_pos: np.ndarray, k: np.ndarray, local_dirs: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The world rays of S distance sensors in one C pass (``sp_sensor_rays``): (positions (S, 3),
    origins (S * N, 3), directions (S, N, 3)), bit for bit the numpy path of
    :meth:`.batched.BatchedSimulation._plan_distances` (``batches._frames_t``, ``_rotate_t``). Sensor s
    is on slot ``slots[s]`` of copy ``copies[s]`` (``rot`` (C, R, 3, 3), ``pos`` (C, R, 3)) with local
    frame ``pi[s]`` (``local_rot`` (P, 3, 3), ``local_pos`` (P, 3)) and ray directions ``k[s]``
    (``local_dirs`` (G, N, 3)); every index must lie within its array. None without the helper."""
    lib = library()
    if lib is None:
        return None
    f64, i64 = np.float64, np.int64
    S = len(copies)
    C, R = rot.shape[:2]
    G, N = local_dirs.shape[:2]
    for a, shape in ((rot, (C, R, 3, 3)), (pos, (C, R, 3)), (local_rot, (len(local_rot), 3, 3)),
                     (local_pos, (len(local_rot), 3)), (local_dirs, (G, N, 3))):
        _check_buffer("sensor_rays", a, f64, shape)
    idx = [np.ascontiguousarray(a, dtype=i64) for a in (copies, slots, pi, k)]
    if any(a.shape != (S,) for a in idx):
        raise TypeError("sensor_rays: inconsistent shapes")
    positions, origins, dirs = np.empty((S, 3)), np.empty((S * N, 3)), np.empty((S, N, 3))
    p = _small_addresses([*idx, rot, pos, local_rot, local_pos, local_dirs, positions, origins, dirs])
    lib.sp_sensor_rays(S, N, R, p[0], p[1], p[4], p[5], p[2], p[6], p[7], p[3], p[8], p[9], p[10], p[11])
    return positions, origins, dirs


def plane1(pl, O: np.ndarray, D: np.ndarray, lo, hi, excl, check_owner: bool, distance_only: bool):
    """:func:`.planes.cast_planes` for one axis-aligned plane (``pl.axis >= 0``) in one C pass
    (``sp_plane1``): its (dist, shape, normal) (shape and normal None with ``distance_only``), None
    when no ray passes its tests, bit for bit; ``lo`` = max(t_near, eps64) and ``hi`` = t_far
    (scalars or (n,)); ``check_owner``: rays skip the plane where it belongs to ``excl`` (cast_planes
    decides); or False without the helper (the caller's numpy path)."""
    lib = library()
    if lib is None or D.dtype != np.float64 or O.dtype != np.float64:
        return False
    n = len(D)
    f64 = np.float64
    if O.strides[0] == 0:
        O, o_stride = np.ascontiguousarray(O[:1]), 0
    else:
        O, o_stride = np.ascontiguousarray(O), 3
    D = np.ascontiguousarray(D)
    lo_a = np.ascontiguousarray(lo, dtype=f64) if isinstance(lo, np.ndarray) else None
    hi_a = np.ascontiguousarray(hi, dtype=f64) if isinstance(hi, np.ndarray) else None
    ex_a = np.ascontiguousarray(excl, dtype=np.int64) if check_owner and isinstance(excl, np.ndarray) else None
    dist = np.empty(n)
    shape = None if distance_only else np.empty(n, dtype=np.int64)
    normal = None if distance_only else np.empty((n, 3))
    p_pt, p_nz, p_ax, p_ay, p_half = pl.native_rows()   # the plane's rows, contiguous
    p = _small_addresses([O, D, dist])
    k = lib.sp_plane1(n, p[0], o_stride, p[1], pl.axis, float(pl.nz[0, pl.axis]), 1 if pl.visual else 0, p_pt, p_nz,
                      _ptr(lo_a), 0.0 if lo_a is not None else float(lo), _ptr(hi_a),
                      0.0 if hi_a is not None else float(hi), 1 if pl.sized else 0, p_ax, p_ay, p_half,
                      1 if check_owner else 0, int(pl.owner[0]), _ptr(ex_a),
                      0 if ex_a is not None or not check_owner else int(excl), int(pl.sid[0]), p[2], _ptr(shape),
                      _ptr(normal))
    if not k:
        return None
    return dist, shape, normal


def cos_sin(a: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(cos, sin) of each element of the (n,) float64 array ``a`` through libm's ``cos`` and ``sin``,
    the functions ``math.cos`` and ``math.sin`` call (``sp_cos_sin``: the same bits as calling them
    element by element, without the Python floats); None without the helper, for another array, or
    when an angle is infinite (``math.cos`` refuses it: the caller's Python way says so)."""
    lib = library()
    if lib is None or a.dtype != np.float64 or a.ndim != 1:
        return None
    a = np.ascontiguousarray(a)
    c, s = np.empty(len(a)), np.empty(len(a))
    if lib.sp_cos_sin(len(a), *_small_addresses((a, c, s))):
        return None
    return c, s


def analytic(tier, slots: np.ndarray, O: np.ndarray, D: np.ndarray, lo: np.ndarray, hi: np.ndarray, normals: bool
             ) -> tuple[np.ndarray, np.ndarray | None] | None:
    """``refine._analytic`` (the true-surface hit of curved shapes, tier-frame rays: (t, tier-frame
    unit normal or None without ``normals``)) in one C pass (``sp_analytic``, the judging passes'
    own: the same bits, tests/test_native_judging.py), for the few rays the general loop refines
    in FAST (~40 numpy calls a ray otherwise); None without the helper or the tier's struct."""
    lib = library()
    st = tier.native(False) if lib is not None else None
    if st is None:
        return None
    f64 = np.float64
    m = len(slots)
    s64 = np.ascontiguousarray(slots, dtype=np.int64)
    O, D = np.ascontiguousarray(O, dtype=f64), np.ascontiguousarray(D, dtype=f64)
    lo = np.ascontiguousarray(np.broadcast_to(np.asarray(lo, dtype=f64), (m,)))
    hi = np.ascontiguousarray(np.broadcast_to(np.asarray(hi, dtype=f64), (m,)))
    if O.shape != (m, 3) or D.shape != (m, 3):
        raise TypeError(f"analytic: rays of shapes {O.shape}, {D.shape} for {m} slots")
    t = np.empty(m)
    n = np.empty((m, 3)) if normals else None
    lib.sp_analytic(st, m, s64.ctypes.data, O.ctypes.data, D.ctypes.data, lo.ctypes.data, hi.ctypes.data,
                    t.ctypes.data, _ptr(n))
    return t, n


def arc_steps(x: np.ndarray, y: np.ndarray, yaw: np.ndarray, v: np.ndarray, w: np.ndarray, dt: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """:func:`.batched._arc_steps` and the new yaws' cos and sin (the poses' Rz, ``_cos_sin``) in one C
    pass (``sp_arc_steps``): (x, y, yaw, cos yaw, sin yaw) of n robots, the numpy path's bits (its
    operations element by element, libm's cos/sin as math.cos/math.sin, numpy's remainder); None
    without the helper, for other arrays, or when an angle is infinite (math.cos refuses it: the
    caller's Python way says so)."""
    lib = library()
    if lib is None:
        return None
    n = len(x)
    ins = []
    for a in (x, y, yaw, v, w):
        if a.dtype != np.float64 or a.shape != (n,):
            return None
        ins.append(np.ascontiguousarray(a))
    outs = [np.empty(n) for _ in range(5)]
    p = _small_addresses(ins + outs)
    if lib.sp_arc_steps(n, *p[:5], float(dt), *p[5:]):
        return None
    return outs[0], outs[1], outs[2], outs[3], outs[4]


def drive_moves(slots: np.ndarray, centre: np.ndarray | None, x: np.ndarray, y: np.ndarray, yaw: np.ndarray,
                v: np.ndarray, w: np.ndarray, dt: float,
                mid: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Two-wheel robots' moves in one C pass (``sp_drive_moves``, :class:`DriveStep`'s): move i of
    robot slot ``slots[i]`` by its arc about its origin (:func:`.batched._arc_steps`), or, when
    ``centre[slot]`` (``centre``: (R, 2) float64, or None for none) is off its origin, by the
    origin's body twist (v + w cy, -w cx, w) (:func:`.batched_holonomic.twist_steps`), or, when
    ``mid[slot]`` (``mid``: (R,) uint8, or None for none) is set, by the straight segment along the
    mid-step heading (:func:`.batched._mid_heading_steps`, ``step_rule: mid_heading``): the new
    (x, y, yaw), the numpy path's bits; None without the helper or when an angle is infinite
    (math.cos refuses it: the caller's numpy way says so)."""
    lib = library()
    if lib is None:
        return None
    n = len(x)
    ins = [np.ascontiguousarray(a, dtype=np.float64) for a in (x, y, yaw, v, w)]
    if any(a.shape != (n,) for a in ins) or len(slots) != n:
        raise TypeError("drive_moves: inconsistent shapes")
    slots = np.ascontiguousarray(slots, dtype=np.int64)
    if centre is not None:
        _check_buffer("drive_moves", centre, np.float64, centre.shape[:1] + (2,))
        if n and (slots.min() < 0 or slots.max() >= len(centre)):
            raise IndexError("drive_moves: a slot beyond the centres")
    if mid is not None:
        _check_buffer("drive_moves", mid, np.uint8, mid.shape[:1])
        if n and (slots.min() < 0 or slots.max() >= len(mid)):
            raise IndexError("drive_moves: a slot beyond the mid_heading flags")
    outs = [np.empty(n) for _ in range(5)]
    p = _small_addresses([slots, *ins, *outs])
    if lib.sp_drive_moves(n, p[0], _ptr(centre), _ptr(mid), *p[1:6], float(dt), *p[6:]):
        return None
    return outs[0], outs[1], outs[2]


def box3(O: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(each column's minimum, maximum) of the rows of a C-contiguous float64 (n, 3) array, n >= 1,
    in one C pass (``sp_box3``: numpy's min and max, NaN propagated); None without the helper or
    for another array."""
    lib = library()
    if lib is None or O.dtype != np.float64 or O.ndim != 2 or O.shape[1] != 3 or not len(O) \
            or not O.flags.c_contiguous:
        return None
    out = np.empty(6)
    lib.sp_box3(len(O), O.ctypes.data, out.ctypes.data)
    return out[:3], out[3:]


def inside_shells(tier, Ot: np.ndarray, D: np.ndarray, lo, shells, bound_first: bool = False
                  ) -> tuple[np.ndarray, np.ndarray] | None:
    """``refine._inside_shell`` of the start points ``Ot + lo D`` for each listed curved slot of
    ``tier``, in one C pass (``sp_inside_shells``): (rows, slots), slot by slot, rows ascending, the
    numpy loop's pairs; or None without the helper. ``Ot`` may be one broadcast origin.
    ``bound_first``: the start point must also lie in the slot's bounding sphere (the dense pass's
    test before the extent)."""
    lib = library()
    if lib is None:
        return None
    m = len(Ot)
    f64, i64 = np.float64, np.int64
    if Ot.strides[0] == 0:
        O, o_stride = np.ascontiguousarray(Ot[:1], dtype=f64), 0
    else:
        O, o_stride = np.ascontiguousarray(Ot, dtype=f64), 3
    D = np.ascontiguousarray(D, dtype=f64)
    lo_a = np.ascontiguousarray(lo, dtype=f64) if isinstance(lo, np.ndarray) else None
    kept = tier.__dict__.get("_native_shells")
    if kept is None:   # the tier's shells never change: their arrays and addresses made once
        arrays = [np.ascontiguousarray(getattr(tier, name), dtype=dt) for name, dt in (
            ("c_code", i64), ("c_pos", f64), ("c_rot", f64), ("c_bound2", f64), ("c_rad2", f64), ("c_ax", f64))]
        every = np.arange(len(arrays[0]), dtype=i64)
        kept = tier._native_shells = (arrays, every, [a.ctypes.data for a in (every, *arrays)])
    every, ptrs = kept[1], kept[2]
    if isinstance(shells, range) and shells == range(len(every)):   # every shell (the dense pass)
        ks, p_ks = every, ptrs[0]
    else:
        ks = np.asarray(shells, dtype=i64)
        p_ks = ks.ctypes.data
    out_row, out_slot, p_row, p_slot = _pair_buffers(m * len(ks))
    p = _small_addresses([O, D])
    k = lib.sp_inside_shells(m, p[0], o_stride, p[1], _ptr(lo_a), 0.0 if lo_a is not None else float(lo), len(ks),
                             p_ks, *ptrs[1:], 1 if bound_first else 0, p_row, p_slot)
    return out_row[:k].copy(), out_slot[:k].copy()


def _small_addresses(arrays) -> list[int]:
    """The data addresses of the small arrays a batched pass reads and writes, step after step:
    ``a.ctypes.data`` costs ~3 us an array, a ctypes view of an array owning its writable buffer
    ~1 us. Views (a broadcast view would warn on a writable export), read-only and empty arrays
    take the first way."""
    out = []
    for a in arrays:
        if a.flags.owndata:
            try:
                out.append(ctypes.addressof(_BYTE.from_buffer(a)))
                continue
            except (TypeError, ValueError, BufferError):
                pass
        out.append(a.ctypes.data)
    return out


_BYTE = ctypes.c_char
pair_buffers = _pair_buffers         # (copies.py's lean path fills them through sp_copy_cast)
addresses = _small_addresses


def contact_near(copies: np.ndarray, slots: np.ndarray, starts: np.ndarray, reach: np.ndarray,
                 foot_radius: np.ndarray, foot_low: np.ndarray, foot_high: np.ndarray, heights: np.ndarray,
                 centres: np.ndarray, grow: np.ndarray, lo: np.ndarray, hi: np.ndarray, zlo: np.ndarray,
                 zhi: np.ndarray, eps: float, floor: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The contact broad phase of :meth:`.batched.BatchedSimulation._contact` in one C pass
    (``sp_contact_near``): (solid_hit (k, S), robot_hit (k, R), near (k,)) as bool arrays, the
    numpy path's comparisons; or None without the helper. Move m is slot ``slots[m]`` of copy
    ``copies[m]`` leaving ``starts[m]`` with ``reach[m]``; ``heights``/``grow`` (C, R),
    ``centres`` (C, R, 2); solids: ``lo``/``hi`` (S, 2), ``zlo``/``zhi`` (S,); ``eps`` and
    ``floor``: contact.EPS and contact.FLOOR (a solid whose top is at most ``floor`` above a band's
    bottom is no candidate)."""
    lib = library()
    if lib is None:
        return None
    k, R, S = len(copies), len(foot_radius), len(zlo)
    f64, i64 = np.float64, np.int64
    args = [np.ascontiguousarray(a, dtype=dt) for a, dt in (
        (copies, i64), (slots, i64), (starts, f64), (reach, f64), (foot_radius, f64), (foot_low, f64),
        (foot_high, f64), (heights, f64), (centres, f64), (grow, f64), (lo, f64), (hi, f64), (zlo, f64), (zhi, f64))]
    if args[2].shape != (k, 2) or args[8].shape != args[7].shape + (2,) or args[7].shape[1:] != (R,) \
            or args[9].shape != args[7].shape or args[10].shape != (S, 2) or args[11].shape != (S, 2):
        raise TypeError("contact_near: inconsistent shapes")
    solid_hit = np.empty((k, S), dtype=np.bool_)
    robot_hit = np.zeros((k, R), dtype=np.bool_)
    near = np.empty(k, dtype=np.bool_)
    p = _small_addresses(args + [solid_hit, robot_hit, near])
    lib.sp_contact_near(k, R, S, *p[:14], float(eps), float(floor), *p[14:])
    return solid_hit, robot_hit, near


def drive_wheels(live: np.ndarray, driven: np.ndarray, target: np.ndarray, velocity: np.ndarray,
                 angle: np.ndarray, dt: float, sides: np.ndarray, radius: np.ndarray, axle: np.ndarray,
                 sign: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The wheels and drives of :meth:`.batched.BatchedSimulation._drive` in one C pass
    (``sp_drive_wheels``): every live copy's driven slots' wheel motors advanced (``angle`` (C, R, 2)
    written in place), and the moving robots' (copies, slots, v, w) in the numpy path's order and
    bits; or None without the helper (nothing written). ``target``/``velocity``/``angle`` (C, R, 2),
    ``sides`` (R, 2) wheels per side, ``radius``/``axle`` (R,), ``sign`` (R, 2) each side's sign (-1.0: its
    wheels mounted mirrored) or None (every side 1.0)."""
    lib = library()
    if lib is None:
        return None
    f64, i64 = np.float64, np.int64
    C, R = angle.shape[:2]
    for a, dt_, shape in ((target, f64, (C, R, 2)), (velocity, f64, (C, R, 2)), (sides, i64, (R, 2)),
                          (radius, f64, (R,)), (axle, f64, (R,))):
        _check_buffer("drive_wheels", a, dt_, shape)
    if sign is not None:
        _check_buffer("drive_wheels", sign, f64, (R, 2))
    _check_buffer("drive_wheels", angle, f64, (C, R, 2), writes=True)      # advanced in place
    live = np.ascontiguousarray(live, dtype=i64)
    driven = np.ascontiguousarray(driven, dtype=i64)
    n = len(live) * len(driven)
    copies, slots = np.empty(n, dtype=i64), np.empty(n, dtype=i64)
    v, w = np.empty(n), np.empty(n)
    p = _small_addresses((live, driven, target, velocity, angle, sides, radius, axle, copies, slots, v, w))
    k = lib.sp_drive_wheels(len(live), len(driven), R, *p[:5], float(dt), *p[5:8], _ptr(sign), *p[8:])
    return copies[:k], slots[:k], v[:k], w[:k]


def lidar_beams(rot: np.ndarray, org: np.ndarray, columns, out=None) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The beams of n scans of one fixed lidar in one C pass (``sp_lidar_beams``): (origins, directions,
    directions as float32), (n * W, 3) each, scan i's beam w at row i * W + w; the directions the
    sums of :meth:`.batched.BatchedSimulation._plan_lidars`' numpy path (``rot`` (n, 3, 3) @ the
    beam's (x, y, z) in the sensor frame, ``columns`` three (W,) float64 arrays), bit for bit; or
    None without the helper. ``out``: those three arrays to write (scan after scan the same
    buffers: fresh ones of a 64-copy scan cost more in page faults than the pass itself)."""
    lib = library()
    if lib is None:
        return None
    f64 = np.float64
    rot = np.ascontiguousarray(rot, dtype=f64)
    org = np.ascontiguousarray(org, dtype=f64)
    x, y, z = (np.ascontiguousarray(c, dtype=f64) for c in columns)
    n, W = len(rot), len(x)
    if rot.shape != (n, 3, 3) or org.shape != (n, 3) or y.shape != (W,) or z.shape != (W,):
        raise TypeError("lidar_beams: inconsistent shapes")
    if out is None:
        out = np.empty((n * W, 3)), np.empty((n * W, 3)), np.empty((n * W, 3), dtype=np.float32)
    out_org, out_dir, out_d32 = out
    for a, dt_ in ((out_org, f64), (out_dir, f64), (out_d32, np.float32)):
        _check_buffer("lidar_beams", a, dt_, (n * W, 3), writes=True)
    lib.sp_lidar_beams(n, W, *_small_addresses((rot, org, x, y, z, out_org, out_dir, out_d32)))
    return out_org, out_dir, out_d32


class DriveStep:
    """:meth:`.batched.BatchedSimulation._drive` up to the contact narrow phase in one C pass
    (``sp_drive_step``: arcs about the robots' origins, the origin's twist for a robot whose
    wheels' centre is off it, the state's optional ``centre`` (R, 2)) and its last writes in another
    (``sp_pose_scatter``), over the simulation's state arrays, whose addresses are taken once (the simulation writes them in place, never
    rebinds them; the contact's solid arrays are re-read when a Supervisor rebuilds them). After
    :meth:`run` returned k moves, their copies, slots, starts and ends, the broad phase (when
    ``status[1]``: some move is near something) and the Rz and base of each lie in the first k
    rows of this object's arrays. :func:`drive_step` makes one, or None without the helper."""

    def __init__(self, lib, state: dict[str, np.ndarray], contact: dict[str, np.ndarray] | None):
        self.lib = lib
        self.state = state
        C, R = state["x"].shape
        self.C, self.R = C, R
        n = C * R
        i64 = np.int64
        self.copies, self.slots = np.empty(n, dtype=i64), np.empty(n, dtype=i64)
        self.v, self.w = np.empty(n), np.empty(n)
        self.starts, self.ends = np.empty((n, 2)), np.empty((n, 2))
        self.gathered = [np.empty(n) for _ in range(8)]   # x0, y0, yaw0, x1, y1, yaw1, cos, sin
        self.cos, self.sin = self.gathered[6], self.gathered[7]
        self.rz, self.base, self.rot = np.empty((n, 3, 3)), np.empty((n, 3, 3)), np.empty((n, 3, 3))
        self.status = np.zeros(2, dtype=i64)
        self.contact = contact
        S = self.S = 0   # (the solids' count, set by run)
        self.reach, self.grow = np.empty(n), np.empty((C, R))
        self.solid_hit = np.zeros((n, S), dtype=np.bool_)
        self.robot_hit = np.zeros((n, R), dtype=np.bool_)
        self.near = np.zeros(n, dtype=np.bool_)
        for name, dt_, shape in (("target", np.float64, (C, R, 2)), ("velocity", np.float64, (C, R, 2)),
                                 ("sides", i64, (R, 2)), ("radius", np.float64, (R,)), ("axle", np.float64, (R,)),
                                 ("base", np.float64, (C, R, 3, 3)), ("z", np.float64, (C, R))):
            _check_buffer("drive_step", state[name], dt_, shape)
        for name, dt_, shape in (("angle", np.float64, (C, R, 2)), ("x", np.float64, (C, R)),
                                 ("y", np.float64, (C, R)), ("yaw", np.float64, (C, R)),
                                 ("pressing", np.bool_, (C, R)), ("rot", np.float64, (C, R, 3, 3)),
                                 ("pos", np.float64, (C, R, 3))):
            _check_buffer("drive_step", state[name], dt_, shape, writes=True)
        arrays = [state[k] for k in ("target", "velocity", "angle", "sides", "radius", "axle", "x", "y", "yaw",
                                     "pressing")]
        arrays += [self.copies, self.slots, self.v, self.w, self.starts, self.ends, *self.gathered, self.rz,
                   state["base"], self.base, self.reach, self.grow]
        if contact is not None:
            for name, shape in (("foot_radius", (R,)), ("foot_low", (R,)), ("foot_high", (R,)),
                                ("heights", (C, R))):
                _check_buffer("drive_step", contact[name], np.float64, shape)
            _check_buffer("drive_step", contact["centres"], np.float64, (C, R, 2), writes=True)
            arrays += [contact[k] for k in ("foot_radius", "foot_low", "foot_high", "heights", "centres")]
            _check_buffer("drive_step", contact["spin"], np.float64, (R,))
        # a[34..40]: the solids' arrays and the broad phase's outputs (run); a[41]: the spin reach;
        # a[42]: the wheels' centres of the slots (R, 2) when some robot's is off its origin, else NULL;
        # a[43]: the slots' mid_heading flags (R,) uint8 when some robot has step_rule mid_heading, else NULL;
        # a[44]: the slots' side signs (R, 2) when some robot's wheels are mounted mirrored, else NULL
        spin = contact["spin"] if contact is not None else self.reach
        centre = state.get("centre")
        if centre is not None:
            _check_buffer("drive_step", centre, np.float64, (R, 2))
        mid = state.get("mid_heading")
        if mid is not None:
            _check_buffer("drive_step", mid, np.uint8, (R,))
        sign = state.get("sign")
        if sign is not None:
            _check_buffer("drive_step", sign, np.float64, (R, 2))
        self.ptrs = (ctypes.c_void_p * 45)(*(a.ctypes.data for a in arrays), *([0] * (41 - len(arrays))),
                                           spin.ctypes.data, None if centre is None else centre.ctypes.data,
                                           None if mid is None else mid.ctypes.data,
                                           None if sign is None else sign.ctypes.data)
        self._solids: tuple = ()
        self.p_status = self.status.ctypes.data
        self.p_scatter = [a.ctypes.data for a in (self.copies, self.slots, self.rot, state["x"], state["y"],
                                                  state["z"], state["rot"], state["pos"])]

    def run(self, live: np.ndarray, driven: np.ndarray, dt: float, eps: float, floor: float, solids=None) -> int:
        """One basic step of the live copies' driven slots (int64 arrays); ``eps``, ``floor``:
        contact.EPS and contact.FLOOR; ``solids``: the contact's (lo, hi, zlo, zhi) arrays (None: no
        contact). Returns the number of moves."""
        if solids is not None and (len(self._solids) != 4 or any(a is not b for a, b in zip(solids, self._solids))):
            for a, shape in zip(solids, ((len(solids[2]), 2), (len(solids[2]), 2), (len(solids[2]),),
                                         (len(solids[2]),))):
                _check_buffer("drive_step", a, np.float64, shape)
            S = len(solids[2])
            if S != self.S:
                self.S = S
                self.solid_hit = np.zeros((self.C * self.R, S), dtype=np.bool_)
            self._solids = tuple(solids)
            for j, a in enumerate((*solids, self.solid_hit, self.robot_hit, self.near)):
                self.ptrs[34 + j] = a.ctypes.data
        live = np.ascontiguousarray(live, dtype=np.int64)
        return self.lib.sp_drive_step(len(live), live.ctypes.data, len(driven), driven.ctypes.data, self.C, self.R,
                                      self.S, dt, eps, floor, 0 if solids is None else 1, self.ptrs,
                                      self.p_status)

    def scatter(self, k: int) -> None:
        """Move m's rotation (``self.rot[m]``) and its (x, y, z) written into the state's rot and pos."""
        p = self.p_scatter
        self.lib.sp_pose_scatter(k, self.R, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7])


def drive_step(state: dict[str, np.ndarray], contact: dict[str, np.ndarray] | None) -> DriveStep | None:
    """A :class:`DriveStep` over these state arrays, or None without the helper."""
    lib = library()
    if lib is None:
        return None
    return DriveStep(lib, state, contact)


def lookup(table, values: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``table.interpolate(values)`` (a :class:`.lookup.LookupTable` of two rows or more with strictly
    increasing inputs, (n,) float64 values) in one C pass (``sp_lookup``: the same operations, the
    same bits); None without the helper or for another table or array."""
    lib = library()
    if lib is None or len(table) < 2 or not table._increasing or values.dtype != np.float64 or values.ndim != 1:
        return None
    got = _tables.get(id(table))
    if got is None or got[0] is not table:
        rows = [np.ascontiguousarray(a) for a in (table._x, table._y, table._n)]
        got = _tables[id(table)] = (table, rows, [a.ctypes.data for a in rows])
    values = np.ascontiguousarray(values)
    out_y, out_n = np.empty(len(values)), np.empty(len(values))
    p = got[2]
    lib.sp_lookup(len(values), values.ctypes.data, len(got[1][0]), p[0], p[1], p[2], out_y.ctypes.data,
                  out_n.ctypes.data)
    return out_y, out_n


_tables: dict[int, tuple] = {}   # per lookup table (tables are immutable): its rows and their addresses


def atan2(y: np.ndarray, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray | None:
    """``math.atan2`` of each pair of the (n,) float64 arrays ``y``, ``x`` in one C pass (``sp_atan2``:
    libm's atan2, the function math.atan2 calls: the same bits, without the Python floats), into
    ``out`` when given; strided views allowed (positive strides of whole elements, ``out`` too).
    None without the helper or for other arrays (nothing written)."""
    lib = library()
    if lib is None:
        return None
    if out is None:
        out = np.empty(y.shape)
    if not out.flags.writeable or not all(a.dtype == np.float64 and a.ndim == 1 and a.shape == y.shape
                                          and a.strides[0] > 0 and a.strides[0] % 8 == 0 for a in (y, x, out)):
        return None
    lib.sp_atan2(len(y), y.ctypes.data, y.strides[0] // 8, x.ctypes.data, x.strides[0] // 8, out.ctypes.data,
                 out.strides[0] // 8)
    return out


def cross_norm(u: np.ndarray, back: np.ndarray) -> np.ndarray | None:
    """``|u x back|`` of each row of the (S, N, 3) float64 arrays (``sp_cross_norm``: distance.py's
    sonar_incidence's operations before its arctan2), (S, N); None without the helper or for
    other arrays."""
    lib = library()
    if lib is None or u.dtype != np.float64 or back.dtype != np.float64 or u.shape != back.shape or u.ndim != 3 \
            or u.shape[2] != 3:
        return None
    u, back = np.ascontiguousarray(u), np.ascontiguousarray(back)
    out = np.empty(u.shape[:2])
    lib.sp_cross_norm(out.size, u.ctypes.data, back.ctypes.data, out.ctypes.data)
    return out


def constrained_twists(places: np.ndarray, driven: np.ndarray, radius: np.ndarray, u: np.ndarray, cos: np.ndarray,
                       sin: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """SteeredDrive.constrained_twist of one robot (``places`` (W, 2), ``driven`` (W,) uint8, ``radius``
    (W,)) in n copies from their wheel speeds ``u`` and headings' ``cos``, ``sin`` (n, ≥ W) float64
    (``sp_constrained_twists``: batched_steered.constrained_twists' numpy operations): the twists (n, 3)
    and a (n,) bool, True where a copy needs the caller's least-squares fit (its twist unwritten); None
    without the helper or for other arrays."""
    lib = library()
    if lib is None or not all(a.dtype == np.float64 and a.ndim == 2 and a.shape == u.shape for a in (u, cos, sin)):
        return None
    n, width = u.shape
    W = len(places)
    if places.shape != (W, 2) or driven.shape != (W,) or radius.shape != (W,) or W > width or W > 64 \
            or places.dtype != np.float64 or driven.dtype != np.uint8 or radius.dtype != np.float64:
        return None
    u, cos, sin = np.ascontiguousarray(u), np.ascontiguousarray(cos), np.ascontiguousarray(sin)
    places, driven, radius = np.ascontiguousarray(places), np.ascontiguousarray(driven), np.ascontiguousarray(radius)
    out, fallback = np.empty((n, 3)), np.empty(n, dtype=np.uint8)
    lib.sp_constrained_twists(n, W, *_small_addresses((places, driven, radius, u, cos, sin)), width,
                              *_small_addresses((out, fallback)))
    return out, fallback.view(bool)


def sonar_nearest(r: np.ndarray, beta: np.ndarray, rmax: np.ndarray, max_incidence: float) -> np.ndarray | None:
    """Each of S sonars' reading from its N rays' distances ``r`` and incidence angles ``beta``
    ((S, N) float64) and its range ``rmax`` ((S,)): distance.py's every-sonar combine after the
    angles, in one C pass (``sp_sonar_nearest``, the same comparisons); None without the helper or
    for other arrays."""
    lib = library()
    if lib is None or r.dtype != np.float64 or beta.dtype != np.float64 or rmax.dtype != np.float64 \
            or r.ndim != 2 or beta.shape != r.shape or rmax.shape != r.shape[:1]:
        return None
    r, beta, rmax = np.ascontiguousarray(r), np.ascontiguousarray(beta), np.ascontiguousarray(rmax)
    out = np.empty(len(r))
    lib.sp_sonar_nearest(r.shape[0], r.shape[1], r.ctypes.data, beta.ctypes.data, rmax.ctypes.data,
                         float(max_incidence), out.ctypes.data)
    return out


class SensorRays:
    """:func:`sensor_rays` of fixed sensors (the same copies, slots, frames and directions step after
    step: a batched step's due distance sensors) over arrays written in place (the poses): their
    checks and addresses made once, each call one C pass into fresh outputs."""

    def __init__(self, lib, copies: np.ndarray, slots: np.ndarray, rot: np.ndarray, pos: np.ndarray, pi: np.ndarray,
                 local_rot: np.ndarray, local_pos: np.ndarray, k: np.ndarray, local_dirs: np.ndarray):
        f64, i64 = np.float64, np.int64
        self.lib = lib
        self.S = S = len(copies)
        C, self.R = rot.shape[:2]
        G, self.N = local_dirs.shape[:2]
        for a, shape in ((rot, (C, self.R, 3, 3)), (pos, (C, self.R, 3)), (local_rot, (len(local_rot), 3, 3)),
                         (local_pos, (len(local_rot), 3)), (local_dirs, (G, self.N, 3))):
            _check_buffer("sensor_rays", a, f64, shape)
        idx = [np.ascontiguousarray(a, dtype=i64) for a in (copies, slots, pi, k)]
        if any(a.shape != (S,) for a in idx):
            raise TypeError("sensor_rays: inconsistent shapes")
        self.kept = (*idx, rot, pos, local_rot, local_pos, local_dirs)
        p = [a.ctypes.data for a in self.kept]
        self.args = (p[0], p[1], p[4], p[5], p[2], p[6], p[7], p[3], p[8])

    def __call__(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        S, N = self.S, self.N
        positions, origins, dirs = np.empty((S, 3)), np.empty((S * N, 3)), np.empty((S, N, 3))
        self.lib.sp_sensor_rays(S, N, self.R, *self.args, *_small_addresses((positions, origins, dirs)))
        return positions, origins, dirs


def sensor_rays_of(copies: np.ndarray, slots: np.ndarray, rot: np.ndarray, pos: np.ndarray, pi: np.ndarray,
                   local_rot: np.ndarray, local_pos: np.ndarray, k: np.ndarray, local_dirs: np.ndarray
                   ) -> SensorRays | None:
    """A :class:`SensorRays` of these sensors (arguments as :func:`sensor_rays`), or None without the helper."""
    lib = library()
    if lib is None:
        return None
    return SensorRays(lib, copies, slots, rot, pos, pi, local_rot, local_pos, k, local_dirs)


def clearance_gaps(d: np.ndarray, far: float, radius: float) -> np.ndarray | None:
    """AvoidObstacles' gaps from its clearance cast's distances ``d`` ((n, rays) float64): each row's
    nearest finite distance (``far`` when none) minus ``radius``, in one C pass
    (``sp_clearance_gaps``, task.py's numpy operations); None without the helper or for another array."""
    lib = library()
    if lib is None or d.dtype != np.float64 or d.ndim != 2:
        return None
    d = np.ascontiguousarray(d)
    gap = np.empty(len(d))
    lib.sp_clearance_gaps(d.shape[0], d.shape[1], d.ctypes.data, float(far), float(radius), gap.ctypes.data)
    return gap


def avoid_reward(copies: np.ndarray, slot: int, velocity: np.ndarray, vmax: tuple[float, float], gap: np.ndarray,
                 near: float, contact: float, penalty: float) -> np.ndarray | None:
    """AvoidObstacles' reward of the named copies (int64 ``copies``, their robot ``slot``'s wheel
    ``velocity`` (C, R, 2) over each wheel's own maximum ``vmax`` (left, right), their ``gap`` (n,)) in one C pass (``sp_avoid_reward``, task.py's numpy
    operations element by element); None without the helper or for other arrays."""
    lib = library()
    if lib is None or copies.dtype != np.int64 or gap.dtype != np.float64 or gap.shape != copies.shape \
            or copies.ndim != 1:
        return None
    C, R = velocity.shape[:2]
    _check_buffer("avoid_reward", velocity, np.float64, (C, R, 2))
    if not 0 <= slot < R or (len(copies) and not (0 <= int(copies.min()) and int(copies.max()) < C)):
        raise IndexError(f"avoid_reward: slot {slot} or copies outside ({C}, {R})")
    copies, gap = np.ascontiguousarray(copies), np.ascontiguousarray(gap)
    out = np.empty(len(copies))
    lib.sp_avoid_reward(len(copies), copies.ctypes.data, R, int(slot), velocity.ctypes.data, float(vmax[0]),
                        float(vmax[1]), gap.ctypes.data, float(near), float(contact), float(penalty), out.ctypes.data)
    return out


# ---------------------------------------------------------------- batched kinematic devices
# (sim/batched_kinematic.py: the libm calls of the GPS, inertial unit and gyro models per element)

def _rows(a: np.ndarray, width: int) -> np.ndarray | None:
    """``a`` as a C-contiguous float64 (n, width) array, or None for another array."""
    if a.dtype != np.float64 or a.ndim != 2 or a.shape[1] != width:
        return None
    return np.ascontiguousarray(a)


def roll_pitch_yaw(q: np.ndarray, nue: bool) -> np.ndarray | None:
    """orientation.roll_pitch_yaw of each (x, y, z, w) row of the (n, 4) float64 ``q`` in one C pass
    (``sp_roll_pitch_yaw``: libm's atan2 and asin as math.atan2 and math.asin call them, the
    arithmetic around them the numpy path's): (n, 3) roll, pitch, yaw; None without the helper or
    for another array."""
    lib = library()
    q = _rows(q, 4) if lib is not None else None
    if q is None:
        return None
    out = np.empty((len(q), 3))
    p = _small_addresses((q, out))
    lib.sp_roll_pitch_yaw(len(q), p[0], 1 if nue else 0, p[1])
    return out


def half_angles(q: np.ndarray) -> np.ndarray | None:
    """orientation.inertial_quaternion's half angle ``atan2(sqrt(x**2 + y**2 + z**2), w)`` of each row
    of the (n, 4) float64 ``q`` in one C pass (``sp_half_angles``, each square libm's pow as numpy's
    scalar power calls it); None without the helper, for another array or a non-finite component."""
    lib = library()
    q = _rows(q, 4) if lib is not None else None
    if q is None:
        return None
    out = np.empty(len(q))
    if lib.sp_half_angles(len(q), *_small_addresses((q, out))):
        return None
    return out


def correlation_ratios(corr: np.ndarray, exponent: np.ndarray) -> np.ndarray | None:
    """gps.position's ``correlation ** exponent`` (0 where the correlation is 0) of two (n,) float64
    arrays in one C pass (``sp_correlation_ratios``: libm's pow, as Python's float power calls it for a
    positive base); None without the helper, for other arrays, or for a base or exponent Python's
    power treats otherwise."""
    lib = library()
    if lib is None or corr.dtype != np.float64 or exponent.dtype != np.float64 or corr.ndim != 1 \
            or exponent.shape != corr.shape:
        return None
    c, e = np.ascontiguousarray(corr), np.ascontiguousarray(exponent)
    out = np.empty(len(c))
    if lib.sp_correlation_ratios(len(c), *_small_addresses((c, e, out))):
        return None
    return out


def gyro_rates(rel: np.ndarray, dt: float) -> np.ndarray | None:
    """motion_sensors.angular_velocity of each turn ``rel`` ((n, 3, 3) float64, r0ᵀ·r1 as numpy
    multiplied them) over ``dt`` seconds in one C pass (``sp_gyro``: libm's acos and sin as math.acos
    and math.sin call them): (n, 3); None without the helper or for another array."""
    lib = library()
    if lib is None or rel.dtype != np.float64 or rel.ndim != 3 or rel.shape[1:] != (3, 3):
        return None
    rel = np.ascontiguousarray(rel)
    out = np.empty((len(rel), 3))
    p = _small_addresses((rel, out))
    lib.sp_gyro(len(rel), p[0], float(dt), p[1])
    return out


# ---------------------------------------------------------------- batched step, round 2
# (the vector env's step: a few numpy calls each in one C pass, their signatures and the kept
# arrays' checks made once, so that a call costs its pass and little else)

def box_clip32(img: np.ndarray, lo: float, hi: float) -> np.ndarray | None:
    """A fresh float32 copy of ``img`` clipped to [lo, hi] (float32 bounds, lo <= hi, hi > 0) with a
    NaN set to ``hi`` and, where ``lo`` is a zero, a zero set to ``lo``: the steps of
    :meth:`.gym.vector.SensoriumVectorEnv._observe` for a range image (np.clip's values, its NaN
    kept until set) in one C pass (``sp_box_clip32``); None without the helper or for another array."""
    lib = library()
    if lib is None or img.dtype != np.float32 or not img.flags.c_contiguous:
        return None
    out = np.empty(img.shape, dtype=np.float32)
    lib.sp_box_clip32(img.size, img.ctypes.data, float(lo), float(hi), out.ctypes.data)
    return out


class AvoidOutcome:
    """AvoidObstacles' gaps, reward and termination of the named copies from their clearance cast
    (``sp_avoid_outcome``: ``sp_clearance_gaps`` then ``sp_avoid_reward``, the vectorised goal's C
    passes) over one simulation's wheel velocities (C, R, 2), which the simulation writes in place
    and never rebinds: that array's checks and address made once."""

    def __init__(self, lib, velocity: np.ndarray):
        self.lib = lib
        self.C, self.R = velocity.shape[:2]
        _check_buffer("avoid_outcome", velocity, np.float64, (self.C, self.R, 2))
        self.velocity = velocity
        self.p_velocity = velocity.ctypes.data

    def __call__(self, d: np.ndarray, far: float, radius: float, copies: np.ndarray, slot: int,
                 vmax: tuple[float, float], near: float, contact: float,
                 penalty: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(gap, reward, terminated) of copies ``copies`` (int64 (n,)) whose clearance distances are
        ``d`` ((n, rays) float64), their robot in ``slot``; None for other arrays."""
        n = len(copies)
        if d.dtype != np.float64 or d.ndim != 2 or d.shape[0] != n or copies.dtype != np.int64 or copies.ndim != 1:
            return None
        if not 0 <= slot < self.R:
            raise IndexError(f"avoid_outcome: slot {slot} outside [0, {self.R})")
        d, copies = np.ascontiguousarray(d), np.ascontiguousarray(copies)
        gap, reward, term = np.empty(n), np.empty(n), np.empty(n, dtype=np.bool_)
        p = _small_addresses((d, copies, gap, reward, term))
        if self.lib.sp_avoid_outcome(n, d.shape[1], p[0], far, radius, p[1], self.C, self.R, slot, self.p_velocity,
                                     vmax[0], vmax[1], near, contact, penalty, p[2], p[3], p[4]):
            raise IndexError(f"avoid_outcome: a copy outside [0, {self.C})")
        return gap, reward, term


def avoid_outcome(velocity: np.ndarray) -> AvoidOutcome | None:
    """An :class:`AvoidOutcome` over this velocity array, or None without the helper."""
    lib = library()
    if lib is None:
        return None
    return AvoidOutcome(lib, velocity)


def lidar_ranges(dist: np.ndarray, lo: float, hi: float, ranges: np.ndarray) -> bool:
    """:func:`lidar_scan` of a cylindrical scan without noise, resolution or points on one thread
    (``dist`` (n,) float64, ``ranges`` (n,) float32 written), its one C call made directly; False
    without the helper (nothing written)."""
    lib = library()
    if lib is None:
        return False
    n = len(dist)
    _check_buffer("lidar_ranges", dist, np.float64, (n,))
    _check_buffer("lidar_ranges", ranges, np.float32, (n,), writes=True)
    lib.sp_lidar_scan(n, dist.ctypes.data, None, lo, float(np.float32(hi)), None, None, None, ranges.ctypes.data, None)
    return True


class DueScan:
    """:meth:`.batched.BatchedSimulation._due` of one device kind over every copy in one C pass
    (``sp_due``): the (copies, columns) whose period is positive and elapsed, in numpy's nonzero
    order, over the simulation's clocks (C,) and the kind's last times and periods (C, D), int64
    arrays it writes in place and never rebinds (their checks and addresses made once)."""

    def __init__(self, lib, time: np.ndarray, last: np.ndarray, period: np.ndarray):
        self.lib = lib
        self.C, self.D = last.shape
        for a, shape in ((time, (self.C,)), (last, (self.C, self.D)), (period, (self.C, self.D))):
            _check_buffer("due_scan", a, np.int64, shape)
        self.kept = (time, last, period)
        self.p = [a.ctypes.data for a in self.kept]

    def __call__(self) -> tuple[np.ndarray, np.ndarray]:
        n = self.C * self.D
        copies, cols = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
        p = self.p
        k = self.lib.sp_due(self.C, self.D, p[0], p[1], p[2], *_small_addresses((copies, cols)))
        return copies[:k], cols[:k]


def due_scan(time: np.ndarray, last: np.ndarray, period: np.ndarray) -> DueScan | None:
    """A :class:`DueScan` over these arrays, or None without the helper."""
    lib = library()
    if lib is None:
        return None
    return DueScan(lib, time, last, period)
