"""Regenerate the pictures of docs/structure.md (docs/img/structure-*.png).

Run from the repository root: ``python docs/structure_figures.py``.
"""

from __future__ import annotations

from pathlib import Path

from ruledmesh.constructions import hyperboloid_mesh
from ruledmesh.design import build_file
from ruledmesh.io import write_atomic
from ruledmesh.structure import support_structure
from ruledmesh.structure.beams import edge_beams, thick_panels
from ruledmesh.structure.figure import render_structure

ROOT = Path(__file__).resolve().parent.parent
IMG = ROOT / "docs" / "img"

# (picture, example, offset as a fraction of the diagonal, axes method, beams?, view)
FIGURES = [
    ("structure-hyperboloid", "fig7b-hyperboloid-circular", 0.05, "auto", True, (20.0, -60.0)),
    ("structure-generators", "fig7c-hyperboloid-generators", 0.05, "auto", True, (20.0, -60.0)),
    ("structure-helicoid", "fig8-helicoid", 0.05, "auto", False, (35.0, -50.0)),
    ("structure-skew", "skew", 0.05, "auto", False, (30.0, -70.0)),
    ("structure-skew-parallel", "skew", 0.05, "parallel", False, (30.0, -70.0)),
]


def main() -> None:
    for name, example, frac, method, beams, view in FIGURES:
        mesh = build_file(ROOT / "examples" / f"{example}.toml").mesh
        s = support_structure(mesh, frac * mesh.diagonal(), method=method)
        solids = edge_beams(s, 0.004 * mesh.diagonal()) if beams else None
        title = (f"{example}: {s.method.value} axes, "
                 f"{'torsion-free' if s.exact else 'not torsion-free'} "
                 f"(torsion <= {float(s.torsion.max()):.2g} deg, "
                 f"axes <= {float(s.deviation.max()):.2g} deg from normals)")
        write_atomic(IMG / f"{name}.png", render_structure(s, beams=solids, view=view,
                                                           size=(1000, 800), title=title))
        print(f"wrote docs/img/{name}.png")
    # A close-up: a coarse hyperboloid strip with edge beams and 4 cm thick panels.
    s = support_structure(hyperboloid_mesh(1.0, 1.5, 0.6, 12, 2), -0.25)
    picture = render_structure(s, beams=edge_beams(s, 0.04), panels=thick_panels(s, 0.04),
                               view=(40.0, -70.0), size=(1000, 700),
                               title="circular axes, edge beams 0.04 wide to the offset layer, "
                                     "panels 0.04 thick")
    write_atomic(IMG / "structure-detail.png", picture)
    print("wrote docs/img/structure-detail.png")


if __name__ == "__main__":
    main()
