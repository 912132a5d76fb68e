"""Webots' image devices: ``wb_range_finder_*`` and ``wb_camera_*``, readings cached per step.

The images arrive with the step reply (PROTOCOL.md §3.6) as raw bytes; constants (size, field of
view, ranges) come from the ``attach`` description. As in Webots' library, reading the image of a
disabled device prints Webots' error and still returns the last image (zeros before the first).
"""

from __future__ import annotations

import math
import sys
from typing import Any

from sensorium.client import arrays, images
from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import DeviceState, c_string, current, sensor_enable, sensor_period, sensor_reading

RANGE_FINDER = "RangeFinder"

__all__ = ["CAMERA", "camera_bytes", "wb_camera_enable", "wb_camera_disable", "wb_camera_get_sampling_period",
           "wb_camera_get_image", "wb_camera_image_get_red", "wb_camera_image_get_green", "wb_camera_image_get_blue",
           "wb_camera_image_get_gray", "wb_camera_image_get_grey", "wb_camera_get_width", "wb_camera_get_height",
           "wb_camera_get_fov", "wb_camera_get_min_fov", "wb_camera_get_max_fov", "wb_camera_set_fov",
           "wb_camera_get_exposure", "wb_camera_set_exposure", "wb_camera_get_focal_length",
           "wb_camera_get_focal_distance", "wb_camera_get_min_focal_distance", "wb_camera_get_max_focal_distance",
           "wb_camera_set_focal_distance", "wb_camera_get_near", "wb_camera_save_image", "wb_camera_has_recognition",
           "wb_camera_recognition_enable", "wb_camera_recognition_disable", "wb_camera_recognition_get_sampling_period",
           "wb_camera_recognition_get_number_of_objects", "wb_camera_recognition_get_objects",
           "wb_camera_recognition_has_segmentation", "wb_camera_recognition_enable_segmentation",
           "wb_camera_recognition_disable_segmentation", "wb_camera_recognition_is_segmentation_enabled",
           "wb_camera_recognition_get_segmentation_image", "wb_camera_recognition_save_segmentation_image",
           "recognition_objects", "segmentation_bytes",
           "RANGE_FINDER", "wb_range_finder_enable", "wb_range_finder_disable", "wb_range_finder_get_sampling_period",
           "wb_range_finder_get_range_image", "wb_range_finder_image_get_depth", "wb_range_finder_get_width",
           "wb_range_finder_get_height", "wb_range_finder_get_fov", "wb_range_finder_get_min_range",
           "wb_range_finder_get_max_range", "wb_range_finder_save_image", "range_finder_bytes"]


def _desc(dev: DeviceState, key: str, func: str) -> Any:
    try:
        return dev.desc[key]
    except KeyError:
        raise SensoriumError(ErrorCode.BAD_REPLY, f"{func}(): the server described {dev.name!r} without {key!r}") from None


# ---------------------------------------------------------------------- range finder

def _rf(tag: int, func: str) -> DeviceState:
    return current().device(tag, RANGE_FINDER, func)


def wb_range_finder_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, RANGE_FINDER, sampling_period, "wb_range_finder_enable")


def wb_range_finder_disable(tag: int) -> None:
    sensor_enable(tag, RANGE_FINDER, 0, "wb_range_finder_disable")


def wb_range_finder_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, RANGE_FINDER, "wb_range_finder_get_sampling_period")


def wb_range_finder_get_width(tag: int) -> int:
    return int(_desc(_rf(tag, "wb_range_finder_get_width"), "width", "wb_range_finder_get_width"))


def wb_range_finder_get_height(tag: int) -> int:
    return int(_desc(_rf(tag, "wb_range_finder_get_height"), "height", "wb_range_finder_get_height"))


def wb_range_finder_get_fov(tag: int) -> float:
    return float(_desc(_rf(tag, "wb_range_finder_get_fov"), "fov", "wb_range_finder_get_fov"))


def wb_range_finder_get_min_range(tag: int) -> float:
    return float(_desc(_rf(tag, "wb_range_finder_get_min_range"), "minRange", "wb_range_finder_get_min_range"))


def wb_range_finder_get_max_range(tag: int) -> float:
    return float(_desc(_rf(tag, "wb_range_finder_get_max_range"), "maxRange", "wb_range_finder_get_max_range"))


def range_finder_bytes(tag: int, func: str = "wb_range_finder_get_range_image") -> bytes:
    """The raw little-endian float32 image (``height`` rows of ``width``), zeros before the first
    image; a disabled device prints Webots' error once and still returns it (Webots)."""
    dev = sensor_reading(tag, RANGE_FINDER, func, "wb_range_finder_enable")
    if dev.range_bytes is None:
        return bytes(4 * int(dev.desc.get("width", 0)) * int(dev.desc.get("height", 0)))
    return dev.range_bytes


def wb_range_finder_get_range_image(tag: int) -> Any:
    """The latest range image, ``height × width`` float32 values row by row (top row first, left to
    right): a read-only numpy array, or ``array('f')`` without numpy; ``+inf`` where nothing valid
    is seen (Webots)."""
    buf = range_finder_bytes(tag)
    dev = current().devices[tag - 1]
    if dev._range is None:           # decoded once per new image (the step reply resets it)
        dev._range = arrays.float32s(buf)
    return dev._range


def wb_range_finder_image_get_depth(image: Any, width: int, x: int, y: int) -> float:
    """Webots' macro: ``image[y·width + x]``."""
    return float(image[y * width + x])


def depth_scale(buf: bytes, near: float, max_range: float) -> list[float]:
    """Webots' range-finder picture values: ``clamp((v − near)/maxRange, 0, 1)`` (``near`` = the
    device's minRange, as Webots' library has it)."""
    out = []
    for v in arrays.float32_list(buf):
        g = (v - near) / max_range
        out.append(1.0 if not g <= 1.0 else (0.0 if g < 0.0 else g))     # NaN and inf: 1 (as the C comparisons)
    return out


def depth_gray(buf: bytes, near: float, max_range: float) -> bytes:
    """Webots' range-finder PNG/JPEG: grey ``(unsigned char)(255·clamp((v − near)/maxRange, 0, 1))``,
    as RGB bytes."""
    return b"".join(bytes((int(g * 255.0),)) * 3 for g in depth_scale(buf, near, max_range))


def wb_range_finder_save_image(tag: int, filename: str, quality: int) -> int:
    """The latest range image in Webots' scale (``(depth − minRange)/maxRange`` clamped to [0, 1]):
    a grey PNG (or JPEG with Pillow), or Webots' float grey Radiance ``.hdr``; ``.tif``/``.tiff``
    answer Webots' "not supported anymore" line; 0 or -1."""
    filename = c_string(filename)
    func = "wb_range_finder_save_image"
    dev = _rf(tag, func)
    buf = range_finder_bytes(tag, func)
    w, h = int(dev.desc.get("width", 0)), int(dev.desc.get("height", 0))
    near, max_range = float(dev.desc.get("minRange", 0.0)), float(dev.desc.get("maxRange", math.inf))
    lower = str(filename).lower() if filename else ""
    if lower.endswith((".hdr", ".tif", ".tiff")):
        if not images.check_save(func, filename, quality):
            return -1
        if not lower.endswith(".hdr"):
            print(f"Error: {func}(): .tiff image not supported anymore, use .hdr instead.", file=sys.stderr)
            return -1
        return images.write_file(func, filename, images.hdr_bytes(depth_scale(buf, near, max_range), w, h))
    return images.save_rgb(func, filename, quality, depth_gray(buf, near, max_range), w, h)


# ---------------------------------------------------------------------- camera

CAMERA = "Camera"


def _cam(tag: int, func: str) -> DeviceState:
    return current().device(tag, CAMERA, func)


def wb_camera_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, CAMERA, sampling_period, "wb_camera_enable")


def wb_camera_disable(tag: int) -> None:
    sensor_enable(tag, CAMERA, 0, "wb_camera_disable")


def wb_camera_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, CAMERA, "wb_camera_get_sampling_period")


def _black(dev: DeviceState) -> bytes:
    """Webots' image before the first one: every pixel 0xFF000000 (BGRA 0, 0, 0, 255)."""
    return b"\0\0\0\xff" * (int(dev.desc.get("width", 0)) * int(dev.desc.get("height", 0)))


def camera_bytes(tag: int, func: str = "wb_camera_get_image") -> bytes | None:
    """The latest image, BGRA bytes row by row (top row first); ``None`` with Webots' error while the
    camera is disabled (Webots returns NULL)."""
    r = current()
    dev = _cam(tag, func)
    if dev.sampling_period <= 0:
        r.warn_disabled(dev, func, "wb_camera_enable")
        return None
    img = dev.camera.get("image")
    return _black(dev) if img is None else bytes(img)


def wb_camera_get_image(tag: int) -> bytes | None:
    """Webots' BGRA image (4 bytes a pixel, ``width × height``, top row first) as ``bytes``;
    ``None`` while the camera is disabled."""
    return camera_bytes(tag)


def _channel(image: Any, width: int, x: int, y: int, c: int) -> int:
    return int(image[4 * (y * width + x) + c])


def wb_camera_image_get_red(image: Any, width: int, x: int, y: int) -> int:
    return _channel(image, width, x, y, 2)


def wb_camera_image_get_green(image: Any, width: int, x: int, y: int) -> int:
    return _channel(image, width, x, y, 1)


def wb_camera_image_get_blue(image: Any, width: int, x: int, y: int) -> int:
    return _channel(image, width, x, y, 0)


def wb_camera_image_get_gray(image: Any, width: int, x: int, y: int) -> int:
    """The integer mean of red, green and blue (Webots' C macro)."""
    i = 4 * (y * width + x)
    return (int(image[i]) + int(image[i + 1]) + int(image[i + 2])) // 3


wb_camera_image_get_grey = wb_camera_image_get_gray


def _cam_const(tag: int, key: str, func: str) -> Any:
    return _desc(_cam(tag, func), key, func)


def wb_camera_get_width(tag: int) -> int:
    return int(_cam_const(tag, "width", "wb_camera_get_width"))


def wb_camera_get_height(tag: int) -> int:
    return int(_cam_const(tag, "height", "wb_camera_get_height"))


def wb_camera_get_fov(tag: int) -> float:
    return float(_cam_const(tag, "fov", "wb_camera_get_fov"))


def _zoom_range(dev: DeviceState, func: str) -> tuple[float, float]:
    """The camera's Zoom range (Webots' min = max = fov without a Zoom node)."""
    fov = float(_desc(dev, "fov", func))
    return float(dev.desc.get("min_fov", fov)), float(dev.desc.get("max_fov", fov))


def wb_camera_get_min_fov(tag: int) -> float:
    func = "wb_camera_get_min_fov"
    return _zoom_range(_cam(tag, func), func)[0]


def wb_camera_get_max_fov(tag: int) -> float:
    func = "wb_camera_get_max_fov"
    return _zoom_range(_cam(tag, func), func)[1]


def wb_camera_set_fov(tag: int, fov: float) -> None:
    """Webots' checks (the projection's bound, then the Zoom's range, each its error line); a new field
    of view is the server's for the next images, and getFov answers it at once (as Webots' library)."""
    func = "wb_camera_set_fov"
    dev = _cam(tag, func)
    cur = float(_desc(dev, "fov", func))
    low, high = _zoom_range(dev, func)
    planar = dev.desc.get("projection", "planar") == "planar"
    hi = math.pi if planar else 2.0 * math.pi
    if isinstance(fov, bool) or not isinstance(fov, (int, float)) or not 0.0 <= fov <= hi:
        print(f"Error: {func}() called with 'fov' argument outside of the [0, {'pi' if planar else '2.0*pi'}] range.",
              file=sys.stderr)
    elif not low <= fov <= high:
        print(f"Error: {func}() out of zoom range [{low:f}, {high:f}].", file=sys.stderr)
    elif fov != cur:
        current().device_set(dev, "set_fov", float(fov), func)
        dev.desc["fov"] = float(fov)


def wb_camera_get_exposure(tag: int) -> float:
    return float(_cam_const(tag, "exposure", "wb_camera_get_exposure"))


def wb_camera_set_exposure(tag: int, exposure: float) -> None:
    func = "wb_camera_set_exposure"
    r = current()
    dev = _cam(tag, func)
    if isinstance(exposure, bool) or not isinstance(exposure, (int, float)) or not math.isfinite(exposure):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): 'exposure' must be a finite number, got {exposure!r}")
    if exposure < 0:
        print(f"Error: 'exposure' argument of {func}() can't be negative.", file=sys.stderr)
        return
    r.device_set(dev, "set_exposure", float(exposure), func)
    dev.desc["exposure"] = float(exposure)


def _focus(tag: int, key: str, func: str) -> float:
    """The camera's Focus value (0 without a Focus node, as in Webots)."""
    return float(_cam(tag, func).desc.get(key, 0.0))


def wb_camera_get_focal_length(tag: int) -> float:
    return _focus(tag, "focal_length", "wb_camera_get_focal_length")


def wb_camera_get_focal_distance(tag: int) -> float:
    return _focus(tag, "focal_distance", "wb_camera_get_focal_distance")


def wb_camera_get_min_focal_distance(tag: int) -> float:
    return _focus(tag, "min_focal_distance", "wb_camera_get_min_focal_distance")


def wb_camera_get_max_focal_distance(tag: int) -> float:
    return _focus(tag, "max_focal_distance", "wb_camera_get_max_focal_distance")


def wb_camera_set_focal_distance(tag: int, focal_distance: float) -> None:
    """Webots' checks (planar, then the Focus range, each its error line); the distance is kept here, as
    Webots' library keeps it for getFocalDistance: the image shows no depth of field."""
    func = "wb_camera_set_focal_distance"
    dev = _cam(tag, func)
    low, high = float(dev.desc.get("min_focal_distance", 0.0)), float(dev.desc.get("max_focal_distance", 0.0))
    if dev.desc.get("projection", "planar") != "planar":
        print(f"Error: {func}() can only be called on a planar camera.", file=sys.stderr)
    elif isinstance(focal_distance, bool) or not isinstance(focal_distance, (int, float)) \
            or not low <= focal_distance <= high:
        print(f"Error: {func}() out of focus range [{low:f}, {high:f}].", file=sys.stderr)
    else:
        dev.desc["focal_distance"] = float(focal_distance)


def wb_camera_get_near(tag: int) -> float:
    return float(_cam_const(tag, "near", "wb_camera_get_near"))


def save_bgra(func: str, filename: str, quality: int, bgra: bytes | None, width: int, height: int) -> int:
    if not filename:
        print(f"Error: {func}() called with NULL or empty 'filename' argument.", file=sys.stderr)
        return -1
    lower = str(filename).lower()
    if not lower.endswith((".png", ".jpg", ".jpeg")):
        print(f"Error: {func}() called with unsupported image format (should be PNG or JPEG).", file=sys.stderr)
        return -1
    if bgra is None:
        return -1
    return images.save_rgb(func, filename, quality if lower.endswith((".jpg", ".jpeg")) else 100,
                           images.bgra_to_rgb(bgra), width, height)


def wb_camera_save_image(tag: int, filename: str, quality: int) -> int:
    """The latest image as PNG (or JPEG with Pillow); 0, or -1 (Webots)."""
    filename = c_string(filename)
    func = "wb_camera_save_image"
    dev = _cam(tag, func)
    img = dev.camera.get("image")
    return save_bgra(func, filename, quality, _black(dev) if img is None else bytes(img),
                     int(dev.desc.get("width", 0)), int(dev.desc.get("height", 0)))


# ---------------------------------------------------------------------- camera recognition

def _rec(tag: int, func: str, need_enabled: bool = False) -> DeviceState | None:
    """The camera, or None with Webots' error when it has no Recognition node (or, with
    ``need_enabled``, when the recognition is disabled)."""
    dev = _cam(tag, func)
    if not dev.desc.get("has_recognition", False):
        print(f"Error: {func}() called on a Camera without Recognition node.", file=sys.stderr)
        return None
    if need_enabled and int(dev.camera.get("recognition_period", dev.desc.get("recognition_sampling_period", 0))) <= 0:
        print(f"Error: {func}() called for a disabled device! Please use: wb_camera_recognition_enable().", file=sys.stderr)
        return None
    return dev


def wb_camera_has_recognition(tag: int) -> bool:
    return bool(_cam(tag, "wb_camera_has_recognition").desc.get("has_recognition", False))


def wb_camera_recognition_enable(tag: int, sampling_period: int) -> None:
    func = "wb_camera_recognition_enable"
    r = current()
    dev = _rec(tag, func)
    if dev is None:
        return
    if isinstance(sampling_period, bool) or not isinstance(sampling_period, int) or sampling_period < 0:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): sampling period must be an integer >= 0, got {sampling_period!r}")
    r.device_set(dev, "recognition_enable", sampling_period, func)
    dev.camera["recognition_period"] = sampling_period
    if sampling_period == 0:
        dev.camera["segmentation_enabled"] = False


def wb_camera_recognition_disable(tag: int) -> None:
    if _rec(tag, "wb_camera_recognition_disable") is not None:
        wb_camera_recognition_enable(tag, 0)


def wb_camera_recognition_get_sampling_period(tag: int) -> int:
    dev = _rec(tag, "wb_camera_recognition_get_sampling_period")
    return 0 if dev is None else int(dev.camera.get("recognition_period", dev.desc.get("recognition_sampling_period", 0)))


def recognition_objects(tag: int, func: str = "wb_camera_recognition_get_objects") -> list[dict] | None:
    """The latest recognised objects as maps (PROTOCOL.md §3.6); None with Webots' error while the
    recognition is disabled or the camera has none."""
    dev = _rec(tag, func, need_enabled=True)
    if dev is None:
        return None
    return list(dev.camera.get("recognition") or [])


def wb_camera_recognition_get_number_of_objects(tag: int) -> int:
    objs = recognition_objects(tag, "wb_camera_recognition_get_number_of_objects")
    return 0 if objs is None else len(objs)


def wb_camera_recognition_get_objects(tag: int) -> list[dict] | None:
    return recognition_objects(tag)


def wb_camera_recognition_has_segmentation(tag: int) -> bool:
    return bool(_cam(tag, "wb_camera_recognition_has_segmentation").desc.get("has_segmentation", False))


def _segmentation(tag: int, on: bool, func: str) -> None:
    r = current()
    dev = _rec(tag, func)
    if dev is None:
        return
    if not dev.desc.get("has_segmentation", False):
        print(f"Error: {func}() called on a Camera whose Recognition node has no segmentation.", file=sys.stderr)
        return
    if on and int(dev.camera.get("recognition_period", 0)) <= 0:
        print(f"Error: {func}() called while the recognition is disabled! Please use: wb_camera_recognition_enable().",
              file=sys.stderr)
        return
    r.device_set(dev, "enable_segmentation", bool(on), func)
    dev.camera["segmentation_enabled"] = bool(on)


def wb_camera_recognition_enable_segmentation(tag: int) -> None:
    _segmentation(tag, True, "wb_camera_recognition_enable_segmentation")


def wb_camera_recognition_disable_segmentation(tag: int) -> None:
    _segmentation(tag, False, "wb_camera_recognition_disable_segmentation")


def wb_camera_recognition_is_segmentation_enabled(tag: int) -> bool:
    dev = _cam(tag, "wb_camera_recognition_is_segmentation_enabled")
    return bool(dev.camera.get("segmentation_enabled", False))


def segmentation_bytes(tag: int, func: str = "wb_camera_recognition_get_segmentation_image") -> bytes | None:
    """The latest segmentation image (BGRA like the camera's); None with Webots' error unless the
    segmentation is enabled."""
    dev = _cam(tag, func)
    if not dev.camera.get("segmentation_enabled", False):
        print(f"Error: {func}() called while the segmentation is disabled! Please use: "
              "wb_camera_recognition_enable_segmentation().", file=sys.stderr)
        return None
    img = dev.camera.get("segmentation_image")
    return _black(dev) if img is None else bytes(img)


def wb_camera_recognition_get_segmentation_image(tag: int) -> bytes | None:
    return segmentation_bytes(tag)


def wb_camera_recognition_save_segmentation_image(tag: int, filename: str, quality: int) -> int:
    filename = c_string(filename)
    func = "wb_camera_recognition_save_segmentation_image"
    dev = _cam(tag, func)
    return save_bgra(func, filename, quality, segmentation_bytes(tag, func), int(dev.desc.get("width", 0)),
                     int(dev.desc.get("height", 0)))
