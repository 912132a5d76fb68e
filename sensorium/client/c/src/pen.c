/* Sensorium C controller library: Pen. The server inks what the pen points at, every basic step
 * while it writes (infra-red sensors read the ink). Both functions are one RPC each, answered
 * before the next step starts (libController sends them with the next step request: the same
 * step paints with them). As in Webots, color is 0xRRGGBB (higher bits ignored) and density is
 * clamped to [0, 1]; a NaN density is printed and ignored. */
#include <math.h>
#include <stdio.h>

#include <webots/nodes.h>
#include <webots/pen.h>

#include "internal.h"

/* the pen of tag, NULL (after Webots' error or the "not simulated" warning) otherwise */
static sn_device *pen(WbDeviceTag tag, const char *func) {
  sn_device *d = sn_device_get(tag, SN_OTHER, func);
  if (d == NULL)
    return NULL;
  if (d->node_type != WB_NODE_PEN) {
    fprintf(stderr, "Error: %s(): device tag %u is '%s', a %s\n", func, (unsigned)tag, sn_shown(d->name), d->type_name);
    return NULL;
  }
  if (!d->simulated) { /* a server that lists pens only */
    sn_unsimulated(tag, WB_NODE_PEN, func);
    return NULL;
  }
  return d;
}

void wb_pen_write(WbDeviceTag tag, bool write) {
  sn_device *d = pen(tag, "wb_pen_write");
  if (d != NULL)
    sn_device_set(d, "write", sn_arg_bool, &write, "wb_pen_write");
}

typedef struct {
  int color;
  double density;
} ink;

static void ink_args(sn_req *r, const void *arg) {
  const ink *k = arg;
  sn_req_key(r, "color");
  msgpack_pack_int(&r->pk, k->color);
  sn_req_key(r, "density");
  msgpack_pack_double(&r->pk, k->density);
}

void wb_pen_set_ink_color(WbDeviceTag tag, int color, double density) {
  const char *func = "wb_pen_set_ink_color";
  sn_device *d = pen(tag, func);
  sn_robot *rb = sn_robot_get(func);
  if (d == NULL || rb->terminated)
    return;
  if (isnan(density)) {
    fprintf(stderr, "Error: %s() called with an invalid 'density' argument (NaN).\n", func);
    return;
  }
  /* Webots keeps (color >> 16) & 0xff, (color >> 8) & 0xff, color & 0xff */
  ink k = {(int)((unsigned)color & 0xFFFFFFu), density < 0.0 ? 0.0 : density > 1.0 ? 1.0 : density};
  char item[512];
  snprintf(item, sizeof item, "%s/set_ink_color", d->name);
  sn_reply rep;
  if (sn_robot_call(rb, item, 2, ink_args, &k, func, &rep) == 0)
    sn_reply_free(&rep);
}
