"""Seeing a simulation in Foxglove: a live WebSocket server (``bridge``) and the world as a 3D
scene with transforms (``scene``). Needs the ``foxglove`` extra (foxglove-sdk, rosbags)."""
