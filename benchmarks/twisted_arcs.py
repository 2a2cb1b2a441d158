"""Write the sweep of twisted hyperboloids between coaxial arcs that docs/mesh-quality.md measures.

32 designs: arcs of 120 and 180 degrees, the lower of radius 4 at z = 0, the upper of
radius 4 or 3 at height 3 or 6 and turned by 60, 90, 120 or 140 degrees; 51 generators
at equal arc length, 24 rows.  Measure them with the independent checker::

    python benchmarks/twisted_arcs.py /tmp/twist
    python benchmarks/quality.py --no-defaults /tmp/twist/*.toml
"""

from __future__ import annotations

import argparse
import itertools
from pathlib import Path

TURNS = (60, 90, 120, 140)
SPANS = (120, 180)
RADII = (4, 3)
HEIGHTS = (3, 6)


def design(turn: float, span: int, radius: float, height: float, count: int = 51,
           rows: int = 24, mesh: str = "") -> tuple[str, str]:
    """The name and TOML text of one surface of the sweep (``count`` generators, ``rows``,
    and ``mesh``: more lines of its ``[mesh]`` table)."""
    name = f"arcs-t{turn}-s{span}-r{radius}-h{height}"
    text = f'''# Hyperboloid between an arc of {span} degrees, r = 4 at z = 0, and one of r = {radius} at
# z = {height} turned by {turn} degrees.
# quality: general
name = "{name}"

[curves.c1]
type = "arc"
center = [0.0, 0.0, 0.0]
radius = 4
normal = [0.0, 0.0, 1.0]
start_angle = 0
end_angle = {span}

[curves.c2]
type = "arc"
center = [0.0, 0.0, {height:.1f}]
radius = {radius}
normal = [0.0, 0.0, 1.0]
start_angle = {turn}
end_angle = {turn + span}

[rulings]
between = ["c1", "c2"]
distribution = "arc-length"
count = {count}

[mesh]
rows = {rows}
{mesh}'''
    return name, text


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", 1)[0])
    p.add_argument("folder", type=Path, help="where to write the design files")
    args = p.parse_args(argv)
    args.folder.mkdir(parents=True, exist_ok=True)
    for turn, span, radius, height in itertools.product(TURNS, SPANS, RADII, HEIGHTS):
        name, text = design(turn, span, radius, height)
        (args.folder / f"{name}.toml").write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
