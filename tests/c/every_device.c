/* Every Webots device through the C API (our own, in Webots' test style; the twin of
 * tests/controllers/every_device.py: the same lines, doubles as the 16 hex digits of their bits): the
 * device list in Webots' order with node types and models, every simulated device's reading after one
 * step, every listed-only device's "no value" answers, an emitter's packet, waiting for user input,
 * joystick and mouse, INFINITY from types.h. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <webots/accelerometer.h>
#include <webots/altimeter.h>
#include <webots/brake.h>
#include <webots/camera.h>
#include <webots/compass.h>
#include <webots/connector.h>
#include <webots/display.h>
#include <webots/distance_sensor.h>
#include <webots/emitter.h>
#include <webots/gps.h>
#include <webots/gyro.h>
#include <webots/inertial_unit.h>
#include <webots/joystick.h>
#include <webots/led.h>
#include <webots/lidar.h>
#include <webots/light_sensor.h>
#include <webots/motor.h>
#include <webots/mouse.h>
#include <webots/nodes.h>
#include <webots/pen.h>
#include <webots/position_sensor.h>
#include <webots/radar.h>
#include <webots/range_finder.h>
#include <webots/receiver.h>
#include <webots/robot.h>
#include <webots/skin.h>
#include <webots/speaker.h>
#include <webots/touch_sensor.h>
#include <webots/vacuum_gripper.h>

static void h(double x) {
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  printf(" %016llx", (unsigned long long)u);
}

static void hs(const double *v, int n) {
  if (v == NULL) {
    printf(" none");
    return;
  }
  for (int i = 0; i < n; i++) {
    uint64_t u;
    memcpy(&u, &v[i], sizeof u);
    printf("%s%016llx", i ? "," : " ", (unsigned long long)u);
  }
}

static void hf(const float *v, int n) {
  double d[16];
  for (int i = 0; i < n && i < 16; i++)
    d[i] = v[i];
  hs(d, n);
}

int main(void) {
  wb_robot_init();
  int n = wb_robot_get_number_of_devices();
  for (int i = 0; i < n; i++) {
    WbDeviceTag t = wb_robot_get_device_by_index(i);
    const char *model = wb_device_get_model(t);
    printf("device %d %s %d %s\n", i, wb_device_get_name(t), (int)wb_device_get_node_type(t), *model ? model : "-");
  }
  WbDeviceTag gps = wb_robot_get_device("gps"), acc = wb_robot_get_device("accelerometer");
  WbDeviceTag alt = wb_robot_get_device("altimeter"), compass = wb_robot_get_device("compass");
  WbDeviceTag gyro = wb_robot_get_device("gyro"), imu = wb_robot_get_device("imu"), ds = wb_robot_get_device("ds");
  WbDeviceTag lidar = wb_robot_get_device("lidar"), light = wb_robot_get_device("light");
  WbDeviceTag encoder = wb_robot_get_device("left encoder"), bumper = wb_robot_get_device("bumper");
  WbDeviceTag emitter = wb_robot_get_device("emitter"), receiver = wb_robot_get_device("receiver");
  WbDeviceTag led = wb_robot_get_device("led");
  wb_gps_enable(gps, 16);
  wb_accelerometer_enable(acc, 16);
  wb_altimeter_enable(alt, 16);
  wb_compass_enable(compass, 16);
  wb_gyro_enable(gyro, 16);
  wb_inertial_unit_enable(imu, 16);
  wb_distance_sensor_enable(ds, 16);
  wb_lidar_enable(lidar, 16);
  wb_light_sensor_enable(light, 16);
  wb_position_sensor_enable(encoder, 16);
  wb_touch_sensor_enable(bumper, 16);
  wb_receiver_enable(receiver, 16);
  printf("before");
  hs(wb_gps_get_values(gps), 3);
  h(wb_altimeter_get_value(alt));
  hs(wb_inertial_unit_get_quaternion(imu), 4);
  printf("\n");
  const double floats[2] = {1.5, -2.0};
  int sent1 = wb_emitter_send(emitter, "hello", 5), sent2 = wb_emitter_send(emitter, floats, sizeof floats);
  printf("send %d %d %d", sent1, sent2, wb_emitter_get_channel(emitter));
  h(wb_emitter_get_range(emitter));
  printf(" %d\n", wb_emitter_get_buffer_size(emitter));
  wb_led_set(led, 2);
  wb_robot_step(16);

  printf("gps");
  hs(wb_gps_get_values(gps), 3);
  h(wb_gps_get_speed(gps));
  hs(wb_gps_get_speed_vector(gps), 3);
  printf(" %d\n", (int)wb_gps_get_coordinate_system(gps));
  printf("accelerometer");
  hs(wb_accelerometer_get_values(acc), 3);
  printf(" %d\n", 3 * wb_accelerometer_get_lookup_table_size(acc));
  printf("altimeter");
  h(wb_altimeter_get_value(alt));
  printf("\ncompass");
  hs(wb_compass_get_values(compass), 3);
  printf("\ngyro");
  hs(wb_gyro_get_values(gyro), 3);
  printf("\nimu");
  hs(wb_inertial_unit_get_roll_pitch_yaw(imu), 3);
  hs(wb_inertial_unit_get_quaternion(imu), 4);
  h(wb_inertial_unit_get_noise(imu));
  printf("\nds");
  h(wb_distance_sensor_get_value(ds));
  printf(" %d\nlidar", (int)wb_distance_sensor_get_type(ds));
  hf(wb_lidar_get_range_image(lidar), 4);
  printf("\nlight");
  h(wb_light_sensor_get_value(light));
  printf("\nencoder");
  h(wb_position_sensor_get_value(encoder));
  printf("\nbumper");
  h(wb_touch_sensor_get_value(bumper));
  printf(" %d", (int)wb_touch_sensor_get_type(bumper));
  hs(wb_touch_sensor_get_values(bumper), 3);
  printf("\nled %d\n", wb_led_get(led));
  printf("receiver %d %d", wb_receiver_get_queue_length(receiver), wb_receiver_get_channel(receiver));
  h(wb_receiver_get_signal_strength(receiver));
  hs(wb_receiver_get_emitter_direction(receiver), 3);
  WbDeviceTag wheel = wb_robot_get_device("left wheel motor");
  printf("\nwheel");
  h(wb_motor_get_max_velocity(wheel));
  printf(" %d", (int)wb_motor_get_type(wheel));
  h(wb_motor_get_torque_feedback(wheel));
  printf("\n");

  /* listed, not simulated: Webots' "no value", one warning per device */
  WbDeviceTag radar = wb_robot_get_device("radar"), brake = wb_robot_get_device("brake");
  WbDeviceTag connector = wb_robot_get_device("connector"), display = wb_robot_get_device("display");
  WbDeviceTag skin = wb_robot_get_device("skin"), speaker = wb_robot_get_device("speaker");
  WbDeviceTag gripper = wb_robot_get_device("gripper"), linear = wb_robot_get_device("linear motor");
  WbDeviceTag arm = wb_robot_get_device("arm motor");
  wb_radar_enable(radar, 16); /* simulated: no target yet (NULL before the first value), its world range */
  printf("radar %d %d %d\n", wb_radar_get_number_of_targets(radar), wb_radar_get_targets(radar) == NULL ? 0 : -1,
         isnan(wb_radar_get_max_range(radar)) ? 1 : 0);
  printf("brake %d %d\n", (int)wb_brake_get_type(brake), wb_brake_get_motor(brake) == 0);
  printf("connector %d %d\n", wb_connector_get_presence(connector), (int)wb_connector_is_locked(connector));
  wb_display_draw_text(display, "hi", 0, 0);
  printf("display %d %d\n", wb_display_get_width(display), wb_display_get_height(display));
  printf("skin %d %d\n", wb_skin_get_bone_count(skin), *wb_skin_get_bone_name(skin, 0) == 0);
  wb_speaker_play_sound(speaker, speaker, "beep.wav", 1.0, 1.0, 0.0, false); /* simulated: no such file */
  printf("speaker %d %d\n", (int)wb_speaker_is_speaking(speaker), strcmp(wb_speaker_get_engine(speaker), "pico") == 0);
  wb_vacuum_gripper_enable_presence(gripper, 16); /* simulated: no value yet, the pump off */
  printf("gripper %d %d\n", (int)wb_vacuum_gripper_get_presence(gripper), (int)wb_vacuum_gripper_is_on(gripper));
  wb_motor_set_velocity(linear, 1.0);
  printf("linear %d", (int)wb_motor_get_type(linear));
  h(wb_motor_get_velocity(linear));
  printf("\narm %d", (int)wb_motor_get_type(arm));
  h(wb_motor_get_target_position(arm));
  printf("\n");
  /* present whatever their state of simulation */
  if (!wb_robot_get_device("camera") || !wb_robot_get_device("range finder") || !wb_robot_get_device("pen"))
    return 2;

  printf("joystick %d %d\n", (int)wb_joystick_is_connected(), wb_joystick_get_pressed_button());
  wb_mouse_enable(16);
  WbMouseState state = wb_mouse_get_state();
  printf("mouse %d %d\n", isnan(state.u) ? 1 : 0, (int)state.left);
  printf("battery %d\n", isnan(wb_robot_battery_sensor_get_value()) ? 1 : 0);
  double t0 = wb_robot_get_time();
  WbUserInputEvent e = wb_robot_wait_for_user_input_event(WB_EVENT_KEYBOARD | WB_EVENT_MOUSE_CLICK, 100);
  printf("wait %d %.0f\n", (int)e, (wb_robot_get_time() - t0) * 1000);
  printf("infinity %d\n", isinf(INFINITY));
  wb_robot_cleanup();
  return 0;
}
