"""Hypothesis profiles for the whole test suite (see docs/robustness.md).

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
