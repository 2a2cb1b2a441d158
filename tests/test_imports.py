"""The layering of ``src/ruledmesh``, checked against its real imports.

The package reads bottom-up like the paper: foundations (errors, tolerances, checks), the core
geometry (meshes, curves, the smooth reference surfaces, per-face measures), the generators
(rulings, §2), the meshers (constructions §2-§3, transforms, the §4 meshers), the analysis that
judges a mesh, the outputs (exports, fabrication, structure, pictures), the design layer that
reads design files, and the applications (CLI, designer, Grasshopper, Blender).

A module may import from its own layer and from the layers below it, never from above; between
top-level units (``ruledmesh.<name>``) the graph has no cycle; and across units only public names
are imported. Every import counts, also those inside functions and under ``TYPE_CHECKING``: a lazy
import is a dependency all the same.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "ruledmesh"

#: Bottom to top. Entries are modules or packages relative to ``ruledmesh``; a module belongs to
#: the longest entry that prefixes its name. "" is the package's top level (``__init__``).
LAYERS: list[tuple[str, list[str]]] = [
    ("foundation", ["errors", "_version", "tolerances", "_validation", "_arrays", "units", "progress",
                    "_files", "roots", "budget", "normalise", "kernels"]),
    # Per-face measures and the distance to the smooth patch are geometry of a mesh that the
    # meshers check their own output with; they depend on the mesh only.  The slender share
    # (analysis.asymptotic) is geometry of the generators, by the hop, and how far triangles lie
    # off the generators they span (analysis.spans) of the mesh and its generators: the mesher's
    # warnings use both.
    ("core", ["mesh", "notebook", "registry", "curves", "triangulate", "hop", "surfaces", "labels",
              "analysis.faces", "analysis.circularity", "analysis.surface", "analysis.asymptotic",
              "analysis.spans", "analysis.__init__"]),
    ("generators", ["rulings"]),
    ("meshers", ["constructions", "transforms", "pq", "skew", "hybrid", "compound"]),
    ("analysis", ["analysis"]),
    ("outputs", ["io", "fabricate", "structure", "render"]),
    ("design", ["design", "bundled", "api", ""]),
    ("applications", ["cli", "web", "hops", "blender", "__main__"]),
]

#: The Blender add-on runs inside Blender and imports the installed package like a user would.
SKIP = ("blender/ruledmesh_blender/",)


def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC).with_suffix("")
    return ".".join(rel.parts)  # "analysis.__init__" for a package's own module


def _package(module: str) -> list[str]:
    parts = module.split(".")
    return parts[:-1]


def _imports(path: Path) -> list[tuple[str, list[str], int]]:
    """(imported module relative to ruledmesh, imported names, line) of every import."""
    module = _module_name(path)
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = _package(module)[: len(_package(module)) - (node.level - 1)]
                target = ".".join([*base, node.module] if node.module else base)
            elif node.module and (node.module == "ruledmesh" or node.module.startswith("ruledmesh.")):
                target = node.module[len("ruledmesh."):] if node.module != "ruledmesh" else ""
            else:
                continue
            out.append((target, [a.name for a in node.names], node.lineno))
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name == "ruledmesh" or a.name.startswith("ruledmesh."):
                    out.append((a.name[len("ruledmesh."):] if a.name != "ruledmesh" else "", [], node.lineno))
    return out


def _sources() -> list[Path]:
    return [p for p in sorted(SRC.rglob("*.py")) if not any(s in p.as_posix() for s in SKIP)]


def _resolve(target: str, names: list[str]) -> list[str]:
    """``from .analysis import faces`` imports the module analysis.faces, not the package."""
    out = []
    for name in names or [None]:
        sub = f"{target}.{name}" if target and name else (name or target)
        if name and ((SRC / sub.replace(".", "/")).with_suffix(".py").exists()
                     or (SRC / sub.replace(".", "/") / "__init__.py").exists()):
            out.append(sub)
        else:
            out.append(target)
    return out


def _as_module(target: str) -> str:
    """The module file a dotted target names: packages by their ``__init__``."""
    if target == "":
        return "__init__"
    if (SRC / target.replace(".", "/") / "__init__.py").exists():
        return f"{target}.__init__"
    return target


def _layer(module: str) -> int:
    if module == "__init__":
        return next(i for i, (_, entries) in enumerate(LAYERS) if "" in entries)
    best, index = -1, None
    for i, (_, entries) in enumerate(LAYERS):
        for entry in entries:
            if entry and (module == entry or module.startswith(entry + ".")) and len(entry) > best:
                best, index = len(entry), i
    assert index is not None, f"ruledmesh.{module} is in no layer: add it to LAYERS"
    return index


#: Modules that belong to another unit: the Jupyter view of a Mesh is called by Mesh._repr_html_.
SAME_UNIT = {"notebook": "mesh"}


def _unit(module: str) -> str:
    unit = "" if module == "__init__" else module.split(".")[0]
    return SAME_UNIT.get(unit, unit)


def _edges() -> list[tuple[str, str, list[str], int]]:
    edges = []
    for path in _sources():
        source = _module_name(path)
        for target, names, line in _imports(path):
            for mod in _resolve(target, names):
                edges.append((source, _as_module(mod), names, line))
    return edges


def test_every_module_has_a_layer():
    for path in _sources():
        _layer(_module_name(path))


def test_imports_follow_the_layers():
    wrong = []
    for source, target, _, line in _edges():
        if _layer(target) > _layer(source):
            wrong.append(f"ruledmesh.{source}:{line} ({LAYERS[_layer(source)][0]}) imports "
                         f"ruledmesh.{target} ({LAYERS[_layer(target)][0]})")
    assert not wrong, "imports against the layering:\n" + "\n".join(wrong)


def test_no_cycle_between_top_level_units():
    graph: dict[str, set[str]] = {}
    for source, target, _, _ in _edges():
        a, b = _unit(source), _unit(target)
        if a != b and b != "" and a not in ("", "__main__"):
            graph.setdefault(a, set()).add(b)
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " -> ".join(f"ruledmesh.{c}" for c in cycle))
            if nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)


def test_only_public_names_cross_units():
    wrong = []
    for source, target, names, line in _edges():
        if _unit(source) == _unit(target):
            continue
        private = [n for n in names if n.startswith("_") and not n.startswith("__")]
        hidden = [p for p in target.split(".") if p.startswith("_") and not p.startswith("__")]
        # a private module of a unit is private to it; the top-level helpers (_validation,
        # _version, _files, _arrays) are the package's shared foundation
        if hidden and _unit(target) not in ("_validation", "_version", "_files", "_arrays"):
            private.append(target)
        if private:
            wrong.append(f"ruledmesh.{source}:{line} uses {', '.join(private)} of ruledmesh.{target}")
    assert not wrong, "private names used across units:\n" + "\n".join(wrong)


def test_the_checker_sees_relative_and_lazy_imports(tmp_path):
    # the rules above are only as good as the import extraction: pin it on known imports
    found = {(t, tuple(n)) for t, n, _ in _imports(SRC / "analysis" / "report.py")}
    assert ("mesh", ("FaceKind", "Mesh")) in found
    assert ("analysis.guarantees", ("check_guarantee", "format_guarantee")) in found  # inside a function
    assert ("analysis", ("faces",)) in found
    assert _resolve("analysis", ["faces"]) == ["analysis.faces"]
    assert _layer("skew.pq.mesher") > _layer("rulings") > _layer("mesh") > _layer("errors")


#: The longest a function of src/ruledmesh may be, docstring included (house style: few over 60).
MAX_FUNCTION_LINES = 100


def test_no_function_is_longer_than_the_limit():
    long = []
    for path in sorted(SRC.rglob("*.py")):  # the Blender add-on too
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(f"ruledmesh.{_module_name(path)}.{node.name}: {lines} lines")
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines:\n" + "\n".join(long)


#: Where DesignError (an error naming a design file and field) may be used: the design layer reads
#: the file, the applications report it, errors.py defines it and the top level re-exports it.
DESIGN_ERROR_UNITS = ("design", "cli", "web", "errors", "")
#: Still to move: the §4.3 mesher's design-file builder.
DESIGN_ERROR_PENDING: tuple[str, ...] = ()


def test_design_errors_only_in_the_design_layer():
    wrong = []
    for path in _sources():
        module = _module_name(path)
        if _unit(module) in DESIGN_ERROR_UNITS or module in DESIGN_ERROR_PENDING:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            name = (node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute)
                    else None)
            if name == "DesignError":
                wrong.append(f"ruledmesh.{module}:{node.lineno}")
    assert not wrong, ("DesignError outside the design layer (maths raises ParameterError):\n"
                       + "\n".join(sorted(set(wrong))))


def test_earlier_import_paths_of_the_section_4_meshers_still_work():
    # ruledmesh.hybrid and ruledmesh.compound are named in earlier releases' docs: they re-export
    # the same objects from ruledmesh.skew.
    import ruledmesh
    from ruledmesh import compound, hybrid, pq, skew

    assert hybrid.hybrid_mesh is skew.hybrid_mesh is ruledmesh.hybrid_mesh
    assert pq.pq_mesh is skew.pq_mesh is ruledmesh.pq_mesh
    for module in (compound, hybrid, pq):
        for name in module.__all__:
            assert getattr(module, name) is getattr(skew, name)
