/* A Webots-style C supervisor importing nodes (tests/worlds/supervisor_remove.yaml, its closed forms):
 * a box imported with its face at x = 0.5 is read by the distance sensor from the next step, a light
 * 0.25 m ahead adds 1 / 0.25^2 = 16 to the light sensor; the new nodes have new ids and their DEF;
 * removing them restores the readings; a robot and a bad string are refused with one line each.
 * Prints "key values" lines for tests/test_c_client.py. */
#include <stdio.h>

#include <webots/distance_sensor.h>
#include <webots/light_sensor.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  int dt = (int)wb_robot_get_basic_time_step();
  WbDeviceTag ds = wb_robot_get_device("ds"), eye = wb_robot_get_device("eye");
  wb_distance_sensor_enable(ds, dt);
  wb_light_sensor_enable(eye, dt);
  WbFieldRef children = wb_supervisor_node_get_field(wb_supervisor_node_get_root(), "children");

  wb_robot_step(dt);
  printf("before %.17g %.17g %d\n", wb_distance_sensor_get_value(ds), wb_light_sensor_get_value(eye),
         wb_supervisor_field_get_count(children));
  wb_supervisor_field_import_mf_node_from_string(
    children, -1,
    "DEF BALL Solid { translation 0.6 0 0.25 children [ Shape { geometry Box { size 0.2 4 0.5 } } ] "
    "boundingObject Box { size 0.2 4 0.5 } }");
  wb_supervisor_field_import_mf_node_from_string(children, 0,
                                                 "DEF SPARK PointLight { location 0.25 0 0.1 attenuation 0 0 1 }");
  wb_supervisor_field_import_mf_node_from_string(children, -1, "Robot { name \"spy\" }"); /* refused: one line */
  wb_supervisor_field_import_mf_node_from_string(children, -1, "Solid {\n  translation 1\n}"); /* one line */
  wb_supervisor_field_import_mf_node_from_string(NULL, -1, "Solid { }");                     /* Webots' line */
  wb_robot_step(dt);
  WbNodeRef ball = wb_supervisor_node_get_from_def("BALL");
  printf("after %.17g %.17g %d\n", wb_distance_sensor_get_value(ds), wb_light_sensor_get_value(eye),
         wb_supervisor_field_get_count(children));
  printf("ids %d %d %s %s\n", wb_supervisor_node_get_id(ball),
         wb_supervisor_node_get_id(wb_supervisor_field_get_mf_node(children, 0)), wb_supervisor_node_get_def(ball),
         wb_supervisor_node_get_type_name(ball));
  const int ball_id = wb_supervisor_node_get_id(ball);
  wb_supervisor_node_remove(ball);
  wb_supervisor_node_remove(wb_supervisor_node_get_from_def("SPARK"));
  wb_robot_step(dt);
  printf("removed %.17g %.17g %d %d\n", wb_distance_sensor_get_value(ds), wb_light_sensor_get_value(eye),
         wb_supervisor_field_get_count(children), wb_supervisor_node_get_from_id(ball_id) == NULL);
  wb_robot_cleanup();
  return 0;
}
