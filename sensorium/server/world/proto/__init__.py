"""Webots PROTOs, read like Webots' reference manual (the PROTO chapter, "Procedural PROTO Nodes",
EXTERNPROTO): **resolve** (:mod:`.resolve`: where a url's file is on this machine, never
downloading), **parse** (:mod:`.interface`: header, interface fields, types, accepted values),
**instantiate** (:mod:`.instantiate`: field values, IS at any depth, slots, DEF/USE scopes, cycles,
bounds) and **template** (:mod:`.template`: JavaScript bodies in a sandboxed QuickJS, with our own
``modules/``). Errors are :class:`ProtoError`, a ``WbtSyntaxError``: one line, file:line:col.

``expand(wbt, search)`` turns a parsed world into base nodes; ``resolve_url`` and ``asset_roots``
serve asset urls (meshes, textures) the same way.
"""

from sensorium.server.world.proto.errors import ProtoError
from sensorium.server.world.proto.instantiate import Expansion, ProtoUse, expand, interface_levels, protos_used
from sensorium.server.world.proto.resolve import ProtoSearch, asset_roots, resolve_url

__all__ = ["ProtoError", "ProtoSearch", "Expansion", "ProtoUse", "expand", "interface_levels", "protos_used", "resolve_url", "asset_roots"]
