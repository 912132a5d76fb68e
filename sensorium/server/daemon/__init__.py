"""The daemon: services (sans-IO core), lockstep, topics, transport and the serve loop.

The core (:mod:`.services`, :mod:`.lockstep`, :mod:`.topics`) takes frames in and gives replies
and messages out with no socket or clock inside; :mod:`.transport` is the only daemon module that
imports zmq; :mod:`.serve` builds world → simulation → core → transport (``sensorium serve``).
Imports sim, world and schemas; never recording (a recorder is handed to ``Topics.set_recorder``
by whoever builds the server) and never cli.
"""
