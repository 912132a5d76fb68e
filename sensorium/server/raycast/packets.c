/* Packet traversal for the ray engine: Embree's rtcIntersect16 over a batch of rays, and the
 * judging of the hits (below: sp_fast_pass, sp_exact_pass).
 *
 * embreex casts one ray per rtcIntersect1 call. Here the same Embree library (found and opened by
 * packets.py, normally the one embreex itself loaded) traces the batch in packets of 16 with the
 * ray-query flag that says whether the rays are coherent (a lidar's beams from one origin): Embree
 * then traverses each BVH node once for the packet. The scenes, the rays (float32, tnear 0) and the
 * outputs are those of embreex's EmbreeScene.run(..., output=1), so the answers are the same.
 *
 * Built by packets.py with the system C compiler (no Embree headers needed: the few declarations
 * below follow Embree 4's public API, rtcore_*.h). No Python API: called through ctypes, which
 * releases the GIL, so two threads trace two halves of a batch at once.
 */
#ifdef __linux__
#define _GNU_SOURCE   /* pthread_setaffinity_np: the pass's threads run on the process's CPUs */
#include <sched.h>
#endif
#include <dlfcn.h>
#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

enum { GEOMETRY_TRIANGLE = 0, BUFFER_INDEX = 0, BUFFER_VERTEX = 1, FORMAT_UINT3 = 0x5003,
       FORMAT_FLOAT3 = 0x9003, SCENE_ROBUST = 1 << 2, QUERY_COHERENT = 1 << 16 };
#define INVALID 0xFFFFFFFFu

/* RTCRayHit16 (rtcore_ray.h); the hit part may be longer in builds with more instance levels or
 * instance arrays: room to spare after it */
struct ray_hit16 {
  float org_x[16], org_y[16], org_z[16], tnear[16];
  float dir_x[16], dir_y[16], dir_z[16], time[16];
  float tfar[16];
  unsigned mask[16], id[16], flags[16];
  float ng_x[16], ng_y[16], ng_z[16], u[16], v[16];
  unsigned prim[16], geom[16], inst[16];
  unsigned spare[16 * 16];
} __attribute__((aligned(64)));

/* RTCIntersectArguments (rtcore_ray.h, Embree 4), with room to spare */
struct intersect_args {
  int flags;
  unsigned feature_mask;
  void* context;
  void* filter;
  void* intersect;
  float min_width_distance_factor;
  unsigned spare[16];
} __attribute__((aligned(16)));

static void* (*new_device)(const char*);
static void (*release_device)(void*);
static int (*device_error)(void*);
static void* (*new_scene)(void*);
static void (*set_scene_flags)(void*, int);
static void (*commit_scene)(void*);
static void (*release_scene)(void*);
static void* (*new_geometry)(void*, int);
static void* (*new_geometry_buffer)(void*, int, unsigned, int, size_t, size_t);
static void (*shared_geometry_buffer)(void*, int, unsigned, int, const void*, size_t, size_t, size_t);
static void (*commit_geometry)(void*);
static unsigned (*attach_geometry)(void*, void*);
static void (*release_geometry)(void*);
static void (*intersect16)(const int*, void*, struct ray_hit16*, struct intersect_args*);

#define LOAD(var, name) if (!(*(void**)(&var) = dlsym(lib, name))) return name;

/* Opens the Embree library at `path`; NULL when ready, else the name of what is missing. */
const char* sp_open(const char* path) {
  void* lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!lib) return "dlopen";
  LOAD(new_device, "rtcNewDevice") LOAD(release_device, "rtcReleaseDevice")
  LOAD(device_error, "rtcGetDeviceError") LOAD(new_scene, "rtcNewScene")
  LOAD(set_scene_flags, "rtcSetSceneFlags") LOAD(commit_scene, "rtcCommitScene")
  LOAD(release_scene, "rtcReleaseScene") LOAD(new_geometry, "rtcNewGeometry")
  LOAD(new_geometry_buffer, "rtcSetNewGeometryBuffer")
  LOAD(shared_geometry_buffer, "rtcSetSharedGeometryBuffer") LOAD(commit_geometry, "rtcCommitGeometry")
  LOAD(attach_geometry, "rtcAttachGeometry") LOAD(release_geometry, "rtcReleaseGeometry")
  LOAD(intersect16, "rtcIntersect16")
  return NULL;
}

void* sp_new_device(void) { return new_device(NULL); }

void sp_release_device(void* device) { release_device(device); }

/* A packet's query arguments and the lanes' constant fields (tnear 0, every mask bit, no time). */
static void packet_init(struct ray_hit16* r, struct intersect_args* args, int coherent) {
  memset(args, 0, sizeof *args);
  args->flags = coherent ? QUERY_COHERENT : 0;
  args->feature_mask = INVALID;
  args->min_width_distance_factor = 1.0f;
  for (int k = 0; k < 16; k++) {
    r->tnear[k] = 0.0f; r->time[k] = 0.0f; r->mask[k] = INVALID; r->id[k] = 0; r->flags[k] = 0;
  }
}

/* A triangle geometry of nv vertices and nf faces: `shared`, Embree reads the caller's arrays (which
 * must outlive the scene and have 16 bytes readable past their ends: Embree loads the last vertex
 * with a 16-byte load); else it copies them into buffers of its own. */
static int add_triangles(void* device, void* scene, size_t nv, const float* vertices, size_t nf, const int32_t* faces,
                         int shared) {
  void* g = new_geometry(device, GEOMETRY_TRIANGLE);
  if (!g) return -1;
  if (shared) {
    shared_geometry_buffer(g, BUFFER_VERTEX, 0, FORMAT_FLOAT3, vertices, 0, 3 * sizeof(float), nv);
    shared_geometry_buffer(g, BUFFER_INDEX, 0, FORMAT_UINT3, faces, 0, 3 * sizeof(int32_t), nf);
  } else {
    float* vb = new_geometry_buffer(g, BUFFER_VERTEX, 0, FORMAT_FLOAT3, 3 * sizeof(float), nv);
    int32_t* ib = new_geometry_buffer(g, BUFFER_INDEX, 0, FORMAT_UINT3, 3 * sizeof(int32_t), nf);
    if (!vb || !ib) { release_geometry(g); return -1; }
    memcpy(vb, vertices, nv * 3 * sizeof(float));
    memcpy(ib, faces, nf * 3 * sizeof(int32_t));
  }
  commit_geometry(g);
  attach_geometry(scene, g);
  release_geometry(g);
  return 0;
}

/* A committed scene of one triangle geometry (id 0) and, when nv1 > 0, a second one (id 1); bit k
 * of `shared`: geometry k's arrays are shared with Embree (see add_triangles), else copied; NULL on
 * any Embree error. */
void* sp_new_scene(void* device, int robust, size_t nv0, const float* v0, size_t nf0, const int32_t* f0,
                   size_t nv1, const float* v1, size_t nf1, const int32_t* f1, int shared) {
  void* scene = new_scene(device);
  if (!scene) return NULL;
  if (robust) set_scene_flags(scene, SCENE_ROBUST);
  int bad = nf0 && add_triangles(device, scene, nv0, v0, nf0, f0, shared & 1);
  if (!bad && nv1) bad = add_triangles(device, scene, nv1, v1, nf1, f1, shared & 2);
  if (!bad) commit_scene(scene);
  if (bad || device_error(device)) { release_scene(scene); return NULL; }
  return scene;
}

void sp_release_scene(void* scene) { release_scene(scene); }

/* Nearest hits of n rays: origins (n,3) float32 with row stride `o_stride` floats (0: one origin
 * for all rays), directions (n,3), tnear 0. `out` holds n far limits on entry (float32) and
 * receives, in blocks of n 32-bit words: the hit distance (the far limit on a miss, as embreex),
 * primID (-1: miss), and with `full`: geomID (-1: miss), u, v, then Ng as (n,3) (zeros on a miss).
 * `coherent`: the rays are traced as coherent packets (one origin: a lidar). */
void sp_intersect(void* scene, size_t n, const float* origins, size_t o_stride, const float* directions,
                  float* out, int full, int coherent) {
  float* tfar = out;
  int32_t* prim = (int32_t*)(out + n);
  int32_t* geom = full ? (int32_t*)(out + 2 * n) : NULL;
  float* u = out + 3 * n;
  float* v = out + 4 * n;
  float* ng = out + 5 * n;
  struct ray_hit16 r;
  struct intersect_args args;
  packet_init(&r, &args, coherent);
  int valid[16];
  for (size_t a = 0; a < n; a += 16) {
    int m = n - a < 16 ? (int)(n - a) : 16;
    for (int k = 0; k < 16; k++) {
      size_t i = a + (k < m ? (size_t)k : 0);
      const float* o = origins + o_stride * i;
      const float* d = directions + 3 * i;
      valid[k] = k < m ? -1 : 0;
      r.org_x[k] = o[0]; r.org_y[k] = o[1]; r.org_z[k] = o[2];
      r.dir_x[k] = d[0]; r.dir_y[k] = d[1]; r.dir_z[k] = d[2];
      r.tfar[k] = tfar[i];
      r.geom[k] = INVALID; r.prim[k] = INVALID; r.inst[k] = INVALID;
    }
    intersect16(valid, scene, &r, &args);
    for (int k = 0; k < m; k++) {
      size_t i = a + (size_t)k;
      int hit = r.geom[k] != INVALID;
      prim[i] = hit ? (int32_t)r.prim[k] : -1;
      if (hit) tfar[i] = r.tfar[k];
      if (geom) {
        geom[i] = hit ? (int32_t)r.geom[k] : -1;
        u[i] = hit ? r.u[k] : 0.0f; v[i] = hit ? r.v[k] : 0.0f;
        ng[3 * i] = hit ? r.ng_x[k] : 0.0f; ng[3 * i + 1] = hit ? r.ng_y[k] : 0.0f; ng[3 * i + 2] = hit ? r.ng_z[k] : 0.0f;
      }
    }
  }
}

/* ---------------------------------------------------------------------------------------------
 * One pass over a tier in C: the traversal above and the judging of its hits that the engine's
 * numpy code does (trace.py: FAST's _trace_fast/_judge_fast, EXACT's first pass of _trace_loop
 * with refine.py's float64 refinement), for the rays whose first hit is settled in that pass. A
 * ray it cannot settle (a guard met first, a hit near a triangle's edge, a refinement that misses,
 * an excluded owner, a self-hit, a shell left from inside) is flagged and the engine traces it
 * again on the numpy path, which answers it as it always did (a ray's answer never depends on the
 * other rays of its batch). So the answers are the numpy path's, bit for bit: the same formulas in
 * the same order, each operation rounded as numpy rounds it (compiled with -ffp-contract=off, so
 * no fused multiply-add; float32 where numpy computes in float32, e.g. comparisons of float32
 * arrays with Python floats).
 */
#include <math.h>

/* A tier's arrays (tiers.py, _Tier), read only; `n` triangles, sentinel rows where noted. A
 * triangle's first vertex v0 = V[F[i][0]], its edges e1 = V[F[i][1]] - v0, e2 = V[F[i][2]] - v0 and
 * its box (the componentwise min and max of its vertices) are taken from V and F where needed:
 * the values of the numpy path's arrays, without holding 120 bytes per triangle of them. */
struct sp_tier {
  const double* normal;      /* (n+1, 3) unit normals, zero sentinel row */
  const double* g1;          /* (n+1, 3) dual basis: barycentric u = (P - v0).g1 (EXACT) */
  const double* g2;          /* (n+1, 3) ... v = (P - v0).g2 (EXACT) */
  const double* h_min;       /* (n,) smallest height (EXACT) */
  const double* V;           /* vertices (float64, tier frame) */
  const int32_t* F;          /* (n, 3) faces */
  const int32_t* tri_slot;   /* (n+1,) curved slot of a triangle, -1: flat (and the sentinel) */
  const int64_t* tri_shape;  /* (n+1,) global shape, sentinel -1 */
  const int32_t* tri_owner;  /* (n+1,) owner, -2: none */
  const int64_t* c_code;     /* per curved slot: 1 sphere, 2 cylinder, 3 capsule */
  const double* c_r;
  const double* c_h;
  const double* c_rot;       /* (slots, 3, 3) */
  const double* c_pos;       /* (slots, 3) */
  const int64_t* c_shape;
  const uint8_t* c_isolated;
  double eps;                /* the tier's self-hit distance and continuation step */
  double ng_max;             /* largest |Embree Ng| */
  int64_t guarded;           /* geometry 1 of the scene holds edge guards */
  /* EXACT only: */
  const int64_t* ring_vptr;  /* CSR: the triangles of vertex v (ascending); triangle i's vertex ring */
  const int32_t* ring_tri;   /* is its three corners' lists in order */
  const int64_t* guard_ptr;  /* CSR: the flat triangles to test for a ray near risky edge e */
  const int64_t* guard_idx;
  int64_t n_tri;
  int64_t prism_triangles;   /* guard prism triangle k guards edge k / prism_triangles */
  double grow;               /* eps + 8 res: float32 uncertainty of a hit point */
  void* bare;                /* the EXACT scene without guards */
};

#define INF_D ((double)INFINITY)
enum { SPHERE = 1, CYLINDER = 2, CAPSULE = 3 };

/* numpy's minimum and maximum: a NaN in either operand wins (the first one); else b unless a is
 * strictly smaller (greater) */
static inline double np_min(double a, double b) { return (a < b || a != a) ? a : b; }
static inline double np_max(double a, double b) { return (a > b || a != a) ? a : b; }
static inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* A curved shape's frame in and out, as refine._analytic moves rays and normals (einsum's sums:
 * x @ R summed (x0 R0j + x1 R1j) + x2 R2j, x @ R.T summed (x0 Ri0 + x2 Ri2) + x1 Ri1, each added to
 * +0.0, so a sum of zeros is +0.0) */
static inline void to_frame(const double* x, const double* R, double* out) {
  for (int j = 0; j < 3; j++) out[j] = (x[0] * R[j] + x[1] * R[3 + j] + x[2] * R[6 + j]) + 0.0;
}

static inline void from_frame(const double* x, const double* R, double* out) {
  for (int i = 0; i < 3; i++) out[i] = (x[0] * R[3 * i] + x[2] * R[3 * i + 2] + x[1] * R[3 * i + 1]) + 0.0;
}

/* exact._roots_into for one row */
static void roots(double a, double b, double c, double disc, double* t) {
  double s = sqrt(np_max(disc, 0.0));
  double q = -(b + copysign(s, b));
  double t1 = q / a, t2 = c / q;
  if (q == 0.0) t2 = t1;
  if (disc < 0.0 || !isfinite(t1)) t1 = t2 = INF_D;
  t[0] = t1;
  t[1] = t2;
}

/* exact._sphere_roots_into for one row */
static void sphere_roots(const double* p, const double* d, double r, double* t) {
  double a = dot3(d, d), b = dot3(p, d), c = dot3(p, p) - r * r;
  double x[3] = {p[1] * d[2] - p[2] * d[1], p[2] * d[0] - p[0] * d[2], p[0] * d[1] - p[1] * d[0]};
  roots(a, b, c, a * r * r - dot3(x, x), t);
}

/* exact._analytic_local for one row (the vectorised semantics, signed zeros included): the
 * nearest true-surface hit with lo <= t <= hi in the shape frame; +inf and a zero normal if none
 * (`n` NULL: the distance only). */
static double analytic(int64_t code, const double* p, const double* d, double r, double h, double lo, double hi,
                       double* n) {
  double ts[6];
  int k_n = 2;
  double tol = 1e-12 * (r + h);
  double pz = p[2], dz = d[2];
  if (code == SPHERE) {
    sphere_roots(p, d, r, ts);
  } else {
    double px = p[0], py = p[1], dx = d[0], dy = d[1];
    double a = dx * dx + dy * dy;
    double x = px * dy - py * dx;
    roots(a, px * dx + py * dy, px * px + py * py - r * r, a * r * r - x * x, ts);
    for (int j = 0; j < 2; j++)
      if (!(fabs(pz + ts[j] * dz) <= h + tol)) ts[j] = INF_D;
    if (code == CYLINDER) {
      k_n = 4;
      for (int j = 0; j < 2; j++) {
        double c = (j == 0 ? h * 1.0 : h * -1.0);
        double t = (c - pz) / dz;
        double cx = px + t * dx, cy = py + t * dy;
        ts[2 + j] = (isfinite(t) && cx * cx + cy * cy <= r * r + tol * r) ? t : INF_D;
      }
    } else {
      k_n = 6;
      for (int j = 0; j < 2; j++) {
        double sign = j == 0 ? 1.0 : -1.0;
        double pc[3] = {p[0], p[1], pz - sign * h};
        sphere_roots(pc, d, r, ts + 2 + 2 * j);
        for (int q = 2 + 2 * j; q < 4 + 2 * j; q++)
          if (!(sign * (pz + ts[q] * dz) >= h - tol)) ts[q] = INF_D;
      }
    }
  }
  double t = INF_D;
  int k = 0;
  for (int j = 0; j < k_n; j++) {
    double c = (ts[j] >= lo && ts[j] <= hi) ? ts[j] : INF_D;
    if (j == 0 || c < t) { t = c; k = j; }     /* argmin: the first of equal candidates */
  }
  if (n == NULL) return t;
  int hit = t < INF_D;
  double t0 = hit ? t : 0.0;
  double v[3] = {p[0] + t0 * d[0], p[1] + t0 * d[1], p[2] + t0 * d[2]};
  if (code == CYLINDER) {
    double side = k < 2 ? 1.0 : 0.0;
    v[0] *= side;
    v[1] *= side;
    v[2] = (k == 2 ? 1.0 : 0.0) - (k == 3 ? 1.0 : 0.0);
  } else if (code == CAPSULE) {
    v[2] -= k < 2 ? v[2] : (k < 4 ? h : -h);
  }
  double norm = sqrt(dot3(v, v));
  for (int j = 0; j < 3; j++) n[j] = hit ? v[j] / norm : 0.0;
  return t;
}

/* refine._analytic for one (ray, slot): tier-frame origin o and direction d; the normal back in
 * the tier frame (NULL: distance only). */
static double analytic_slot(const struct sp_tier* T, int64_t s, const double* o, const double* d, double lo,
                            double hi, double* n) {
  const double* R = T->c_rot + 9 * s;
  double x[3] = {o[0] - T->c_pos[3 * s], o[1] - T->c_pos[3 * s + 1], o[2] - T->c_pos[3 * s + 2]};
  double p[3], dl[3], nl[3];
  to_frame(x, R, p);
  to_frame(d, R, dl);
  double t = analytic(T->c_code[s], p, dl, T->c_r[s], T->c_h[s], lo, hi, n ? nl : NULL);
  if (n) from_frame(nl, R, n);
  return t;
}

/* For tests: the analytic hit of m rays on one curved slot each, as analytic_slot computes it. */
void sp_analytic(const struct sp_tier* T, size_t m, const int64_t* slots, const double* O, const double* D,
                 const double* lo, const double* hi, double* t, double* n) {
  for (size_t i = 0; i < m; i++)
    t[i] = analytic_slot(T, slots[i], O + 3 * i, D + 3 * i, lo[i], hi[i], n ? n + 3 * i : NULL);
}

static inline void cross3(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Triangle tri's first vertex (tiers.py's v0 row) */
static inline const double* first_vertex(const struct sp_tier* T, int64_t tri) { return T->V + 3 * (size_t)T->F[3 * tri]; }

/* exact._moller_trumbore for one (ray, triangle): inside within the barycentric tolerance, and t */
static int moller_trumbore(const struct sp_tier* T, int64_t tri, const double* o, const double* d, double* t_out) {
  const int32_t* f = T->F + 3 * tri;
  const double *v0 = T->V + 3 * (size_t)f[0], *v1 = T->V + 3 * (size_t)f[1], *v2 = T->V + 3 * (size_t)f[2];
  const double e1[3] = {v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]};   /* tiers.py's e1, e2 rows */
  const double e2[3] = {v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]};
  double p[3], q[3], sv[3] = {o[0] - v0[0], o[1] - v0[1], o[2] - v0[2]};
  cross3(d, e2, p);
  double inv = 1.0 / dot3(e1, p);
  double u = dot3(sv, p) * inv;
  cross3(sv, e1, q);
  double v = dot3(d, q) * inv;
  double t = dot3(e2, q) * inv;
  *t_out = t;
  return isfinite(t) && u >= -1e-9 && v >= -1e-9 && u + v <= 1.0 + 1e-9;
}

/* refine._refine_triangles (the hit triangle, else its vertex ring; of equal distances the ring's
 * last) and, failing both, refine._nearby_triangles (flat triangles whose grown box holds the
 * Embree hit point at t_e, hits up to t_e + eps; of equal distances the first): 1 and t, tri when
 * found (tri -1 when nothing near). */
static int refine_flat(const struct sp_tier* T, int64_t* tri, const double* o, const double* d, double lo, double hi,
                       double t_e, const int64_t* excl, double* t_out) {
  double t;
  if (moller_trumbore(T, *tri, o, d, &t) && t >= lo && t <= hi) { *t_out = t; return 1; }
  double best = INF_D;
  int64_t btri = -1;
  const int32_t* corner = T->F + 3 * *tri;
  for (int j = 0; j < 3; j++) for (int64_t k = T->ring_vptr[corner[j]]; k < T->ring_vptr[corner[j] + 1]; k++) {
    int64_t c = (int64_t)T->ring_tri[k];
    double tc;
    int ok = moller_trumbore(T, c, o, d, &tc) && tc >= lo && tc <= hi;
    if (!ok) continue;
    if (tc < best) best = tc;
  }
  if (isfinite(best)) {
    for (int j = 0; j < 3; j++) for (int64_t k = T->ring_vptr[corner[j]]; k < T->ring_vptr[corner[j] + 1]; k++) {
      int64_t c = (int64_t)T->ring_tri[k];   /* the last candidate at best */
      double tc;
      if (moller_trumbore(T, c, o, d, &tc) && tc >= lo && tc <= hi && tc == best) btri = c;
    }
    *t_out = best;
    *tri = btri;
    return 1;
  }
  double te = t_e < 1e300 ? t_e : 1e300;
  double P[3] = {o[0] + te * d[0], o[1] + te * d[1], o[2] + te * d[2]};
  double top = np_min(hi, t_e + T->eps);
  const double g = T->grow;
  best = INF_D;
  btri = -1;
  for (int64_t c = 0; c < T->n_tri; c++) {
    if (T->tri_slot[c] >= 0) continue;
    const int32_t* f = T->F + 3 * c;   /* its box: tiers.py's t_lo, t_hi rows (numpy's min/max) */
    const double *p0 = T->V + 3 * (size_t)f[0], *p1 = T->V + 3 * (size_t)f[1], *p2 = T->V + 3 * (size_t)f[2];
    double a[3], b[3];
    for (int j = 0; j < 3; j++) {
      a[j] = np_min(np_min(p0[j], p1[j]), p2[j]);
      b[j] = np_max(np_max(p0[j], p1[j]), p2[j]);
    }
    if (!(P[0] >= a[0] - g && P[1] >= a[1] - g && P[2] >= a[2] - g && P[0] <= b[0] + g && P[1] <= b[1] + g &&
          P[2] <= b[2] + g)) continue;
    if (excl && T->tri_owner[c] == *excl) continue;
    double tc;
    int ok = moller_trumbore(T, c, o, d, &tc) && tc >= lo && tc <= top;
    if (!ok) tc = INF_D;
    if (btri < 0 || tc < best) { best = tc; btri = c; }
  }
  *t_out = best;
  *tri = isfinite(best) ? btri : -1;
  return isfinite(best);
}

/* refine._guard_hits for one ray that met the guard prism triangle `gprim`: the flat triangles of
 * that edge tested in float64; the nearest hit with lo <= t <= hi and t < best_t is taken (of
 * equal distances the first), and hi becomes it. Returns 1 when one was taken. */
static int guard_hits(const struct sp_tier* T, int64_t gprim, const double* o, const double* d, double lo, double* hi,
                      const int64_t* excl, double* best_t, int64_t* best_s, double* best_n) {
  int64_t e = gprim / T->prism_triangles;
  double best = INF_D;
  int64_t btri = -1;
  for (int64_t k = T->guard_ptr[e]; k < T->guard_ptr[e + 1]; k++) {
    int64_t c = T->guard_idx[k];
    if (excl && T->tri_owner[c] == *excl) continue;
    double t;
    if (!(moller_trumbore(T, c, o, d, &t) && t >= lo && t <= *hi && t < *best_t)) continue;
    if (t < best) { best = t; btri = c; }
  }
  if (btri < 0) return 0;
  *best_t = best;
  *hi = best;
  if (best_n) {
    const double* nrm = T->normal + 3 * btri;
    double f = dot3(nrm, d) > 0.0 ? -1.0 : 1.0;
    *best_s = T->tri_shape[btri];
    if (f < 0.0) { best_n[0] = nrm[0] * f; best_n[1] = nrm[1] * f; best_n[2] = nrm[2] * f; }
    else { best_n[0] = nrm[0]; best_n[1] = nrm[1]; best_n[2] = nrm[2]; }
  }
  return 1;
}

/* One ray through Embree (a packet with one valid lane: the same answer as in any packet). */
static void intersect1(void* scene, float ox, float oy, float oz, float dx, float dy, float dz, float far,
                       struct ray_hit16* r, struct intersect_args* args) {
  int valid[16];
  for (int k = 0; k < 16; k++) {
    valid[k] = k == 0 ? -1 : 0;
    r->org_x[k] = ox; r->org_y[k] = oy; r->org_z[k] = oz;
    r->dir_x[k] = dx; r->dir_y[k] = dy; r->dir_z[k] = dz;
    r->tnear[k] = 0.0f; r->time[k] = 0.0f; r->mask[k] = INVALID; r->id[k] = 0; r->flags[k] = 0;
    r->tfar[k] = far;
    r->geom[k] = INVALID; r->prim[k] = INVALID; r->inst[k] = INVALID;
  }
  intersect16(valid, scene, r, args);
}

/* EXACT: trace.py's _trace_loop over the rays with alive[i] (a robust scene, incoherent packets),
 * for a tier with edge guards or no risky edge: each pass judges every hit -- a guard met first
 * gets refine.py's second look (the guarded edge's triangles in float64, the hit of the scene
 * without guards, every further guard up to it), flat hits their float64 plane with barycentrics
 * checked near edges and the triangle's vertex ring or nearby triangles where needed, curved hits
 * the true surface -- and continues the rays it rejects past their hit, up to 32 passes per ray.
 * Per ray: the Embree start seg (updated in place as rays continue), lo, lim (after the pre-pass;
 * updated in place), the owner excluded (`excl` NULL: none in this tier). `thr` = 4 eps d_max.
 * best_t, best_s, best_n (NULL: distances only) as the numpy loop sets them. Packets are refilled
 * as rays finish (a ray's answer does not depend on the rays traced beside it).
 * counts[0] += rays continued, counts[1] += rays unresolved after 32 passes (or 32 guard steps),
 * counts[2] += float64 hits found by the guards' second look.
 * Why incoherent packets even for a lidar's one-origin rays: coherent ones traverse ~1.4x faster
 * (LidarAvoid x64's EXACT step: -11 %), but where a ray meets two triangles at the same float32
 * distance (a face's diagonal, a wall standing on a floor) a coherent traversal may report the
 * other one, and the float64 answer then comes from that triangle's plane: 1 ulp apart, or the
 * other shape (2 of 28,648 adversarial edge rays). EXACT must give embreex's answers bit for bit. */
void sp_exact_pass(void* scene, const struct sp_tier* T, size_t m, const double* O, size_t o_stride,
                   const double* D, const float* d32, double* seg, const double* lo, size_t lo_stride, double* lim,
                   const int64_t* excl, size_t excl_stride, const uint8_t* alive, double thr, double* best_t,
                   int64_t* best_s, double* best_n, size_t* counts) {
  struct ray_hit16 r, r1;
  struct intersect_args args;
  packet_init(&r, &args, 0);
  int valid[16];
  size_t lane_row[16];
  double lane_delta[16];
  int lane_pass[16];
  int lanes = 0;
  size_t next = 0;
  const double eps = T->eps;
  const double slack = 1.0 + 0x1p-20;
  const double w = 4.0 * eps;
  for (;;) {
    while (lanes < 16 && next < m) {   /* refill the packet with the next rays */
      if (alive[next]) {
        lane_row[lanes] = next; lane_delta[lanes] = 0.25 * eps; lane_pass[lanes] = 0;
        lanes++;
      }
      next++;
    }
    if (lanes == 0) break;
    double far64[16];
    for (int k = 0; k < 16; k++) {
      size_t i = lane_row[k < lanes ? k : 0];
      const double* o = O + o_stride * i;
      const double* d = D + 3 * i;
      double sa = seg[i];
      valid[k] = k < lanes ? -1 : 0;
      r.org_x[k] = (float)(o[0] + d[0] * sa);
      r.org_y[k] = (float)(o[1] + d[1] * sa);
      r.org_z[k] = (float)(o[2] + d[2] * sa);
      if (d32) {
        r.dir_x[k] = d32[3 * i]; r.dir_y[k] = d32[3 * i + 1]; r.dir_z[k] = d32[3 * i + 2];
      } else {
        r.dir_x[k] = (float)d[0]; r.dir_y[k] = (float)d[1]; r.dir_z[k] = (float)d[2];
      }
      far64[k] = ((lim[i] - sa) + eps) * slack;
      r.tfar[k] = (float)(far64[k] >= 0.0 ? far64[k] : -1.0);
      r.geom[k] = INVALID; r.prim[k] = INVALID; r.inst[k] = INVALID;
    }
    intersect16(valid, scene, &r, &args);
    int kept = 0;
    for (int q = 0; q < lanes; q++) {
      size_t row = lane_row[q];
      const double* o = O + o_stride * row;
      const double* d = D + 3 * row;
      const int64_t* ex = excl ? excl + excl_stride * row : NULL;
      double* bn = best_n ? best_n + 3 * row : NULL;
      int64_t* bs = best_n ? best_s + row : NULL;
      double sa = seg[row];
      double lo_i = lo[lo_stride * row];
      unsigned geom = r.geom[q], prim = r.prim[q];
      float tf = r.tfar[q], u = r.u[q], v = r.v[q];
      int cont = 0;
      if (geom == INVALID) goto done;                           /* no hit: done */
      if (T->guarded && geom == 1) {   /* a guard first: the second look (refine._guard_rays) */
        double s = (double)tf;
        float ox = r.org_x[q], oy = r.org_y[q], oz = r.org_z[q], dx = r.dir_x[q], dy = r.dir_y[q], dz = r.dir_z[q];
        intersect1(T->bare, ox, oy, oz, dx, dy, dz, (float)(far64[q] >= 0.0 ? far64[q] : -1.0), &r1, &args);
        double stop = np_min(far64[q], r1.geom[0] != INVALID ? (double)r1.tfar[0] + 4.0 * w : INF_D);
        counts[2] += guard_hits(T, prim, o, d, lo_i, lim + row, ex, best_t + row, bs, bn);
        geom = r1.geom[0]; prim = r1.prim[0]; tf = r1.tfar[0]; u = r1.u[0]; v = r1.v[0];
        int steps = 0;
        for (; steps < 32; steps++) {
          s = s + 0.5 * w;
          double f = stop - s;
          if (!(f >= 0.0)) break;
          double at = sa + s;
          intersect1(scene, (float)(o[0] + at * d[0]), (float)(o[1] + at * d[1]), (float)(o[2] + at * d[2]), dx, dy,
                     dz, (float)f, &r1, &args);
          if (r1.geom[0] == INVALID) break;
          s = s + (double)r1.tfar[0];
          if (r1.geom[0] == 1) counts[2] += guard_hits(T, r1.prim[0], o, d, lo_i, lim + row, ex, best_t + row, bs, bn);
        }
        if (steps == 32) counts[1]++;
        if (geom == INVALID) goto done;
      }
      int64_t tri = (int64_t)prim;
      double lim_i = lim[row];
      double t_e = sa + (double)tf;
      if (ex && T->tri_owner[tri] == *ex) { cont = 1; goto next_pass; }   /* an excluded owner */
      int32_t slot = T->tri_slot[tri];
      if (slot < 0) {   /* a flat triangle: its float64 plane, barycentrics checked near edges */
        const double* nrm = T->normal + 3 * tri;
        const double* v0 = first_vertex(T, tri);
        double dn = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2];
        double wv[3] = {v0[0] - o[0], v0[1] - o[1], v0[2] - o[2]};
        double tx = dot3(wv, nrm) / dn;
        int ok = isfinite(tx) && tx >= lo_i && tx <= lim_i;
        float m1 = (u < v || u != u) ? u : v;                  /* np.minimum in float32 */
        float m2 = (1.0f - u) - v;
        float margin = (m1 < m2 || m1 != m1) ? m1 : m2;
        int near_edge = !(margin > 1e-4f);
        if (!near_edge && !((double)margin * T->h_min[tri] * fabs(dn) > thr)) {
          double P[3] = {o[0] + tx * d[0] - v0[0], o[1] + tx * d[1] - v0[1], o[2] + tx * d[2] - v0[2]};
          double bu = dot3(P, T->g1 + 3 * tri), bv = dot3(P, T->g2 + 3 * tri);
          near_edge = !(bu >= -1e-9 && bv >= -1e-9 && bu + bv <= 1.0 + 1e-9);
        }
        if (near_edge) {   /* float64 tests of the hit triangle, its vertex ring, nearby triangles */
          ok = refine_flat(T, &tri, o, d, lo_i, lim_i, t_e, ex, &tx);
          nrm = T->normal + 3 * (tri >= 0 ? tri : T->n_tri);
          dn = dot3(d, nrm);
        }
        if (ok && tx < best_t[row]) {
          best_t[row] = tx;
          if (best_n) {
            double f = dn > 0.0 ? -1.0 : 1.0;
            best_s[row] = T->tri_shape[tri];
            best_n[3 * row] = nrm[0] * f; best_n[3 * row + 1] = nrm[1] * f; best_n[3 * row + 2] = nrm[2] * f;
          }
        }
        cont = !ok;                                            /* refinement missed: continued */
      } else {          /* a curved shell: the true surface */
        double nw[3];
        double ta = analytic_slot(T, slot, o, d, lo_i, lim_i, best_n ? nw : NULL);
        int found = isfinite(ta);
        if (found && ta < best_t[row]) {
          best_t[row] = ta;
          if (best_n) {
            if (dot3(nw, d) > 0.0) { nw[0] *= -1.0; nw[1] *= -1.0; nw[2] *= -1.0; }
            best_s[row] = T->c_shape[slot];
            best_n[3 * row] = nw[0]; best_n[3 * row + 1] = nw[1]; best_n[3 * row + 2] = nw[2];
          }
        }
        lim[row] = np_min(lim_i, found ? ta : INF_D);
        /* continued if missed, or if something else could lie between the shell and the surface */
        cont = !found || (ta > t_e + eps && !T->c_isolated[slot]);
      }
    next_pass:
      if (cont) {   /* past the hit: a wider step each time no progress is made */
        double delta = t_e < sa + eps ? lane_delta[q] * 4.0 : eps;
        seg[row] = np_max(t_e, sa) + delta;
        counts[0]++;
        if (!(seg[row] <= lim[row] + eps)) goto done;
        if (++lane_pass[q] >= 32) { counts[1]++; goto done; }
        lane_row[kept] = row; lane_delta[kept] = delta; lane_pass[kept] = lane_pass[q];
        kept++;
      }
    done:;
    }
    lanes = kept;
  }
}

/* FAST: trace.py's _trace_fast from the Embree call to its judging (_judge_fast, _special): one
 * plain-scene call (`coherent`: one origin, a lidar), then per ray t = tfar + start (float64),
 * limited by lim when `lim_min`; shape and normal toward the origin unless `distance_only`; and
 * special[i] = 1 for the rays the general loop must redo (possible self-hits, a curved shell hit
 * from inside, an excluded owner). Misses: t = inf, shape -1, a zero normal (-0.0 when most rays
 * hit, as the numpy path's whole-array judging leaves it). Returns the number of hits.
 * Per-ray values come as a pointer, or NULL and one value for all rays: the float32 origins o32
 * (row stride o_stride; NULL: o1, or start32 * d + o1 in float32 when `shifted`, as numpy computes
 * a lidar's shifted origins; o1 NULL too: the rows of Ot rounded to float32, + start32 * d when
 * `shifted`, numpy's astype and sum), the far limits (NULL: far_value, or none when `far_none`), the tier
 * frame origins Ot (NULL: `origin`), start, lim, the owner excluded (`has_excl`). */
/* One FAST pass's arguments (sp_fast_pass), shared by the threads that trace parts of it. */
struct fast_job {
  void* scene; const struct sp_tier* T; size_t m; int coherent; const float* o32; size_t o_stride;
  const float* o1; int shifted; float start32; const float* d32; const float* far; float far_value;
  int far_none; const double* Ot; size_t ot_stride; const double* origin; const double* D;
  const double* start; double start_value; const double* lim; double lim_value; int lim_min;
  const int64_t* excl; int64_t excl_value; int has_excl; int distance_only; double* t_out;
  int64_t* s_out; double* n_out; uint8_t* special; size_t run; const int64_t* seg_end;
};

/* A part of a FAST pass: the rays [a0, a1) (a0 a multiple of 16, or of the run: every packet holds
 * the rays it holds in one pass over all); its number of hits. */
struct fast_part { const struct fast_job* job; size_t a0, a1, n_hit; };

static void* fast_range(void* arg) {
  struct fast_part* P = arg;
  const struct fast_job* J = P->job;
  void* scene = J->scene; const struct sp_tier* T = J->T; const int coherent = J->coherent;
  const float* o32 = J->o32; const size_t o_stride = J->o_stride; const float* o1 = J->o1;
  const int shifted = J->shifted; const float start32 = J->start32; const float* d32 = J->d32;
  const float* far = J->far; const float far_value = J->far_value; const int far_none = J->far_none;
  const double* Ot = J->Ot; const size_t ot_stride = J->ot_stride; const double* origin = J->origin;
  const double* D = J->D; const double* start = J->start; const double start_value = J->start_value;
  const double* lim = J->lim; const double lim_value = J->lim_value; const int lim_min = J->lim_min;
  const int64_t* excl = J->excl; const int64_t excl_value = J->excl_value; const int has_excl = J->has_excl;
  const int distance_only = J->distance_only; double* t_out = J->t_out; int64_t* s_out = J->s_out;
  double* n_out = J->n_out; uint8_t* special = J->special;
  const size_t run = coherent ? J->run : 0;
  const int64_t* seg_end = coherent ? J->seg_end : NULL;
  const size_t m = P->a1;
  struct ray_hit16 r;
  struct intersect_args args;
  packet_init(&r, &args, coherent);
  int valid[16];
  size_t n_hit = 0;
  const float eps32 = (float)T->eps;
  const float graze = (float)(1e-5 * T->ng_max);
  const float far1 = far_none ? 1e37f : far_value;
  for (size_t a = P->a0, next; a < m; a = next) {
    /* a coherent packet never spans two runs: each run is packed from its first ray, as its own
       one-origin cast packs it -- a coherent packet's traversal can change a lane's answer with the
       packet's other rays (seen far from the origin, where float32 is coarse) */
    next = a + 16 < m ? a + 16 : m;
    if (run > 0 && (a / run + 1) * run < next) next = (a / run + 1) * run;
    if (seg_end && (size_t)seg_end[a] < next) next = (size_t)seg_end[a];
    int mk = (int)(next - a);
    for (int k = 0; k < 16; k++) {
      size_t i = a + (k < mk ? (size_t)k : 0);
      const float* d = d32 + 3 * i;
      valid[k] = k < mk ? -1 : 0;
      if (o32) {
        const float* o = o32 + o_stride * i;
        r.org_x[k] = o[0]; r.org_y[k] = o[1]; r.org_z[k] = o[2];
      } else if (!o1) {   /* Ot's rows rounded to float32 (numpy's astype), shifted as below */
        const double* ot = Ot ? Ot + ot_stride * i : origin;
        const float ox = (float)ot[0], oy = (float)ot[1], oz = (float)ot[2];
        if (shifted) { r.org_x[k] = ox + start32 * d[0]; r.org_y[k] = oy + start32 * d[1]; r.org_z[k] = oz + start32 * d[2]; }
        else { r.org_x[k] = ox; r.org_y[k] = oy; r.org_z[k] = oz; }
      } else if (shifted) {
        r.org_x[k] = start32 * d[0] + o1[0]; r.org_y[k] = start32 * d[1] + o1[1]; r.org_z[k] = start32 * d[2] + o1[2];
      } else {
        r.org_x[k] = o1[0]; r.org_y[k] = o1[1]; r.org_z[k] = o1[2];
      }
      r.dir_x[k] = d[0]; r.dir_y[k] = d[1]; r.dir_z[k] = d[2];
      r.tfar[k] = far ? far[i] : far1;
      r.geom[k] = INVALID; r.prim[k] = INVALID; r.inst[k] = INVALID;
    }
    intersect16(valid, scene, &r, &args);
    for (int k = 0; k < mk; k++) {
      size_t i = a + (size_t)k;
      special[i] = 0;
      if (r.geom[k] == INVALID) {
        t_out[i] = INF_D;
        if (!distance_only) { s_out[i] = -1; n_out[3 * i] = n_out[3 * i + 1] = n_out[3 * i + 2] = 0.0; }
        continue;
      }
      n_hit++;
      int64_t tri = (int64_t)r.prim[k];
      float tf = r.tfar[k];
      double t = (double)tf + (start ? start[i] : start_value);
      if (lim_min) t = np_min(t, lim ? lim[i] : lim_value);
      t_out[i] = t;
      int curved = T->tri_slot[tri] >= 0;
      int back = 0;
      if (!distance_only || curved) {   /* the side hit: Embree's Ng has our winding */
        const float* d = d32 + 3 * i;
        float dots = r.ng_x[k] * d[0] + r.ng_y[k] * d[1] + r.ng_z[k] * d[2];
        back = dots > 0.0f;
        if (fabsf(dots) < graze) back = dot3(T->normal + 3 * tri, D + 3 * i) > 0.0;   /* grazing: float64 */
      }
      if (!distance_only) {
        const double* nrm = T->normal + 3 * tri;
        s_out[i] = T->tri_shape[tri];
        if (back) { n_out[3 * i] = nrm[0] * -1.0; n_out[3 * i + 1] = nrm[1] * -1.0; n_out[3 * i + 2] = nrm[2] * -1.0; }
        else { n_out[3 * i] = nrm[0]; n_out[3 * i + 1] = nrm[1]; n_out[3 * i + 2] = nrm[2]; }
      }
      int sp = 0;
      if (tf < eps32) {   /* possible self-hit: the origin on the triangle's plane */
        const double* v = T->V + 3 * (size_t)T->F[3 * tri];
        const double* o = Ot ? Ot + ot_stride * i : origin;
        double w[3] = {o[0] - v[0], o[1] - v[1], o[2] - v[2]};
        sp = fabs(dot3(w, T->normal + 3 * tri)) <= 2.0 * T->eps;
      }
      if (back && curved) sp = 1;                              /* leaving a curved shell */
      if (has_excl && T->tri_owner[tri] == (excl ? excl[i] : excl_value)) sp = 1;
      special[i] = (uint8_t)sp;
    }
  }
  P->n_hit = n_hit;
  return NULL;
}

#ifdef __linux__
static cpu_set_t worker_cpus;
static int worker_cpus_set = 0;
#endif

/* The CPUs a pass's threads run on (the process's CPUs as it started: a server that pinned its
 * loop thread to one CPU, `serve --cpu`, still traces its large casts on every CPU); n = 0: the
 * caller's. Returns 1 where threads can be placed (Linux), else 0. */
int sp_set_worker_cpus(size_t n, const int32_t* cpus) {
#ifdef __linux__
  CPU_ZERO(&worker_cpus);
  for (size_t k = 0; k < n; k++)
    if (cpus[k] >= 0 && cpus[k] < CPU_SETSIZE) CPU_SET(cpus[k], &worker_cpus);
  worker_cpus_set = n > 0;
  return 1;
#else
  (void)n; (void)cpus;
  return 0;
#endif
}

static void place_thread(void) {
#ifdef __linux__
  if (worker_cpus_set) pthread_setaffinity_np(pthread_self(), sizeof worker_cpus, &worker_cpus);
#endif
}

static void* fast_thread(void* arg) {
  place_thread();
  return fast_range(arg);
}

static void* probe_thread(void* arg) {
  place_thread();
#ifdef __linux__
  cpu_set_t got;
  if (pthread_getaffinity_np(pthread_self(), sizeof got, &got) == 0) *(int*)arg = CPU_COUNT(&got);
#endif
  return NULL;
}

/* The number of CPUs a pass's thread may run on, read back in a thread started as the pass starts
 * them (tests); -1 where unknown. */
int sp_probe_worker_cpus(void) {
  int n = -1;
  pthread_t t;
  if (pthread_create(&t, NULL, probe_thread, &n) != 0) return -1;
  pthread_join(t, NULL);
  return n;
}

/* FAST: trace.py's _trace_fast from the Embree call to its judging (see above the struct). With
 * `threads` > 1 and enough rays, the rays are split in `threads` parts traced side by side (POSIX
 * threads; the caller takes the first part): every ray's answer is the one a single pass gives.
 * `run` > 0 with `coherent`: the rays come in runs of `run` from one origin each (a batched world's
 * lidars), each packed from its own first ray, as its one-origin cast packs it. `seg_end` (NULL:
 * none) with `coherent`: runs of any length, seg_end[i] the end of ray i's run (every copy's pairs
 * with one body, as copies.py traces them): packed and split between threads the same way. */
size_t sp_fast_pass(void* scene, const struct sp_tier* T, size_t m, int coherent, const float* o32, size_t o_stride,
                    const float* o1, int shifted, float start32, const float* d32, const float* far, float far_value,
                    int far_none, const double* Ot, size_t ot_stride, const double* origin, const double* D,
                    const double* start, double start_value, const double* lim, double lim_value, int lim_min,
                    const int64_t* excl, int64_t excl_value, int has_excl, int distance_only, double* t_out,
                    int64_t* s_out, double* n_out, uint8_t* special, int threads, size_t run,
                    const int64_t* seg_end) {
  struct fast_job J = {scene, T, m, coherent, o32, o_stride, o1, shifted, start32, d32, far, far_value, far_none, Ot,
                       ot_stride, origin, D, start, start_value, lim, lim_value, lim_min, excl, excl_value, has_excl,
                       distance_only, t_out, s_out, n_out, special, run, seg_end};
  enum { MAX_THREADS = 64, MIN_PART = 4096 };
  if (threads > MAX_THREADS) threads = MAX_THREADS;
  if (threads > 1 && m / (size_t)threads < MIN_PART) threads = (int)(m / MIN_PART);
  if (threads < 1) threads = 1;
  struct fast_part parts[MAX_THREADS];
  pthread_t tid[MAX_THREADS];
  int started[MAX_THREADS];
  /* the parts start where packets start: at a packet of 16, or at a run when coherent runs are given */
  const size_t unit = coherent && run > 0 ? run : 16, packs = (m + unit - 1) / unit;
  for (int k = 0; k < threads; k++) {
    parts[k].job = &J;
    parts[k].a0 = unit * (packs * (size_t)k / (size_t)threads);
    parts[k].a1 = k + 1 == threads ? m : unit * (packs * (size_t)(k + 1) / (size_t)threads);
    parts[k].n_hit = 0;
  }
  if (coherent && seg_end)   /* a part starts where a run starts: at the end of the run it would cut */
    for (int k = 1; k < threads; k++) {
      size_t b = parts[k].a0;
      if (b > 0 && b < m && (size_t)seg_end[b - 1] > b) b = (size_t)seg_end[b - 1];
      if (b < parts[k - 1].a0) b = parts[k - 1].a0;
      parts[k - 1].a1 = parts[k].a0 = b;
    }
  for (int k = 1; k < threads; k++)   /* a thread that cannot start: its part is traced here below */
    started[k] = pthread_create(&tid[k], NULL, fast_thread, &parts[k]) == 0;
  fast_range(&parts[0]);
  size_t n_hit = parts[0].n_hit;
  for (int k = 1; k < threads; k++) {
    if (started[k]) pthread_join(tid[k], NULL);
    else fast_range(&parts[k]);
    n_hit += parts[k].n_hit;
  }
  if (!distance_only && 2 * n_hit >= m) {   /* the whole-array judging's misses: -0.0 normals */
    for (size_t i = 0; i < m; i++)
      if (s_out[i] < 0) n_out[3 * i] = n_out[3 * i + 1] = n_out[3 * i + 2] = -0.0;
  }
  return n_hit;
}

/* ---- a batched (CopyRays) cast in one call ----
 * copies.py's lean path: the planes, the static tier and the movers' broad phase of
 * CopyRays.cast for a FAST cast whose stages reduce, from its data, to sp_plane1 (one axis-aligned
 * plane, or none), one sp_fast_pass and sp_copy_pairs -- with the values the engine's Python
 * around them computes (the largest origin coordinate, the self-hit epsilon, each ray's limit and
 * float32 far limit, the merge of plane and mesh hits), each operation as numpy rounds it. The
 * stages of RayEngine.cast that this data rules out (origins outside the tier's sphere, start points
 * near a curved shell: the pre-pass) are screened first, conservatively: where one may apply, the
 * call returns -1 having written no output, and copies.py takes the general path. Every field is
 * 8 bytes (copies.py's ctypes mirror). */
struct sp_copy_job {
  /* rays: origins O and directions D (n, 3); d32 the directions in float32, or NULL: rounded here
     into d32_buf; t_near one value; t_far per ray (far) or one value; rows: the distinct origins
     (n_rows of them) or NULL */
  int64_t n; const double* O; const double* D; const float* d32; float* d32_buf;
  double near; const double* far; double far_value; int64_t distance_only; int64_t coherent; int64_t threads;
  int64_t n_rows; const double* rows;
  /* the plane (plane != 0): sp_plane1's arguments */
  int64_t plane; int64_t axis; double c; int64_t visual; const double* pt; const double* nz; int64_t sized;
  const double* ax; const double* ay; const double* half; int64_t sid;
  /* the static tier (scene NULL: none); its curved shells' centres and screening radii */
  void* scene; const struct sp_tier* T; double radius; int64_t n_shells; const double* shell_c;
  const double* shell_bound;
  /* scratch, n rows each: each ray's limit, its float32 far limit, the tier's hits, the redo flags */
  double* lim; float* far32; double* st_t; int64_t* st_s; double* st_n; uint8_t* special;
  /* outputs (s, nrm NULL when distance_only) */
  double* t; int64_t* s; double* nrm;
  /* the movers' broad phase (R = 0: none): C copies of R slots, rot (C, R, 3, 3), pos (C, R, 3),
     each slot's sphere anchor (R, 3) and r2, centre (C, R, 3) written here */
  int64_t C; int64_t R; int64_t run; const int64_t* copy; const double* rot; const double* pos;
  const double* anchor; const double* r2; const uint8_t* present; double* centre; const int64_t* excl;
  int64_t excl_value; const int64_t* mnt; int64_t mnt_value; int64_t* out_ray; int64_t* out_body;
  /* results */
  double big; double eps64; int64_t plane_hits; int64_t n_hit; int64_t n_special; int64_t into_out;
  int64_t n_pairs;
};

size_t sp_plane1(size_t n, const double* O, size_t o_stride, const double* D, int axis, double c, int visual,
                 const double* pt, const double* nz, const double* lo, double lo_value, const double* hi,
                 double hi_value, int sized, const double* ax, const double* ay, const double* half, int check_owner,
                 int64_t owner, const int64_t* excl, int64_t excl_value, int64_t sid, double* dist, int64_t* shape,
                 double* normal);
size_t sp_copy_pairs(size_t n, size_t R, size_t run, const double* O, const double* D, const int64_t* copy,
                     const double* centre, const double* r2, const uint8_t* present, const double* lo,
                     double lo_value, const double* lim, double lim_value, const double* dist,
                     const int64_t* excl, int64_t excl_value, const int64_t* mnt, int64_t mnt_value,
                     int64_t* out_ray, int64_t* out_body);

/* The merge of the tier's hits into the plane's (engine._cast_static) and the broad phase
 * (copies.py: each slot's sphere centre pos + rot @ anchor, summed as einsum sums it, then
 * sp_copy_pairs against the merged distances); the number of pairs. */
int64_t sp_copy_finish(struct sp_copy_job* J) {
  const size_t n = (size_t)J->n;
  if (J->plane_hits > 0 && J->n_hit > 0) {
    if (J->distance_only) {
      for (size_t i = 0; i < n; i++) J->t[i] = np_min(J->t[i], J->st_t[i]);
    } else {
      for (size_t i = 0; i < n; i++)
        if (J->st_t[i] < J->t[i]) {
          J->t[i] = J->st_t[i]; J->s[i] = J->st_s[i];
          J->nrm[3 * i] = J->st_n[3 * i]; J->nrm[3 * i + 1] = J->st_n[3 * i + 1]; J->nrm[3 * i + 2] = J->st_n[3 * i + 2];
        }
    }
  }
  J->n_pairs = 0;
  if (J->R <= 0) return 0;
  const size_t R = (size_t)J->R, CR = (size_t)J->C * R;
  for (size_t b = 0; b < CR; b++) {
    const double* M = J->rot + 9 * b;
    const double* a = J->anchor + 3 * (b % R);
    for (int i = 0; i < 3; i++) {
      double acc = 0.0;
      acc += M[3 * i] * a[0]; acc += M[3 * i + 1] * a[1]; acc += M[3 * i + 2] * a[2];
      J->centre[3 * b + (size_t)i] = J->pos[3 * b + (size_t)i] + acc;
    }
  }
  J->n_pairs = (int64_t)sp_copy_pairs(n, R, (size_t)J->run, J->O, J->D, J->copy, J->centre, J->r2, J->present, NULL,
                                      J->near, J->far, J->far_value, J->t, J->excl, J->excl_value, J->mnt,
                                      J->mnt_value, J->out_ray, J->out_body);
  return J->n_pairs;
}

/* The cast: -1 where the general path must answer (nothing written but scratch); 1 where some rays
 * need the general loop's redo (the special flags; copies.py redoes them, then sp_copy_finish); 0
 * done (the broad phase's pairs in n_pairs). */
int64_t sp_copy_cast(struct sp_copy_job* J) {
  const size_t n = (size_t)J->n;
  /* the largest |coordinate| of the origins (RayEngine.cast: over the distinct rows when given) */
  const double* src = J->rows ? J->rows : J->O;
  const size_t ns = J->rows ? (size_t)J->n_rows : n;
  double lo = INF_D, hi = -INF_D;
  for (size_t k = 0; k < 3 * ns; k++) {
    const double x = src[k];
    if (!(x - x == 0.0)) return -1;   /* NaN or infinite: the general path */
    if (x < lo) lo = x;
    if (x > hi) hi = x;
  }
  const double big = -lo > hi ? -lo : hi;
  const double eps64 = 1e-9 + 1e-14 * big;
  const double lo_near = eps64 > J->near ? eps64 : J->near;   /* max(t_near, eps64) */
  J->big = big; J->eps64 = eps64;
  const struct sp_tier* T = J->T;
  if (J->scene) {
    /* origins outside the tier's sphere (trace.py clips them): a float32 test with margin */
    if (big * 1.7321 > J->radius) {
      const double thr = (double)(float)(J->radius * J->radius) * (1.0 - 1e-5);
      for (size_t k = 0; k < ns; k++) {
        const double x = (double)(float)src[3 * k], y = (double)(float)src[3 * k + 1], z = (double)(float)src[3 * k + 2];
        if (x * x + y * y + z * z > thr) return -1;
      }
    }
    /* a start point maybe in a curved shell's sphere (trace._near_shells, the same operations) */
    for (size_t k = 0; k < ns && J->n_shells > 0; k++) {
      const double* o = src + 3 * k;
      for (int64_t q = 0; q < J->n_shells; q++) {
        const double* c = J->shell_c + 3 * q;
        const double dx = o[0] - c[0], dy = o[1] - c[1], dz = o[2] - c[2];
        if (sqrt(dx * dx + dy * dy + dz * dz) <= (J->shell_bound[q] + lo_near) * (1.0 + 1e-9)) return -1;
      }
    }
  }
  /* the plane (cast_planes -> packets.plane1): its hits straight into the outputs */
  int64_t k = 0;
  if (J->plane)
    k = (int64_t)sp_plane1(n, J->O, 3, J->D, (int)J->axis, J->c, (int)J->visual, J->pt, J->nz, NULL, lo_near, J->far,
                           J->far_value, (int)J->sized, J->ax, J->ay, J->half, 0, 0, NULL, 0, J->sid, J->t,
                           J->distance_only ? NULL : J->s, J->nrm);
  J->plane_hits = k;
  J->n_hit = 0; J->n_special = 0; J->into_out = k == 0;
  if (!J->scene) {
    if (!J->plane) {   /* nothing to hit: engine._cast_static's empty answer */
      for (size_t i = 0; i < n; i++) {
        J->t[i] = INF_D;
        if (!J->distance_only) { J->s[i] = -1; J->nrm[3 * i] = J->nrm[3 * i + 1] = J->nrm[3 * i + 2] = 0.0; }
      }
    }
    return sp_copy_finish(J), 0;
  }
  /* each ray's limit: t_far, or np.minimum(t_far, plane hit) once a plane was hit; FAST's float32
     far limit from it (trace.py: (lim - start) * slack, per ray or one value) */
  const double slack = 1.0 + 0x1p-20;
  const double* lim = NULL;
  double lim_value = J->far_value;
  if (k > 0) {
    for (size_t i = 0; i < n; i++) J->lim[i] = np_min(J->far ? J->far[i] : J->far_value, J->t[i]);
    lim = J->lim;
  } else if (J->far) {
    lim = J->far;
  }
  const float* far32 = NULL;
  float far_value32 = 0.0f;
  int far_none = 0;
  if (lim) {
    for (size_t i = 0; i < n; i++) J->far32[i] = (float)((J->near == 0.0 ? lim[i] : lim[i] - J->near) * slack);
    far32 = J->far32;
  } else {
    const double f = (lim_value - J->near) * slack;
    far_none = f == INF_D;
    far_value32 = far_none ? 0.0f : (float)f;
  }
  const float* d32 = J->d32;
  if (!d32) {
    for (size_t i = 0; i < 3 * n; i++) J->d32_buf[i] = (float)J->D[i];
    d32 = J->d32_buf;
  }
  const int shifted = J->near > 0.0;
  double* tt = k > 0 ? J->st_t : J->t;
  int64_t* ss = J->distance_only ? NULL : (k > 0 ? J->st_s : J->s);
  double* nn = J->distance_only ? NULL : (k > 0 ? J->st_n : J->nrm);
  const int lim_min = lim != NULL || lim_value != INF_D;
  J->n_hit = (int64_t)sp_fast_pass(J->scene, T, n, (int)J->coherent, NULL, 0, NULL, shifted, shifted ? (float)J->near : 0.0f,
                                   d32, far32, far_value32, far_none, J->O, 3, J->O, J->D, NULL, J->near, lim,
                                   lim ? 0.0 : lim_value, lim_min, NULL, 0, 0, (int)J->distance_only, tt, ss, nn,
                                   J->special, (int)J->threads, (size_t)J->run, NULL);
  int64_t sp = 0;
  for (size_t i = 0; i < n; i++) sp += J->special[i];
  J->n_special = sp;
  if (sp) return 1;
  return sp_copy_finish(J), 0;
}

/* A fixed lidar's scan from its beams' distances, rows [0, n) (sensors.py, Lidar.finish): lidar.py's
 * ranges_from_hits without noise or resolution, then point_xyz, one pass. Per beam v = dist[i]
 * (times factor[i] for a planar lidar), range = float32(v), +inf unless v >= lo and
 * range < hi32; with xyz, the point float32(c_k[i] * (double)range) along the point-cloud columns
 * cx, cy, cz (inf * 0 gives NaN, as numpy's product). Each operation is numpy's, rounded as it
 * rounds it, so the same bits (tests/test_lidar_native.py). */
void sp_lidar_scan(size_t n, const double* dist, const double* factor, double lo, float hi32, const double* cx,
                   const double* cy, const double* cz, float* range, float* xyz) {
  for (size_t i = 0; i < n; i++) {
    double v = factor ? dist[i] * factor[i] : dist[i];
    float r = (float)v;
    if (!(v >= lo) || r >= hi32) r = INFINITY;
    range[i] = r;
    if (xyz) {
      double rd = (double)r;
      xyz[3 * i] = (float)(cx[i] * rd); xyz[3 * i + 1] = (float)(cy[i] * rd); xyz[3 * i + 2] = (float)(cz[i] * rd);
    }
  }
}

/* The rows i of the (n,3) directions D with D[i] . v >= thr, into out (ascending); their number.
 * movers.py's cone test of a lidar's beams against a neighbouring body (a conservative test with
 * slack: the rounding of the dot product does not matter). */
size_t sp_cone(size_t n, const double* D, const double* v, double thr, int64_t* out) {
  size_t k = 0;
  const double v0 = v[0], v1 = v[1], v2 = v[2];
  for (size_t i = 0; i < n; i++) {
    const double* d = D + 3 * i;
    out[k] = (int64_t)i;
    k += d[0] * v0 + d[1] * v1 + d[2] * v2 >= thr;
  }
  return k;
}

/* exact._to_frame of gathered rows: out[i] = x[rows[i]] @ R, each summed (x0 R0j + x1 R1j) + x2 R2j
 * (no +0.0: the engine's rays into a body frame); rows NULL: every row in order. */
void sp_to_frame(size_t n, const double* x, const int64_t* rows, const double* R, double* out) {
  for (size_t i = 0; i < n; i++) {
    const double* v = x + 3 * (rows ? (size_t)rows[i] : i);
    double* o = out + 3 * i;
    for (int j = 0; j < 3; j++) o[j] = v[0] * R[j] + v[1] * R[3 + j] + v[2] * R[6 + j];
  }
}

/* ---- batched copies ---- */

/* copies.py's broad phase: the (ray, body) pairs of rays of many copies of a world, each ray
 * against the bounding sphere of every robot slot's body in its own copy only. Ray i (origin
 * O[i], unit direction D[i], interval [lo, f]) of copy copy[i] is paired with slot r when r is
 * present, is not the ray's excluded slot nor its mount slot, f >= lo, and the segment comes
 * within the sphere (centre[copy[i]][r], r2[r]) -- the numpy path's test, operation for operation
 * (it is conservative, with a slack of 1e-9 (1 + e2)). The ray's limit f is np.minimum(t_far,
 * dist[i]) (t_far: lim[i], or lim_value when lim is NULL; dist: its static hit). Pairs are written
 * slot by slot, each slot's rays ascending (the numpy path's order): ray into out_ray,
 * copy * R + r into out_body; returns their number (at most n * R). lo, excl, mnt: per ray when not
 * NULL, else the scalar value.
 * `run` > 0: the rays come in runs of `run` consecutive rays sharing one origin and one copy (a
 * lidar's scan, the clearance rays of a copy; the last run may be shorter): the origin's offset
 * to the sphere centre and its square (the same operations on the same values, so the same bits)
 * are made once per run, and with scalar lo and t_far a run whose origin lies so far from the
 * sphere that no segment of length max(|lo|, |t_far|) can reach it, with a margin far above the
 * rounding of the per-ray test, is passed over: it would give no pair. */
static inline size_t pair_rays(size_t a, size_t b, size_t R, size_t r, double rr, const double* cc, const double* O,
                               const double* D, const int64_t* copy, const double* lo, double lo_value,
                               const double* lim, double lim_value, const double* dist, const int64_t* excl,
                               const int64_t* mnt, int one, int64_t* out_ray, int64_t* out_body, size_t k) {
  double x = 0.0, y = 0.0, z = 0.0, e2 = 0.0;
  int64_t c = 0;
  if (one) {   /* a run: one origin, one copy */
    c = copy[a];
    cc += 3 * ((size_t)c * R + r);
    const double* o = O + 3 * a;
    x = cc[0] - o[0]; y = cc[1] - o[1]; z = cc[2] - o[2];
    e2 = x * x + y * y + z * z;
  }
  for (size_t i = a; i < b; i++) {
    if (excl && excl[i] == (int64_t)r) continue;
    if (mnt && mnt[i] == (int64_t)r) continue;
    const double l = lo ? lo[i] : lo_value;
    const double f = np_min(lim ? lim[i] : lim_value, dist[i]);
    if (!(f >= l)) continue;
    if (!one) {
      c = copy[i];
      const double* s = cc + 3 * ((size_t)c * R + r);
      const double* o = O + 3 * i;
      x = s[0] - o[0]; y = s[1] - o[1]; z = s[2] - o[2];
      e2 = x * x + y * y + z * z;
    }
    const double* d = D + 3 * i;
    const double bb = x * d[0] + y * d[1] + z * d[2];
    const double tc = np_min(np_max(bb, l), f);
    out_ray[k] = (int64_t)i;
    out_body[k] = c * (int64_t)R + (int64_t)r;
    k += e2 - tc * (bb + bb - tc) <= rr + 1e-9 * (1.0 + e2);
  }
  return k;
}

size_t sp_copy_pairs(size_t n, size_t R, size_t run, const double* O, const double* D, const int64_t* copy,
                     const double* centre, const double* r2, const uint8_t* present, const double* lo,
                     double lo_value, const double* lim, double lim_value, const double* dist,
                     const int64_t* excl, int64_t excl_value, const int64_t* mnt, int64_t mnt_value,
                     int64_t* out_ray, int64_t* out_body) {
  size_t k = 0;
  /* the longest segment a ray of a run can test (scalar limits only): |tc| <= max(|lo|, |t_far|) */
  const double reach = (!lo && !lim) ? np_max(fabs(lo_value), fabs(lim_value)) : INF_D;
  for (size_t r = 0; r < R; r++) {
    if (!present[r]) continue;
    if (!excl && excl_value == (int64_t)r) continue;
    if (!mnt && mnt_value == (int64_t)r) continue;
    const double rr = r2[r];
    if (!run) {
      k = pair_rays(0, n, R, r, rr, centre, O, D, copy, lo, lo_value, lim, lim_value, dist, excl, mnt, 0, out_ray,
                    out_body, k);
      continue;
    }
    for (size_t a = 0; a < n; a += run) {
      const size_t b = n - a < run ? n : a + run;
      if (reach < INF_D) {   /* |c - o - tc d| >= |c - o| - |tc|: far beyond the test's slack */
        const double* s = centre + 3 * ((size_t)copy[a] * R + r);
        const double* o = O + 3 * a;
        const double x = s[0] - o[0], y = s[1] - o[1], z = s[2] - o[2];
        const double e2 = x * x + y * y + z * z;
        const double e = sqrt(e2), gap = e - reach;
        if (gap > 0.0 && gap * gap > rr + 1e-9 * (1.0 + e2) + 1e-12 * (1.0 + (e + reach) * (e + reach))) continue;
      }
      k = pair_rays(a, b, R, r, rr, centre, O, D, copy, lo, lo_value, lim, lim_value, dist, excl, mnt, 1, out_ray,
                    out_body, k);
    }
  }
  return k;
}

/* batched.py's distance-sensor rays (batches._frames_t and _rotate_t's numpy path, operation for
 * operation): sensor s of robot slot slots[s] in copy copies[s] (rot (C, R, 3, 3), pos (C, R, 3))
 * with local frame pi[s] (local_rot (P, 3, 3), local_pos (P, 3)) and local ray directions k[s]
 * (local_dirs (G, N, 3)): its world frame W = robot rotation A @ local rotation, each entry summed
 * ((a0 l0 + a1 l1) + a2 l2) + 0.0, its position ((a0 p0 + a2 p2) + a1 p1) + 0.0 + robot position,
 * each ray W @ d summed ((w0 d0 + w2 d2) + w1 d1) + 0.0. Writes positions (S, 3), every ray's
 * origin (S * N, 3: its sensor's position) and direction (S * N, 3). Indices are the caller's,
 * within those arrays. */
void sp_sensor_rays(size_t S, size_t N, size_t R, const int64_t* copies, const int64_t* slots, const double* rot,
                    const double* pos, const int64_t* pi, const double* local_rot, const double* local_pos,
                    const int64_t* k, const double* local_dirs, double* positions, double* origins, double* dirs) {
  for (size_t s = 0; s < S; s++) {
    const size_t b = (size_t)copies[s] * R + (size_t)slots[s];
    const double* A = rot + 9 * b;
    const double* P = pos + 3 * b;
    const double* L = local_rot + 9 * (size_t)pi[s];
    const double* lp = local_pos + 3 * (size_t)pi[s];
    double W[9], p[3];
    for (int i = 0; i < 3; i++) {
      for (int q = 0; q < 3; q++)
        W[3 * i + q] = ((A[3 * i] * L[q] + A[3 * i + 1] * L[3 + q]) + A[3 * i + 2] * L[6 + q]) + 0.0;
      p[i] = (((A[3 * i] * lp[0] + A[3 * i + 2] * lp[2]) + A[3 * i + 1] * lp[1]) + 0.0) + P[i];
      positions[3 * s + (size_t)i] = p[i];
    }
    const double* d = local_dirs + 3 * N * (size_t)k[s];
    for (size_t n = 0; n < N; n++) {
      const double* dn = d + 3 * n;
      double* o = dirs + 3 * (N * s + n);
      double* g = origins + 3 * (N * s + n);
      for (int i = 0; i < 3; i++) {
        o[i] = ((W[3 * i] * dn[0] + W[3 * i + 2] * dn[2]) + W[3 * i + 1] * dn[1]) + 0.0;
        g[i] = p[i];
      }
    }
  }
}

/* The box of n points (rows of an (n,3) array): out[0..2] each column's minimum, out[3..5] its
 * maximum, NaN when the column holds one (numpy's min and max: refine.py's screening of the starts
 * of many rays, one pass over the rows where numpy's three column reductions make three). */
#define SP_LO(acc, x) acc = (x) < acc ? (x) : acc
#define SP_HI(acc, x) acc = (x) > acc ? (x) : acc
void sp_box3(size_t n, const double* O, double* out) {
  /* two rows a step into separate minima and maxima held in registers (independent chains, no
     NaN test in them: a comparison with NaN keeps the accumulator), NaN columns flagged apart */
  double l0 = O[0], l1 = O[1], l2 = O[2], h0 = O[0], h1 = O[1], h2 = O[2];
  double m0 = l0, m1 = l1, m2 = l2, g0 = h0, g1 = h1, g2 = h2;
  int n0 = O[0] != O[0], n1 = O[1] != O[1], n2 = O[2] != O[2];
  size_t i = 1;
  for (; i + 1 < n; i += 2) {
    const double* a = O + 3 * i;
    const double a0 = a[0], a1 = a[1], a2 = a[2], b0 = a[3], b1 = a[4], b2 = a[5];
    SP_LO(l0, a0); SP_LO(l1, a1); SP_LO(l2, a2); SP_HI(h0, a0); SP_HI(h1, a1); SP_HI(h2, a2);
    SP_LO(m0, b0); SP_LO(m1, b1); SP_LO(m2, b2); SP_HI(g0, b0); SP_HI(g1, b1); SP_HI(g2, b2);
    n0 |= (a0 != a0) | (b0 != b0); n1 |= (a1 != a1) | (b1 != b1); n2 |= (a2 != a2) | (b2 != b2);
  }
  if (i < n) {
    const double* a = O + 3 * i;
    SP_LO(l0, a[0]); SP_LO(l1, a[1]); SP_LO(l2, a[2]); SP_HI(h0, a[0]); SP_HI(h1, a[1]); SP_HI(h2, a[2]);
    n0 |= a[0] != a[0]; n1 |= a[1] != a[1]; n2 |= a[2] != a[2];
  }
  SP_LO(l0, m0); SP_LO(l1, m1); SP_LO(l2, m2); SP_HI(h0, g0); SP_HI(h1, g1); SP_HI(h2, g2);
  out[0] = n0 ? NAN : l0; out[1] = n1 ? NAN : l1; out[2] = n2 ? NAN : l2;
  out[3] = n0 ? NAN : h0; out[4] = n1 ? NAN : h1; out[5] = n2 ? NAN : h2;
}
#undef SP_LO
#undef SP_HI

/* refine.py's screening of the curved-shell pre-pass, for many rays of many origins (the copies of
 * a batched world: their origins span the world, so every shell is near some ray): the start
 * points S[i] = O[i] + lo[i] D[i] inside each listed shell k's extent -- its bounding sphere for a
 * sphere, else the cylinder (rad2, ax) of its vertices in the shape frame -- with the numpy path's
 * operations (refine._inside_shell: S - pos, exact._to_frame's sums (x0 R0j + x1 R1j) + x2 R2j).
 * bound_first: a cylinder's or capsule's start point must also lie within its bounding sphere
 * (bound2; the dense pass of refine.py tests the sphere first, then the extent). Pairs shell by
 * shell, rows ascending: row into out_row, k into out_slot; their number (at most m * nk).
 * o_stride 0: one origin for every ray. lo NULL: lo_value for every ray. */
size_t sp_inside_shells(size_t m, const double* O, size_t o_stride, const double* D, const double* lo,
                        double lo_value, size_t nk, const int64_t* shells, const int64_t* code,
                        const double* pos, const double* rot, const double* bound2, const double* rad2,
                        const double* ax, int bound_first, int64_t* out_row, int64_t* out_slot) {
  size_t k = 0;
  for (size_t q = 0; q < nk; q++) {
    const int64_t s = shells[q];
    const double* c = pos + 3 * s;
    const double* R = rot + 9 * s;
    const int sphere = code[s] == 1;
    for (size_t i = 0; i < m; i++) {
      const double* o = O + o_stride * i;
      const double* d = D + 3 * i;
      const double l = lo ? lo[i] : lo_value;
      const double p0 = (o[0] + l * d[0]) - c[0], p1 = (o[1] + l * d[1]) - c[1], p2 = (o[2] + l * d[2]) - c[2];
      int in;
      if (sphere || bound_first) in = (p0 * p0 + p1 * p1) + p2 * p2 <= bound2[s];
      else in = 1;
      if (!sphere && in) {
        const double x = (p0 * R[0] + p1 * R[3]) + p2 * R[6];
        const double y = (p0 * R[1] + p1 * R[4]) + p2 * R[7];
        const double z = (p0 * R[2] + p1 * R[5]) + p2 * R[8];
        in = (x * x + y * y <= rad2[s]) && (fabs(z) <= ax[s]);
      }
      out_row[k] = (int64_t)i;
      out_slot[k] = s;
      k += in;
    }
  }
  return k;
}

/* batched.py's contact broad phase (Contact.resolve_all's, for the moving robots of many copies):
 * move m (robot slot slots[m] of copy copies[m], from starts[m] (xy) with reach[m] = |end - start|
 * + EPS) against every solid j (its xy box lo/hi (S, 2), its z range zlo/zhi) and every other slot
 * j of its own copy (centre centres[copy][j] (C, R, 2) before the step, radius foot_radius[j] grown
 * by grow[copy][j] (C, R): that robot's own reach when it moves this step, else 0), each within
 * the height band (heights (C, R) + foot_low/foot_high (R)), a solid only when its top rises more
 * than floor_tol above the band's bottom (contact.FLOOR: lower, it is the ground the robot rests on)
 * -- the numpy path's comparisons, operation for operation (EPS = eps, FLOOR = floor_tol). Writes
 * solid_hit (k, S) and robot_hit (k, R) (0/1; a move never hits its own slot) and near[m] (any
 * hit); returns the number of near moves. A NaN radius (a robot without a footprint) hits nothing,
 * as there. */
size_t sp_contact_near(size_t k, size_t R, size_t S, const int64_t* copies, const int64_t* slots,
                       const double* starts, const double* reach, const double* foot_radius,
                       const double* foot_low, const double* foot_high, const double* heights,
                       const double* centres, const double* grow, const double* lo, const double* hi,
                       const double* zlo, const double* zhi, double eps, double floor_tol, uint8_t* solid_hit,
                       uint8_t* robot_hit, uint8_t* near) {
  size_t count = 0;
  for (size_t m = 0; m < k; m++) {
    const int64_t c = copies[m], s = slots[m];
    const double grown = reach[m] + foot_radius[s];
    const double bl0 = starts[2 * m] - grown, bl1 = starts[2 * m + 1] - grown;
    const double bh0 = starts[2 * m] + grown, bh1 = starts[2 * m + 1] + grown;
    const double h = heights[(size_t)c * R + (size_t)s];
    const double band_lo = h + foot_low[s], band_hi = h + foot_high[s];
    const double z_above = band_lo + eps, z_below = band_hi - eps, z_floor = band_lo + floor_tol;
    int any = 0;
    uint8_t* sh = solid_hit + m * S;
    for (size_t j = 0; j < S; j++) {
      const int in = lo[2 * j] <= bh0 && lo[2 * j + 1] <= bh1 && hi[2 * j] >= bl0 && hi[2 * j + 1] >= bl1
                     && zhi[j] > z_floor && zlo[j] < z_below;
      sh[j] = (uint8_t)in;
      any |= in;
    }
    if (R > 1) {
      uint8_t* rh = robot_hit + m * R;
      const double* cc = centres + 2 * (size_t)c * R;
      const double* hc = heights + (size_t)c * R;
      const double* gc = grow + (size_t)c * R;
      for (size_t j = 0; j < R; j++) {
        const double r_all = foot_radius[j] + gc[j];
        const double x = cc[2 * j], y = cc[2 * j + 1];
        const int in = (int64_t)j != s && x + r_all >= bl0 && x - r_all <= bh0 && y + r_all >= bl1
                       && y - r_all <= bh1 && hc[j] + foot_high[j] > z_above && hc[j] + foot_low[j] < z_below;
        rh[j] = (uint8_t)in;
        any |= in;
      }
    }
    near[m] = (uint8_t)any;
    count += (size_t)any;
  }
  return count;
}

/* batched.py's wheels and drives of one basic step, for every driven slot driven[d] (d < D) of
 * every live copy live[l] (l < L): WheelMotor.advance of its left and right wheel (target,
 * velocity, angle: (C, R, 2); the angle advanced in place), DifferentialDrive.step's side means
 * (for a slot with a side of several equal wheels, each side 0 + w + ... + w (its count times),
 * then / count), each side's sign (sign (R, 2): -1.0 for a side mounted mirrored; NULL: 1.0) and its
 * speeds v = r (wl + wr) / 2, w = r (wr - wl) / axle -- the numpy path's
 * operations, element for element (np.minimum's NaN). The moving robots (a side turning), copy
 * by copy and slot by slot: their copy, slot, v and w into out_*; returns their number. */
size_t sp_drive_wheels(size_t L, size_t D, size_t R, const int64_t* live, const int64_t* driven,
                       const double* target, const double* velocity, double* angle, double dt,
                       const int64_t* sides, const double* radius, const double* axle, const double* sign,
                       int64_t* out_copy, int64_t* out_slot, double* out_v, double* out_w) {
  size_t k = 0;
  for (size_t l = 0; l < L; l++) {
    const int64_t c = live[l];
    for (size_t d = 0; d < D; d++) {
      const int64_t s = driven[d];
      const size_t at = ((size_t)c * R + (size_t)s) * 2;
      const int skid = sides[2 * s] > 1 || sides[2 * s + 1] > 1;
      double om[2];
      for (int side = 0; side < 2; side++) {
        const double tgt = target[at + side], vel = velocity[at + side], ang = angle[at + side];
        double o;
        if (isinf(tgt)) {
          o = vel;
        } else {
          const double remaining = tgt - ang;
          const double speed = dt > 0 ? np_min(fabs(vel), fabs(remaining) / dt) : 0.0;
          o = remaining != 0.0 ? copysign(speed, remaining) : 0.0;
        }
        angle[at + side] = ang + o * dt;
        if (skid) {
          const int64_t n = sides[2 * s + side];
          double acc = 0.0 + o;
          for (int64_t i = 1; i < n; i++) acc = acc + o;
          o = acc / (double)n;
        }
        if (sign) o = o * sign[2 * s + side];
        om[side] = o;
      }
      if (om[0] != 0.0 || om[1] != 0.0) {
        out_copy[k] = c;
        out_slot[k] = s;
        out_v[k] = radius[s] * (om[0] + om[1]) / 2.0;
        out_w[k] = radius[s] * (om[1] - om[0]) / axle[s];
        k++;
      }
    }
  }
  return k;
}

/* batched.py's lidar planning: the beams of n scans of one fixed lidar, W beams each -- beam w of
 * scan i goes from org[i] along rot[i] (x[w], y[w], z[w]) (_rotate_columns, component j being
 * (x rot[j][0] + y rot[j][1]) + z rot[j][2], the numpy path's sums) -- written as rows i * W + w
 * of out_org, out_dir (float64) and out_d32 (the directions rounded to float32). */
void sp_lidar_beams(size_t n, size_t W, const double* rot, const double* org, const double* x, const double* y,
                    const double* z, double* restrict out_org, double* restrict out_dir, float* restrict out_d32) {
  for (size_t i = 0; i < n; i++) {
    const double* R = rot + 9 * i;
    /* the scan's matrix and origin held in locals: the outputs (restrict: the caller's own
     * buffers) cannot change them, so each beam is its three sums and stores */
    const double r00 = R[0], r01 = R[1], r02 = R[2], r10 = R[3], r11 = R[4], r12 = R[5], r20 = R[6], r21 = R[7],
                 r22 = R[8];
    const double o0 = org[3 * i], o1 = org[3 * i + 1], o2 = org[3 * i + 2];
    for (size_t w = 0; w < W; w++) {
      const size_t r = 3 * (i * W + w);
      const double xw = x[w], yw = y[w], zw = z[w];
      double a0 = xw * r00, a1 = xw * r10, a2 = xw * r20;
      a0 += yw * r01; a1 += yw * r11; a2 += yw * r21;
      a0 += zw * r02; a1 += zw * r12; a2 += zw * r22;
      out_dir[r] = a0; out_dir[r + 1] = a1; out_dir[r + 2] = a2;
      out_d32[r] = (float)a0; out_d32[r + 1] = (float)a1; out_d32[r + 2] = (float)a2;
      out_org[r] = o0;
      out_org[r + 1] = o1;
      out_org[r + 2] = o2;
    }
  }
}

/* batched.py's _cos_sin: libm's cos and sin of each of n angles, the calls Python's math.cos and
 * math.sin make (the single simulation's). Two loops, so that the compiler does not merge a cos and
 * a sin of one angle into one sincos call (another libm entry point). Returns the number of
 * infinite angles (math.cos refuses them: the caller then takes Python's way, error included). */
/* numpy's float64 remainder (npy_remainder: fmod, moved to b's sign; a zero takes b's sign) */
static inline double np_remainder(double a, double b) {
  double mod = fmod(a, b);
  if (!b) return mod;
  if (mod) {
    if ((b < 0) != (mod < 0)) mod += b;
  } else {
    mod = copysign(0.0, b);
  }
  return mod;
}

/* batched.py's _arc_steps (motion.arc_step per robot, element by element the same float64
 * operations: straight when |w dt| < 1e-9, x + (v dt) cos(yaw + dyaw / 2); else with r = v / w,
 * x + r (sin(yaw + dyaw) - sin(yaw)), y - r (cos(yaw + dyaw) - cos(yaw)); the new yaw
 * remainder((yaw + dyaw) + pi, 2 pi) - pi) and then the new yaw's cos and sin (the pose's Rz), the
 * libm calls math.cos/math.sin make. Returns the number of infinite angles handed to cos or sin
 * (math.cos refuses them: the caller's Python way says so); the outputs are then not to be used. */
/* one robot's arc of sp_arc_steps (its new x, y and yaw); returns its infinite angles' count. ``straight``:
 * the straight branch whatever the turn (motion.mid_heading_step: Webots' rule without Physics) */
static inline size_t arc_one(double x, double y, double yaw, double v, double w, double dt, int straight,
                             double* out_x, double* out_y, double* out_yaw) {
  const double pi = 3.141592653589793, two_pi = 2.0 * 3.141592653589793;
  size_t inf = 0;
  const double dyaw = w * dt;
  if (straight || fabs(dyaw) < 1e-9) {
    const double mid = yaw + 0.5 * dyaw;
    const double cm = cos(mid);
    const double sm = sin(mid);
    inf += isinf(mid) != 0;
    *out_x = x + v * dt * cm;
    *out_y = y + v * dt * sm;
  } else {
    const double r = v / w;
    const double a1 = yaw + dyaw;
    const double c1 = cos(a1);
    const double s1 = sin(a1);
    const double c0 = cos(yaw);
    const double s0 = sin(yaw);
    inf += (isinf(a1) != 0) + (isinf(yaw) != 0);
    *out_x = x + r * (s1 - s0);
    *out_y = y - r * (c1 - c0);
  }
  *out_yaw = np_remainder(yaw + dyaw + pi, two_pi) - pi;
  return inf;
}

/* one robot's step at the constant body twist (vx, vy, w) (batched_holonomic.py's twist_steps,
 * motion.twist_step: a = dt, b = 0 when w is 0, else a = sin(w dt) / w, b = 2 sin(0.5 w dt)^2 / w;
 * dx = a vx - b vy, dy = b vx + a vy turned by the starting heading; the new yaw wrapped as the
 * arcs'), element by element the numpy path's float64 operations; returns its infinite angles' count */
static inline size_t twist_one(double x, double y, double yaw, double vx, double vy, double w, double dt,
                               double* out_x, double* out_y, double* out_yaw) {
  const double pi = 3.141592653589793, two_pi = 2.0 * 3.141592653589793;
  size_t inf = 0;
  double a = dt, b = 0.0;
  if (w != 0.0) {
    const double h = 0.5 * w * dt, full = w * dt;
    const double half = sin(h);
    a = sin(full) / w;
    b = 2.0 * half * half / w;
    inf += (isinf(h) != 0) + (isinf(full) != 0);
  }
  const double dx = a * vx - b * vy, dy = b * vx + a * vy;
  const double c = cos(yaw);
  const double s = sin(yaw);
  inf += isinf(yaw) != 0;
  *out_x = x + c * dx - s * dy;
  *out_y = y + s * dx + c * dy;
  *out_yaw = np_remainder(yaw + w * dt + pi, two_pi) - pi;
  return inf;
}

/* the new yaws' cos and sin, in two loops (see sp_cos_sin); the infinite yaws' count */
static size_t new_yaws_cos_sin(size_t n, const double* out_yaw, double* out_cos, double* out_sin) {
  size_t inf = 0;
  for (size_t i = 0; i < n; i++) {
    out_cos[i] = cos(out_yaw[i]);
    inf += isinf(out_yaw[i]) != 0;
  }
  for (size_t i = 0; i < n; i++) out_sin[i] = sin(out_yaw[i]);
  return inf;
}

size_t sp_arc_steps(size_t n, const double* x, const double* y, const double* yaw, const double* v, const double* w,
                    double dt, double* out_x, double* out_y, double* out_yaw, double* out_cos, double* out_sin) {
  size_t inf = 0;
  for (size_t i = 0; i < n; i++)
    inf += arc_one(x[i], y[i], yaw[i], v[i], w[i], dt, 0, out_x + i, out_y + i, out_yaw + i);
  return inf + new_yaws_cos_sin(n, out_yaw, out_cos, out_sin);
}

/* sp_drive_step's moves: move i of slot slot[i] by its arc about its origin, or, when the slot's
 * wheels' centre (centre[2 slot], centre[2 slot + 1]) is off its origin (centre not NULL), by the
 * origin's body twist (v + w cy, -w cx, w) (batched.py's _drive_numpy: DifferentialDrive.step's
 * twist), or, when mid[slot] is set (mid not NULL: step_rule mid_heading), by the straight segment
 * along the mid-step heading; then the new yaws' cos and sin. Returns the infinite angles' count. */
static size_t drive_moves(size_t n, const int64_t* slot, const double* centre, const uint8_t* mid, const double* x,
                          const double* y, const double* yaw, const double* v, const double* w, double dt,
                          double* out_x, double* out_y, double* out_yaw, double* out_cos, double* out_sin) {
  size_t inf = 0;
  for (size_t i = 0; i < n; i++) {
    const double* cc = centre ? centre + 2 * (size_t)slot[i] : NULL;
    if (cc && (cc[0] != 0.0 || cc[1] != 0.0))
      inf += twist_one(x[i], y[i], yaw[i], v[i] + w[i] * cc[1], -w[i] * cc[0], w[i], dt, out_x + i, out_y + i,
                       out_yaw + i);
    else
      inf += arc_one(x[i], y[i], yaw[i], v[i], w[i], dt, mid && mid[slot[i]], out_x + i, out_y + i, out_yaw + i);
  }
  return inf + new_yaws_cos_sin(n, out_yaw, out_cos, out_sin);
}

size_t sp_cos_sin(size_t n, const double* a, double* out_cos, double* out_sin) {
  size_t inf = 0;
  for (size_t i = 0; i < n; i++) {
    out_cos[i] = cos(a[i]);
    inf += isinf(a[i]) != 0;
  }
  for (size_t i = 0; i < n; i++) out_sin[i] = sin(a[i]);
  return inf;
}

/* planes.py's cast_planes for one axis-aligned plane (a floor), every output it makes, operation
 * for operation: ray i (origin O + o_stride i, direction D + 3 i) meets the plane (point pt, normal
 * nz whose only non-zero component is nz[axis] = c) where den = D[axis] (times c unless c is 1)
 * passes (visual: den < 0, one-sided; else den != 0), t = ((r0 nz0 + r1 nz1) + r2 nz2) / den with
 * r = pt - o lies in [lo, hi] (per ray when not NULL, else the values), within the size when sized
 * (|x . ax| <= half[0] and |x . ay| <= half[1], x = t D - r, each dot summed ((x0 a0 + x1 a1) + x2 a2))
 * and, when check_owner, the plane's owner (-2: none) is not the ray's excluded owner. Writes dist
 * (t, else inf) and, unless shape is NULL, shape (sid, else -1) and normal (nz times -1 when
 * den > 0, else 1: toward the origin; 0 rows for misses). Returns the number of rays that passed
 * every test (cast_planes' count of ok: 0 means "no hit", its None). */
size_t sp_plane1(size_t n, const double* O, size_t o_stride, const double* D, int axis, double c, int visual,
                 const double* pt, const double* nz, const double* lo, double lo_value, const double* hi,
                 double hi_value, int sized, const double* ax, const double* ay, const double* half, int check_owner,
                 int64_t owner, const int64_t* excl, int64_t excl_value, int64_t sid, double* dist, int64_t* shape,
                 double* normal) {
  size_t hits = 0;
  for (size_t i = 0; i < n; i++) {
    const double* o = O + o_stride * i;
    const double* d = D + 3 * i;
    const double den = c == 1.0 ? d[axis] : d[axis] * c;
    int ok = visual ? den < 0.0 : den != 0.0;
    double t = INFINITY;
    if (ok) {
      const double r0 = pt[0] - o[0], r1 = pt[1] - o[1], r2 = pt[2] - o[2];
      t = (r0 * nz[0] + r1 * nz[1] + r2 * nz[2]) / den;
      ok = t >= (lo ? lo[i] : lo_value) && t <= (hi ? hi[i] : hi_value);
      if (ok && sized) {
        const double x0 = t * d[0] - r0, x1 = t * d[1] - r1, x2 = t * d[2] - r2;
        ok = fabs(x0 * ax[0] + x1 * ax[1] + x2 * ax[2]) <= half[0] && fabs(x0 * ay[0] + x1 * ay[1] + x2 * ay[2]) <= half[1];
      }
      if (ok && check_owner) ok = owner != (excl ? excl[i] : excl_value);
      if (!ok) t = INFINITY;
    }
    dist[i] = t;
    if (shape) {
      const int hit = t < INFINITY;
      const double sign = den > 0.0 ? -1.0 : 1.0;
      shape[i] = hit ? sid : -1;
      for (int j = 0; j < 3; j++) normal[3 * i + (size_t)j] = hit ? nz[j] * sign : 0.0;
    }
    hits += ok != 0;
  }
  return hits;
}

/* drive_moves for the numpy drive pass of a world with other drives too (packets.drive_moves):
 * the two-wheel robots' moves in C, the cars' and holonomic robots' beside them in numpy. */
size_t sp_drive_moves(size_t n, const int64_t* slot, const double* centre, const uint8_t* mid, const double* x,
                      const double* y, const double* yaw, const double* v, const double* w, double dt, double* out_x,
                      double* out_y, double* out_yaw, double* out_cos, double* out_sin) {
  return drive_moves(n, slot, centre, mid, x, y, yaw, v, w, dt, out_x, out_y, out_yaw, out_cos, out_sin);
}

/* batched.py's _drive up to the contact narrow phase, in one pass over the state arrays (their
 * addresses in a[], see DriveStep in packets.py): the live copies' robots stop pressing; their
 * wheels and drives (sp_drive_wheels); the moving robots' arcs (sp_arc_steps, from x, y, yaw
 * gathered), or their origin's twist for a robot whose wheels' centre is off its origin (a[42]:
 * the slots' centres (R, 2), NULL when none is; a[43]: the slots' mid_heading flags (R,) uint8, NULL
 * when none has it: drive_moves; a[44]: the slots' side signs (R, 2), NULL when no robot's wheels are mounted
 * mirrored: sp_drive_wheels), and their new yaws written; with contact, each move's reach hypot(end - start) + eps
 * + spin[slot] * fmin(|yaw1 - yaw0|, 2) (a shaped robot's push off what its turn goes into)
 * (np.hypot is libm's hypot), the grown discs (grow: 0, then the movers' reach) and the broad phase
 * (sp_contact_near). When no move is near anything, the moves end where Contact._clip without
 * candidates puts them (start + (end - start); a robot without a footprint: at its end): centres,
 * x and y written; else nothing more is written (the caller's narrow phase). Then each move's Rz
 * (its new yaw's cos and sin) and its base, gathered, for the pose's product. status[0]: infinite
 * angles (the outputs are then not to be used: the caller's Python way says so), status[1]: near
 * moves. Returns the number of moves. */
size_t sp_drive_step(size_t L, const int64_t* live, size_t D, const int64_t* driven, size_t C, size_t R, size_t S,
                     double dt, double eps, double floor_tol, int contact, void* const* a, int64_t* status) {
  const double* target = a[0];
  const double* velocity = a[1];
  double* angle = a[2];
  const int64_t* sides = a[3];
  const double* radius = a[4];
  const double* axle = a[5];
  double* x = a[6];
  double* y = a[7];
  double* yaw = a[8];
  uint8_t* pressing = a[9];
  int64_t* mc = a[10];
  int64_t* ms = a[11];
  double* v = a[12];
  double* w = a[13];
  double* starts = a[14];   /* (k, 2) */
  double* ends = a[15];     /* (k, 2) */
  double* x0 = a[16];       /* scratch: (k,) x, y, yaw gathered, then the arcs' outputs */
  double* y0 = a[17];
  double* yaw0 = a[18];
  double* x1 = a[19];
  double* y1 = a[20];
  double* yaw1 = a[21];
  double* cs = a[22];
  double* sn = a[23];
  double* rz = a[24];       /* (k, 3, 3) */
  const double* base = a[25];
  double* base_g = a[26];   /* (k, 3, 3) */
  status[0] = status[1] = 0;
  for (size_t l = 0; l < L; l++) memset(pressing + (size_t)live[l] * R, 0, R);
  const size_t k = sp_drive_wheels(L, D, R, live, driven, target, velocity, angle, dt, sides, radius, axle, a[44], mc,
                                   ms, v, w);
  if (!k) return 0;
  for (size_t m = 0; m < k; m++) {
    const size_t at = (size_t)mc[m] * R + (size_t)ms[m];
    x0[m] = x[at];
    y0[m] = y[at];
    yaw0[m] = yaw[at];
  }
  status[0] = (int64_t)drive_moves(k, ms, a[42], a[43], x0, y0, yaw0, v, w, dt, x1, y1, yaw1, cs, sn);
  if (status[0]) return k;
  for (size_t m = 0; m < k; m++) {
    const size_t at = (size_t)mc[m] * R + (size_t)ms[m];
    yaw[at] = yaw1[m];
    starts[2 * m] = x0[m];
    starts[2 * m + 1] = y0[m];
    ends[2 * m] = x1[m];
    ends[2 * m + 1] = y1[m];
    double* r = rz + 9 * m;
    r[0] = cs[m]; r[1] = -sn[m]; r[2] = 0.0;
    r[3] = sn[m]; r[4] = cs[m]; r[5] = 0.0;
    r[6] = 0.0; r[7] = 0.0; r[8] = 1.0;
    memcpy(base_g + 9 * m, base + 9 * at, 9 * sizeof(double));
  }
  if (contact) {
    double* reach = a[27];
    double* grow = a[28];     /* (C, R) */
    const double* foot_radius = a[29];
    double* centres = a[33];  /* (C, R, 2) */
    const double* spin = a[41];   /* (R,): contact.spin_reach */
    memset(grow, 0, C * R * sizeof(double));
    for (size_t m = 0; m < k; m++) {
      /* a shaped robot's turn may push it off what it turns into (Contact.resolve_all's reach) */
      reach[m] = hypot(x1[m] - x0[m], y1[m] - y0[m]) + eps + spin[ms[m]] * fmin(fabs(yaw1[m] - yaw0[m]), 2.0);
      grow[(size_t)mc[m] * R + (size_t)ms[m]] = reach[m];
    }
    status[1] = (int64_t)sp_contact_near(k, R, S, mc, ms, starts, reach, foot_radius, a[30], a[31], a[32], centres,
                                         grow, a[34], a[35], a[36], a[37], eps, floor_tol, a[38], a[39], a[40]);
    if (status[1]) return k;
    for (size_t m = 0; m < k; m++) {
      const size_t at = (size_t)mc[m] * R + (size_t)ms[m];
      const int bare = isnan(foot_radius[ms[m]]);
      centres[2 * at] = bare ? x1[m] : x0[m] + (x1[m] - x0[m]);
      centres[2 * at + 1] = bare ? y1[m] : y0[m] + (y1[m] - y0[m]);
    }
  }
  for (size_t m = 0; m < k; m++) {
    const size_t at = (size_t)mc[m] * R + (size_t)ms[m];
    x[at] = x1[m];
    y[at] = y1[m];
  }
  return k;
}

/* batched.py's _drive after the product: move m's rotation rot_in[m] (k, 3, 3) and position
 * (x, y, z of its copy and slot, (C, R) each) written into rot (C, R, 3, 3) and pos (C, R, 3). */
void sp_pose_scatter(size_t k, size_t R, const int64_t* mc, const int64_t* ms, const double* rot_in, const double* x,
                     const double* y, const double* z, double* rot, double* pos) {
  for (size_t m = 0; m < k; m++) {
    const size_t at = (size_t)mc[m] * R + (size_t)ms[m];
    memcpy(rot + 9 * at, rot_in + 9 * m, 9 * sizeof(double));
    pos[3 * at] = x[at];
    pos[3 * at + 1] = y[at];
    pos[3 * at + 2] = z[at];
  }
}

/* lookup.py's LookupTable.interpolate for a table of m >= 2 rows with strictly increasing inputs x:
 * for each of the count values v, the bracket numpy's searchsorted(x, v, side="right") - 1 gives
 * (NaN sorts last), clamped to [0, m - 2]; u = (v - x[lo]) / span (0 for a zero span), y and n
 * interpolated as (1 - u) y[lo] + u y[hi]; below or at x[0] the first row's, at or above the last
 * input the last row's -- the numpy path's operations, element by element. */
void sp_lookup(size_t count, const double* v, size_t m, const double* x, const double* y, const double* n,
               double* out_y, double* out_n) {
  for (size_t i = 0; i < count; i++) {
    const double vi = v[i];
    size_t lo;
    if (vi != vi) {
      lo = m - 2;
    } else {
      size_t a = 0, b = m;   /* the first input above vi */
      while (a < b) {
        const size_t mid = (a + b) / 2;
        if (x[mid] <= vi) a = mid + 1;
        else b = mid;
      }
      lo = a == 0 ? 0 : a - 1;
      if (lo > m - 2) lo = m - 2;
    }
    const size_t hi = lo + 1;
    const double span = x[hi] - x[lo];
    const double u = span != 0.0 ? (vi - x[lo]) / span : 0.0;
    double oy = (1.0 - u) * y[lo] + u * y[hi];
    double on = (1.0 - u) * n[lo] + u * n[hi];
    if (vi <= x[0]) {
      oy = y[0];
      on = n[0];
    } else if (vi >= x[m - 1]) {
      oy = y[m - 1];
      on = n[m - 1];
    }
    out_y[i] = oy;
    out_n[i] = on;
  }
}

/* libm's atan2 of n pairs (y[i * ys], x[i * xs]) into out[i * os]: the calls math.atan2 makes
 * (vector.py's poses' yaw). */
void sp_atan2(size_t n, const double* y, size_t ys, const double* x, size_t xs, double* out, size_t os) {
  for (size_t i = 0; i < n; i++) out[i * os] = atan2(y[i * ys], x[i * xs]);
}

/* distance.py's sonar_incidence without its last two steps: for each of n rays, |u x back| with
 * the numpy path's operations (each component a1 b2 - a2 b1, ..., the squares summed
 * (c0 c0 + c1 c1) + c2 c2, the root); u and back (n, 3). */
void sp_cross_norm(size_t n, const double* u, const double* back, double* out) {
  for (size_t i = 0; i < n; i++) {
    const double u0 = u[3 * i], u1 = u[3 * i + 1], u2 = u[3 * i + 2];
    const double b0 = back[3 * i], b1 = back[3 * i + 1], b2 = back[3 * i + 2];
    const double c0 = u1 * b2 - u2 * b1;
    const double c1 = u2 * b0 - u0 * b2;
    const double c2 = u0 * b1 - u1 * b0;
    out[i] = sqrt((c0 * c0 + c1 * c1) + c2 * c2);
  }
}

/* distance.py's combine for S sonars of N rays once the incidence angles beta (S, N) are known:
 * a ray echoes when its distance r is finite, within rmax[s] and beta < max_incidence; each
 * sonar's nearest echo (inf: none), then np.minimum with rmax[s] (NaN propagated as there). */
void sp_sonar_nearest(size_t S, size_t N, const double* r, const double* beta, const double* rmax,
                      double max_incidence, double* out) {
  for (size_t s = 0; s < S; s++) {
    double m = INFINITY;
    for (size_t j = 0; j < N; j++) {
      const double d = r[s * N + j];
      const int echo = isfinite(d) && d <= rmax[s] && beta[s * N + j] < max_incidence;
      const double v = echo ? d : INFINITY;
      m = np_min(m, v);
    }
    out[s] = np_min(m, rmax[s]);
  }
}

/* task.py's AvoidObstacles for many copies after the clearance cast: copy i's gap is the nearest
 * finite distance of its `rays` rays (d (n, rays)), far when none, minus the body radius -- the
 * numpy path's comparisons and its one subtraction (np.where / min / np.where, NaN propagated as
 * numpy's min propagates it). */
void sp_clearance_gaps(size_t n, size_t rays, const double* d, double far, double radius, double* gap) {
  for (size_t i = 0; i < n; i++) {
    double m = INFINITY;
    for (size_t j = 0; j < rays; j++) {
      const double v = d[i * rays + j];
      m = np_min(m, isfinite(v) ? v : INFINITY);
    }
    gap[i] = (isfinite(m) ? m : far) - radius;
  }
}

/* task.py's AvoidObstacles reward for n copies: wheel speeds wl, wr (velocity (C, R, 2) at copy
 * copies[i], slot `slot`) each over its own maximum (vmax_l, vmax_r), v = 0.5 (wl + wr), dv = |wl - wr| / 2, p = min(max(1 - gap / near,
 * 0), 1), r = v (1 - sqrt(dv)) (1 - p), minus the penalty when gap < contact -- the numpy path's
 * operations, element by element (np.maximum/np.minimum's NaN). */
void sp_avoid_reward(size_t n, const int64_t* copies, size_t R, size_t slot, const double* velocity, double vmax_l,
                     double vmax_r, const double* gap, double near, double contact, double penalty, double* out) {
  for (size_t i = 0; i < n; i++) {
    const double* vel = velocity + ((size_t)copies[i] * R + slot) * 2;
    const double wl = vel[0] / vmax_l, wr = vel[1] / vmax_r;
    const double v = 0.5 * (wl + wr);
    const double dv = fabs(wl - wr) / 2.0;
    const double q = 1.0 - gap[i] / near;
    const double lo = (q > 0.0 || q != q) ? q : 0.0;          /* np.maximum(q, 0.0) */
    const double p = (lo < 1.0 || lo != lo) ? lo : 1.0;       /* np.minimum(.., 1.0) */
    const double r = v * (1.0 - sqrt(dv)) * (1.0 - p);
    out[i] = gap[i] < contact ? r - penalty : r;
  }
}

/* ------------------------------------------------------------------------------------------------
 * batched kinematic devices (sim/batched_kinematic.py): the per-element libm calls of the GPS,
 * inertial unit and gyro models, so that every copy's device costs no Python float. Each is the
 * function Python's math module (or numpy's scalar power) calls, with the same arguments in the
 * same order, and the arithmetic around it is the numpy path's, element by element (no fused
 * multiply-adds: -ffp-contract=off). A non-zero return means an input the Python way treats
 * specially (an infinite angle math.sin refuses, a base Python's ** would not give to pow): the
 * caller then takes that way.
 * --------------------------------------------------------------------------------------------- */

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* math.atan2 (CPython's m_atan2): NaNs, infinities and zeros decided before libm's atan2 */
static double py_atan2(double y, double x) {
  if (isnan(x) || isnan(y)) return NAN;
  if (isinf(y)) {
    if (isinf(x)) return copysign(copysign(1.0, x) == 1.0 ? 0.25 * M_PI : 0.75 * M_PI, y);
    return copysign(0.5 * M_PI, y);
  }
  if (isinf(x) || y == 0.0) return copysign(1.0, x) == 1.0 ? copysign(0.0, y) : copysign(M_PI, y);
  return atan2(y, x);
}

/* Python's max(-1.0, min(1.0, v)): NaN gives 1.0 */
static inline double py_clamp1(double v) {
  const double m = v < 1.0 ? v : 1.0;
  return m > -1.0 ? m : -1.0;
}

/* orientation.roll_pitch_yaw of n (x, y, z, w) rows q: (roll, pitch, yaw) rows, ENU or (nue) NUE */
void sp_roll_pitch_yaw(size_t n, const double* q, int nue, double* out) {
  for (size_t i = 0; i < n; i++) {
    const double x = q[4 * i], y = q[4 * i + 1], z = q[4 * i + 2], w = q[4 * i + 3];
    double* o = out + 3 * i;
    if (nue) {
      o[2] = py_atan2(2.0 * y * w - 2.0 * x * z, 1.0 - 2.0 * y * y - 2.0 * z * z);
      o[0] = py_atan2(2.0 * x * w - 2.0 * y * z, 1.0 - 2.0 * x * x - 2.0 * z * z);
      o[1] = asin(py_clamp1(2.0 * x * y + 2.0 * z * w));
    } else {
      o[0] = py_atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y));
      o[1] = asin(py_clamp1(2.0 * (w * y - z * x)));
      o[2] = py_atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
    }
  }
}

/* the exponent 2 of orientation.inertial_quaternion's squares, out of the compiler's sight: pow(v,
 * 2.0) with a constant 2 is folded into v * v, which is not what numpy's scalar power calls */
static volatile double pow_two = 2.0;

/* inertial_quaternion's half angle of n (x, y, z, w) rows: atan2(sqrt(x**2 + y**2 + z**2), w),
 * each square libm's pow(v, 2) as numpy's scalar power computes it; non-zero for a non-finite
 * component (left to the Python way) */
size_t sp_half_angles(size_t n, const double* q, double* out) {
  const double two = pow_two;
  size_t odd = 0;
  for (size_t i = 0; i < n; i++) {
    const double* r = q + 4 * i;
    odd += !isfinite(r[0]) || !isfinite(r[1]) || !isfinite(r[2]) || !isfinite(r[3]);
    out[i] = py_atan2(sqrt(pow(r[0], two) + pow(r[1], two) + pow(r[2], two)), r[3]);
  }
  return odd;
}

/* gps.position's Gauss-Markov ratio: correlation ** exponent (Python's float power: libm's pow for
 * a positive finite base and a finite exponent), 0 where the correlation is 0; non-zero for any
 * other base or exponent (left to the Python way) */
size_t sp_correlation_ratios(size_t n, const double* corr, const double* expo, double* out) {
  size_t odd = 0;
  for (size_t i = 0; i < n; i++) {
    const double c = corr[i], e = expo[i];
    if (c == 0.0) {
      out[i] = 0.0;
      continue;
    }
    odd += !(c > 0.0) || !isfinite(c) || !isfinite(e);
    out[i] = e == 0.0 || c == 1.0 ? 1.0 : pow(c, e);
  }
  return odd;
}

/* motion_sensors.angular_velocity of n turns rel = r0^T r1 (row-major 3x3s, the numpy products):
 * the rotation vector over dt (s), rows of 3 */
void sp_gyro(size_t n, const double* rel, double dt, double* out) {
  for (size_t i = 0; i < n; i++) {
    const double* m = rel + 9 * i;
    double* o = out + 3 * i;
    const double angle = acos(py_clamp1(((m[0] + m[4] + m[8]) - 1.0) / 2.0));
    const double v0 = m[7] - m[5], v1 = m[2] - m[6], v2 = m[3] - m[1];
    if (angle < 1e-6) {
      o[0] = v0 / 2.0 / dt;
      o[1] = v1 / 2.0 / dt;
      o[2] = v2 / 2.0 / dt;
    } else {
      const double f = angle / (2.0 * sin(angle));
      o[0] = v0 * f / dt;
      o[1] = v1 * f / dt;
      o[2] = v2 * f / dt;
    }
  }
}

/* ------------------------------------------------------------------------------------------------
 * batched step, round 2: passes that replace a few numpy calls of the vector env's step each
 * (gym/vector.py, gym/task.py, sim/batched.py), element by element the numpy operations' values.
 */

/* gym/vector.py's clip of a range image to its Box's two float32 bounds lo <= hi (hi > 0): numpy's
 * clip (its maximum then minimum, a NaN kept), NaN -> hi, and where lo is a zero, a zero -> lo. */
void sp_box_clip32(size_t n, const float* in, float lo, float hi, float* out) {
  const int zero_lo = lo == 0.0f;
  for (size_t i = 0; i < n; i++) {
    float v = in[i];
    if (v != v) {
      out[i] = hi;
      continue;
    }
    v = v > lo ? v : lo;
    v = v < hi ? v : hi;
    out[i] = zero_lo && v == 0.0f ? lo : v;
  }
}

/* AvoidObstacles' outcome of n copies in one call: sp_clearance_gaps of the clearance cast's
 * distances d (n, rays) into gap, then sp_avoid_reward into reward and gap < contact into term.
 * Returns 1 (nothing written) when a copy lies outside [0, C). */
int sp_avoid_outcome(size_t n, size_t rays, const double* d, double far, double radius, const int64_t* copies,
                     size_t C, size_t R, size_t slot, const double* velocity, double vmax_l, double vmax_r, double near,
                     double contact, double penalty, double* gap, double* reward, uint8_t* term) {
  for (size_t i = 0; i < n; i++)
    if (copies[i] < 0 || (size_t)copies[i] >= C) return 1;
  sp_clearance_gaps(n, rays, d, far, radius, gap);
  sp_avoid_reward(n, copies, R, slot, velocity, vmax_l, vmax_r, gap, near, contact, penalty, reward);
  for (size_t i = 0; i < n; i++) term[i] = gap[i] < contact;
  return 0;
}

/* batched.py's _due over every copy: the (copy, column) pairs, row by row as numpy's nonzero lists
 * them, where per > 0 and time - last >= per (int64, numpy's wrap-around); their number. */
size_t sp_due(size_t C, size_t D, const int64_t* time, const int64_t* last, const int64_t* per, int64_t* out_c,
              int64_t* out_d) {
  size_t k = 0;
  for (size_t c = 0; c < C; c++) {
    const uint64_t t = (uint64_t)time[c];
    for (size_t d = 0; d < D; d++) {
      const int64_t p = per[c * D + d];
      if (p > 0 && (int64_t)(t - (uint64_t)last[c * D + d]) >= p) {
        out_c[k] = (int64_t)c;
        out_d[k] = (int64_t)d;
        k++;
      }
    }
  }
  return k;
}

/* batched_steered.py's constrained_twists: SteeredDrive.constrained_twist of one robot of W wheels
 * (places (W, 2), driven[j] 1 where wheel j has a motor, radius (W)) in n copies, from their wheel
 * speeds u and headings' cos and sin (n rows of stride ws): the no-sideways-slip rows, the first of the
 * largest cross products of two (the single drive's strict >), each sum from 0.0 left to right, the
 * numpy path's operations. out (n, 3) the twists; fallback[i] 1 (out[i] unwritten) where copy i's rows
 * leave no one line or its driven wheels no speed along it, for the caller's least-squares fit. The
 * number of fallbacks; W above 64 is refused (every copy a fallback). */
size_t sp_constrained_twists(size_t n, size_t W, const double* places, const uint8_t* driven, const double* radius,
                             const double* u, const double* cs, const double* sn, size_t ws, double* out,
                             uint8_t* fallback) {
  double rows[64][3];
  size_t falls = 0;
  for (size_t i = 0; i < n; i++) {
    if (W > 64) {
      fallback[i] = 1;
      falls++;
      continue;
    }
    const double* ci = cs + i * ws;
    const double* si = sn + i * ws;
    for (size_t j = 0; j < W; j++) {
      const double px = places[2 * j], py = places[2 * j + 1];
      rows[j][0] = -si[j];
      rows[j][1] = ci[j];
      rows[j][2] = px * ci[j] + py * si[j];
    }
    double best = 0.0, d0 = 0.0, d1 = 0.0, d2 = 0.0;
    for (size_t a = 0; a < W; a++)
      for (size_t b = a + 1; b < W; b++) {
        const double* ra = rows[a];
        const double* rb = rows[b];
        const double x0 = ra[1] * rb[2] - ra[2] * rb[1];
        const double x1 = ra[2] * rb[0] - ra[0] * rb[2];
        const double x2 = ra[0] * rb[1] - ra[1] * rb[0];
        const double size = sqrt((x0 * x0 + x1 * x1) + x2 * x2);
        if (size > best) {
          best = size;
          d0 = x0;
          d1 = x1;
          d2 = x2;
        }
      }
    double scale = 0.0;
    for (size_t j = 0; j < W; j++)
      for (size_t m = 0; m < 3; m++) scale = scale + fabs(rows[j][m]);
    int line = best > 1e-12 * scale * scale;
    for (size_t j = 0; j < W && line; j++)
      line = fabs((rows[j][0] * d0 + rows[j][1] * d1) + rows[j][2] * d2) <= 1e-9 * best * scale;
    double total = 0.0, spread = 0.0, rim = 0.0, crossed = 0.0, square = 0.0;
    for (size_t j = 0; j < W; j++) {
      if (!driven[j]) continue;
      const double c = ci[j], s = si[j];
      const double along = (c * d0 + s * d1) + (places[2 * j + 1] * -c + places[2 * j] * s) * d2;
      const double r = u[i * ws + j] * radius[j];
      total = total + along;
      spread = spread + fabs(along);
      rim = rim + r;
      crossed = crossed + along * r;
      square = square + along * along;
    }
    if (!line || !(spread > 0.0)) {
      fallback[i] = 1;
      falls++;
      continue;
    }
    fallback[i] = 0;
    const double k = fabs(total) > 1e-9 * spread ? rim / total : crossed / square;
    out[3 * i] = k * d0;
    out[3 * i + 1] = k * d1;
    out[3 * i + 2] = k * d2;
  }
  return falls;
}
