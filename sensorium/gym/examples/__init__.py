"""Runnable examples: ``python -m sensorium.gym.examples.random_policy``."""
