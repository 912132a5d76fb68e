/* Emitter and Receiver between two controllers (tests/worlds/c_api.yaml, robots "alice" and "bob",
 * 3 m apart; run one process per robot, started together). alice pings bob on channel 3, bob answers
 * on channel 4: a packet sent before a step is read right after it (both receivers sample every basic
 * step), with the signal strength 1/r² = 1/9 and the emitter's direction in the receiver's frame. */
#include <webots/emitter.h>
#include <webots/receiver.h>

#include "ts.h"

#define STEP 16

int main(void) {
  ts_setup();
  bool is_alice = strcmp(wb_robot_get_name(), "alice") == 0;
  WbDeviceTag tx = wb_robot_get_device("tx"), rx = wb_robot_get_device("rx");
  wb_receiver_enable(rx, STEP);
  ts_assert_int_equal(wb_receiver_get_sampling_period(rx), STEP, "receiver period");
  ts_assert_int_equal(wb_emitter_get_channel(tx), is_alice ? 3 : 4, "emitter channel from the world");
  ts_assert_int_equal(wb_receiver_get_channel(rx), is_alice ? 4 : 3, "receiver channel from the world");
  ts_assert_double_equal(wb_emitter_get_range(tx), is_alice ? 10.0 : -1.0, "emitter range from the world");
  ts_assert_int_equal(wb_emitter_get_buffer_size(tx), -1, "unlimited buffer");
  ts_assert_int_equal(wb_emitter_send(tx, "x", 0), 0, "an empty packet is refused");
  for (int k = 1; k <= 3; k++) {
    char msg[32];
    snprintf(msg, sizeof msg, "%s %d", is_alice ? "ping" : "pong", k);
    ts_assert_int_equal(wb_emitter_send(tx, msg, (int)strlen(msg) + 1), 1, "send %d", k);
    wb_robot_step(STEP);
    ts_assert_int_equal(wb_receiver_get_queue_length(rx), 1, "one packet after step %d", k);
    char want[32];
    snprintf(want, sizeof want, "%s %d", is_alice ? "pong" : "ping", k);
    ts_assert_string_equal((const char *)wb_receiver_get_data(rx), want, "the packet of step %d", k);
    ts_assert_int_equal(wb_receiver_get_data_size(rx), (int)strlen(want) + 1, "data size");
    ts_assert_double_in_delta(wb_receiver_get_signal_strength(rx), 1.0 / 9.0, 1e-15, "signal strength 1/r^2");
    const double *dir = wb_receiver_get_emitter_direction(rx);
    if (is_alice) /* bob is 3 m along +y of alice, who faces +x: to her left */
      ts_assert_vec3_in_delta(dir, 0.0, 1.0, 0.0, 1e-15, "bob's direction in alice's frame");
    else /* bob faces +y: alice is right behind him */
      ts_assert_vec3_in_delta(dir, -1.0, 0.0, 0.0, 1e-15, "alice's direction in bob's frame");
    wb_receiver_next_packet(rx);
    ts_assert_int_equal(wb_receiver_get_queue_length(rx), 0, "queue empty after next_packet");
  }
  /* channels: alice moves to channel 5, bob does not listen there; broadcast reaches him */
  if (is_alice) {
    wb_emitter_set_channel(tx, 5);
    wb_emitter_send(tx, "lost", 5);
    wb_emitter_set_channel(tx, WB_CHANNEL_BROADCAST);
    wb_emitter_send(tx, "all", 4);
  }
  wb_robot_step(STEP);
  if (!is_alice) {
    ts_assert_int_equal(wb_receiver_get_queue_length(rx), 1, "only the broadcast packet");
    ts_assert_string_equal((const char *)wb_receiver_get_data(rx), "all", "the broadcast packet");
    wb_receiver_next_packet(rx);
  }
  ts_assert_pointer_null(wb_receiver_get_data(rx), "no data once the queue is empty");
  ts_assert_double_equal(wb_receiver_get_signal_strength(rx), NAN, "no signal once the queue is empty");
  /* range: alice's 2 m cannot reach bob 3 m away */
  if (is_alice) {
    wb_emitter_set_range(tx, 2.0);
    ts_assert_double_equal(wb_emitter_get_range(tx), 2.0, "range set");
    wb_emitter_send(tx, "far", 4);
  }
  wb_robot_step(STEP);
  if (!is_alice)
    ts_assert_int_equal(wb_receiver_get_queue_length(rx), 0, "out of range");
  wb_robot_step(STEP); /* both end together */
  ts_send_success();
  return 0;
}
