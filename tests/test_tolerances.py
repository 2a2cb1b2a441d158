"""Tolerances and work limits live in one place each: ``ruledmesh.tolerances`` and ``ruledmesh.budget``.

The scan reads every module of ``src/ruledmesh`` and lists the small float literals (``1e-9``
and the like, magnitude at most 1e-3) outside ``tolerances.py``. The ones still allowed are
listed below as data with the reason; any other is a tolerance that belongs in
``tolerances.py`` under a name and a comment saying why it has its value.
"""

from __future__ import annotations

import ast
from collections import Counter
from pathlib import Path

from ruledmesh import budget, tolerances

SRC = Path(__file__).resolve().parents[1] / "src" / "ruledmesh"

#: The largest magnitude a float literal may have and still count as a tolerance.
SMALL = 1e-3

#: (module relative to src/ruledmesh, value) -> how many times, with why it is allowed.
ALLOWED: dict[tuple[str, float], int] = {
    # Unit factors (millimetres to metres), not tolerances.
    ("units.py", 1e-3): 1,
    ("blender/ruledmesh_blender/__init__.py", 1e-3): 1,  # the add-on runs without the package
    # Stroke width of a cutting-sheet drawing, a share of the sheet: a drawing size.
    ("fabricate/sheets.py", 5e-4): 1,
    # The range of lengths whose squares stay normal doubles: a limit on input, not a tolerance.
    ("_validation.py", 1e-150): 1,
    # The low halves of atan(1/2) and atan(1) in the corner angles' atan (fdlibm's), not tolerances.
    ("_arrays.py", 2.26987774529616870924e-17): 1,
    ("_arrays.py", 3.06161699786838301793e-17): 1,
    # The §4.3 mesher's modules that are being reworked at the time of writing; their literals
    # move to tolerances.py with that work.
}


def _small_literals() -> Counter[tuple[str, float]]:
    found: Counter[tuple[str, float]] = Counter()
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel == "tolerances.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), rel)):
            if (isinstance(node, ast.Constant) and type(node.value) is float
                    and 0 < abs(node.value) <= SMALL):
                found[rel, abs(node.value)] += 1
    return found


def test_no_tolerance_literal_outside_tolerances_module():
    found = _small_literals()
    extra = {k: n - ALLOWED.get(k, 0) for k, n in found.items() if n > ALLOWED.get(k, 0)}
    assert not extra, (f"tolerance literals outside tolerances.py (name them there): {extra}")


def test_allow_list_is_not_stale():
    # An allowed literal that has gone must leave the list too, so the list only shrinks.
    found = _small_literals()
    stale = {k: n for k, n in ALLOWED.items() if found.get(k, 0) < n}
    assert not stale, f"allowed literals no longer in the code (remove them from ALLOWED): {stale}"


def _documented_constants(module) -> list[str]:
    """Module-level UPPER_CASE assignments of ``module`` without a comment line just above."""
    path = Path(module.__file__)
    lines = path.read_text(encoding="utf-8").splitlines()
    bare = []
    for node in ast.parse("\n".join(lines)).body:
        if (isinstance(node, ast.Assign) and len(node.targets) == 1
                and isinstance(node.targets[0], ast.Name) and node.targets[0].id.isupper()):
            above = lines[node.lineno - 2].strip() if node.lineno > 1 else ""
            if not above.startswith("#"):
                bare.append(node.targets[0].id)
    return bare


def test_every_tolerance_and_limit_says_why():
    assert _documented_constants(tolerances) == []
    assert _documented_constants(budget) == []


def test_constants_are_exported():
    for module in (tolerances, budget):
        for name in dir(module):
            if name.isupper() and not name.startswith("_"):
                assert name in module.__all__, f"{module.__name__}.{name} is not in __all__"
