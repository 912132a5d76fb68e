/* Robot extras, LED, keyboard and the Supervisor subset (tests/worlds/cdevices.yaml): prints
 * "key value" lines for tests/test_c_client.py. On a non-supervisor robot every supervisor call
 * prints Webots' error and answers NULL. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <webots/keyboard.h>
#include <webots/led.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

static void vec(const char *key, const double *v, int n) {
  printf("%s", key);
  if (v == NULL)
    printf(" NULL");
  for (int i = 0; v != NULL && i < n; i++)
    printf(" %.17g", v[i]);
  printf("\n");
}

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  printf("model %s\n", wb_robot_get_model());
  printf("custom_data %s\n", wb_robot_get_custom_data());
  printf("supervisor %d\n", (int)wb_robot_get_supervisor());
  printf("mode %d\n", (int)wb_robot_get_mode());
  WbNodeRef buddy = wb_supervisor_node_get_from_def("buddy");
  printf("buddy_null %d\n", buddy == NULL);
  if (!wb_robot_get_supervisor()) {
    wb_robot_step(dt);
    wb_robot_cleanup();
    return 0;
  }
  wb_robot_set_custom_data("gain=3;from C");
  printf("custom_data_after %s\n", wb_robot_get_custom_data());
  WbDeviceTag led0 = wb_robot_get_device("led0"), rgb = wb_robot_get_device("rgb");
  printf("led0_initial %d\n", wb_led_get(led0));
  wb_led_set(led0, 2);
  wb_led_set(led0, 3); /* out of range: message, ignored */
  wb_led_set(rgb, 0x336699);
  printf("led0 %d rgb %d\n", wb_led_get(led0), wb_led_get(rgb));
  WbDeviceTag dim = wb_robot_get_device("dim");
  wb_led_set(dim, 128);
  wb_led_set(dim, 0x336699); /* a monochrome LED's intensity is 0..255: message, ignored */
  printf("dim %d\n", wb_led_get(dim));
  printf("keyboard_disabled_key %d\n", wb_keyboard_get_key());
  wb_keyboard_enable(dt);
  printf("keyboard %d %d\n", wb_keyboard_get_sampling_period(), wb_keyboard_get_key());
  wb_keyboard_disable();
  printf("keyboard_after %d\n", wb_keyboard_get_sampling_period());

  WbNodeRef self = wb_supervisor_node_get_self();
  printf("self_null %d missing_null %d same_ref %d\n", self == NULL, wb_supervisor_node_get_from_def("nobody") == NULL,
         wb_supervisor_node_get_from_def("buddy") == buddy);
  WbFieldRef tr = wb_supervisor_node_get_field(buddy, "translation");
  WbFieldRef rot = wb_supervisor_node_get_field(buddy, "rotation");
  printf("fields %d %s %d %s bogus_null %d\n", (int)wb_supervisor_field_get_type(tr), wb_supervisor_field_get_name(tr),
         (int)wb_supervisor_field_get_type(rot), wb_supervisor_field_get_name(rot),
         wb_supervisor_node_get_field(buddy, "mass") == NULL);
  vec("buddy_translation", wb_supervisor_field_get_sf_vec3f(tr), 3);
  const double where[3] = {0.25, -0.5, 0.0};
  const double turn[4] = {0.0, 0.0, 1.0, 1.5707963267948966};
  wb_supervisor_field_set_sf_vec3f(tr, where);
  wb_supervisor_field_set_sf_rotation(rot, turn);
  wb_supervisor_field_set_sf_vec3f(rot, where); /* wrong type: message, ignored */
  wb_robot_step(dt);
  vec("buddy_translation_after", wb_supervisor_field_get_sf_vec3f(tr), 3);
  vec("buddy_rotation_after", wb_supervisor_field_get_sf_rotation(rot), 4);
  vec("buddy_position", wb_supervisor_node_get_position(buddy), 3);
  vec("buddy_orientation", wb_supervisor_node_get_orientation(buddy), 9);
  vec("self_position", wb_supervisor_node_get_position(self), 3);
  printf("sim_mode %d\n", (int)wb_supervisor_simulation_get_mode());
  wb_supervisor_simulation_set_mode(WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME);
  printf("sim_mode_after %d\n", (int)wb_supervisor_simulation_get_mode());
  wb_supervisor_simulation_set_mode(WB_SUPERVISOR_SIMULATION_MODE_FAST);
  wb_supervisor_simulation_reset();
  wb_robot_step(dt);
  vec("buddy_translation_reset", wb_supervisor_field_get_sf_vec3f(tr), 3);
  printf("led0_reset %d\n", wb_led_get(led0));
  wb_led_set(led0, 1);
  wb_robot_set_custom_data("after reset"); /* the reset restored the world file's custom data */
  printf("time %.0f\n", wb_robot_get_time() * 1000.0);
  wb_robot_cleanup();
  return 0;
}
