"""The simulation server, one sub-package per stage of the data flow.

world → raycast → devices → sim → daemon → recording. Arrows point one way: a stage imports only
the stages before it and :mod:`sensorium.schemas`; nothing here imports :mod:`sensorium.cli` or
:mod:`sensorium.client`.
"""
