"""The twin of tests/c/image_reader.c: the same lines from the Python client."""

import sys

from sensorium.client import wb

wb.wb_robot_init()
name, steps = sys.argv[1], int(sys.argv[2])
tag = wb.wb_robot_get_device(name)
step = int(wb.wb_robot_get_basic_time_step())
wb.wb_range_finder_enable(tag, step)
w, h = wb.wb_range_finder_get_width(tag), wb.wb_range_finder_get_height(tag)
for _ in range(steps):
    status = wb.wb_robot_step(step)
    print(f"{round(wb.wb_robot_get_time() * 1000)} {status} {name}={wb.range_finder_bytes(tag).hex()}")
    if status == -1:
        break
print(f"# info {w} {h} {wb.wb_range_finder_get_fov(tag):.17g} {wb.wb_range_finder_get_min_range(tag):.17g} "
      f"{wb.wb_range_finder_get_max_range(tag):.17g}")
print(f"# save {wb.wb_range_finder_save_image(tag, '/nonexistent-dir/x.png', 100)}")
wb.wb_robot_cleanup()
