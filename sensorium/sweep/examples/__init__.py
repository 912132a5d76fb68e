"""Example sweep specs (``ir_noise.yaml``)."""
