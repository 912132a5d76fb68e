/* Hostile and careless calls on PROTO fields from C (tests/worlds/proto/supervisor_proto_harden.wbt): NULL
 * and foreign refs, indexes out of range both ways, the wrong getter for each type, names empty, long and
 * huge, non-finite values set through IS. The same stdout as tests/controllers/supervisor_proto_harden.py;
 * the lines on stderr are Webots' where Webots prints one. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <webots/robot.h>
#include <webots/supervisor.h>

#define LONG_NAME "aVeryLongParameterNameThatGoesOnAndOnPastTheSixtyFourCharactersOfOrdinaryFieldNamesX"

static void numbers(const char *what, const double *v, int n) {
  printf("%s", what);
  for (int i = 0; i < n; i++)
    printf(" %.17g", v ? v[i] : -999.0);
  printf("%s\n", v ? "" : " null");
}

int main(void) {
  wb_robot_init();
  int step = (int)wb_robot_get_basic_time_step();
  wb_robot_step(step);
  WbNodeRef me = wb_supervisor_node_get_self();
  WbNodeRef lengthy = wb_supervisor_node_get_from_def("LONG");
  WbNodeRef box = wb_supervisor_node_get_from_def("BOX");
  WbProtoRef proto = wb_supervisor_node_get_proto(lengthy);
  int dummy = 0;
  WbProtoRef foreign = (WbProtoRef)(void *)&dummy; /* not a ref of the library's: compared, never read */

  /* NULL and foreign refs */
  printf("nullnode %d\n", wb_supervisor_node_get_proto(NULL) == NULL);
  printf("nullproto [%s] %d %d %d %d %d\n", wb_supervisor_proto_get_type_name(NULL), wb_supervisor_proto_is_derived(NULL),
         wb_supervisor_proto_get_number_of_fields(NULL), wb_supervisor_proto_get_parent(NULL) == NULL,
         wb_supervisor_proto_get_field(NULL, "translation") == NULL, wb_supervisor_proto_get_field_by_index(NULL, 0) == NULL);
  printf("foreign [%s] %d %d\n", wb_supervisor_proto_get_type_name(foreign), wb_supervisor_proto_get_number_of_fields(foreign),
         wb_supervisor_proto_get_field(foreign, "translation") == NULL);
  printf("nullfield %d %d %.17g %d\n", wb_supervisor_field_get_count(NULL), wb_supervisor_field_get_mf_int32(NULL, 0),
         wb_supervisor_field_get_mf_float(NULL, 0), wb_supervisor_field_get_sf_vec2f(NULL) == NULL);
  WbFieldRef stranger = (WbFieldRef)(void *)&dummy; /* likewise for a field */
  printf("foreignfield %d %.17g %d\n", wb_supervisor_field_get_count(stranger),
         wb_supervisor_field_get_mf_float(stranger, 0), wb_supervisor_field_get_sf_vec2f(stranger) == NULL);
  printf("basenull %d %d\n", wb_supervisor_node_get_base_node_field(NULL, "name") == NULL,
         wb_supervisor_node_get_number_of_fields(NULL));

  /* indexes */
  int n = wb_supervisor_proto_get_number_of_fields(proto);
  printf("proto %s %d\n", wb_supervisor_proto_get_type_name(proto), n);
  const int bad[] = {-1, n, INT_MAX, INT_MIN};
  for (int i = 0; i < 4; i++)
    printf("index %d %d %d\n", bad[i], wb_supervisor_proto_get_field_by_index(proto, bad[i]) == NULL,
           wb_supervisor_node_get_field_by_index(lengthy, bad[i]) == NULL);
  printf("last %s\n", wb_supervisor_field_get_name(wb_supervisor_proto_get_field_by_index(proto, n - 1)));

  /* names */
  char *huge = malloc(100001);
  memset(huge, 'x', 100000);
  huge[100000] = '\0';
  printf("names %d %d %d %d\n", wb_supervisor_node_get_field(lengthy, NULL) == NULL,
         wb_supervisor_node_get_field(lengthy, "") == NULL, wb_supervisor_proto_get_field(proto, huge) == NULL,
         wb_supervisor_node_get_base_node_field(lengthy, huge) == NULL);
  free(huge);
  WbFieldRef longest = wb_supervisor_node_get_field(lengthy, LONG_NAME);
  printf("long %s %.17g %.17g\n", wb_supervisor_field_get_type_name(longest), wb_supervisor_field_get_sf_float(longest),
         wb_supervisor_field_get_sf_float(wb_supervisor_proto_get_field(proto, LONG_NAME)));
  printf("unknown %d\n", wb_supervisor_node_get_field(lengthy, "nosuchfield") == NULL);

  /* values at the edges, empty lists, MF indexes */
  WbFieldRef none = wb_supervisor_node_get_field(lengthy, "none");
  WbFieldRef corners = wb_supervisor_node_get_field(lengthy, "corners");
  WbFieldRef turns = wb_supervisor_node_get_field(lengthy, "turns");
  WbFieldRef size2 = wb_supervisor_node_get_field(lengthy, "size2");
  WbFieldRef label = wb_supervisor_node_get_field(lengthy, "label");
  printf("none %d %.17g\n", wb_supervisor_field_get_count(none), wb_supervisor_field_get_mf_float(none, 0));
  numbers("corner0", wb_supervisor_field_get_mf_vec2f(corners, 0), 2);
  numbers("corner-1", wb_supervisor_field_get_mf_vec2f(corners, -1), 2);
  numbers("corner-2", wb_supervisor_field_get_mf_vec2f(corners, -2), 2);
  numbers("corner-3", wb_supervisor_field_get_mf_vec2f(corners, -3), 2);
  numbers("corner2", wb_supervisor_field_get_mf_vec2f(corners, 2), 2);
  numbers("cornermin", wb_supervisor_field_get_mf_vec2f(corners, INT_MIN), 2);
  numbers("turn", wb_supervisor_field_get_mf_rotation(turns, 0), 4);
  numbers("size2", wb_supervisor_field_get_sf_vec2f(size2), 2);
  printf("label [%s] %d\n", wb_supervisor_field_get_sf_string(label), wb_supervisor_field_get_count(label));

  /* the wrong getter for each type: Webots' line, its "no value" */
  printf("wrong %.17g %d %d %d %d %d %d [%s] %d\n", wb_supervisor_field_get_mf_float(corners, 0),
         wb_supervisor_field_get_mf_int32(corners, 0), wb_supervisor_field_get_mf_bool(none, 0),
         wb_supervisor_field_get_mf_vec3f(corners, 0) == NULL, wb_supervisor_field_get_mf_vec2f(turns, 0) == NULL,
         wb_supervisor_field_get_mf_rotation(size2, 0) == NULL, wb_supervisor_field_get_sf_vec2f(corners) == NULL,
         wb_supervisor_field_get_mf_string(label, 0), wb_supervisor_field_get_mf_color(none, 0) == NULL);

  /* sets through IS: non-finite refused with Webots' line, a finite one moves the solid; the others read-only */
  WbFieldRef move = wb_supervisor_node_get_field(lengthy, "translation");
  const double nan3[3] = {NAN, 0.0, 0.0}, inf3[3] = {0.0, INFINITY, 0.0}, far3[3] = {1e300, 0.0, 0.0};
  const double ok3[3] = {0.25, -0.5, 0.1};
  wb_supervisor_field_set_sf_vec3f(move, nan3);
  wb_supervisor_field_set_sf_vec3f(move, inf3);
  wb_supervisor_field_set_sf_vec3f(move, far3);
  wb_supervisor_field_set_sf_vec3f(move, NULL);
  wb_supervisor_field_set_sf_float(longest, NAN);
  wb_supervisor_field_set_sf_float(longest, 2.0);
  wb_robot_step(step);
  numbers("moved", wb_supervisor_field_get_sf_vec3f(move), 3);
  wb_supervisor_field_set_sf_vec3f(move, ok3);
  wb_robot_step(step);
  numbers("moved", wb_supervisor_field_get_sf_vec3f(wb_supervisor_node_get_base_node_field(lengthy, "translation")), 3);
  printf("kept %.17g\n", wb_supervisor_field_get_sf_float(longest));

  /* a parent PROTO and a base node */
  WbProtoRef parent = wb_supervisor_proto_get_parent(wb_supervisor_node_get_proto(wb_supervisor_node_get_from_def("BIG")));
  printf("parent %s %d\n", wb_supervisor_proto_get_type_name(parent),
         wb_supervisor_proto_get_field_by_index(parent, 3) == NULL);
  printf("box %d %d %d\n", wb_supervisor_node_get_proto(box) == NULL, wb_supervisor_node_get_number_of_fields(box),
         wb_supervisor_node_get_field_by_index(box, 0) == NULL);
  printf("me %d\n", wb_supervisor_node_get_number_of_fields(me));
  fflush(stdout);
  wb_robot_cleanup();
  return 0;
}
