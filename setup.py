"""The optional C part: the lockstep's step path (sensorium/server/daemon/_steppath.c).

Built by ``pip install .`` when a C compiler and Python's headers are there (``optional=True``: a
failed build only warns, and the server uses its pure-Python step path, same behaviour, slower).
It links no library: it calls the libzmq that pyzmq loaded (sensorium/server/daemon/steppath.py).
Everything else is in pyproject.toml."""

from setuptools import Extension, setup

setup(ext_modules=[Extension("sensorium.server.daemon._steppath", ["sensorium/server/daemon/_steppath.c"],
                             extra_compile_args=["-O2", "-std=c11", "-Wall", "-Wextra"], optional=True)])
