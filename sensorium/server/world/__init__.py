"""World files → validated model → scene: loading, geometry (poses, shapes), meshes.

Owns everything about *what the world is* before anything moves. Imports only
:mod:`sensorium.schemas` (and numpy/trimesh); every other server stage builds on it.
"""
