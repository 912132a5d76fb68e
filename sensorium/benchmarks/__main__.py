"""``python -m sensorium.benchmarks`` = ``sensorium bench``."""

import argparse
import sys

from sensorium.cli.bench import add_arguments, main

parser = argparse.ArgumentParser(prog="python -m sensorium.benchmarks", description="Sensorium's benchmark suite")
add_arguments(parser)
sys.exit(main(parser.parse_args()))
