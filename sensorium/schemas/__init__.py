"""The contract: world-file model, message and service definitions, wire framing, JSON Schema
export. No I/O and no server imports; the client keeps its own copy of the error codes (a test
keeps the two equal).
"""
