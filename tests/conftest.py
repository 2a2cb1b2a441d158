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

import importlib.abc
import importlib.util
import os
import sys
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


# ------------------------------------------------------------------ shared helpers
ROOT = Path(__file__).resolve().parents[1]
TESTS = Path(__file__).resolve().parent

#: Helper modules of tests/ that test files import by name (``import export_meshes``).
HELPERS = ("_shared", "export_meshes", "_catalogue_checks")


class _HelperFinder(importlib.abc.MetaPathFinder):
    """Finds the :data:`HELPERS` in tests/, and nothing else.

    With ``--import-mode=importlib`` the tests folder is not on ``sys.path``, so a test file
    cannot import a sibling module; this finder lets it import exactly the shared helpers
    (loaded once, on first import), instead of every file loading its own copy by path.
    """

    def find_spec(self, name, path=None, target=None):
        if name not in HELPERS:
            return None
        return importlib.util.spec_from_file_location(name, TESTS / f"{name}.py")


if not any(isinstance(f, _HelperFinder) for f in sys.meta_path):
    sys.meta_path.append(_HelperFinder())

import _shared  # noqa: E402 - importable only once the finder is in place

SMALL_DESIGN = _shared.SMALL_DESIGN

# The longest test files, longest first (seconds of one worker, measured with --durations=0 on
# 2026-12-08, 1,190 s in all, 614 s of wall time).  The two workers take a file at a time in
# collection order (--dist loadfile --no-loadscope-reorder): the longest files first, so the
# short ones even out the end.  (pytest-xdist orders the files by their number of tests unless
# told not to, which it can be since 3.8: until then this order had no effect, the long files
# with few tests each came last, and one worker ran on alone for about 70 s.)
LONGEST_FIRST = ("test_fuzz.py",               # 174 s
                 "test_designer_browser.py",   # 130 s
                 "test_quality.py",            # 118 s (and two build processes of its own)
                 "test_designer.py",           # 82 s
                 "test_pq_choice.py",          # 53 s
                 "test_pq_splinters.py",       # 49 s
                 "test_pq_quality.py",         # 43 s
                 "test_help_examples.py",      # 34 s
                 "test_pq_thinned.py",         # 34 s
                 "test_robustness_geometry.py",  # 30 s
                 "test_designer_security.py",  # 29 s
                 "test_cli.py",                # 26 s
                 "test_bundled_examples.py")   # 24 s


def pytest_collection_modifyitems(config, items):
    """Run the :data:`LONGEST_FIRST` files first, so that the short ones even out the end."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


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
    """The text of :data:`_shared.SMALL_DESIGN`."""
    return SMALL_DESIGN
