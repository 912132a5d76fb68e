"""The simulation: integer clock, the schedule of due devices, batched ray requests, motion.

:class:`~sensorium.server.sim.simulation.Simulation` is the in-process API. Imports world,
raycast and devices; knows nothing of sockets, topics or files beyond loading a world.
"""
