/* The calls of Webots' motor3 device sample controller, our own text (tests/test_sweep19.py runs Webots'
 * file instead when WEBOTS_HOME has it): a BallJoint's three motors, each sent to 1, -1 and 0 in turn
 * ("motor 1" at steps 50, 100, 200, "motor 2" at 300, 400, 500, "motor 3" at 600, 700, 800), then all
 * three following cosines and a sine of the step count from step 901. */
#include <math.h>
#include <stddef.h>

#include <webots/motor.h>
#include <webots/robot.h>

static const struct {
  int step;
  int motor;
  double target;
} PLAN[] = {{50, 0, 1.0},  {100, 0, -1.0}, {200, 0, 0.0}, {300, 1, 1.0}, {400, 1, -1.0},
            {500, 1, 0.0}, {600, 2, 1.0},  {700, 2, -1.0}, {800, 2, 0.0}};

int main(void) {
  wb_robot_init();
  const int step = (int)wb_robot_get_basic_time_step();
  const WbDeviceTag motors[3] = {wb_robot_get_device("motor 1"), wb_robot_get_device("motor 2"),
                                 wb_robot_get_device("motor 3")};
  for (int n = 1; wb_robot_step(step) != -1; ++n) {
    for (size_t i = 0; i < sizeof(PLAN) / sizeof(PLAN[0]); ++i)
      if (PLAN[i].step == n)
        wb_motor_set_position(motors[PLAN[i].motor], PLAN[i].target);
    if (n > 900) {
      wb_motor_set_position(motors[0], cos(0.01 * n));
      wb_motor_set_position(motors[1], sin(0.012 * n));
      wb_motor_set_position(motors[2], cos(0.013 * n));
    }
  }
  wb_robot_cleanup();
  return 0;
}
