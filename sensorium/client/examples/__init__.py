"""Example Webots-style controllers (run with `sensorium controller`)."""
