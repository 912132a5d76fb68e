/* Sensorium C controller library: Emitter and Receiver, with libController's client-side rules (the
 * same as the Python client's sensorium.client.wb_radio):
 *  - wb_emitter_send queues a packet (the emitter's channel and range now) if it fits bufferSize;
 *    with each step request the head of the queue leaves while the baud rate allows (byte_rate x step
 *    duration more bytes per step, a packet leaves whole); the server sends it at the next basic step;
 *  - the step reply brings the packets that became readable; one joins the receiver's queue if it fits
 *    the receiver's bufferSize, else it is lost; the getters read the head packet.
 * Channels and ranges are this controller's copies (sent with each packet); a receiver's channel is
 * set on the server at once (it decides which packets the receiver hears). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/emitter.h>
#include <webots/receiver.h>

#include "internal.h"

static sn_packet *packet_new(const void *data, int size) {
  sn_packet *p = malloc(sizeof *p + (size_t)size);
  if (p == NULL)
    return NULL;
  memset(p, 0, sizeof *p);
  p->size = size;
  memcpy(p->data, data, (size_t)size);
  return p;
}

static void enqueue(sn_device *d, sn_packet *p) {
  if (d->queue_tail)
    d->queue_tail->next = p;
  else
    d->queue = p;
  d->queue_tail = p;
  d->queue_length++;
  d->queue_bytes += p->size;
}

static sn_packet *dequeue(sn_device *d) {
  sn_packet *p = d->queue;
  if (p == NULL)
    return NULL;
  d->queue = p->next;
  if (d->queue == NULL)
    d->queue_tail = NULL;
  d->queue_length--;
  d->queue_bytes -= p->size;
  return p;
}

void sn_radio_free(sn_device *d) {
  sn_packet *p;
  while ((p = dequeue(d)) != NULL)
    free(p);
  free(d->allowed);
  d->allowed = NULL;
}

static bool allowed(const sn_device *d, int channel, const char *func) {
  if (channel < -1) {
    fprintf(stderr, "Error: %s() called with an invalid channel=%d. Please use a channel inside the range [-1,inf).\n",
            func, channel);
    return false;
  }
  if (d->n_allowed <= 0)
    return true;
  for (int i = 0; i < d->n_allowed; i++)
    if (d->allowed[i] == channel)
      return true;
  fprintf(stderr, "Error: %s() called with channel=%d, which is not between allowed channels. Please use an allowed "
          "channel.\n", func, channel);
  return false;
}

/* ------------------------------------------------------------------ emitter */

int sn_radio_pace(sn_device *d, int duration) {
  d->sending = 0;
  if (d->queue == NULL)
    return 0;
  if (d->byte_rate != -1.0)
    d->bytes_to_send += d->byte_rate * duration;
  double budget = d->bytes_to_send;
  for (const sn_packet *p = d->queue; p != NULL && (d->byte_rate == -1.0 || p->size <= budget); p = p->next) {
    budget -= p->size;
    d->sending++;
  }
  return d->sending;
}

void sn_radio_pack(sn_device *d, sn_req *r) {
  sn_req_str(r, d->name);
  msgpack_pack_array(&r->pk, (size_t)d->sending);
  for (int i = 0; i < d->sending; i++) {
    sn_packet *p = dequeue(d);
    msgpack_pack_map(&r->pk, 3);
    sn_req_key(r, "data");
    msgpack_pack_bin(&r->pk, (size_t)p->size);
    msgpack_pack_bin_body(&r->pk, p->data, (size_t)p->size);
    sn_req_key(r, "channel");
    msgpack_pack_int(&r->pk, p->channel);
    sn_req_key(r, "range");
    msgpack_pack_double(&r->pk, p->range);
    d->bytes_to_send -= p->size;
    free(p);
  }
  d->sending = 0;
}

int wb_emitter_send(WbDeviceTag tag, const void *data, int size) {
  if (data == NULL) {
    fprintf(stderr, "Error: wb_emitter_send(): invalid argument: data = NULL.\n");
    return 0;
  }
  if (size < 1) {
    fprintf(stderr, "Error: wb_emitter_send(): invalid size=%d argument.\n", size);
    return 0;
  }
  sn_device *d = sn_device_get(tag, SN_EMITTER, "wb_emitter_send");
  if (d == NULL)
    return 0;
  if (d->buffer_size != -1 && size > d->buffer_size - d->queue_bytes)
    return 0;
  sn_packet *p = packet_new(data, size);
  if (p == NULL)
    return 0;
  p->channel = d->channel;
  p->range = d->range;
  if (d->queue == NULL)
    d->bytes_to_send = 0.0; /* libController restarts the count with an empty queue */
  enqueue(d, p);
  return 1;
}

int wb_emitter_get_buffer_size(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_EMITTER, "wb_emitter_get_buffer_size");
  return d ? d->buffer_size : -1;
}

void wb_emitter_set_channel(WbDeviceTag tag, int channel) {
  sn_device *d = sn_device_get(tag, SN_EMITTER, "wb_emitter_set_channel");
  if (d != NULL && allowed(d, channel, "wb_emitter_set_channel"))
    d->channel = channel;
}

int wb_emitter_get_channel(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_EMITTER, "wb_emitter_get_channel");
  return d ? d->channel : -1;
}

double wb_emitter_get_range(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_EMITTER, "wb_emitter_get_range");
  return d ? d->range : NAN;
}

void wb_emitter_set_range(WbDeviceTag tag, double range) {
  if ((range < 0.0 && range != -1.0) || isnan(range)) {
    fprintf(stderr, "Error: wb_emitter_set_range(): invalid range=%f argument.\n", range);
    return;
  }
  sn_device *d = sn_device_get(tag, SN_EMITTER, "wb_emitter_set_range");
  if (d == NULL)
    return;
  if (range == -1.0)
    d->range = d->emitter_max_range; /* the largest range allowed */
  else if (d->emitter_max_range == -1.0)
    d->range = range;
  else
    d->range = range > d->emitter_max_range ? d->emitter_max_range : range;
}

/* ------------------------------------------------------------------ receiver */

void sn_radio_receive(sn_device *d, const msgpack_object *packets) {
  if (packets == NULL || packets->type != MSGPACK_OBJECT_ARRAY)
    return;
  for (uint32_t i = 0; i < packets->via.array.size; i++) {
    const msgpack_object *m = &packets->via.array.ptr[i];
    const msgpack_object *data = sn_get(m, "data");
    if (data == NULL || data->type != MSGPACK_OBJECT_BIN || data->via.bin.size > (1u << 30))
      continue;
    int size = (int)data->via.bin.size;
    if (d->buffer_size != -1 && size > d->buffer_size - d->queue_bytes)
      continue; /* no room left in the receiver's buffer: lost, as in Webots */
    sn_packet *p = packet_new(data->via.bin.ptr, size);
    if (p == NULL)
      continue;
    p->signal = sn_double_or(m, "signal_strength", NAN);
    const msgpack_object *dir = sn_get(m, "direction");
    for (uint32_t k = 0; k < 3; k++)
      if (dir == NULL || dir->type != MSGPACK_OBJECT_ARRAY || dir->via.array.size != 3 ||
          !sn_as_double(&dir->via.array.ptr[k], &p->direction[k]))
        p->direction[k] = NAN;
    enqueue(d, p);
  }
}

void wb_receiver_enable(WbDeviceTag tag, int sampling_period) {
  sn_sensor_enable(tag, SN_RECEIVER, sampling_period, "wb_receiver_enable");
}

void wb_receiver_disable(WbDeviceTag tag) { sn_sensor_enable(tag, SN_RECEIVER, 0, "wb_receiver_disable"); }

int wb_receiver_get_sampling_period(WbDeviceTag tag) {
  return sn_sensor_period(tag, SN_RECEIVER, "wb_receiver_get_sampling_period");
}

void wb_receiver_set_channel(WbDeviceTag tag, int channel) {
  sn_device *d = sn_device_get(tag, SN_RECEIVER, "wb_receiver_set_channel");
  if (d == NULL || channel == d->channel || !allowed(d, channel, "wb_receiver_set_channel"))
    return;
  if (!sn_device_set(d, "set_channel", sn_arg_int, &channel, "wb_receiver_set_channel"))
    return;
  d->channel = channel;
}

int wb_receiver_get_channel(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_RECEIVER, "wb_receiver_get_channel");
  return d ? d->channel : -1;
}

int wb_receiver_get_queue_length(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_RECEIVER, "wb_receiver_get_queue_length");
  if (d == NULL)
    return -1;
  if (d->sampling_period <= 0)
    fprintf(stderr, "Error: wb_receiver_get_queue_length() called for a disabled device! Please use: "
                    "wb_receiver_enable().\n");
  return d->queue_length;
}

void wb_receiver_next_packet(WbDeviceTag tag) {
  sn_device *d = sn_device_get(tag, SN_RECEIVER, "wb_receiver_next_packet");
  if (d != NULL)
    free(dequeue(d));
}

static const sn_packet *head(WbDeviceTag tag, const char *func) {
  sn_device *d = sn_device_get(tag, SN_RECEIVER, func);
  if (d == NULL)
    return NULL;
  if (d->queue == NULL)
    fprintf(stderr, "Error: %s(): the receiver queue is empty.\n", func);
  return d->queue;
}

int wb_receiver_get_data_size(WbDeviceTag tag) {
  const sn_packet *p = head(tag, "wb_receiver_get_data_size");
  return p ? p->size : -1;
}

const void *wb_receiver_get_data(WbDeviceTag tag) {
  const sn_packet *p = head(tag, "wb_receiver_get_data");
  return p ? (const void *)p->data : NULL;
}

double wb_receiver_get_signal_strength(WbDeviceTag tag) {
  const sn_packet *p = head(tag, "wb_receiver_get_signal_strength");
  return p ? p->signal : NAN;
}

const double *wb_receiver_get_emitter_direction(WbDeviceTag tag) {
  const sn_packet *p = head(tag, "wb_receiver_get_emitter_direction");
  return p ? p->direction : NULL;
}
