"""Webots' ``controller.wb`` module is its ctypes handle on its C library (``wb.wb_robot_step(...)``
through ``ctypes``). Sensorium's Python client does not go through a C library, so a controller
importing it stops here with one line instead of a traceback (README "Webots API")."""

raise SystemExit("Error: controller.wb (Webots' ctypes handle on its C library) has no counterpart in Sensorium's "
                 "Python client: use the classes (from controller import Robot, ...), or Sensorium's libController "
                 "from C.")
