/* Sensorium C controller library: the devices Sensorium lists but does not simulate. Each function
 * checks the tag names a device of its type, prints one warning line per device (sn_unsimulated) and
 * answers Webots' "no value". Written from Webots' documented signatures. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/microphone.h>
#include <webots/radio.h>
#include <webots/skin.h>
#include <webots/nodes.h>

#include "internal.h"

/* a function here reads only its device tag, never its other arguments */
#pragma GCC diagnostic ignored "-Wunused-parameter"

/* ------------------------------------------------------------------ Skin */
void wb_skin_set_bone_orientation(WbDeviceTag tag, int index, const double orientation[4], bool absolute) {
  sn_unsimulated(tag, WB_NODE_SKIN, "wb_skin_set_bone_orientation");
}

void wb_skin_set_bone_position(WbDeviceTag tag, int index, const double position[3], bool absolute) {
  sn_unsimulated(tag, WB_NODE_SKIN, "wb_skin_set_bone_position");
}

int wb_skin_get_bone_count(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_SKIN, "wb_skin_get_bone_count");
  return 0;
}

const char *wb_skin_get_bone_name(WbDeviceTag tag, int index) {
  sn_unsimulated(tag, WB_NODE_SKIN, "wb_skin_get_bone_name");
  return "";
}

const double *wb_skin_get_bone_orientation(WbDeviceTag tag, int index, bool absolute) {
  sn_unsimulated(tag, WB_NODE_SKIN, "wb_skin_get_bone_orientation");
  return sn_no_values();
}

const double *wb_skin_get_bone_position(WbDeviceTag tag, int index, bool absolute) {
  sn_unsimulated(tag, WB_NODE_SKIN, "wb_skin_get_bone_position");
  return sn_no_values();
}

/* ------------------------------------------------------------------ Microphone */
void wb_microphone_enable(WbDeviceTag tag, int sampling_period) {
  sn_unsimulated(tag, WB_NODE_MICROPHONE, "wb_microphone_enable");
}

void wb_microphone_disable(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_MICROPHONE, "wb_microphone_disable");
}

int wb_microphone_get_sampling_period(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_MICROPHONE, "wb_microphone_get_sampling_period");
  return 0;
}

const void *wb_microphone_get_sample_data(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_MICROPHONE, "wb_microphone_get_sample_data");
  return NULL;
}

int wb_microphone_get_sample_size(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_MICROPHONE, "wb_microphone_get_sample_size");
  return 0;
}

/* ------------------------------------------------------------------ Radio */
/* A message is plain data (no device involved): its body bytes and destination, copied. */
typedef struct {
  int length;
  char *body;
  char *destination;
} sn_radio_message;

WbRadioMessage wb_radio_message_new(int length, const char *body, const char *destination) {
  if (length < 0 || (length > 0 && body == NULL)) {
    fprintf(stderr, "Error: wb_radio_message_new(): invalid body (%d bytes at %p)\n", length, (const void *)body);
    return NULL;
  }
  sn_radio_message *m = calloc(1, sizeof *m);
  if (m == NULL)
    return NULL;
  const char *to = destination != NULL ? destination : "";
  m->body = malloc((size_t)length + 1);
  m->destination = malloc(strlen(to) + 1);
  if (m->body == NULL || m->destination == NULL) {
    free(m->body);
    free(m->destination);
    free(m);
    return NULL;
  }
  if (length > 0)
    memcpy(m->body, body, (size_t)length);
  m->body[length] = '\0'; /* a text body reads as a C string too */
  strcpy(m->destination, to);
  m->length = length;
  return m;
}

void wb_radio_message_delete(WbRadioMessage message) {
  sn_radio_message *m = message;
  if (m == NULL)
    return;
  free(m->body);
  free(m->destination);
  free(m);
}

const char *wb_radio_message_get_destination(WbRadioMessage message) {
  return message != NULL ? ((sn_radio_message *)message)->destination : NULL;
}

int wb_radio_message_get_length(WbRadioMessage message) {
  return message != NULL ? ((sn_radio_message *)message)->length : 0;
}

const char *wb_radio_message_get_body(WbRadioMessage message) {
  return message != NULL ? ((sn_radio_message *)message)->body : NULL;
}

void wb_radio_enable(WbDeviceTag tag, int sampling_period) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_enable");
}

void wb_radio_disable(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_disable");
}

void wb_radio_set_address(WbDeviceTag tag, const char *address) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_set_address");
}

const char *wb_radio_get_address(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_get_address");
  return NULL;
}

void wb_radio_set_frequency(WbDeviceTag tag, double hz) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_set_frequency");
}

double wb_radio_get_frequency(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_get_frequency");
  return NAN;
}

void wb_radio_set_channel(WbDeviceTag tag, int channel) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_set_channel");
}

int wb_radio_get_channel(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_get_channel");
  return 0;
}

void wb_radio_set_bitrate(WbDeviceTag tag, int bits_per_second) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_set_bitrate");
}

int wb_radio_get_bitrate(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_get_bitrate");
  return 0;
}

void wb_radio_set_rx_sensitivity(WbDeviceTag tag, double dBm) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_set_rx_sensitivity");
}

double wb_radio_get_rx_sensitivity(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_get_rx_sensitivity");
  return NAN;
}

void wb_radio_set_tx_power(WbDeviceTag tag, double dBm) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_set_tx_power");
}

double wb_radio_get_tx_power(WbDeviceTag tag) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_get_tx_power");
  return NAN;
}

void wb_radio_set_callback(WbDeviceTag tag, void (*callback)(const WbRadioEvent)) {
  (void)callback; /* never called: nothing is received */
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_set_callback");
}

/* No event is ever made (nothing is received), so these only see events a controller made up. */
WbDeviceTag wb_radio_event_get_radio(const WbRadioEvent event) {
  return 0;
}

char *wb_radio_event_get_data(const WbRadioEvent event) {
  return NULL;
}

int wb_radio_event_get_data_size(const WbRadioEvent event) {
  return 0;
}

char *wb_radio_event_get_emitter(const WbRadioEvent event) {
  return NULL;
}

double wb_radio_event_get_rssi(const WbRadioEvent event) {
  return NAN;
}

void wb_radio_send(WbDeviceTag tag, const WbRadioMessage message, double delay) {
  sn_unsimulated(tag, WB_NODE_RADIO, "wb_radio_send");
}
