"""Write random two-B-spline designs at designer sizes, the "typical" surfaces of docs/mesh-quality.md.

Each design rules a skew surface between two B-spline director curves about 10 units long
and 4 apart: cubic or quartic, 4 to 6 control points jittered by up to 2.5 units across the
curve, 40 to 60 generators at equal arc length, 20 to 40 rows, exact mode (or with
``--tolerance``).  The same seed writes the same designs.  Measure them with the independent
checker::

    python benchmarks/random_surfaces.py /tmp/rnd --count 24
    python benchmarks/quality.py --no-defaults /tmp/rnd/*.toml --json rnd.json
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np


def _points(rng: np.random.Generator, k: int, base: tuple[float, float, float]) -> list[list[float]]:
    x = np.linspace(0.0, 10.0, k)
    y = base[1] + rng.uniform(-2.5, 2.5, k)
    z = base[2] + rng.uniform(-1.5, 1.5, k)
    return [[round(float(a), 3), round(float(b), 3), round(float(c), 3)] for a, b, c in zip(x, y, z)]


def design(rng: np.random.Generator, index: int, tolerance: float | None = None) -> tuple[str, str]:
    """The name and TOML text of one random design."""
    name = f"rnd{index:02d}" + ("" if tolerance is None else f"-tol{tolerance:g}")
    curves = []
    for key, base in (("c1", (0.0, 0.0, 0.0)), ("c2", (0.0, 0.0, 4.0))):
        degree = int(rng.integers(3, 5))
        k = int(rng.integers(max(degree + 1, 4), 7))
        curves.append(f'[curves.{key}]\ntype = "bspline"\ndegree = {degree}\npoints = {_points(rng, k, base)}\n')
    count, rows = int(rng.integers(40, 61)), int(rng.integers(20, 41))
    mesh = f"[mesh]\nrows = {rows}\n" + ("" if tolerance is None else f"planarity_tolerance = {tolerance:g}\n")
    text = (f"# Random skew surface between two B-splines, {count} generators, {rows} rows.\n"
            f'# quality: general\nname = "{name}"\n\n' + "\n".join(curves)
            + f'\n[rulings]\nbetween = ["c1", "c2"]\ndistribution = "arc-length"\ncount = {count}\n\n'
            + mesh)
    return name, text


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", 1)[0])
    p.add_argument("folder", help="where to write the designs")
    p.add_argument("--count", type=int, default=24, help="how many designs (default 24)")
    p.add_argument("--seed", type=int, default=2026, help="random seed (default 2026)")
    p.add_argument("--tolerance", type=float, help="[mesh] planarity_tolerance of every design")
    args = p.parse_args(argv)
    out = Path(args.folder)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    for i in range(args.count):
        name, text = design(rng, i, args.tolerance)
        (out / f"{name}.toml").write_text(text)
    print(f"wrote {args.count} designs to {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
