"""Sensorium: a headless stepping sensor simulator with Webots device semantics.

The code lives in the top-level folders ``server/``, ``client/`` and ``schemas/`` of the
repository, installed as ``sensorium.server``, ``sensorium.client`` and ``sensorium.schemas``.
This package stays import-light: the client must work with pyzmq + msgpack alone.
"""

__version__ = "0.1.0"
