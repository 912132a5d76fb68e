"""Sensorium: a headless stepping sensor simulator with Webots device semantics.

Import names match folders: ``sensorium/server`` is :mod:`sensorium.server`, and so on (see
ARCHITECTURE.md). This package stays import-light: the client must work with pyzmq + msgpack alone.
"""

__version__ = "0.1.0"
