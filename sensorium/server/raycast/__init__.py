"""The ray engine: the only package that imports embreex (in :mod:`.tiers`).

Casts batches of rays against a scene's static solids (Embree tiers) and moving bodies, in FAST
(float32 Embree) or EXACT (float64 refinement) precision. Imports :mod:`sensorium.server.world`
only; devices and the simulation call :mod:`.engine`'s public API. One module per job: see
:mod:`.engine`'s docstring.
"""
