"""Sensorium's client library: pyzmq + msgpack only (numpy used when installed, never required).

* :mod:`~sensorium.client.connection` — controller URLs, requests/replies, heartbeats (the only zmq module)
* :mod:`~sensorium.client.wb` — Webots' C API (``wb_*`` over device tags), readings cached per step
* ``webots/controller`` — Webots' Python classes, for ``from controller import Robot``
* :mod:`~sensorium.client.topics` — subscribe to topics from any process
* :mod:`~sensorium.cli.client` — ``sensorium controller``; ``sensorium.cli.topics`` — ``echo``, ``hz``, ``topics``
"""
