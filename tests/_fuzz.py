"""How many random cases a long randomized test draws: a share in the default run, all of them in the
slow stage (CI's ``pytest -m slow``, or ``SENSORIUM_SLOW=1``), where the share's cases are drawn again
with the rest. The default run keeps every path of the test; the slow stage keeps its full search."""

from __future__ import annotations

import pytest


def example_counts(full: int, share: int = 4) -> list:
    """The values of a test's ``examples`` parameter (a Hypothesis test's ``max_examples``, or a seeded
    loop's length): ``full // share`` (at least 10) in the default run, ``full`` as a case marked slow."""
    return [pytest.param(max(full // share, 10), id="few"),
            pytest.param(full, id="all", marks=pytest.mark.slow)]


def seeds(n: int, fast: int = 1) -> list:
    """Seeds 0 .. n-1 of a test's ``seed`` parameter: the first ``fast`` in the default run, the others
    marked slow."""
    return [pytest.param(s, marks=pytest.mark.slow) if s >= fast else s for s in range(n)]
