"""The simulation: integer clock, the schedule of due devices, batched ray requests, motion.

:class:`~sensorium.server.sim.simulation.Simulation` is the in-process API. :mod:`.scene` turns a
validated world into ray-engine bodies and owns the engine; :mod:`.sensors`/:mod:`.batches` ask it
for the rays of every due device and hand the hits to the pure models of
:mod:`sensorium.server.devices`; :mod:`.motion` drives wheels, :mod:`.contact` keeps robots out of
solids (kinematic). Imports world, raycast, devices and schemas; knows nothing of
sockets, topics or files beyond loading a world.
"""
