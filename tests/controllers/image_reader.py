"""The twin of tests/c/image_reader.c: the same lines from the Python client."""

import struct
import sys

from sensorium.client import wb


def bits(v: float) -> str:
    return f"{struct.unpack('<Q', struct.pack('<d', v))[0]:016x}"


wb.wb_robot_init()
name, steps = sys.argv[1], int(sys.argv[2])
tag = wb.wb_robot_get_device(name)
step = int(wb.wb_robot_get_basic_time_step())
camera = wb.wb_device_get_type_name(tag) == "Camera"
if camera:
    print(f"# null_before {int(wb.wb_camera_get_image(tag) is None)}")
    wb.wb_camera_enable(tag, step)
    if wb.wb_camera_has_recognition(tag):
        wb.wb_camera_recognition_enable(tag, step)
        wb.wb_camera_recognition_enable_segmentation(tag)
    w, h = wb.wb_camera_get_width(tag), wb.wb_camera_get_height(tag)
else:
    wb.wb_range_finder_enable(tag, step)
    w, h = wb.wb_range_finder_get_width(tag), wb.wb_range_finder_get_height(tag)
for _ in range(steps):
    status = wb.wb_robot_step(step)
    data = wb.camera_bytes(tag) if camera else wb.range_finder_bytes(tag)
    line = f"{round(wb.wb_robot_get_time() * 1000)} {status} {name}={data.hex()}"
    if camera and wb.wb_camera_has_recognition(tag):
        objs = wb.wb_camera_recognition_get_objects(tag)
        line += f" seg={wb.wb_camera_recognition_get_segmentation_image(tag).hex()} objects={len(objs)}"
        for o in objs:
            line += f" [{o['id']} {o['model']}"
            for key, v in (("p0", o["position"][0]), ("p1", o["position"][1]), ("p2", o["position"][2]),
                           ("a", o["orientation"][3]), ("s0", o["size"][0]), ("s1", o["size"][1])):
                line += f" {key}={bits(v)}"
            line += " " + " ".join(map(str, [*o["position_on_image"], *o["size_on_image"], len(o["colors"]) // 3]))
            line += "".join(f" c={bits(c)}" for c in o["colors"]) + "]"
    print(line)
    if status == -1:
        break
if camera:
    img = wb.wb_camera_get_image(tag)
    px = [f(img, w, w - 1, h - 1) for f in (wb.wb_camera_image_get_red, wb.wb_camera_image_get_green,
                                             wb.wb_camera_image_get_blue, wb.wb_camera_image_get_gray)]
    print(f"# info {w} {h} {wb.wb_camera_get_fov(tag):.17g} {wb.wb_camera_get_near(tag):.17g} "
          f"{wb.wb_camera_get_exposure(tag):.17g} {' '.join(map(str, px))}")
    wb.wb_camera_set_exposure(tag, 2.0)
    print(f"# exposure {wb.wb_camera_get_exposure(tag):.17g}")
    print(f"# save {wb.wb_camera_save_image(tag, '/nonexistent-dir/x.png', 100)}")
else:
    print(f"# info {w} {h} {wb.wb_range_finder_get_fov(tag):.17g} {wb.wb_range_finder_get_min_range(tag):.17g} "
          f"{wb.wb_range_finder_get_max_range(tag):.17g}")
    print(f"# save {wb.wb_range_finder_save_image(tag, '/nonexistent-dir/x.png', 100)}")
    if len(sys.argv) > 3:                  # a directory: Webots' float grey .hdr, and its refused .tiff
        print(f"# hdr {wb.wb_range_finder_save_image(tag, sys.argv[3] + '/depth.hdr', 100)}")
        print(f"# tiff {wb.wb_range_finder_save_image(tag, sys.argv[3] + '/depth.tiff', 100)}")
wb.wb_robot_cleanup()
