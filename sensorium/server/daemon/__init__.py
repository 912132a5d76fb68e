"""The daemon: services (sans-IO core), lockstep, topics, transport and the serve loop.

The core (:mod:`.services`, :mod:`.lockstep`, :mod:`.topics`) takes frames in and gives replies
and messages out with no socket or clock inside; :mod:`.transport` is the only server module that
imports zmq. Imports sim and schemas.
"""
