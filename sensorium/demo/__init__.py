"""The demo: a server, two Webots-style controller processes and a recording, end to end.

``sensorium demo`` is a thin shell over :func:`run_demo`:

* :mod:`.runner`  starts ``sensorium serve`` (fast mode, ``--until``, ``--record``) and the two example
  controllers (``client/examples``) as separate processes, shows progress, and collects exit codes;
* :mod:`.summary` reads the recording back: paths, distances, areas visited, the follower's
  distance to the lamp over time;
* :mod:`.picture` draws the top-down picture (matplotlib).

May import the server (world loading, recordings) and the client; nothing imports it but the CLI.
"""

from sensorium.demo.runner import CONTROLLERS, DemoError, DemoResult, check_demo_world, run_demo

__all__ = ["CONTROLLERS", "DemoError", "DemoResult", "check_demo_world", "run_demo"]
