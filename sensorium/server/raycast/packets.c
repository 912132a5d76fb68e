/* Packet traversal for the ray engine: Embree's rtcIntersect16 over a batch of rays.
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
#include <dlfcn.h>
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
  LOAD(new_geometry_buffer, "rtcSetNewGeometryBuffer") LOAD(commit_geometry, "rtcCommitGeometry")
  LOAD(attach_geometry, "rtcAttachGeometry") LOAD(release_geometry, "rtcReleaseGeometry")
  LOAD(intersect16, "rtcIntersect16")
  return NULL;
}

void* sp_new_device(void) { return new_device(NULL); }

void sp_release_device(void* device) { release_device(device); }

static int add_triangles(void* device, void* scene, size_t nv, const float* vertices, size_t nf, const int32_t* faces) {
  void* g = new_geometry(device, GEOMETRY_TRIANGLE);
  if (!g) return -1;
  float* vb = new_geometry_buffer(g, BUFFER_VERTEX, 0, FORMAT_FLOAT3, 3 * sizeof(float), nv);
  int32_t* ib = new_geometry_buffer(g, BUFFER_INDEX, 0, FORMAT_UINT3, 3 * sizeof(int32_t), nf);
  if (!vb || !ib) { release_geometry(g); return -1; }
  memcpy(vb, vertices, nv * 3 * sizeof(float));
  memcpy(ib, faces, nf * 3 * sizeof(int32_t));
  commit_geometry(g);
  attach_geometry(scene, g);
  release_geometry(g);
  return 0;
}

/* A committed scene of one triangle geometry (id 0) and, when nv1 > 0, a second one (id 1), the
 * vertices copied into Embree's own buffers; NULL on any Embree error. */
void* sp_new_scene(void* device, int robust, size_t nv0, const float* v0, size_t nf0, const int32_t* f0,
                   size_t nv1, const float* v1, size_t nf1, const int32_t* f1) {
  void* scene = new_scene(device);
  if (!scene) return NULL;
  if (robust) set_scene_flags(scene, SCENE_ROBUST);
  int bad = nf0 && add_triangles(device, scene, nv0, v0, nf0, f0);
  if (!bad && nv1) bad = add_triangles(device, scene, nv1, v1, nf1, f1);
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
  memset(&args, 0, sizeof args);
  args.flags = coherent ? QUERY_COHERENT : 0;
  args.feature_mask = INVALID;
  args.min_width_distance_factor = 1.0f;
  int valid[16];
  for (int k = 0; k < 16; k++) {
    r.tnear[k] = 0.0f; r.time[k] = 0.0f; r.mask[k] = INVALID; r.id[k] = 0; r.flags[k] = 0;
  }
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
