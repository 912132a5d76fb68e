"""World files → validated model: loading (YAML/JSON, Webots ``.wbt`` via :mod:`.wbt`), the limits
on what a world may ask for (:mod:`.limits`), geometry (poses, shapes, tessellation), meshes.

Owns everything about *what the world is* before anything moves or is cast against. Imports only
:mod:`sensorium.schemas` (and numpy/trimesh/yaml); every other server stage builds on it. The scene
built from a validated world (ray-engine bodies, shape metadata) is :mod:`sensorium.server.sim.scene`.
"""
