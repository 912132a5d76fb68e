"""`python -m sensorium ...` = the `sensorium` command (works where console scripts are not on PATH)."""

import sys

from sensorium.cli import main

sys.exit(main())
