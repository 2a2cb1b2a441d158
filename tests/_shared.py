"""What several test files share: the small design, in one copy.

Importable from any test file as ``import _shared`` (``conftest.py`` makes the helper modules of
``tests/`` importable; the suite runs with ``--import-mode=importlib``, where the tests folder is
not on ``sys.path``).
"""

from __future__ import annotations

__all__ = ["SMALL_DESIGN", "small_design"]


def small_design(*, name: str = "small", count: int = 9, rows: int = 6) -> str:
    """A small ruled design: ``count`` generators between a B-spline and a polyline, ``rows`` rows.

    Quick to build, with every part of the pipeline in it (curves, rulings, the §4.3 mesher).
    """
    return f"""\
name = "{name}"

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
count = {count}

[mesh]
method = "pq"
rows = {rows}
"""


#: The default :func:`small_design` (nine generators, six rows).
SMALL_DESIGN = small_design()
