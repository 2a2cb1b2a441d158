"""Hypothesis profiles and shared fixtures of the whole test suite (see docs/robustness.md).

``ci`` (the default): derandomised, so a CI run is repeatable, no deadline
(timings on a loaded 2-core machine are noise); the fuzz suite
(``tests/test_fuzz*.py``) runs its base example counts, >= 10,000 examples in
total in a few minutes.

``local`` (``HYPOTHESIS_PROFILE=local python -m pytest tests/test_fuzz.py``):
random seeds and ten times the fuzz example counts (>= 100,000), for a long run
before a release; failures are stored in ``.hypothesis/`` and replayed first.

Tests that set their own ``max_examples`` keep it under both profiles; the fuzz
tests scale theirs with :data:`FUZZ_SCALE` (read from the same variable).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "ci")
# Multiplier of the fuzz tests' example counts; test_fuzz*.py read the same variable.
FUZZ_SCALE = 10 if PROFILE == "local" else 1

settings.register_profile(
    "ci",
    deadline=None,
    derandomize=True,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "local",
    deadline=None,
    derandomize=False,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(PROFILE if PROFILE in ("ci", "local") else "ci")


# ------------------------------------------------------------------ shared designs
ROOT = Path(__file__).resolve().parents[1]

#: A small ruled design (nine generators between a B-spline and a polyline, six rows): quick to
#: build, with every part of the pipeline (curves, rulings, the §4.3 mesher) in it.
SMALL_DESIGN = """\
name = "small"

[curves.c1]
type = "bspline"
degree = 3
points = [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]

[curves.c2]
type = "polyline"
points = [[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]]

[rulings]
between = ["c1", "c2"]
distribution = "parameter"
count = 9

[mesh]
method = "pq"
rows = 6
"""


@pytest.fixture(scope="session")
def examples_dir() -> Path:
    """The repository's examples/ (the bundled example designs)."""
    return ROOT / "examples"


@pytest.fixture(scope="session")
def skew_path(examples_dir: Path) -> Path:
    """examples/skew.toml: the README's design."""
    return examples_dir / "skew.toml"


@pytest.fixture
def small_design() -> str:
    """The text of :data:`SMALL_DESIGN`."""
    return SMALL_DESIGN
