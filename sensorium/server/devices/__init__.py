"""Pure device models: lookup tables, noise streams, light, distance and lidar maths.

Each model is a function of (scene quantities, pose, parameters, random stream): no clock, no I/O,
no global state. Imports numpy and its own modules only.
"""
