/* Webots' C controller API (include/controller/c/webots of Webots R2023b..R2025a): every function a
 * controller can call, written for Sensorium's tests from Webots' headers and reference manual (the
 * facts: names and prototypes). tests/test_webots_api_names.py compiles this file after Sensorium's
 * headers (a prototype that differs is a compile error) and links a table of every function against
 * Sensorium's libController (a missing one is a link error). Left out: the Windows-only
 * wb_robot_init_msvc and the Matlab-only wb_camera_recognition_get_object / wb_lidar_get_point. */

/* robot.h */
int wb_robot_init(void);
int wb_robot_step_begin(int duration);
int wb_robot_step_end(void);
int wb_robot_step(int duration);
WbUserInputEvent wb_robot_wait_for_user_input_event(WbUserInputEvent event_type, int timeout);
void wb_robot_cleanup(void);
double wb_robot_get_time(void);
const char *wb_robot_get_urdf(const char *prefix);
const char *wb_robot_get_name(void);
const char *wb_robot_get_model(void);
const char *wb_robot_get_custom_data(void);
void wb_robot_set_custom_data(const char *data);
WbRobotMode wb_robot_get_mode(void);
void wb_robot_set_mode(WbRobotMode mode, const char *arg);
bool wb_robot_get_synchronization(void);
bool wb_robot_get_supervisor(void);
const char *wb_robot_get_project_path(void);
const char *wb_robot_get_world_path(void);
double wb_robot_get_basic_time_step(void);
WbDeviceTag wb_robot_get_device(const char *name);
int wb_robot_get_number_of_devices(void);
WbDeviceTag wb_robot_get_device_by_index(int index);
void wb_robot_battery_sensor_enable(int sampling_period);
void wb_robot_battery_sensor_disable(void);
int wb_robot_battery_sensor_get_sampling_period(void);
double wb_robot_battery_sensor_get_value(void);
void wb_robot_task_new(void (*task)(void *), void *param);
WbMutexRef wb_robot_mutex_new(void);
void wb_robot_mutex_lock(WbMutexRef mutex);
void wb_robot_mutex_unlock(WbMutexRef mutex);
void wb_robot_mutex_delete(WbMutexRef mutex);
void wb_robot_pin_to_static_environment(bool pin);
const char *wb_robot_get_controller_name(void);
const char *wb_robot_get_data(void);
void wb_robot_set_data(const char *data);

/* supervisor.h */
void wb_supervisor_world_load(const char *filename);
bool wb_supervisor_world_save(const char *filename);
void wb_supervisor_world_reload(void);
void wb_supervisor_simulation_quit(int status);
void wb_supervisor_simulation_reset(void);
void wb_supervisor_simulation_reset_physics(void);
WbSimulationMode wb_supervisor_simulation_get_mode(void);
void wb_supervisor_simulation_set_mode(WbSimulationMode mode);
void wb_supervisor_set_label(int id, const char *text, double x, double y, double size, int color, double transparency,
                             const char *font);
void wb_supervisor_export_image(const char *filename, int quality);
void wb_supervisor_movie_start_recording(const char *filename, int width, int height, int codec, int quality,
                                         int acceleration, bool caption);
void wb_supervisor_movie_stop_recording(void);
bool wb_supervisor_movie_is_ready(void);
bool wb_supervisor_movie_failed(void);
bool wb_supervisor_animation_start_recording(const char *filename);
bool wb_supervisor_animation_stop_recording(void);
WbNodeRef wb_supervisor_node_get_root(void);
WbNodeRef wb_supervisor_node_get_self(void);
int wb_supervisor_node_get_id(WbNodeRef node);
WbNodeRef wb_supervisor_node_get_from_id(int id);
WbNodeRef wb_supervisor_node_get_from_device(WbDeviceTag tag);
WbNodeRef wb_supervisor_node_get_from_def(const char *def);
WbNodeRef wb_supervisor_node_get_from_proto_def(WbNodeRef node, const char *def);
WbNodeRef wb_supervisor_node_get_parent_node(WbNodeRef node);
WbNodeRef wb_supervisor_node_get_selected(void);
WbNodeType wb_supervisor_node_get_type(WbNodeRef node);
WbFieldRef wb_supervisor_node_get_field(WbNodeRef node, const char *field_name);
WbFieldRef wb_supervisor_node_get_field_by_index(WbNodeRef node, const int index);
int wb_supervisor_node_get_number_of_fields(WbNodeRef node);
WbFieldRef wb_supervisor_node_get_base_node_field(WbNodeRef node, const char *field_name);
WbFieldRef wb_supervisor_node_get_base_node_field_by_index(WbNodeRef node, int index);
int wb_supervisor_node_get_number_of_base_node_fields(WbNodeRef node);
void wb_supervisor_node_remove(WbNodeRef node);
void wb_supervisor_node_save_state(WbNodeRef node, const char *state_name);
void wb_supervisor_node_load_state(WbNodeRef node, const char *state_name);
void wb_supervisor_node_set_joint_position(WbNodeRef node, double position, int index);
WbProtoRef wb_supervisor_node_get_proto(WbNodeRef node);
const char *wb_supervisor_node_get_def(WbNodeRef node);
const char *wb_supervisor_node_get_type_name(WbNodeRef node);
const char *wb_supervisor_node_get_base_type_name(WbNodeRef node);
bool wb_supervisor_node_is_proto(WbNodeRef node);
const double *wb_supervisor_node_get_center_of_mass(WbNodeRef node);
const double *wb_supervisor_node_get_contact_point(WbNodeRef node, int index);
WbNodeRef wb_supervisor_node_get_contact_point_node(WbNodeRef node, int index);
int wb_supervisor_node_get_number_of_contact_points(WbNodeRef node, bool include_descendants);
WbContactPoint *wb_supervisor_node_get_contact_points(WbNodeRef node, bool include_descendants, int *size);
const double *wb_supervisor_node_get_orientation(WbNodeRef node);
const double *wb_supervisor_node_get_position(WbNodeRef node);
const double *wb_supervisor_node_get_pose(WbNodeRef node, WbNodeRef from_node);
bool wb_supervisor_node_get_static_balance(WbNodeRef node);
const double *wb_supervisor_node_get_velocity(WbNodeRef node);
void wb_supervisor_node_set_velocity(WbNodeRef node, const double velocity[6]);
void wb_supervisor_node_reset_physics(WbNodeRef node);
void wb_supervisor_node_restart_controller(WbNodeRef node);
const char *wb_supervisor_node_export_string(WbNodeRef node);
void wb_supervisor_node_move_viewpoint(WbNodeRef node);
void wb_supervisor_node_set_visibility(WbNodeRef node, WbNodeRef from, bool visible);
void wb_supervisor_node_add_force(WbNodeRef node, const double force[3], bool relative);
void wb_supervisor_node_add_force_with_offset(WbNodeRef node, const double force[3], const double offset[3], bool relative);
void wb_supervisor_node_add_torque(WbNodeRef node, const double torque[3], bool relative);
const char *wb_supervisor_field_get_name(WbFieldRef field);
WbFieldType wb_supervisor_field_get_type(WbFieldRef field);
const char *wb_supervisor_field_get_type_name(WbFieldRef field);
int wb_supervisor_field_get_count(WbFieldRef field);
WbFieldRef wb_supervisor_field_get_actual_field(WbFieldRef field);
void wb_supervisor_field_enable_sf_tracking(WbFieldRef field, int sampling_period);
void wb_supervisor_field_disable_sf_tracking(WbFieldRef field);
void wb_supervisor_node_enable_pose_tracking(WbNodeRef node, int sampling_period, WbNodeRef from_node);
void wb_supervisor_node_disable_pose_tracking(WbNodeRef node, WbNodeRef from_node);
void wb_supervisor_node_enable_contact_points_tracking(WbNodeRef node, int sampling_period, bool include_descendants);
void wb_supervisor_node_disable_contact_points_tracking(WbNodeRef node);
bool wb_supervisor_field_get_sf_bool(WbFieldRef field);
int wb_supervisor_field_get_sf_int32(WbFieldRef field);
double wb_supervisor_field_get_sf_float(WbFieldRef field);
const double *wb_supervisor_field_get_sf_vec2f(WbFieldRef field);
const double *wb_supervisor_field_get_sf_vec3f(WbFieldRef field);
const double *wb_supervisor_field_get_sf_rotation(WbFieldRef field);
const double *wb_supervisor_field_get_sf_color(WbFieldRef field);
const char *wb_supervisor_field_get_sf_string(WbFieldRef field);
WbNodeRef wb_supervisor_field_get_sf_node(WbFieldRef field);
bool wb_supervisor_field_get_mf_bool(WbFieldRef field, int index);
int wb_supervisor_field_get_mf_int32(WbFieldRef field, int index);
double wb_supervisor_field_get_mf_float(WbFieldRef field, int index);
const double *wb_supervisor_field_get_mf_vec2f(WbFieldRef field, int index);
const double *wb_supervisor_field_get_mf_vec3f(WbFieldRef field, int index);
const double *wb_supervisor_field_get_mf_color(WbFieldRef field, int index);
const double *wb_supervisor_field_get_mf_rotation(WbFieldRef field, int index);
const char *wb_supervisor_field_get_mf_string(WbFieldRef field, int index);
WbNodeRef wb_supervisor_field_get_mf_node(WbFieldRef field, int index);
void wb_supervisor_field_set_sf_bool(WbFieldRef field, bool value);
void wb_supervisor_field_set_sf_int32(WbFieldRef field, int value);
void wb_supervisor_field_set_sf_float(WbFieldRef field, double value);
void wb_supervisor_field_set_sf_vec2f(WbFieldRef field, const double values[2]);
void wb_supervisor_field_set_sf_vec3f(WbFieldRef field, const double values[3]);
void wb_supervisor_field_set_sf_rotation(WbFieldRef field, const double values[4]);
void wb_supervisor_field_set_sf_color(WbFieldRef field, const double values[3]);
void wb_supervisor_field_set_sf_string(WbFieldRef field, const char *value);
void wb_supervisor_field_set_mf_bool(WbFieldRef field, int index, bool value);
void wb_supervisor_field_set_mf_int32(WbFieldRef field, int index, int value);
void wb_supervisor_field_set_mf_float(WbFieldRef field, int index, double value);
void wb_supervisor_field_set_mf_vec2f(WbFieldRef field, int index, const double values[2]);
void wb_supervisor_field_set_mf_vec3f(WbFieldRef field, int index, const double values[3]);
void wb_supervisor_field_set_mf_rotation(WbFieldRef field, int index, const double values[4]);
void wb_supervisor_field_set_mf_color(WbFieldRef field, int index, const double values[3]);
void wb_supervisor_field_set_mf_string(WbFieldRef field, int index, const char *value);
void wb_supervisor_field_insert_mf_bool(WbFieldRef field, int index, bool value);
void wb_supervisor_field_insert_mf_int32(WbFieldRef field, int index, int value);
void wb_supervisor_field_insert_mf_float(WbFieldRef field, int index, double value);
void wb_supervisor_field_insert_mf_vec2f(WbFieldRef field, int index, const double values[2]);
void wb_supervisor_field_insert_mf_vec3f(WbFieldRef field, int index, const double values[3]);
void wb_supervisor_field_insert_mf_rotation(WbFieldRef field, int index, const double values[4]);
void wb_supervisor_field_insert_mf_color(WbFieldRef field, int index, const double values[3]);
void wb_supervisor_field_insert_mf_string(WbFieldRef field, int index, const char *value);
void wb_supervisor_field_remove_mf(WbFieldRef field, int index);
void wb_supervisor_field_import_mf_node_from_string(WbFieldRef field, int position, const char *node_string);
void wb_supervisor_field_remove_sf(WbFieldRef field);
void wb_supervisor_field_import_sf_node_from_string(WbFieldRef field, const char *node_string);
const char *wb_supervisor_proto_get_type_name(WbProtoRef proto);
bool wb_supervisor_proto_is_derived(WbProtoRef proto);
WbProtoRef wb_supervisor_proto_get_parent(WbProtoRef proto);
WbFieldRef wb_supervisor_proto_get_field(WbProtoRef proto, const char *field_name);
WbFieldRef wb_supervisor_proto_get_field_by_index(WbProtoRef proto, int index);
int wb_supervisor_proto_get_number_of_fields(WbProtoRef proto);
bool wb_supervisor_virtual_reality_headset_is_used(void);
const double *wb_supervisor_virtual_reality_headset_get_position(void);
const double *wb_supervisor_virtual_reality_headset_get_orientation(void);
void wb_supervisor_node_enable_contact_point_tracking(WbNodeRef node, int sampling_period, bool include_descendants);
void wb_supervisor_node_disable_contact_point_tracking(WbNodeRef node, bool include_descendants);
void wb_supervisor_simulation_revert(void);
void wb_supervisor_load_world(const char *filename);
bool wb_supervisor_save_world(const char *filename);
void wb_supervisor_field_remove_mf_node(WbFieldRef field, int position);
void wb_supervisor_simulation_physics_reset(void);
int wb_supervisor_movie_get_status(void);
void wb_supervisor_start_movie(const char *file, int width, int height, int codec, int quality, int acceleration,
                               bool caption);
void wb_supervisor_stop_movie(void);
int wb_supervisor_get_movie_status(void);

/* camera.h */
void wb_camera_enable(WbDeviceTag tag, int sampling_period);
void wb_camera_disable(WbDeviceTag tag);
int wb_camera_get_sampling_period(WbDeviceTag tag);
const unsigned char *wb_camera_get_image(WbDeviceTag tag);
int wb_camera_get_width(WbDeviceTag tag);
int wb_camera_get_height(WbDeviceTag tag);
double wb_camera_get_fov(WbDeviceTag tag);
double wb_camera_get_max_fov(WbDeviceTag tag);
double wb_camera_get_min_fov(WbDeviceTag tag);
void wb_camera_set_fov(WbDeviceTag tag, double fov);
double wb_camera_get_exposure(WbDeviceTag tag);
void wb_camera_set_exposure(WbDeviceTag tag, double exposure);
double wb_camera_get_focal_length(WbDeviceTag tag);
double wb_camera_get_focal_distance(WbDeviceTag tag);
double wb_camera_get_max_focal_distance(WbDeviceTag tag);
double wb_camera_get_min_focal_distance(WbDeviceTag tag);
void wb_camera_set_focal_distance(WbDeviceTag tag, double focal_distance);
double wb_camera_get_near(WbDeviceTag tag);
int wb_camera_save_image(WbDeviceTag tag, const char *filename, int quality);
bool wb_camera_has_recognition(WbDeviceTag tag);
void wb_camera_recognition_enable(WbDeviceTag tag, int sampling_period);
void wb_camera_recognition_disable(WbDeviceTag tag);
int wb_camera_recognition_get_sampling_period(WbDeviceTag tag);
int wb_camera_recognition_get_number_of_objects(WbDeviceTag tag);
const WbCameraRecognitionObject *wb_camera_recognition_get_objects(WbDeviceTag tag);
bool wb_camera_recognition_has_segmentation(WbDeviceTag tag);
void wb_camera_recognition_enable_segmentation(WbDeviceTag tag);
void wb_camera_recognition_disable_segmentation(WbDeviceTag tag);
bool wb_camera_recognition_is_segmentation_enabled(WbDeviceTag tag);
const unsigned char *wb_camera_recognition_get_segmentation_image(WbDeviceTag tag);
int wb_camera_recognition_save_segmentation_image(WbDeviceTag tag, const char *filename, int quality);

/* motor.h */
void wb_motor_set_position(WbDeviceTag tag, double position);
void wb_motor_set_acceleration(WbDeviceTag tag, double acceleration);
void wb_motor_set_velocity(WbDeviceTag tag, double velocity);
void wb_motor_set_force(WbDeviceTag tag, double force);
void wb_motor_set_torque(WbDeviceTag tag, double torque);
void wb_motor_set_available_force(WbDeviceTag tag, double force);
void wb_motor_set_available_torque(WbDeviceTag tag, double torque);
void wb_motor_set_control_pid(WbDeviceTag tag, double p, double i, double d);
void wb_motor_enable_force_feedback(WbDeviceTag tag, int sampling_period);
void wb_motor_disable_force_feedback(WbDeviceTag tag);
int wb_motor_get_force_feedback_sampling_period(WbDeviceTag tag);
double wb_motor_get_force_feedback(WbDeviceTag tag);
void wb_motor_enable_torque_feedback(WbDeviceTag tag, int sampling_period);
void wb_motor_disable_torque_feedback(WbDeviceTag tag);
int wb_motor_get_torque_feedback_sampling_period(WbDeviceTag tag);
double wb_motor_get_torque_feedback(WbDeviceTag tag);
WbJointType wb_motor_get_type(WbDeviceTag tag);
double wb_motor_get_target_position(WbDeviceTag tag);
double wb_motor_get_min_position(WbDeviceTag tag);
double wb_motor_get_max_position(WbDeviceTag tag);
double wb_motor_get_velocity(WbDeviceTag tag);
double wb_motor_get_max_velocity(WbDeviceTag tag);
double wb_motor_get_acceleration(WbDeviceTag tag);
double wb_motor_get_available_force(WbDeviceTag tag);
double wb_motor_get_max_force(WbDeviceTag tag);
double wb_motor_get_available_torque(WbDeviceTag tag);
double wb_motor_get_max_torque(WbDeviceTag tag);
double wb_motor_get_multiplier(WbDeviceTag tag);
WbDeviceTag wb_motor_get_brake(WbDeviceTag tag);
WbDeviceTag wb_motor_get_position_sensor(WbDeviceTag tag);

/* display.h */
int wb_display_get_width(WbDeviceTag tag);
int wb_display_get_height(WbDeviceTag tag);
void wb_display_set_color(WbDeviceTag tag, int color);
void wb_display_set_alpha(WbDeviceTag tag, double alpha);
void wb_display_set_opacity(WbDeviceTag tag, double opacity);
void wb_display_set_font(WbDeviceTag tag, const char *font, int size, bool anti_aliasing);
void wb_display_attach_camera(WbDeviceTag tag, WbDeviceTag camera_tag);
void wb_display_detach_camera(WbDeviceTag tag);
void wb_display_draw_pixel(WbDeviceTag tag, int x, int y);
void wb_display_draw_line(WbDeviceTag tag, int x1, int y1, int x2, int y2);
void wb_display_draw_rectangle(WbDeviceTag tag, int x, int y, int width, int height);
void wb_display_draw_oval(WbDeviceTag tag, int cx, int cy, int a, int b);
void wb_display_draw_polygon(WbDeviceTag tag, const int *x, const int *y, int size);
void wb_display_draw_text(WbDeviceTag tag, const char *text, int x, int y);
void wb_display_fill_rectangle(WbDeviceTag tag, int x, int y, int width, int height);
void wb_display_fill_oval(WbDeviceTag tag, int cx, int cy, int a, int b);
void wb_display_fill_polygon(WbDeviceTag tag, const int *x, const int *y, int size);
WbImageRef wb_display_image_new(WbDeviceTag tag, int width, int height, const void *data, int format);
WbImageRef wb_display_image_copy(WbDeviceTag tag, int x, int y, int width, int height);
WbImageRef wb_display_image_load(WbDeviceTag tag, const char *filename);
void wb_display_image_delete(WbDeviceTag tag, WbImageRef ir);
void wb_display_image_paste(WbDeviceTag tag, WbImageRef ir, int x, int y, bool blend);
void wb_display_image_save(WbDeviceTag tag, WbImageRef ir, const char *filename);

/* lidar.h */
void wb_lidar_enable(WbDeviceTag tag, int sampling_period);
void wb_lidar_enable_point_cloud(WbDeviceTag tag);
void wb_lidar_disable(WbDeviceTag tag);
void wb_lidar_disable_point_cloud(WbDeviceTag tag);
int wb_lidar_get_sampling_period(WbDeviceTag tag);
bool wb_lidar_is_point_cloud_enabled(WbDeviceTag tag);
const float *wb_lidar_get_range_image(WbDeviceTag tag);
const float *wb_lidar_get_layer_range_image(WbDeviceTag tag, int layer);
const WbLidarPoint *wb_lidar_get_point_cloud(WbDeviceTag tag);
const WbLidarPoint *wb_lidar_get_layer_point_cloud(WbDeviceTag tag, int layer);
int wb_lidar_get_number_of_points(WbDeviceTag tag);
int wb_lidar_get_horizontal_resolution(WbDeviceTag tag);
int wb_lidar_get_number_of_layers(WbDeviceTag tag);
double wb_lidar_get_min_frequency(WbDeviceTag tag);
double wb_lidar_get_max_frequency(WbDeviceTag tag);
double wb_lidar_get_frequency(WbDeviceTag tag);
void wb_lidar_set_frequency(WbDeviceTag tag, double frequency);
double wb_lidar_get_fov(WbDeviceTag tag);
double wb_lidar_get_vertical_fov(WbDeviceTag tag);
double wb_lidar_get_min_range(WbDeviceTag tag);
double wb_lidar_get_max_range(WbDeviceTag tag);

/* vehicle/driver.h */
bool wbu_driver_initialization_is_possible(void);
void wbu_driver_init(void);
void wbu_driver_cleanup(void);
int wbu_driver_step(void);
void wbu_driver_set_steering_angle(double steering_angle);
double wbu_driver_get_steering_angle(void);
void wbu_driver_set_cruising_speed(double speed);
double wbu_driver_get_target_cruising_speed(void);
double wbu_driver_get_current_speed(void);
void wbu_driver_set_throttle(double throttle);
double wbu_driver_get_throttle(void);
void wbu_driver_set_brake_intensity(double intensity);
double wbu_driver_get_brake_intensity(void);
void wbu_driver_set_indicator(WbuDriverIndicatorState state);
void wbu_driver_set_hazard_flashers(bool state);
WbuDriverIndicatorState wbu_driver_get_indicator(void);
bool wbu_driver_get_hazard_flashers(void);
void wbu_driver_set_dipped_beams(bool state);
void wbu_driver_set_antifog_lights(bool state);
bool wbu_driver_get_dipped_beams(void);
bool wbu_driver_get_antifog_lights(void);
double wbu_driver_get_rpm(void);
int wbu_driver_get_gear(void);
void wbu_driver_set_gear(int gear);
int wbu_driver_get_gear_number(void);
WbuDriverControlMode wbu_driver_get_control_mode(void);
void wbu_driver_set_wiper_mode(WbuDriverWiperMode mode);
WbuDriverWiperMode wbu_driver_get_wiper_mode(void);
void wbu_driver_set_brake(double brake);
double wbu_driver_get_brake(void);
void wbu_driver_set_wipers_mode(wbu_wipers_mode mode);
wbu_wipers_mode wbu_driver_get_wipers_mode(void);

/* vehicle/car.h */
void wbu_car_init(void);
void wbu_car_cleanup(void);
WbuCarType wbu_car_get_type(void);
WbuCarEngineType wbu_car_get_engine_type(void);
void wbu_car_set_indicator_period(double period);
double wbu_car_get_indicator_period(void);
bool wbu_car_get_backwards_lights(void);
bool wbu_car_get_brake_lights(void);
double wbu_car_get_track_front(void);
double wbu_car_get_track_rear(void);
double wbu_car_get_wheelbase(void);
double wbu_car_get_front_wheel_radius(void);
double wbu_car_get_rear_wheel_radius(void);
double wbu_car_get_wheel_encoder(WbuCarWheelIndex wheel_index);
double wbu_car_get_wheel_speed(WbuCarWheelIndex wheel_index);
void wbu_car_set_left_steering_angle(double angle);
void wbu_car_set_right_steering_angle(double angle);
double wbu_car_get_right_steering_angle(void);
double wbu_car_get_left_steering_angle(void);
void wbu_car_enable_limited_slip_differential(bool enable);
void wbu_car_enable_indicator_auto_disabling(bool enable);

/* speaker.h */
void wb_speaker_play_sound(WbDeviceTag left, WbDeviceTag right, const char *sound, double volume, double pitch,
                           double balance, bool loop);
void wb_speaker_stop(WbDeviceTag tag, const char *sound);
bool wb_speaker_is_sound_playing(WbDeviceTag tag, const char *sound);
bool wb_speaker_set_engine(WbDeviceTag tag, const char *engine);
bool wb_speaker_set_language(WbDeviceTag tag, const char *language);
const char *wb_speaker_get_engine(WbDeviceTag tag);
const char *wb_speaker_get_language(WbDeviceTag tag);
void wb_speaker_speak(WbDeviceTag tag, const char *text, double volume);
bool wb_speaker_is_speaking(WbDeviceTag tag);

/* radio.h */
WbRadioMessage wb_radio_message_new(int length, const char *body, const char *destination);
void wb_radio_message_delete(WbRadioMessage message);
const char *wb_radio_message_get_destination(WbRadioMessage message);
int wb_radio_message_get_length(WbRadioMessage message);
const char *wb_radio_message_get_body(WbRadioMessage message);
void wb_radio_enable(WbDeviceTag tag, int sampling_period);
void wb_radio_disable(WbDeviceTag tag);
void wb_radio_set_address(WbDeviceTag tag, const char *address);
const char *wb_radio_get_address(WbDeviceTag tag);
void wb_radio_set_frequency(WbDeviceTag tag, double hz);
double wb_radio_get_frequency(WbDeviceTag tag);
void wb_radio_set_channel(WbDeviceTag tag, int channel);
int wb_radio_get_channel(WbDeviceTag tag);
void wb_radio_set_bitrate(WbDeviceTag tag, int bits_per_second);
int wb_radio_get_bitrate(WbDeviceTag tag);
void wb_radio_set_rx_sensitivity(WbDeviceTag tag, double dBm);
double wb_radio_get_rx_sensitivity(WbDeviceTag tag);
void wb_radio_set_tx_power(WbDeviceTag tag, double dBm);
double wb_radio_get_tx_power(WbDeviceTag tag);
void wb_radio_set_callback(WbDeviceTag tag, void (*callback)(const WbRadioEvent));
WbDeviceTag wb_radio_event_get_radio(const WbRadioEvent event);
char *wb_radio_event_get_data(const WbRadioEvent event);
int wb_radio_event_get_data_size(const WbRadioEvent event);
char *wb_radio_event_get_emitter(const WbRadioEvent event);
double wb_radio_event_get_rssi(const WbRadioEvent event);
void wb_radio_send(WbDeviceTag tag, const WbRadioMessage message, double delay);

/* accelerometer.h, compass.h, gyro.h */
void wb_accelerometer_enable(WbDeviceTag tag, int sampling_period);
void wb_accelerometer_disable(WbDeviceTag tag);
int wb_accelerometer_get_sampling_period(WbDeviceTag tag);
const double *wb_accelerometer_get_values(WbDeviceTag tag);
int wb_accelerometer_get_lookup_table_size(WbDeviceTag tag);
const double *wb_accelerometer_get_lookup_table(WbDeviceTag tag);
void wb_compass_enable(WbDeviceTag tag, int sampling_period);
void wb_compass_disable(WbDeviceTag tag);
int wb_compass_get_sampling_period(WbDeviceTag tag);
const double *wb_compass_get_values(WbDeviceTag tag);
int wb_compass_get_lookup_table_size(WbDeviceTag tag);
const double *wb_compass_get_lookup_table(WbDeviceTag tag);
void wb_gyro_enable(WbDeviceTag tag, int sampling_period);
void wb_gyro_disable(WbDeviceTag tag);
int wb_gyro_get_sampling_period(WbDeviceTag tag);
const double *wb_gyro_get_values(WbDeviceTag tag);
int wb_gyro_get_lookup_table_size(WbDeviceTag tag);
const double *wb_gyro_get_lookup_table(WbDeviceTag tag);

/* altimeter.h */
void wb_altimeter_enable(WbDeviceTag tag, int sampling_period);
void wb_altimeter_disable(WbDeviceTag tag);
int wb_altimeter_get_sampling_period(WbDeviceTag tag);
double wb_altimeter_get_value(WbDeviceTag tag);

/* brake.h */
void wb_brake_set_damping_constant(WbDeviceTag tag, double damping_constant);
WbJointType wb_brake_get_type(WbDeviceTag tag);
WbDeviceTag wb_brake_get_motor(WbDeviceTag tag);
WbDeviceTag wb_brake_get_position_sensor(WbDeviceTag tag);

/* connector.h */
void wb_connector_enable_presence(WbDeviceTag tag, int sampling_period);
void wb_connector_disable_presence(WbDeviceTag tag);
int wb_connector_get_presence_sampling_period(WbDeviceTag tag);
int wb_connector_get_presence(WbDeviceTag tag);
bool wb_connector_is_locked(WbDeviceTag tag);
void wb_connector_lock(WbDeviceTag tag);
void wb_connector_unlock(WbDeviceTag tag);

/* device.h */
const char *wb_device_get_name(WbDeviceTag tag);
const char *wb_device_get_model(WbDeviceTag tag);
WbNodeType wb_device_get_node_type(WbDeviceTag tag);

/* distance_sensor.h */
void wb_distance_sensor_enable(WbDeviceTag tag, int sampling_period);
void wb_distance_sensor_disable(WbDeviceTag tag);
int wb_distance_sensor_get_sampling_period(WbDeviceTag tag);
double wb_distance_sensor_get_value(WbDeviceTag tag);
double wb_distance_sensor_get_max_value(WbDeviceTag tag);
double wb_distance_sensor_get_min_value(WbDeviceTag tag);
double wb_distance_sensor_get_aperture(WbDeviceTag tag);
int wb_distance_sensor_get_lookup_table_size(WbDeviceTag tag);
const double *wb_distance_sensor_get_lookup_table(WbDeviceTag tag);
WbDistanceSensorType wb_distance_sensor_get_type(WbDeviceTag tag);

/* emitter.h */
int wb_emitter_send(WbDeviceTag tag, const void *data, int size);
int wb_emitter_get_buffer_size(WbDeviceTag tag);
void wb_emitter_set_channel(WbDeviceTag tag, int channel);
int wb_emitter_get_channel(WbDeviceTag tag);
double wb_emitter_get_range(WbDeviceTag tag);
void wb_emitter_set_range(WbDeviceTag tag, double range);

/* gps.h */
void wb_gps_enable(WbDeviceTag tag, int sampling_period);
void wb_gps_disable(WbDeviceTag tag);
int wb_gps_get_sampling_period(WbDeviceTag tag);
const double *wb_gps_get_values(WbDeviceTag tag);
double wb_gps_get_speed(WbDeviceTag tag);
const double *wb_gps_get_speed_vector(WbDeviceTag tag);
const char *wb_gps_convert_to_degrees_minutes_seconds(double decimal_degree);
WbGpsCoordinateSystem wb_gps_get_coordinate_system(WbDeviceTag tag);

/* inertial_unit.h */
void wb_inertial_unit_enable(WbDeviceTag tag, int sampling_period);
void wb_inertial_unit_disable(WbDeviceTag tag);
int wb_inertial_unit_get_sampling_period(WbDeviceTag tag);
double wb_inertial_unit_get_noise(WbDeviceTag tag);
const double *wb_inertial_unit_get_roll_pitch_yaw(WbDeviceTag tag);
const double *wb_inertial_unit_get_quaternion(WbDeviceTag tag);

/* joystick.h */
void wb_joystick_enable(int sampling_period);
void wb_joystick_disable(void);
int wb_joystick_get_sampling_period(void);
bool wb_joystick_is_connected(void);
const char *wb_joystick_get_model(void);
int wb_joystick_get_number_of_axes(void);
int wb_joystick_get_axis_value(int axis);
int wb_joystick_get_number_of_povs(void);
int wb_joystick_get_pov_value(int pov);
int wb_joystick_get_pressed_button(void);
void wb_joystick_set_constant_force(int level);
void wb_joystick_set_constant_force_duration(double duration);
void wb_joystick_set_auto_centering_gain(double gain);
void wb_joystick_set_resistance_gain(double gain);
void wb_joystick_set_force_axis(int axis);

/* keyboard.h */
void wb_keyboard_enable(int sampling_period);
void wb_keyboard_disable(void);
int wb_keyboard_get_sampling_period(void);
int wb_keyboard_get_key(void);

/* led.h */
void wb_led_set(WbDeviceTag tag, int value);
int wb_led_get(WbDeviceTag tag);

/* light_sensor.h */
void wb_light_sensor_enable(WbDeviceTag tag, int sampling_period);
void wb_light_sensor_disable(WbDeviceTag tag);
int wb_light_sensor_get_sampling_period(WbDeviceTag tag);
double wb_light_sensor_get_value(WbDeviceTag tag);
int wb_light_sensor_get_lookup_table_size(WbDeviceTag tag);
const double *wb_light_sensor_get_lookup_table(WbDeviceTag tag);

/* microphone.h */
void wb_microphone_enable(WbDeviceTag tag, int sampling_period);
void wb_microphone_disable(WbDeviceTag tag);
int wb_microphone_get_sampling_period(WbDeviceTag tag);
const void *wb_microphone_get_sample_data(WbDeviceTag tag);
int wb_microphone_get_sample_size(WbDeviceTag tag);

/* mouse.h */
void wb_mouse_enable(int sampling_period);
void wb_mouse_disable(void);
int wb_mouse_get_sampling_period(void);
void wb_mouse_enable_3d_position(void);
void wb_mouse_disable_3d_position(void);
bool wb_mouse_is_3d_position_enabled(void);
WbMouseState wb_mouse_get_state(void);

/* pen.h */
void wb_pen_write(WbDeviceTag tag, bool write);
void wb_pen_set_ink_color(WbDeviceTag tag, int color, double density);

/* position_sensor.h */
void wb_position_sensor_enable(WbDeviceTag tag, int sampling_period);
void wb_position_sensor_disable(WbDeviceTag tag);
int wb_position_sensor_get_sampling_period(WbDeviceTag tag);
double wb_position_sensor_get_value(WbDeviceTag tag);
WbJointType wb_position_sensor_get_type(WbDeviceTag tag);
WbDeviceTag wb_position_sensor_get_motor(WbDeviceTag tag);
WbDeviceTag wb_position_sensor_get_brake(WbDeviceTag tag);

/* radar.h */
void wb_radar_enable(WbDeviceTag tag, int sampling_period);
void wb_radar_disable(WbDeviceTag tag);
int wb_radar_get_sampling_period(WbDeviceTag tag);
int wb_radar_get_number_of_targets(WbDeviceTag tag);
const WbRadarTarget *wb_radar_get_targets(WbDeviceTag tag);
double wb_radar_get_min_range(WbDeviceTag tag);
double wb_radar_get_max_range(WbDeviceTag tag);
double wb_radar_get_horizontal_fov(WbDeviceTag tag);
double wb_radar_get_vertical_fov(WbDeviceTag tag);

/* range_finder.h */
void wb_range_finder_enable(WbDeviceTag tag, int sampling_period);
void wb_range_finder_disable(WbDeviceTag tag);
int wb_range_finder_get_sampling_period(WbDeviceTag tag);
const float *wb_range_finder_get_range_image(WbDeviceTag tag);
int wb_range_finder_get_width(WbDeviceTag tag);
int wb_range_finder_get_height(WbDeviceTag tag);
double wb_range_finder_get_fov(WbDeviceTag tag);
double wb_range_finder_get_min_range(WbDeviceTag tag);
double wb_range_finder_get_max_range(WbDeviceTag tag);
int wb_range_finder_save_image(WbDeviceTag tag, const char *filename, int quality);

/* receiver.h */
void wb_receiver_enable(WbDeviceTag tag, int sampling_period);
void wb_receiver_disable(WbDeviceTag tag);
int wb_receiver_get_sampling_period(WbDeviceTag tag);
void wb_receiver_set_channel(WbDeviceTag tag, int channel);
int wb_receiver_get_channel(WbDeviceTag tag);
int wb_receiver_get_queue_length(WbDeviceTag tag);
void wb_receiver_next_packet(WbDeviceTag tag);
int wb_receiver_get_data_size(WbDeviceTag tag);
const void *wb_receiver_get_data(WbDeviceTag tag);
double wb_receiver_get_signal_strength(WbDeviceTag tag);
const double *wb_receiver_get_emitter_direction(WbDeviceTag tag);

/* skin.h */
void wb_skin_set_bone_orientation(WbDeviceTag tag, int index, const double orientation[4], bool absolute);
void wb_skin_set_bone_position(WbDeviceTag tag, int index, const double position[3], bool absolute);
int wb_skin_get_bone_count(WbDeviceTag tag);
const char *wb_skin_get_bone_name(WbDeviceTag tag, int index);
const double *wb_skin_get_bone_orientation(WbDeviceTag tag, int index, bool absolute);
const double *wb_skin_get_bone_position(WbDeviceTag tag, int index, bool absolute);

/* touch_sensor.h */
void wb_touch_sensor_enable(WbDeviceTag tag, int sampling_period);
void wb_touch_sensor_disable(WbDeviceTag tag);
int wb_touch_sensor_get_sampling_period(WbDeviceTag tag);
double wb_touch_sensor_get_value(WbDeviceTag tag);
const double *wb_touch_sensor_get_values(WbDeviceTag tag);
WbTouchSensorType wb_touch_sensor_get_type(WbDeviceTag tag);
int wb_touch_sensor_get_lookup_table_size(WbDeviceTag tag);
const double *wb_touch_sensor_get_lookup_table(WbDeviceTag tag);

/* vacuum_gripper.h */
void wb_vacuum_gripper_enable_presence(WbDeviceTag tag, int sampling_period);
void wb_vacuum_gripper_disable_presence(WbDeviceTag tag);
int wb_vacuum_gripper_get_presence_sampling_period(WbDeviceTag tag);
bool wb_vacuum_gripper_get_presence(WbDeviceTag tag);
void wb_vacuum_gripper_turn_on(WbDeviceTag tag);
void wb_vacuum_gripper_turn_off(WbDeviceTag tag);
bool wb_vacuum_gripper_is_on(WbDeviceTag tag);

/* console.h */
void wb_console_print(const char *text, int stream);

/* utils/motion.h */
WbMotionRef wbu_motion_new(const char *filename);
void wbu_motion_delete(WbMotionRef motion);
void wbu_motion_play(WbMotionRef motion);
void wbu_motion_stop(WbMotionRef motion);
void wbu_motion_set_loop(WbMotionRef motion, bool loop);
void wbu_motion_set_reverse(WbMotionRef motion, bool reverse);
bool wbu_motion_is_over(WbMotionRef motion);
int wbu_motion_get_duration(WbMotionRef motion);
int wbu_motion_get_time(WbMotionRef motion);
void wbu_motion_set_time(WbMotionRef motion, int time);

/* utils/system.h */
const char *wbu_system_getenv(const char *variable);
const char *wbu_system_short_path(const char *path);
const char *wbu_system_tmpdir(void);
const char *wbu_system_webots_instance_path(bool refresh);

/* utils/string.h */
char *wbu_string_strsep(char **stringp, const char *delim);
char *wbu_string_replace(char *value, const char *before, const char *after);

/* plugins/robot_window/robot_wwi.h (wb_robot_wwi_send_text is a macro) */
void wb_robot_wwi_send(const char *data, int size);
const char *wb_robot_wwi_receive(int *size);
const char *wb_robot_wwi_receive_text(void);

/* constants a controller uses, with the values Webots' headers give them */
_Static_assert(WB_MODE_SIMULATION == 0, "WB_MODE_SIMULATION");
_Static_assert(WB_MODE_CROSS_COMPILATION == 1, "WB_MODE_CROSS_COMPILATION");
_Static_assert(WB_MODE_REMOTE_CONTROL == 2, "WB_MODE_REMOTE_CONTROL");
_Static_assert(WB_EVENT_QUIT == -1, "WB_EVENT_QUIT");
_Static_assert(WB_EVENT_NO_EVENT == 0, "WB_EVENT_NO_EVENT");
_Static_assert(WB_EVENT_MOUSE_CLICK == 1, "WB_EVENT_MOUSE_CLICK");
_Static_assert(WB_EVENT_MOUSE_MOVE == 2, "WB_EVENT_MOUSE_MOVE");
_Static_assert(WB_EVENT_KEYBOARD == 4, "WB_EVENT_KEYBOARD");
_Static_assert(WB_EVENT_JOYSTICK_BUTTON == 8, "WB_EVENT_JOYSTICK_BUTTON");
_Static_assert(WB_EVENT_JOYSTICK_AXIS == 16, "WB_EVENT_JOYSTICK_AXIS");
_Static_assert(WB_EVENT_JOYSTICK_POV == 32, "WB_EVENT_JOYSTICK_POV");
_Static_assert(WB_NO_FIELD == 0, "WB_NO_FIELD");
_Static_assert(WB_SF_BOOL == 1, "WB_SF_BOOL");
_Static_assert(WB_MF_BOOL == 17, "WB_MF_BOOL");
_Static_assert(WB_SF_INT32 == 2, "WB_SF_INT32");
_Static_assert(WB_MF_INT32 == 18, "WB_MF_INT32");
_Static_assert(WB_SF_FLOAT == 3, "WB_SF_FLOAT");
_Static_assert(WB_MF_FLOAT == 19, "WB_MF_FLOAT");
_Static_assert(WB_SF_VEC2F == 4, "WB_SF_VEC2F");
_Static_assert(WB_MF_VEC2F == 20, "WB_MF_VEC2F");
_Static_assert(WB_SF_VEC3F == 5, "WB_SF_VEC3F");
_Static_assert(WB_MF_VEC3F == 21, "WB_MF_VEC3F");
_Static_assert(WB_SF_ROTATION == 6, "WB_SF_ROTATION");
_Static_assert(WB_MF_ROTATION == 22, "WB_MF_ROTATION");
_Static_assert(WB_SF_COLOR == 7, "WB_SF_COLOR");
_Static_assert(WB_MF_COLOR == 23, "WB_MF_COLOR");
_Static_assert(WB_SF_STRING == 8, "WB_SF_STRING");
_Static_assert(WB_MF_STRING == 24, "WB_MF_STRING");
_Static_assert(WB_SF_NODE == 9, "WB_SF_NODE");
_Static_assert(WB_MF_NODE == 25, "WB_MF_NODE");
_Static_assert(WB_MF == 16, "WB_MF");
_Static_assert(WB_SUPERVISOR_SIMULATION_MODE_PAUSE == 0, "WB_SUPERVISOR_SIMULATION_MODE_PAUSE");
_Static_assert(WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME == 1, "WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME");
_Static_assert(WB_SUPERVISOR_SIMULATION_MODE_FAST == 2, "WB_SUPERVISOR_SIMULATION_MODE_FAST");
_Static_assert(WB_SUPERVISOR_MOVIE_READY == 0, "WB_SUPERVISOR_MOVIE_READY");
_Static_assert(WB_SUPERVISOR_MOVIE_RECORDING == 1, "WB_SUPERVISOR_MOVIE_RECORDING");
_Static_assert(WB_SUPERVISOR_MOVIE_SAVING == 2, "WB_SUPERVISOR_MOVIE_SAVING");
_Static_assert(WB_SUPERVISOR_MOVIE_WRITE_ERROR == 3, "WB_SUPERVISOR_MOVIE_WRITE_ERROR");
_Static_assert(WB_SUPERVISOR_MOVIE_ENCODING_ERROR == 4, "WB_SUPERVISOR_MOVIE_ENCODING_ERROR");
_Static_assert(WB_SUPERVISOR_MOVIE_SIMULATION_ERROR == 5, "WB_SUPERVISOR_MOVIE_SIMULATION_ERROR");
_Static_assert(WB_IMAGE_RGB == 3, "WB_IMAGE_RGB");
_Static_assert(WB_IMAGE_RGBA == 4, "WB_IMAGE_RGBA");
_Static_assert(WB_IMAGE_ARGB == 5, "WB_IMAGE_ARGB");
_Static_assert(WB_IMAGE_BGRA == 6, "WB_IMAGE_BGRA");
_Static_assert(WB_IMAGE_ABGR == 7, "WB_IMAGE_ABGR");
_Static_assert(WB_STDOUT == 1, "WB_STDOUT");
_Static_assert(WB_STDERR == 2, "WB_STDERR");
_Static_assert(WB_KEYBOARD_END == 312, "WB_KEYBOARD_END");
_Static_assert(WB_KEYBOARD_HOME == 313, "WB_KEYBOARD_HOME");
_Static_assert(WB_KEYBOARD_LEFT == 314, "WB_KEYBOARD_LEFT");
_Static_assert(WB_KEYBOARD_UP == 315, "WB_KEYBOARD_UP");
_Static_assert(WB_KEYBOARD_RIGHT == 316, "WB_KEYBOARD_RIGHT");
_Static_assert(WB_KEYBOARD_DOWN == 317, "WB_KEYBOARD_DOWN");
_Static_assert(WB_KEYBOARD_PAGEUP == 366, "WB_KEYBOARD_PAGEUP");
_Static_assert(WB_KEYBOARD_PAGEDOWN == 367, "WB_KEYBOARD_PAGEDOWN");
_Static_assert(WB_KEYBOARD_NUMPAD_HOME == 375, "WB_KEYBOARD_NUMPAD_HOME");
_Static_assert(WB_KEYBOARD_NUMPAD_LEFT == 376, "WB_KEYBOARD_NUMPAD_LEFT");
_Static_assert(WB_KEYBOARD_NUMPAD_UP == 377, "WB_KEYBOARD_NUMPAD_UP");
_Static_assert(WB_KEYBOARD_NUMPAD_RIGHT == 378, "WB_KEYBOARD_NUMPAD_RIGHT");
_Static_assert(WB_KEYBOARD_NUMPAD_DOWN == 379, "WB_KEYBOARD_NUMPAD_DOWN");
_Static_assert(WB_KEYBOARD_NUMPAD_END == 382, "WB_KEYBOARD_NUMPAD_END");
_Static_assert(WB_KEYBOARD_KEY == 65535, "WB_KEYBOARD_KEY");
_Static_assert(WB_KEYBOARD_SHIFT == 65536, "WB_KEYBOARD_SHIFT");
_Static_assert(WB_KEYBOARD_CONTROL == 131072, "WB_KEYBOARD_CONTROL");
_Static_assert(WB_KEYBOARD_ALT == 262144, "WB_KEYBOARD_ALT");
_Static_assert(WB_NODE_NO_NODE == 0, "WB_NODE_NO_NODE");
_Static_assert(WB_NODE_APPEARANCE == 1, "WB_NODE_APPEARANCE");
_Static_assert(WB_NODE_BACKGROUND == 2, "WB_NODE_BACKGROUND");
_Static_assert(WB_NODE_BILLBOARD == 3, "WB_NODE_BILLBOARD");
_Static_assert(WB_NODE_BOX == 4, "WB_NODE_BOX");
_Static_assert(WB_NODE_CAD_SHAPE == 5, "WB_NODE_CAD_SHAPE");
_Static_assert(WB_NODE_CAPSULE == 6, "WB_NODE_CAPSULE");
_Static_assert(WB_NODE_COLOR == 7, "WB_NODE_COLOR");
_Static_assert(WB_NODE_CONE == 8, "WB_NODE_CONE");
_Static_assert(WB_NODE_COORDINATE == 9, "WB_NODE_COORDINATE");
_Static_assert(WB_NODE_CYLINDER == 10, "WB_NODE_CYLINDER");
_Static_assert(WB_NODE_DIRECTIONAL_LIGHT == 11, "WB_NODE_DIRECTIONAL_LIGHT");
_Static_assert(WB_NODE_ELEVATION_GRID == 12, "WB_NODE_ELEVATION_GRID");
_Static_assert(WB_NODE_FOG == 13, "WB_NODE_FOG");
_Static_assert(WB_NODE_GROUP == 14, "WB_NODE_GROUP");
_Static_assert(WB_NODE_IMAGE_TEXTURE == 15, "WB_NODE_IMAGE_TEXTURE");
_Static_assert(WB_NODE_INDEXED_FACE_SET == 16, "WB_NODE_INDEXED_FACE_SET");
_Static_assert(WB_NODE_INDEXED_LINE_SET == 17, "WB_NODE_INDEXED_LINE_SET");
_Static_assert(WB_NODE_MATERIAL == 18, "WB_NODE_MATERIAL");
_Static_assert(WB_NODE_MESH == 19, "WB_NODE_MESH");
_Static_assert(WB_NODE_MUSCLE == 20, "WB_NODE_MUSCLE");
_Static_assert(WB_NODE_NORMAL == 21, "WB_NODE_NORMAL");
_Static_assert(WB_NODE_PBR_APPEARANCE == 22, "WB_NODE_PBR_APPEARANCE");
_Static_assert(WB_NODE_PLANE == 23, "WB_NODE_PLANE");
_Static_assert(WB_NODE_POINT_LIGHT == 24, "WB_NODE_POINT_LIGHT");
_Static_assert(WB_NODE_POINT_SET == 25, "WB_NODE_POINT_SET");
_Static_assert(WB_NODE_POSE == 26, "WB_NODE_POSE");
_Static_assert(WB_NODE_SHAPE == 27, "WB_NODE_SHAPE");
_Static_assert(WB_NODE_SPHERE == 28, "WB_NODE_SPHERE");
_Static_assert(WB_NODE_SPOT_LIGHT == 29, "WB_NODE_SPOT_LIGHT");
_Static_assert(WB_NODE_TEXTURE_COORDINATE == 30, "WB_NODE_TEXTURE_COORDINATE");
_Static_assert(WB_NODE_TEXTURE_TRANSFORM == 31, "WB_NODE_TEXTURE_TRANSFORM");
_Static_assert(WB_NODE_TRANSFORM == 32, "WB_NODE_TRANSFORM");
_Static_assert(WB_NODE_VIEWPOINT == 33, "WB_NODE_VIEWPOINT");
_Static_assert(WB_NODE_ROBOT == 34, "WB_NODE_ROBOT");
_Static_assert(WB_NODE_ACCELEROMETER == 35, "WB_NODE_ACCELEROMETER");
_Static_assert(WB_NODE_ALTIMETER == 36, "WB_NODE_ALTIMETER");
_Static_assert(WB_NODE_BRAKE == 37, "WB_NODE_BRAKE");
_Static_assert(WB_NODE_CAMERA == 38, "WB_NODE_CAMERA");
_Static_assert(WB_NODE_COMPASS == 39, "WB_NODE_COMPASS");
_Static_assert(WB_NODE_CONNECTOR == 40, "WB_NODE_CONNECTOR");
_Static_assert(WB_NODE_DISPLAY == 41, "WB_NODE_DISPLAY");
_Static_assert(WB_NODE_DISTANCE_SENSOR == 42, "WB_NODE_DISTANCE_SENSOR");
_Static_assert(WB_NODE_EMITTER == 43, "WB_NODE_EMITTER");
_Static_assert(WB_NODE_GPS == 44, "WB_NODE_GPS");
_Static_assert(WB_NODE_GYRO == 45, "WB_NODE_GYRO");
_Static_assert(WB_NODE_INERTIAL_UNIT == 46, "WB_NODE_INERTIAL_UNIT");
_Static_assert(WB_NODE_LED == 47, "WB_NODE_LED");
_Static_assert(WB_NODE_LIDAR == 48, "WB_NODE_LIDAR");
_Static_assert(WB_NODE_LIGHT_SENSOR == 49, "WB_NODE_LIGHT_SENSOR");
_Static_assert(WB_NODE_LINEAR_MOTOR == 50, "WB_NODE_LINEAR_MOTOR");
_Static_assert(WB_NODE_PEN == 51, "WB_NODE_PEN");
_Static_assert(WB_NODE_POSITION_SENSOR == 52, "WB_NODE_POSITION_SENSOR");
_Static_assert(WB_NODE_PROPELLER == 53, "WB_NODE_PROPELLER");
_Static_assert(WB_NODE_RADAR == 54, "WB_NODE_RADAR");
_Static_assert(WB_NODE_RANGE_FINDER == 55, "WB_NODE_RANGE_FINDER");
_Static_assert(WB_NODE_RECEIVER == 56, "WB_NODE_RECEIVER");
_Static_assert(WB_NODE_ROTATIONAL_MOTOR == 57, "WB_NODE_ROTATIONAL_MOTOR");
_Static_assert(WB_NODE_SKIN == 58, "WB_NODE_SKIN");
_Static_assert(WB_NODE_SPEAKER == 59, "WB_NODE_SPEAKER");
_Static_assert(WB_NODE_TOUCH_SENSOR == 60, "WB_NODE_TOUCH_SENSOR");
_Static_assert(WB_NODE_VACUUM_GRIPPER == 61, "WB_NODE_VACUUM_GRIPPER");
_Static_assert(WB_NODE_BALL_JOINT == 62, "WB_NODE_BALL_JOINT");
_Static_assert(WB_NODE_BALL_JOINT_PARAMETERS == 63, "WB_NODE_BALL_JOINT_PARAMETERS");
_Static_assert(WB_NODE_CHARGER == 64, "WB_NODE_CHARGER");
_Static_assert(WB_NODE_CONTACT_PROPERTIES == 65, "WB_NODE_CONTACT_PROPERTIES");
_Static_assert(WB_NODE_DAMPING == 66, "WB_NODE_DAMPING");
_Static_assert(WB_NODE_FLUID == 67, "WB_NODE_FLUID");
_Static_assert(WB_NODE_FOCUS == 68, "WB_NODE_FOCUS");
_Static_assert(WB_NODE_HINGE_JOINT == 69, "WB_NODE_HINGE_JOINT");
_Static_assert(WB_NODE_HINGE_JOINT_PARAMETERS == 70, "WB_NODE_HINGE_JOINT_PARAMETERS");
_Static_assert(WB_NODE_HINGE_2_JOINT == 71, "WB_NODE_HINGE_2_JOINT");
_Static_assert(WB_NODE_IMMERSION_PROPERTIES == 72, "WB_NODE_IMMERSION_PROPERTIES");
_Static_assert(WB_NODE_JOINT_PARAMETERS == 73, "WB_NODE_JOINT_PARAMETERS");
_Static_assert(WB_NODE_LENS == 74, "WB_NODE_LENS");
_Static_assert(WB_NODE_LENS_FLARE == 75, "WB_NODE_LENS_FLARE");
_Static_assert(WB_NODE_PHYSICS == 76, "WB_NODE_PHYSICS");
_Static_assert(WB_NODE_RECOGNITION == 77, "WB_NODE_RECOGNITION");
_Static_assert(WB_NODE_SLIDER_JOINT == 78, "WB_NODE_SLIDER_JOINT");
_Static_assert(WB_NODE_SLOT == 79, "WB_NODE_SLOT");
_Static_assert(WB_NODE_SOLID == 80, "WB_NODE_SOLID");
_Static_assert(WB_NODE_SOLID_REFERENCE == 81, "WB_NODE_SOLID_REFERENCE");
_Static_assert(WB_NODE_TRACK == 82, "WB_NODE_TRACK");
_Static_assert(WB_NODE_TRACK_WHEEL == 83, "WB_NODE_TRACK_WHEEL");
_Static_assert(WB_NODE_WORLD_INFO == 84, "WB_NODE_WORLD_INFO");
_Static_assert(WB_NODE_ZOOM == 85, "WB_NODE_ZOOM");
_Static_assert(WB_NODE_MICROPHONE == 86, "WB_NODE_MICROPHONE");
_Static_assert(WB_NODE_RADIO == 87, "WB_NODE_RADIO");
_Static_assert(WB_ROTATIONAL == 0, "WB_ROTATIONAL");
_Static_assert(WB_ANGULAR == 0, "WB_ANGULAR");
_Static_assert(WB_LINEAR == 1, "WB_LINEAR");
_Static_assert(WB_DISTANCE_SENSOR_GENERIC == 0, "WB_DISTANCE_SENSOR_GENERIC");
_Static_assert(WB_DISTANCE_SENSOR_INFRA_RED == 1, "WB_DISTANCE_SENSOR_INFRA_RED");
_Static_assert(WB_DISTANCE_SENSOR_SONAR == 2, "WB_DISTANCE_SENSOR_SONAR");
_Static_assert(WB_DISTANCE_SENSOR_LASER == 3, "WB_DISTANCE_SENSOR_LASER");
_Static_assert(WB_GPS_LOCAL_COORDINATE == 0, "WB_GPS_LOCAL_COORDINATE");
_Static_assert(WB_GPS_WGS84_COORDINATE == 1, "WB_GPS_WGS84_COORDINATE");
_Static_assert(WB_TOUCH_SENSOR_BUMPER == 0, "WB_TOUCH_SENSOR_BUMPER");
_Static_assert(WB_TOUCH_SENSOR_FORCE == 1, "WB_TOUCH_SENSOR_FORCE");
_Static_assert(WB_TOUCH_SENSOR_FORCE3D == 2, "WB_TOUCH_SENSOR_FORCE3D");
_Static_assert(WB_CHANNEL_BROADCAST == -1, "WB_CHANNEL_BROADCAST");
_Static_assert(WBU_CAR_TRACTION == 0, "WBU_CAR_TRACTION");
_Static_assert(WBU_CAR_PROPULSION == 1, "WBU_CAR_PROPULSION");
_Static_assert(WBU_CAR_FOUR_BY_FOUR == 2, "WBU_CAR_FOUR_BY_FOUR");
_Static_assert(WBU_CAR_COMBUSTION_ENGINE == 0, "WBU_CAR_COMBUSTION_ENGINE");
_Static_assert(WBU_CAR_ELECTRIC_ENGINE == 1, "WBU_CAR_ELECTRIC_ENGINE");
_Static_assert(WBU_CAR_PARALLEL_HYBRID_ENGINE == 2, "WBU_CAR_PARALLEL_HYBRID_ENGINE");
_Static_assert(WBU_CAR_POWER_SPLIT_HYBRID_ENGINE == 3, "WBU_CAR_POWER_SPLIT_HYBRID_ENGINE");
_Static_assert(WBU_CAR_WHEEL_FRONT_RIGHT == 0, "WBU_CAR_WHEEL_FRONT_RIGHT");
_Static_assert(WBU_CAR_WHEEL_FRONT_LEFT == 1, "WBU_CAR_WHEEL_FRONT_LEFT");
_Static_assert(WBU_CAR_WHEEL_REAR_RIGHT == 2, "WBU_CAR_WHEEL_REAR_RIGHT");
_Static_assert(WBU_CAR_WHEEL_REAR_LEFT == 3, "WBU_CAR_WHEEL_REAR_LEFT");
_Static_assert(WBU_CAR_WHEEL_NB == 4, "WBU_CAR_WHEEL_NB");
_Static_assert(OFF == 0, "OFF");
_Static_assert(RIGHT == 1, "RIGHT");
_Static_assert(LEFT == 2, "LEFT");
_Static_assert(UNDEFINED_CONTROL_MODE == -1, "UNDEFINED_CONTROL_MODE");
_Static_assert(SPEED == 0, "SPEED");
_Static_assert(TORQUE == 1, "TORQUE");
_Static_assert(DOWN == 0, "DOWN");
_Static_assert(SLOW == 1, "SLOW");
_Static_assert(NORMAL == 2, "NORMAL");
_Static_assert(FAST == 3, "FAST");

/* type names a controller uses (typedef'd again here: an error if Sensorium lacks one) */
typedef WbDeviceTag webots_api_WbDeviceTag;
typedef WbImageRef webots_api_WbImageRef;
typedef WbMotionRef webots_api_WbMotionRef;
typedef WbNodeRef webots_api_WbNodeRef;
typedef WbProtoRef webots_api_WbProtoRef;
typedef WbFieldRef webots_api_WbFieldRef;
typedef WbJointType webots_api_WbJointType;
typedef WbMutexRef webots_api_WbMutexRef;
typedef WbRobotMode webots_api_WbRobotMode;
typedef WbUserInputEvent webots_api_WbUserInputEvent;
typedef WbFieldType webots_api_WbFieldType;
typedef WbSimulationMode webots_api_WbSimulationMode;
typedef WbNodeType webots_api_WbNodeType;
typedef WbContactPoint webots_api_WbContactPoint;
typedef WbLidarPoint webots_api_WbLidarPoint;
typedef WbCameraRecognitionObject webots_api_WbCameraRecognitionObject;
typedef WbRadarTarget webots_api_WbRadarTarget;
typedef WbMouseState webots_api_WbMouseState;
typedef WbDistanceSensorType webots_api_WbDistanceSensorType;
typedef WbGpsCoordinateSystem webots_api_WbGpsCoordinateSystem;
typedef WbTouchSensorType webots_api_WbTouchSensorType;
typedef WbRadioMessage webots_api_WbRadioMessage;
typedef WbRadioEvent webots_api_WbRadioEvent;
typedef WbuCarType webots_api_WbuCarType;
typedef WbuCarEngineType webots_api_WbuCarEngineType;
typedef WbuCarWheelIndex webots_api_WbuCarWheelIndex;
typedef wbu_car_type webots_api_wbu_car_type;
typedef wbu_car_engine_type webots_api_wbu_car_engine_type;
typedef wbu_car_wheel_index webots_api_wbu_car_wheel_index;
typedef WbuDriverIndicatorState webots_api_WbuDriverIndicatorState;
typedef WbuDriverControlMode webots_api_WbuDriverControlMode;
typedef WbuDriverWiperMode webots_api_WbuDriverWiperMode;
typedef wbu_wipers_mode webots_api_wbu_wipers_mode;
typedef wbu_indicator_state webots_api_wbu_indicator_state;
typedef wbu_control_mode webots_api_wbu_control_mode;

/* the fields a controller reads in the records the API returns */
_Static_assert(offsetof(WbLidarPoint, x) < sizeof(WbLidarPoint), "WbLidarPoint.x");
_Static_assert(offsetof(WbLidarPoint, y) < sizeof(WbLidarPoint), "WbLidarPoint.y");
_Static_assert(offsetof(WbLidarPoint, z) < sizeof(WbLidarPoint), "WbLidarPoint.z");
_Static_assert(offsetof(WbLidarPoint, layer_id) < sizeof(WbLidarPoint), "WbLidarPoint.layer_id");
_Static_assert(offsetof(WbLidarPoint, time) < sizeof(WbLidarPoint), "WbLidarPoint.time");
_Static_assert(offsetof(WbRadarTarget, distance) < sizeof(WbRadarTarget), "WbRadarTarget.distance");
_Static_assert(offsetof(WbRadarTarget, received_power) < sizeof(WbRadarTarget), "WbRadarTarget.received_power");
_Static_assert(offsetof(WbRadarTarget, speed) < sizeof(WbRadarTarget), "WbRadarTarget.speed");
_Static_assert(offsetof(WbRadarTarget, azimuth) < sizeof(WbRadarTarget), "WbRadarTarget.azimuth");
_Static_assert(offsetof(WbMouseState, u) < sizeof(WbMouseState), "WbMouseState.u");
_Static_assert(offsetof(WbMouseState, v) < sizeof(WbMouseState), "WbMouseState.v");
_Static_assert(offsetof(WbMouseState, x) < sizeof(WbMouseState), "WbMouseState.x");
_Static_assert(offsetof(WbMouseState, y) < sizeof(WbMouseState), "WbMouseState.y");
_Static_assert(offsetof(WbMouseState, z) < sizeof(WbMouseState), "WbMouseState.z");
_Static_assert(offsetof(WbMouseState, left) < sizeof(WbMouseState), "WbMouseState.left");
_Static_assert(offsetof(WbMouseState, middle) < sizeof(WbMouseState), "WbMouseState.middle");
_Static_assert(offsetof(WbMouseState, right) < sizeof(WbMouseState), "WbMouseState.right");
_Static_assert(offsetof(WbContactPoint, point) < sizeof(WbContactPoint), "WbContactPoint.point");
_Static_assert(offsetof(WbContactPoint, node_id) < sizeof(WbContactPoint), "WbContactPoint.node_id");
_Static_assert(offsetof(WbCameraRecognitionObject, id) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.id");
_Static_assert(offsetof(WbCameraRecognitionObject, position) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.position");
_Static_assert(offsetof(WbCameraRecognitionObject, orientation) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.orientation");
_Static_assert(offsetof(WbCameraRecognitionObject, size) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.size");
_Static_assert(offsetof(WbCameraRecognitionObject, position_on_image) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.position_on_image");
_Static_assert(offsetof(WbCameraRecognitionObject, size_on_image) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.size_on_image");
_Static_assert(offsetof(WbCameraRecognitionObject, number_of_colors) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.number_of_colors");
_Static_assert(offsetof(WbCameraRecognitionObject, colors) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.colors");
_Static_assert(offsetof(WbCameraRecognitionObject, model) < sizeof(WbCameraRecognitionObject), "WbCameraRecognitionObject.model");

/* macros a controller uses: camera.h's and range_finder.h's pixel readers, robot_wwi.h's text sender,
 * utils/ansi_codes.h's escape sequences */
static inline int webots_api_macros(const unsigned char *image, const float *range) {
  wb_robot_wwi_send_text("text");
  return wb_camera_image_get_red(image, 2, 1, 0) + wb_camera_image_get_green(image, 2, 1, 0) +
         wb_camera_image_get_blue(image, 2, 1, 0) + wb_camera_image_get_gray(image, 2, 1, 0) +
         wb_camera_image_get_grey(image, 2, 1, 0) + (int)wb_range_finder_image_get_depth(range, 2, 1, 0);
}
static const char *const webots_api_ansi_codes[] = {
  ANSI_RESET,
  ANSI_BOLD,
  ANSI_UNDERLINE,
  ANSI_BLACK_BACKGROUND,
  ANSI_RED_BACKGROUND,
  ANSI_GREEN_BACKGROUND,
  ANSI_YELLOW_BACKGROUND,
  ANSI_BLUE_BACKGROUND,
  ANSI_MAGENTA_BACKGROUND,
  ANSI_CYAN_BACKGROUND,
  ANSI_WHITE_BACKGROUND,
  ANSI_BLACK_FOREGROUND,
  ANSI_RED_FOREGROUND,
  ANSI_GREEN_FOREGROUND,
  ANSI_YELLOW_FOREGROUND,
  ANSI_BLUE_FOREGROUND,
  ANSI_MAGENTA_FOREGROUND,
  ANSI_CYAN_FOREGROUND,
  ANSI_WHITE_FOREGROUND,
  ANSI_CLEAR_SCREEN,
};
