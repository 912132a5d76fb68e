"""Webots' ``Display`` class: drawing buffered and sent with the next step, the server rasterises
(see ``wb_display``); ``imageNew``/``imageCopy``/``imageLoad`` answer an image reference. As Webots'
Python class does, coordinates and sizes go through ``int()`` (a float such as ``width / 2`` is
truncated toward zero); the flat ``wb_display_*`` functions take integers only."""

from __future__ import annotations

from typing import Any

from sensorium.client import wb

from .device import Device


class Display(Device):
    RGB = 3
    RGBA = 4
    ARGB = 5
    BGRA = 6
    ABGR = 7

    def getWidth(self) -> int:
        return wb.wb_display_get_width(self._tag)

    def getHeight(self) -> int:
        return wb.wb_display_get_height(self._tag)

    @property
    def width(self) -> int:
        return self.getWidth()

    @property
    def height(self) -> int:
        return self.getHeight()

    def setColor(self, color: int) -> None:
        wb.wb_display_set_color(self._tag, color)

    def setAlpha(self, alpha: float) -> None:
        wb.wb_display_set_alpha(self._tag, alpha)

    def setOpacity(self, opacity: float) -> None:
        wb.wb_display_set_opacity(self._tag, opacity)

    def setFont(self, font: str, size: int, anti_aliasing: bool) -> None:
        wb.wb_display_set_font(self._tag, font, size, anti_aliasing)

    def attachCamera(self, camera: Any) -> None:
        wb.wb_display_attach_camera(self._tag, getattr(camera, "_tag", camera))

    def detachCamera(self) -> None:
        wb.wb_display_detach_camera(self._tag)

    def drawPixel(self, x: int, y: int) -> None:
        wb.wb_display_draw_pixel(self._tag, int(x), int(y))

    def drawLine(self, x1: int, y1: int, x2: int, y2: int) -> None:
        wb.wb_display_draw_line(self._tag, int(x1), int(y1), int(x2), int(y2))

    def drawRectangle(self, x: int, y: int, width: int, height: int) -> None:
        wb.wb_display_draw_rectangle(self._tag, int(x), int(y), int(width), int(height))

    def drawOval(self, cx: int, cy: int, a: int, b: int) -> None:
        wb.wb_display_draw_oval(self._tag, int(cx), int(cy), int(a), int(b))

    def drawPolygon(self, x: Any, y: Any) -> None:
        wb.wb_display_draw_polygon(self._tag, x, y)

    def drawText(self, text: str, x: int, y: int) -> None:
        wb.wb_display_draw_text(self._tag, text, int(x), int(y))

    def fillRectangle(self, x: int, y: int, width: int, height: int) -> None:
        wb.wb_display_fill_rectangle(self._tag, int(x), int(y), int(width), int(height))

    def fillOval(self, cx: int, cy: int, a: int, b: int) -> None:
        wb.wb_display_fill_oval(self._tag, int(cx), int(cy), int(a), int(b))

    def fillPolygon(self, x: Any, y: Any) -> None:
        wb.wb_display_fill_polygon(self._tag, x, y)

    def imageNew(self, data: Any, format: int, width: int | None = None, height: int | None = None) -> Any:
        return wb.wb_display_image_new(self._tag, None if width is None else int(width),
                                       None if height is None else int(height), data, format)

    def imageCopy(self, x: int, y: int, width: int, height: int) -> Any:
        return wb.wb_display_image_copy(self._tag, int(x), int(y), int(width), int(height))

    def imagePaste(self, image: Any, x: int, y: int, blend: bool = False) -> None:
        wb.wb_display_image_paste(self._tag, image, int(x), int(y), blend)

    def imageLoad(self, filename: str) -> Any:
        return wb.wb_display_image_load(self._tag, filename)

    def imageSave(self, image: Any, filename: str) -> None:
        wb.wb_display_image_save(self._tag, image, filename)

    def imageDelete(self, image: Any) -> None:
        wb.wb_display_image_delete(self._tag, image)

    # Webots' write-only properties
    color = property(fset=setColor)
    alpha = property(fset=setAlpha)
    opacity = property(fset=setOpacity)
