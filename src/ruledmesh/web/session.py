"""The designer's state: the current design, its build, undo and redo.

A :class:`Session` holds the current design as a plain dictionary (the TOML
tables) and the mesh built from it.  Every edit makes a new candidate design,
builds it and only then makes it current, so the state always holds a design
that builds; a bad edit raises (with the design file's dotted field path) and
leaves the state as it was.  :meth:`Session.payload` encodes the mesh for the
page as one binary message (see :func:`encode_message`).

The session is also where the designer's file safety lives: it reads and
writes only inside its folder (:meth:`Session.inside`), never replaces a file
it did not load or write itself unless asked to (:class:`OverwriteRefused`),
and refuses designs over the limits (:func:`check_limits`) before building.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import importlib
import json
import math
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..design import Design, build_design, parse_design
from ..errors import DesignError, ExportError, ParameterError, RuledMeshError
from ..mesh import FaceKind, Mesh
from ..registry import Built
from .builder import MAX_BUILD_SECONDS, BuildTimeout, InProcessBuilder, Superseded
from .toml_writer import dumps

__all__ = [
    "DEFAULT_DESIGN",
    "MAX_CONTROL_POINTS",
    "OverwriteRefused",
    "Session",
    "check_limits",
    "edit_label",
    "encode_message",
    "fast_figures",
    "set_path",
    "topology_key",
]

# Shown when the designer starts without a design file (paper Fig. 10, a skew surface).
DEFAULT_DESIGN = """\
name = "skew"
description = "B-spline and polyline director curves, arc-length distribution, PQ mesh"

[curves.c1]
type = "bspline"
degree = 3
points = [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]

[curves.c2]
type = "polyline"
points = [[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]]

[rulings]
between = ["c1", "c2"]
distribution = "arc-length"
count = 41

[mesh]
method = "pq"
rows = 40
primary = "middle"
option = 0
extend = "auto"
trim = true
"""

# Faces of a mesh whose panel read-out (the whole panels.csv table, congruence classes
# included, computed in the server on a click) is given: beyond this it would take seconds.
MAX_PANEL_FACES = 200_000
# Undo steps kept; older ones are dropped so a long session stays bounded in memory.
UNDO_LIMIT = 200
# With previews, an edit shows the quick mesh first only where the session's last full build
# took longer than this: a quick design (examples/skew: 40 ms) would otherwise be built twice
# and drawn twice for each step of a slider, for nothing.
QUICK_AFTER_SECONDS = 0.15
# Points sampled along each director curve for display.
CURVE_SAMPLES = 160
# Control points of one curve (or points of one list of a catalogue surface): each one is a
# handle in the page, and a design is edited by hand, so thousands mean a mistake or an attack.
MAX_CONTROL_POINTS = 2_000


class OverwriteRefused(ParameterError):
    """Save or export would replace a file this session did not load or write itself."""


def check_limits(data: Mapping[str, Any], base_dir: Path) -> None:
    """Refuse, before any work, a design over the designer's limits or reading outside its folder.

    Limits: :data:`MAX_CONTROL_POINTS` points per curve (and per point list of
    a ``[surface]`` table); generators x (rows + 1) grid points at most the
    mesher's own ``MAX_GRID_POINTS`` (the budget of ``ruledmesh build``);
    ``rulings.file`` a name inside ``base_dir``.

    Raises
    ------
    DesignError
        Naming the field and the limit.
    """
    from ..budget import MAX_GRID_POINTS

    def count_points(value: Any, field: str) -> None:
        if isinstance(value, list) and len(value) > MAX_CONTROL_POINTS:
            raise DesignError(f"expected at most {MAX_CONTROL_POINTS:,} points, got "
                              f"{len(value):,}", field)

    curves = data.get("curves")
    if isinstance(curves, Mapping):
        for name, spec in curves.items():
            if isinstance(spec, Mapping):
                count_points(spec.get("points"), f"curves.{name}.points")
    surface = data.get("surface")
    if isinstance(surface, Mapping):
        for key, value in surface.items():
            count_points(value, f"surface.{key}")
    rulings = data.get("rulings")
    mesh = data.get("mesh")
    if isinstance(rulings, Mapping):
        count_points(rulings.get("lines"), "rulings.lines")
        count: Any = rulings.get("count")
        rows: Any = mesh.get("rows", 20) if isinstance(mesh, Mapping) else 20
        if _positive_int(count) and _positive_int(rows):
            points = int(count) * (int(rows) + 1)
            if points > MAX_GRID_POINTS:
                raise DesignError(f"{count:,} generators x {int(rows) + 1:,} points each = "
                                  f"{points:,} grid points; the limit is {MAX_GRID_POINTS:,}",
                                  "rulings.count")
        if "file" in rulings and isinstance(rulings["file"], str):
            inside(base_dir, rulings["file"], "rulings.file", DesignError, must_exist=False)


def _positive_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value > 0


def inside(base_dir: Path, name: str, field: str, err: type = ParameterError,
           must_exist: bool = False) -> Path:
    """``base_dir / name`` if it names a file inside ``base_dir``; else a one-line refusal.

    Refused: absolute paths, ``~``, ``..`` parts, and names whose folder or
    the file itself is a symbolic link leading out of ``base_dir``.  Sub-folders
    that exist inside are fine.
    """
    base = Path(base_dir).resolve()
    where = f"a file name inside the design's folder {base}"
    if not isinstance(name, str) or not name.strip():
        raise err(f"expected {where}, got {name!r}", field)
    if "\0" in name:
        raise err(f"expected {where}, got a name with a NUL character", field)
    path = Path(name)
    if name.startswith("~"):
        raise err(f'expected {where}, got "{name}" (no "~" paths)', field)
    if path.is_absolute() or name.startswith(("/", "\\")):
        raise err(f'expected {where}, got the absolute path "{name}"', field)
    if ".." in path.parts or ".." in name.replace("\\", "/").split("/"):
        raise err(f'expected {where}, got "{name}" (no ".." parts)', field)
    target = base / path
    if not target.parent.resolve().is_relative_to(base):
        raise err(f'expected {where}, got "{name}" (its folder is a link outside)', field)
    if target.is_symlink() and not target.resolve().is_relative_to(base):
        raise err(f'expected {where}, got "{name}" (a link to a file outside)', field)
    if must_exist and not target.parent.is_dir():
        raise err(f'no such folder "{target.parent.relative_to(base)}" in {base}', field)
    return target.parent.resolve() / target.name


def set_path(data: dict, path: Sequence[str | int], value: Any) -> None:
    """Set ``data[path[0]][path[1]]... = value`` in place; ``value=None`` deletes.

    Missing tables along the way are created.  Raises :class:`DesignError`
    naming the dotted path when a step does not exist or has the wrong type.
    """
    if not path:
        raise DesignError("expected a non-empty path", "edit")
    dotted = ".".join(str(p) for p in path)
    node: Any = data
    for step in path[:-1]:
        if isinstance(node, dict) and isinstance(step, str):
            node = node.setdefault(step, {})
        elif isinstance(node, list) and isinstance(step, int) and -len(node) <= step < len(node):
            node = node[step]
        else:
            raise DesignError(f"no such field (at {step!r})", dotted)
    last = path[-1]
    if isinstance(node, dict) and isinstance(last, str):
        if value is None:
            node.pop(last, None)
        else:
            node[last] = value
    elif isinstance(node, list) and isinstance(last, int) and -len(node) <= last < len(node):
        if value is None:
            raise DesignError("cannot delete a list item", dotted)
        node[last] = value
    else:
        raise DesignError(f"no such field (at {last!r})", dotted)


def edit_label(changes: Sequence[tuple[Sequence[str | int], Any]]) -> str:
    """A short description of an edit for the history list, e.g. ``"mesh.rows = 8"``.

    >>> edit_label([(["mesh", "rows"], 8)])
    'mesh.rows = 8'
    >>> edit_label([(["curves", "c1", "points", 2], [1, 2, 3])])
    'curves.c1.points[2] moved'
    """
    words = []
    for path, value in list(changes)[:3]:
        dotted = ".".join(str(p) for p in path if not isinstance(p, int))
        dotted += "".join(f"[{p}]" for p in path if isinstance(p, int))
        if value is None:
            words.append(f"{dotted} removed")
        elif isinstance(value, (bool, int, float, str)):
            words.append(f"{dotted} = {value}"[:60])
        elif isinstance(value, list) and path and path[-1] == "points":
            words.append(f"{dotted}: {len(value)} points")
        elif _is_point(value):
            words.append(f"{dotted} moved")
        else:
            words.append(f"{dotted} changed")
    more = len(changes) - 3
    return ", ".join(words) + (f" (+{more} more)" if more > 0 else "") if words else "edit"


def topology_key(mesh: Mesh) -> str:
    """A fingerprint of a mesh's faces: vertex count, face corners and face kinds.

    Two meshes with the same key have the same display triangles and edges, so
    the page keeps its own (only the vertices move).
    """
    import hashlib

    h = hashlib.blake2b(digest_size=12)
    h.update(np.int64(mesh.n_vertices).tobytes())
    for arr in (mesh.face_offsets, mesh.face_indices, mesh.face_kind):
        h.update(np.ascontiguousarray(arr).tobytes())
    return h.hexdigest()


def fast_figures(mesh: Mesh) -> tuple[dict[str, Any], np.ndarray, np.ndarray]:
    """The figures cheap enough for every edit (counts, planarity, angles, area shares).

    The panel figures are those of ``ruledmesh analyze`` (the same functions of
    :mod:`ruledmesh.analysis.faces`), so the legend and the report agree.

    Returns
    -------
    figures : dict
        Counts, ``planarity_max`` and the face it is at (``planarity_face``), the
        mesh's ``planarity_tolerance`` and the ``planarity_exact`` of rounding, the
        ``planarity_counts`` of faces (not triangles) exact, over the tolerance and in all,
        by :mod:`ruledmesh.analysis.planar`'s rule,
        ``min_angle_deg`` and its face (``min_angle_face``), ``splinters``
        (faces with an angle below ``splinter_deg``), ``area_share`` (as in the
        report's ``quality.area_share``), convexity and the mesher's warnings.
    planarity : (F,) float64
        Per-face planarity as build, analyze and fabricate measure it
        (:func:`ruledmesh.analysis.planar.face_planarity`).
    min_angle : (F,) float64
        Per-face smallest interior angle in degrees (:func:`~ruledmesh.analysis.faces.face_min_angles`).
    """
    from ..analysis import faces as F
    from ..analysis.planar import face_planarity, planarity_bounds, planarity_tolerance, rounding_allowance
    from ..analysis.report import kind_counts
    from ..tolerances import DEFAULT

    plan = face_planarity(mesh)
    angle = F.face_min_angles(mesh)
    # Exact, within the tolerance, over it: analyze's rule (far from the origin, within what
    # the stored coordinates' rounding explains too), over the faces the legend shows (no
    # triangles: flat by definition).
    exact_bound, allowed = planarity_bounds(mesh, rounding_allowance(mesh))
    shown = mesh.valences > 3
    exact = plan <= exact_bound
    over = plan > allowed
    convex = F.convexity(mesh, DEFAULT.convexity)
    worst = int(np.argmax(plan)) if plan.size else None
    sharpest = int(np.argmin(angle)) if angle.size else None
    return {
        "vertices": mesh.n_vertices,
        "faces": mesh.n_faces,
        "triangles": int(np.count_nonzero(mesh.valences == 3)),
        "kinds": mesh.count_kinds(),
        # The same words as the command line: "633 quads, 9 border faces, 306 fill triangles".
        "kinds_text": kind_counts(mesh.count_kinds()),
        "planarity_max": float(plan.max()) if plan.size else 0.0,
        "planarity_face": worst,
        # The design's own ([mesh] planarity_tolerance) where it has one, as analyze says.
        "planarity_tolerance": planarity_tolerance(mesh),
        "planarity_exact": DEFAULT.planarity,
        "planarity_counts": {"exact": int(np.count_nonzero(exact & shown)),
                             "over": int(np.count_nonzero(over & shown)),
                             "faces": int(np.count_nonzero(shown))},
        "min_angle_deg": float(angle.min()) if angle.size else None,
        "min_angle_face": sharpest,
        "splinters": int(np.count_nonzero(angle < F.SPLINTER_DEG)),
        "splinter_deg": F.SPLINTER_DEG,
        "area_share": F.area_shares(mesh) if mesh.n_faces else None,
        "non_convex": int(np.count_nonzero(~convex)),
        "members": len(mesh.members),
        "warnings": [str(w) for w in mesh.info.get("warnings", [])],
    }, plan, angle


def slow_figures(built: Built) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Closeness, coverage and panel count: too slow for every edit on some designs.

    Returns
    -------
    figures : dict
    per_face : dict
        ``"closeness"``: (F,) the distance of each face centroid from the
        smooth surface relative to the bounding-box diagonal (absent without a
        reference); ``"class"``: (F,) the congruence class of each panel.
    """
    from ..analysis import faces as F
    from ..fabricate.panels import congruence_classes

    mesh = built.mesh
    figures: dict[str, Any] = {}
    per_face: dict[str, np.ndarray] = {}
    diag = mesh.diagonal() or 1.0
    if built.reference is not None and mesh.n_faces:
        close = built.reference.distance(F.face_centroids(mesh)) / diag
        per_face["closeness"] = close
        vert = built.reference.distance(mesh.vertices[np.unique(mesh.face_indices)]) / diag
        figures["closeness"] = {"centroids_max": float(close.max()),
                                "centroids_mean": float(close.mean()),
                                "vertices_max": float(vert.max())}
        patch = built.reference.area()
        if patch:
            _, areas = F.face_normals(mesh)
            figures["coverage"] = float(areas.sum() / patch)
    if mesh.n_faces:
        classes = congruence_classes(mesh)
        per_face["class"] = classes
        figures["panels"] = int(classes.max()) + 1
    return figures, per_face


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    return str(value)


def _clean(value: Any) -> Any:
    """JSON cannot hold NaN or infinity: send them as strings."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


def encode_message(header: Mapping[str, Any], arrays: Sequence[tuple[str, np.ndarray]]) -> bytes:
    """One binary message: a JSON header and little-endian arrays.

    Layout: ``uint32`` length of the JSON text, the UTF-8 JSON padded with
    spaces to a multiple of 4 bytes, then each array's bytes (each padded to 4
    bytes).  The header's ``arrays`` list gives each array's name, dtype,
    shape and byte offset from the start of the array section, so the page
    views them without copying.
    """
    table = []
    chunks = []
    offset = 0
    for name, arr in arrays:
        arr = np.ascontiguousarray(arr)
        if arr.dtype.byteorder == ">":
            arr = arr.astype(arr.dtype.newbyteorder("<"))
        raw = arr.tobytes()
        pad = (-len(raw)) % 4
        table.append({"name": name, "dtype": arr.dtype.name, "shape": list(arr.shape),
                      "offset": offset})
        chunks.append(raw + b"\0" * pad)
        offset += len(raw) + pad
    try:
        text = json.dumps({**header, "arrays": table}, default=_json_default, allow_nan=False)
    except ValueError:  # NaN or infinity somewhere (a figure of a degenerate mesh): as strings
        text = json.dumps(_clean({**header, "arrays": table}), default=_json_default,
                          allow_nan=False)
    raw_text = text.encode("utf-8")
    raw_text += b" " * ((-len(raw_text)) % 4)
    return np.uint32(len(raw_text)).tobytes() + raw_text + b"".join(chunks)


@dataclass
class _Snapshot:
    design: dict
    built: Built
    version: int
    toml: str
    frame: dict[str, Any] | None = None  # frame_data, when the build worker made it
    # The quick mesh of a design that refines ([mesh] refine = false) while its full build
    # runs in the background (Session.previews); refine_error: why that build gave no mesh.
    refining: bool = False
    refine_error: str | None = None


# The sampled curves of the last design: they change only when the curves do (not with the
# rows, counts, ...). One entry per process; guarded for the server's threads.
_CURVES: dict[str, Any] = {}
_CURVES_LOCK = threading.Lock()


def frame_data(design: Mapping[str, Any], built: Built) -> dict[str, Any]:
    """What the page's message of a design holds besides the session's state.

    Computed where the design is built (the build worker process, right after
    the build), so the server only encodes it.  Only the cheap figures are
    here (planarity, angles, area shares, convexity, counts); closeness, coverage and the panel
    count come from the figures process on request.

    Returns
    -------
    dict
        ``key`` (:func:`topology_key`), ``header`` (figures, construction,
        curves, handles, bbox), and lists of ``(name, array)``: ``live``
        (vertices, planarity, smallest angles), ``faces`` (triangles, edges, corners, kinds:
        sent when the page has other faces) and ``rest`` (generators, torsal
        generators, sampled curves).
    """
    mesh = built.mesh
    figures, plan, angle = fast_figures(mesh)
    rulings = built.rulings
    if rulings is not None and getattr(rulings, "a", None) is not None:
        gens = np.stack([rulings.a, rulings.b], axis=1)
    elif len(mesh.members):
        gens = mesh.vertices[mesh.members]
    else:
        gens = np.zeros((0, 2, 3))
    spec = json.dumps(design.get("curves", {}), sort_keys=True, default=str)
    with _CURVES_LOCK:
        if _CURVES.get("spec") != spec:
            _CURVES.clear()
            _CURVES.update(spec=spec, value=_curve_polylines(design))
        names, counts, points = _CURVES["value"]
    bbox = mesh.bounding_box() if mesh.n_vertices else np.zeros((2, 3))
    tris, tri_face = mesh.fan_triangles()
    return {
        "key": topology_key(mesh),
        "header": {"figures": figures, "construction": _construction(design, len(gens)),
                   "curves": [{"name": n, "count": c} for n, c in zip(names, counts)],
                   "handles": _handles(design, mesh), "bbox": bbox.tolist()},
        "live": [("vertices", mesh.vertices.astype(np.float32)),
                 ("planarity", plan.astype(np.float32)),
                 ("min_angle", angle.astype(np.float32))],
        "faces": [("triangles", tris.astype(np.uint32)),
                  ("triangle_face", tri_face.astype(np.uint32)),
                  ("kind", mesh.face_kind.astype(np.uint8)),
                  ("edges", mesh.edges().astype(np.uint32)),
                  # The faces themselves (the page's read-out measures areas and angles).
                  ("face_offsets", mesh.face_offsets.astype(np.uint32)),
                  ("face_indices", mesh.face_indices.astype(np.uint32))],
        "rest": [("generators", gens.astype(np.float32)),
                 ("torsal", _torsal(np.asarray(gens, dtype=np.float64), mesh)),
                 ("curve_points", points.astype(np.float32))],
    }


class Session:
    """The designer's state.

    Parameters
    ----------
    text : str, optional
        Design TOML; the built-in skew design when omitted.
    path : path-like, optional
        Where the design was read from and is saved to by default.
    base_dir : path-like, optional
        Folder that relative paths in the design resolve against (default: the
        design's folder, else the working folder).
    undo_limit : int
        Undo steps kept (older ones are dropped, so memory stays bounded).
    builder : InProcessBuilder, optional
        Builds the edits (the server passes a :class:`~ruledmesh.web.builder.BuildWorker`:
        a separate process with a time limit); default: in the calling thread.
    previews : bool
        Make an edit of a design that refines its generators current at once with
        its quick mesh (the same design with ``[mesh] refine = false``: one mesh
        instead of tens) and build the full mesh in the background, which replaces
        it when done (:meth:`settled`); the next edit stops that build.  Only while
        the last full build took more than :data:`QUICK_AFTER_SECONDS`; the starting
        design opens with its quick mesh, built in full once the builder is set
        (:meth:`set_builder`) or the session waits for it (:meth:`settled`).  The
        server turns this on, and ``ruledmesh design`` opens with it: a slider
        dragged over a design that takes seconds to refine shows a mesh for every
        step, and the page opens without waiting for the refinement.

    Raises
    ------
    DesignError, GeometryError
        When the starting design does not build or is over the limits.
    """

    def __init__(self, text: str | None = None, path: str | Path | None = None,
                 base_dir: str | Path | None = None, undo_limit: int = UNDO_LIMIT,
                 builder: InProcessBuilder | None = None, previews: bool = False):
        # Resolved: a design file that is a link is edited where it really lives.
        self.path = Path(path).resolve() if path is not None else None
        if base_dir is None:
            base_dir = self.path.parent if self.path is not None else Path(".")
        # Resolved once: a later chdir or a renamed link does not move the folder written to.
        self.base_dir = Path(base_dir).resolve()
        self.source = self.path.name if self.path is not None else "<designer>"
        # Files this session loaded or wrote: the only ones replaced without asking.
        self._owned: set[Path] = set()
        if self.path is not None:
            self.path = inside(self.base_dir, self.path.name, "path")
            self._owned.add(self.path)
        self._builder = builder or InProcessBuilder()
        # The catalogue kinds' default fields (describe) take half a second to read off the
        # builders, once per process: read here, before the page asks, and in this thread.
        # CPython 3.11's ast.parse in a second thread while another one parses or compiles
        # can fail ("AST constructor recursion depth mismatch"): it did in a CI run.
        from ..design.schema import kind_defaults
        kind_defaults()
        design = parse_design(DEFAULT_DESIGN if text is None else text, self.source, self.base_dir)
        data = _plain(design.data)
        check_limits(data, self.base_dir)
        self._lock = threading.RLock()
        self.previews = bool(previews)
        # Told whenever the current snapshot changes: settled() waits on it.
        self._changed = threading.Condition(self._lock)
        # The background build of a quick snapshot: (that snapshot, its thread).
        self._refiner: tuple[_Snapshot, threading.Thread] | None = None
        # What that build is at ("mesh 7, 60 generators"), and who is told.
        self._note: tuple[_Snapshot, str] | None = None
        self._progress_listeners: list[Callable[[int, str], None]] = []
        # How long the last full build of a design took (previews: see QUICK_AFTER_SECONDS);
        # none yet: the starting design opens with its quick mesh.
        self._full_seconds = math.inf
        quick = self._quick(data)
        started = time.perf_counter()
        self._current = _Snapshot(data, self._build(quick or data), 0, dumps(data), None,
                                  quick is not None)
        if quick is None:
            self._full_seconds = time.perf_counter() - started
        self._undo: list[dict] = []
        self._redo: list[dict] = []
        # What each step did, in the words of the page's history list (parallel to the stacks).
        self._undo_labels: list[str] = []
        self._redo_labels: list[str] = []
        self._label = "opened"
        self._coalesce: str | None = None
        self.undo_limit = int(undo_limit)
        # Called (version) after every change of the current design: the server pushes it to
        # every open page, so two tabs never show different designs.
        self._listeners: list[Callable[[int], None]] = []
        self._panels: tuple[int, dict[str, np.ndarray], Any] | None = None
        self._frame: tuple[int, dict[str, Any]] | None = None  # (version, frame_data)
        self._frame_lock = threading.Lock()

    def add_listener(self, listener: Callable[[int], None]) -> None:
        """Call ``listener(version)`` after every change of the current design."""
        self._listeners.append(listener)

    def add_progress_listener(self, listener: Callable[[int, str], None]) -> None:
        """Call ``listener(version, note)`` as the full build of the quick mesh of version
        ``version`` goes on (``note``: what it is at, e.g. ``"mesh 7, 60 generators"``)."""
        self._progress_listeners.append(listener)

    def _told(self, snap: _Snapshot, note: str) -> None:
        with self._lock:
            if self._current is not snap:
                return
            self._note = (snap, note)
        for listener in list(self._progress_listeners):
            with contextlib.suppress(Exception):  # a closed page must not stop the build
                listener(snap.version, note)

    def history(self) -> dict[str, Any]:
        """The session's steps: ``{"undo": [...], "current": label, "redo": [...]}``.

        ``undo`` lists what the steps that can be undone did (oldest first),
        ``redo`` the steps that can be redone (next first).
        """
        with self._lock:
            return {"undo": list(self._undo_labels), "current": self._label,
                    "redo": list(reversed(self._redo_labels))}

    def set_builder(self, builder: InProcessBuilder, previews: bool | None = None) -> None:
        """Build the next edits with ``builder`` (the server's worker process), with quick
        meshes first where ``previews`` says so (None: as before; see :class:`Session`)."""
        with self._lock:
            self._builder = builder
            if previews is not None:
                self.previews = bool(previews)
            # A starting design opened with its quick mesh is built in full by this builder.
            self._keep_refining()

    def page_opened(self) -> None:
        """A page connected: edits are coming, so the builder gets ready for them now (the
        worker loads the compiled kernels while the page draws its first frame)."""
        self._builder.warm_up()

    # ------------------------------------------------------------- state
    @property
    def design(self) -> dict:
        """A copy of the current design dictionary."""
        with self._lock:
            return copy.deepcopy(self._current.design)

    def snapshot(self) -> tuple[int, dict]:
        """``(version, design)`` read together (a copy of the design)."""
        with self._lock:
            return self._current.version, copy.deepcopy(self._current.design)

    @property
    def built(self) -> Built:
        return self._current.built

    @property
    def version(self) -> int:
        """Increases with every change of the current design (edits, undo, redo)."""
        return self._current.version

    @property
    def can_undo(self) -> bool:
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        return bool(self._redo)

    def _build(self, data: dict) -> Built:
        return build_design(Design(data, self.source, self.base_dir))

    def _commit(self, generation: int, push: bool, data: dict, built: Built,
                text: str | None = None, coalesce: str | None = None,
                label: str | None = None, frame: dict | None = None, quick: bool = False) -> int:
        """Make ``data`` current unless a newer edit arrived while it built (under the lock)."""
        if self._builder.superseded(generation):
            raise Superseded("superseded by a newer edit")
        if push:
            if coalesce is None or coalesce != self._coalesce:
                self._undo.append(self._current.design)
                self._undo_labels.append(self._label)
                del self._undo[:-self.undo_limit]
                del self._undo_labels[:-self.undo_limit]
            self._redo.clear()
            self._redo_labels.clear()
            self._label = label or "edit"
        self._coalesce = coalesce
        self._make_current(data, built, text, frame, quick)
        return self.version

    def _notify(self, version: int) -> None:
        for listener in list(self._listeners):
            with contextlib.suppress(Exception):  # a closed page must not refuse an edit
                listener(version)

    def _make_current(self, data: dict, built: Built, text: str | None = None,
                      frame: dict | None = None, refining: bool = False) -> None:
        self._current = _Snapshot(data, built, self._current.version + 1,
                                  dumps(data) if text is None else text, frame, refining)
        self._changed.notify_all()

    # ------------------------------------------------------------- quick meshes
    def _quick(self, data: dict) -> dict | None:
        """The design to show at once while ``data`` builds in full: ``data`` with
        ``[mesh] refine = false``, or None (no previews, nothing to refine, the last full
        build was quick, or this one's is at hand)."""
        mesh = data.get("mesh")
        if not self.previews or "rulings" not in data or not isinstance(mesh, dict) \
                or mesh.get("method", "pq") != "pq" or mesh.get("refine", True) is not True \
                or self._full_seconds <= QUICK_AFTER_SECONDS:
            return None
        if self._builder.cached(data, self.source, self.base_dir)[1] is not None:
            return None
        return {**data, "mesh": {**mesh, "refine": False}}

    def _build_frame(self, generation: int, data: dict) -> tuple[Built, dict | None, bool]:
        """``(built, frame, quick)``: the build to make current for ``data`` now, and
        whether it is the quick one (:meth:`_quick`)."""
        quick = self._quick(data)
        builds = self._builder.builds
        built, frame = self._builder.build_frame(generation, data if quick is None else quick,
                                                 self.source, self.base_dir)
        if quick is None and self._builder.builds > builds:
            self._full_seconds = self._builder.last_seconds
        return built, frame, quick is not None

    def _keep_refining(self) -> None:
        """Build the current snapshot in full in the background, if it is a quick one and
        no build of it runs (an edit that took the worker stopped the last one)."""
        with self._lock:
            snap = self._current
            if not snap.refining or snap.refine_error is not None:
                return
            if self._refiner is not None and self._refiner[0] is snap and self._refiner[1].is_alive():
                return
            thread = threading.Thread(target=self._refine, args=(snap,), daemon=True,
                                      name="ruledmesh-refine")
            self._refiner = (snap, thread)
            thread.start()

    def _refine(self, snap: _Snapshot) -> None:
        """The background build of quick snapshot ``snap``: it becomes current with the full
        mesh (a new version, the same design and undo step) while ``snap`` is current."""
        error = None
        builds = self._builder.builds
        try:
            done = self._builder.refine_frame(snap.design, self.source, self.base_dir,
                                              lambda note: self._told(snap, note))
            if done is not None and self._builder.builds > builds:
                self._full_seconds = self._builder.last_seconds
        except Superseded:
            done = None                  # the designer is stopping
        except BuildTimeout as exc:
            done, error = None, f"{exc} (the quick mesh is shown: [mesh] refine = false)"
        except MemoryError:
            done, error = None, "out of memory (the quick mesh is shown: [mesh] refine = false)"
        except RuledMeshError as exc:
            done, error = None, str(exc)
        with self._lock:
            if self._current is not snap:
                return                   # an edit, undo or redo made another design current
            if done is None and error is None:
                return                   # an edit took the worker: _keep_refining starts again
            if done is None:
                self._current = dataclasses.replace(snap, version=snap.version + 1, refine_error=error)
                self._changed.notify_all()
            else:
                self._make_current(snap.design, done[0], snap.toml, done[1])
            version = self.version
        self._notify(version)

    def settled(self, timeout: float | None = None) -> bool:
        """Wait until the current mesh is the full build of the current design (not a quick
        one, :class:`Session` ``previews``); whether it is (False: timed out, or the full
        build failed: :meth:`describe`'s ``refine_error`` says why)."""
        with self._lock:
            self._keep_refining()
            ok = self._changed.wait_for(
                lambda: not self._current.refining or self._current.refine_error is not None, timeout)
            return ok and not self._current.refining

    def _full(self) -> _Snapshot:
        """The current snapshot once it is a full build (what exports write); a
        :class:`RuledMeshError` where that build failed or did not finish in time."""
        if not self.settled(self._builder_timeout()):
            with self._lock:
                error = self._current.refine_error or "the full build did not finish in time"
            raise RuledMeshError(f"the design's full mesh is not at hand: {error}")
        return self._current

    def _builder_timeout(self) -> float:
        return float(getattr(self._builder, "timeout", MAX_BUILD_SECONDS)) + 5.0

    # ------------------------------------------------------------- edits
    def replace(self, data: Mapping[str, Any], coalesce: str | None = None,
                generation: int | None = None, label: str = "design replaced") -> int:
        """Make ``data`` the current design if it builds; returns the new version.

        Parameters
        ----------
        data : mapping
            The whole design (TOML tables as dictionaries).
        coalesce : str, optional
            Consecutive edits with the same key (one handle drag, one slider
            gesture) make a single undo step.
        generation : int, optional
            Taken by :meth:`edit` when it read the design it changed.
        label : str
            What the step did, for the history list.

        Raises
        ------
        DesignError, GeometryError, ParameterError
            The edit is refused and the state is unchanged.
        Superseded
            A newer edit arrived while this one was building; it wins.
        """
        if generation is None:
            generation = self._builder.generation()
        if not isinstance(data, Mapping):
            raise DesignError(f"expected a table, got {type(data).__name__}", "design")
        candidate = _plain(data)
        check_limits(candidate, self.base_dir)
        # Parsing the TOML we would save checks the top level and that the design can be written.
        text = dumps(candidate)
        parse_design(text, self.source, self.base_dir)
        # Built outside the lock: state requests (and newer edits) never wait for a build.
        try:
            built, frame, quick = self._build_frame(generation, candidate)
            with self._lock:
                version = self._commit(generation, True, candidate, built, text, coalesce, label,
                                       frame, quick)
        finally:
            self._keep_refining()
        self._notify(version)
        return version

    def edit(self, changes: Sequence[tuple[Sequence[str | int], Any]],
             coalesce: str | None = None) -> int:
        """Apply ``(path, value)`` changes to a copy of the design, then :meth:`replace`.

        ``path`` is a list of keys and list indices, e.g. ``["curves", "c1",
        "points", 2]``; ``value=None`` deletes the key.
        """
        with self._lock:
            generation = self._builder.generation()
            data = self.design
        for path, value in changes:
            if not isinstance(path, (list, tuple)):
                raise DesignError(f"expected a list of keys, got {path!r}", "edit")
            set_path(data, list(path), value)
        return self.replace(data, coalesce, generation, edit_label(changes))

    def load_text(self, text: str) -> int:
        """Replace the design by TOML ``text`` (one undo step)."""
        design = parse_design(text, self.source, self.base_dir)
        return self.replace(design.data, label="design TOML applied")

    def _step(self, back: bool) -> int:
        name = "undo" if back else "redo"
        with self._lock:
            stack = self._undo if back else self._redo
            if not stack:
                raise ParameterError(f"nothing to {name}", name)
            generation = self._builder.generation()
            data = stack[-1]
        try:
            built, frame, quick = self._build_frame(generation, data)
            with self._lock:
                if self._builder.superseded(generation):
                    raise Superseded("superseded by a newer edit")
                stack.pop()
                labels = self._undo_labels if back else self._redo_labels
                label = labels.pop() if labels else "edit"
                (self._redo if back else self._undo).append(self._current.design)
                (self._redo_labels if back else self._undo_labels).append(self._label)
                self._label = label
                version = self._commit(generation, False, data, built, frame=frame, quick=quick)
        finally:
            self._keep_refining()
        self._notify(version)
        return version

    def undo(self) -> int:
        """Go back one edit; raises :class:`ParameterError` when there is none."""
        return self._step(True)

    def redo(self) -> int:
        """Repeat the last undone edit; raises :class:`ParameterError` when there is none."""
        return self._step(False)

    # ------------------------------------------------------------- files
    def toml(self) -> str:
        """The current design as TOML text."""
        return self._current.toml

    def inside(self, name: str, field: str = "path") -> Path:
        """The path of file ``name`` in the design's folder; refuses names leading outside."""
        return inside(self.base_dir, name, field, must_exist=True)

    def _stem(self) -> str:
        stem = self.path.stem if self.path is not None else str(
            self._current.design.get("name") or "design")
        return "".join(c for c in stem if c.isalnum() or c in "-_.").strip(".") or "design"

    def save_name(self) -> str:
        """The name :meth:`save` writes without a path: the design file, else a free name."""
        if self.path is not None:
            return str(self.path.relative_to(self.base_dir))
        stem = self._stem()
        name, k = f"{stem}.toml", 2
        while (self.base_dir / name).exists() or (self.base_dir / name).is_symlink():
            name, k = f"{stem}-{k}.toml", k + 1
        return name

    def _writable(self, name: str, overwrite: bool) -> Path:
        target = self.inside(name)
        if target.is_dir():
            raise ParameterError(f'"{target.name}" is a folder', "path")
        if target.exists() and not overwrite and target not in self._owned:
            raise OverwriteRefused(f'"{target.name}" exists in {self.base_dir} and was not '
                                   "opened in this designer; confirm to replace it", "path")
        return target

    def save(self, path: str | None = None, overwrite: bool = False) -> Path:
        """Write the current design as TOML (atomically); returns the path written.

        Parameters
        ----------
        path : str, optional
            A file name inside the design's folder; default :meth:`save_name`.
        overwrite : bool
            Replace an existing file this session did not load or write.

        Raises
        ------
        ParameterError
            A name outside the folder or not ending in ``.toml``.
        OverwriteRefused
            The file exists, is not the session's own, and ``overwrite`` is false.
        """
        from ..io import write_atomic

        name = path or self.save_name()
        if not str(name).lower().endswith(".toml"):
            raise ParameterError(f'expected a ".toml" file name, got "{Path(str(name)).name}"',
                                 "path")
        target = self._writable(str(name), overwrite)
        write_atomic(target, self.toml().encode("utf-8"))
        self._owned.add(target)
        if self.path is None:
            self.path = target
        return target

    def _writer(self, ext: str) -> tuple[str, Any]:
        """The normalised extension and the :mod:`ruledmesh.io` module writing it."""
        from .. import io

        ext = ext.lower() if ext.startswith(".") else f".{ext.lower()}"
        if ext not in io.WRITERS:
            raise ParameterError(f'cannot write "{ext}" files; known: '
                                 f'{", ".join(io.formats())}', "format")
        try:
            return ext, importlib.import_module(f"ruledmesh.io.{io.WRITERS[ext]}")
        except ImportError as exc:
            raise ExportError(f"{ext} export needs an optional package that is not installed "
                              f"({exc.name or exc}); see the install extras") from None

    def export_files(self, ext: str, target: Path) -> dict[Path, bytes]:
        """Every file ``ruledmesh build -o target`` writes for the current mesh, with its bytes.

        The main file first, then the format's companions (PLY: ``NAME.ruledmesh.ply``
        with the face kinds and generators), exactly as :func:`ruledmesh.io.save`
        writes them.
        """
        from .. import io

        ext, module = self._writer(ext)
        # The file ruledmesh build writes: the full mesh, not the quick one (previews).
        mesh = self._full().built.mesh
        io.check_finite(mesh)
        try:
            files = {Path(target): module.dumpb(mesh)}
            if hasattr(module, "companions"):
                files.update({Path(p): b for p, b in module.companions(target, mesh).items()})
        except ImportError as exc:
            raise ExportError(f"{ext} export needs an optional package that is not installed "
                              f"({exc.name or exc}); see the install extras") from None
        return files

    def export_bytes(self, ext: str) -> bytes:
        """The current mesh in the format of extension ``ext`` (see ``ruledmesh.io.WRITERS``).

        Only the main file (a download is one file): :meth:`export` also writes
        the format's companion files.
        """
        ext, _ = self._writer(ext)
        return self.export_files(ext, Path(f"design{ext}"))[Path(f"design{ext}")]

    def export(self, ext: str, path: str | None = None, overwrite: bool = False) -> Path:
        """Write the current mesh as ``ext`` (atomically) inside the design's folder.

        ``path`` defaults to ``<design name><ext>``; the rules of :meth:`save`
        about folders and overwriting apply.  Returns the path written.
        """
        from ..io import write_atomic

        ext = ext.lower() if ext.startswith(".") else f".{ext.lower()}"
        name = str(path) if path else f"{self._stem()}{ext}"
        if not name.lower().endswith(ext):
            raise ParameterError(f'expected a file name ending in "{ext}", got '
                                 f'"{Path(name).name}"', "path")
        target = self._writable(name, overwrite)
        files = self.export_files(ext, target)
        for file in files:  # every file is checked before any is written
            self._writable(str(file.relative_to(self.base_dir)), overwrite)
        # Companions first, the main file last: as ruledmesh.io.save does.
        for file, data in reversed(list(files.items())):
            write_atomic(file, data)
            self._owned.add(file)
        return target

    # ------------------------------------------------------------- page
    def describe(self) -> dict[str, Any]:
        """State for the page besides the mesh: design, undo flags, choices."""
        from .. import io
        from ..curves import CurveType
        from ..design.schema import kind_choices, kind_defaults
        from ..registry import MESH_METHODS, SURFACE_KINDS, load_plugins
        from ..rulings import Distribution

        load_plugins()
        return {
            "version": self.version,
            # The mesh is the quick one while the full build runs (previews), and stays it
            # where that build failed (refine_error: why).
            "refining": self._current.refining and self._current.refine_error is None,
            "refine_error": self._current.refine_error,
            "refine_note": self._note[1] if self._note is not None and self._note[0] is self._current
            and self._current.refining else None,
            "design": self._current.design,
            # JSON has one number type: the page reads 3.0 as 3 and would give it an integer
            # slider; these fields are decimal in the design (dotted paths).
            "decimal_fields": _decimal_fields(self._current.design) + _decimal_fields(
                kind_defaults().get(_kind(self._current.design) or "", {})),
            "toml": self.toml(),
            "path": str(self.path) if self.path else None,
            "folder": str(self.base_dir),
            "save_name": self.save_name(),
            "can_undo": self.can_undo,
            "can_redo": self.can_redo,
            "history": self.history(),
            "choices": {
                "kinds": sorted(SURFACE_KINDS),
                # Each kind's fields at their defaults, shown while the design leaves them out.
                "kind_fields": kind_defaults(),
                "kind_choices": kind_choices(),
                "methods": sorted(MESH_METHODS),
                "formats": io.formats(),
                "distributions": [d.value for d in Distribution],
                "curve_types": [c.value for c in CurveType],
                "face_kinds": [k.label for k in FaceKind],
            },
        }

    def payload(self, topology: str | None = None) -> bytes:
        """The current state and mesh as one binary message (:func:`encode_message`).

        Parameters
        ----------
        topology : str, optional
            The fingerprint (:func:`topology_key`) of the faces the page already
            has: when the current mesh's is the same, the face arrays (triangles,
            edges, faces, kinds) are left out and ``header["same_topology"]`` is
            true; the vertices, planarity and the rest are always sent.
        """
        return self.frame(topology)[0]

    def frame(self, topology: str | None = None) -> tuple[bytes, str]:
        """:meth:`payload` and the fingerprint of the faces it describes.

        What a message holds (:func:`frame_data`) is computed once per version,
        in the build worker when it built the design, and shared by every answer
        and every open tab; only the header (history, undo flags) and the choice
        of arrays are made per call.
        """
        with self._lock:
            snap = self._current
            header = self.describe()
        parts = self._frame_parts(snap)
        same = topology == parts["key"]
        header.update(parts["header"], topology=parts["key"], same_topology=same)
        arrays = parts["live"] + ([] if same else parts["faces"]) + parts["rest"]
        return encode_message(header, arrays), parts["key"]

    def _frame_parts(self, snap: _Snapshot) -> dict[str, Any]:
        if snap.frame is not None:
            return snap.frame
        with self._frame_lock:  # two tabs asking at once compute it once
            cached = self._frame
            if cached is None or cached[0] != snap.version:
                cached = self._frame = (snap.version, frame_data(snap.design, snap.built))
            return cached[1]

    def panel(self, face: int, topology: str | None = None) -> dict[str, Any]:
        """The unrolled outline and the ``panels.csv`` row of one face of the current mesh.

        Parameters
        ----------
        face : int
            The face's number in the current mesh.
        topology : str, optional
            The fingerprint (:func:`topology_key`) of the faces ``face`` was
            chosen among (the page's faces when it was clicked).  When the
            current mesh has other faces, ``face`` may name another face (or
            none): the answer is then ``{"stale": true}`` instead of a panel.

        Returns
        -------
        dict
            ``{"version", "topology", "face", "outline": (k, 2) list,
            "row": {column: value}}``; the row has the columns of
            ``ruledmesh fabricate``'s ``panels.csv``.  A stale request gets
            ``{"version", "topology", "face", "stale": True}`` with the current
            version and fingerprint.

        Raises
        ------
        ParameterError
            ``face`` is not a face of the current mesh.
        """
        from ..fabricate.panels import panel_table
        from ..fabricate.unroll import unroll

        with self._lock:
            snap = self._current
        mesh = snap.built.mesh
        key = snap.frame["key"] if snap.frame is not None else topology_key(mesh)
        if topology is not None and topology != key:
            return {"version": snap.version, "topology": key, "face": face, "stale": True}
        if isinstance(face, bool) or not isinstance(face, int) or not 0 <= face < mesh.n_faces:
            raise ParameterError(f"expected a face index 0 .. {mesh.n_faces - 1}, got {face!r}",
                                 "face")
        if mesh.n_faces > MAX_PANEL_FACES:
            raise ParameterError(f"the panel read-out is given for meshes of up to "
                                 f"{MAX_PANEL_FACES:,} faces; this one has {mesh.n_faces:,} "
                                 "(ruledmesh fabricate writes panels.csv for any size)", "face")
        cached = self._panels
        if cached is None or cached[0] != snap.version:
            # The whole table once per version (congruence classes need every face).
            unrolled = unroll(mesh, require_planar=False)
            cached = (snap.version, panel_table(mesh, unrolled=unrolled), unrolled)
            self._panels = cached
        _, table, unrolled = cached
        row = {k: v[face].item() if hasattr(v[face], "item") else v[face]
               for k, v in table.items()}
        return {"version": snap.version, "topology": key, "face": face,
                "outline": unrolled.polygon(face).tolist(), "row": row}


def _kind(design: Mapping) -> str | None:
    """The catalogue kind of ``design``, or None (a ruled design)."""
    surface = design.get("surface")
    kind = surface.get("kind") if isinstance(surface, Mapping) else None
    return kind if isinstance(kind, str) else None


def _decimal_fields(design: Mapping, prefix: str = "") -> list[str]:
    """The dotted paths of the fields of ``design``'s tables whose values are floats."""
    out = []
    for key, value in design.items():
        path = f"{prefix}{key}"
        if isinstance(value, float):
            out.append(path)
        elif isinstance(value, Mapping):
            out += _decimal_fields(value, path + ".")
    return out


def _torsal(gens: np.ndarray, mesh: Mesh) -> np.ndarray:
    """(k,) uint32: the torsal generators, where the mesher restarts its rows.

    As the PQ mesher finds them: a pair of consecutive generators that is
    coplanar (twist :func:`ruledmesh.hop.coplanarity` within the tolerance
    ``degenerate``) marks both, a change of the twist's sign marks the
    generator where it changes.

    Parameters
    ----------
    gens : (m, 2, 3) float64
        End points of the generators.
    """
    from ..hop import coplanarity
    from ..tolerances import DEFAULT

    if len(gens) < 3:
        return np.zeros(0, np.uint32)
    a, d = gens[:, 0], gens[:, 1] - gens[:, 0]
    twist = coplanarity(a, d, mesh.diagonal() or 1.0)
    flat = np.abs(twist) <= DEFAULT.degenerate
    sign = np.sign(np.where(flat, 0.0, twist))
    flips = np.flatnonzero(sign[:-1] * sign[1:] < 0) + 1
    pairs = np.flatnonzero(flat)
    marked = np.unique(np.concatenate([flips, pairs, pairs + 1]))
    return marked.astype(np.uint32)


def _construction(design: Mapping, generators: int) -> dict[str, Any]:
    """What the page draws of the construction: the primary generator and its division."""
    mesh = design.get("mesh")
    if not isinstance(mesh, Mapping) or generators == 0:
        return {}
    primary = mesh.get("primary", "middle")
    if isinstance(primary, int) and not isinstance(primary, bool):
        index = primary % generators
    else:
        index = generators // 2  # the mesher's "middle"
    rows = mesh.get("rows", 20)
    return {"primary": index, "rows": rows if isinstance(rows, int) else 20}


def _plain(value: Any) -> Any:
    """Deep copy of TOML data as plain dicts and lists (tomllib may return other mappings)."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _is_point(value: Any) -> bool:
    return (isinstance(value, list) and len(value) == 3
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value))


def _is_points(value: Any) -> bool:
    return isinstance(value, list) and len(value) >= 1 and all(_is_point(p) for p in value)


def _curve_polylines(design: Mapping) -> tuple[list[str], list[int], np.ndarray]:
    """Sampled director curves: names, point counts and the (n, 3) points, concatenated.

    Curves that do not build are left out (the build reports their errors).
    """
    from ..design.curves import curve_from_spec

    names: list[str] = []
    counts: list[int] = []
    chunks = [np.zeros((0, 3))]
    curves = design.get("curves", {})
    if isinstance(curves, Mapping):
        for name, spec in curves.items():
            try:
                pts = np.asarray(curve_from_spec(spec, f"curves.{name}").sample(CURVE_SAMPLES),
                                 dtype=np.float64).reshape(-1, 3)
            except Exception:  # noqa: BLE001 - display only; the build reports the error
                continue
            names.append(name)
            counts.append(len(pts))
            chunks.append(pts)
    return names, counts, np.concatenate(chunks)


# Point-valued keys of [surface] tables that are positions (dragging them makes sense);
# other 3-vectors (axes, normals) are directions and stay fields of the TOML pane.
_POSITION_KEYS = ("center", "origin", "apex", "base", "start", "end")


def _handles(design: Mapping, mesh: Mesh) -> list[dict[str, Any]]:
    """Draggable points of the design: control points, directrix points, plane normal.

    Each handle is ``{path, position, kind}`` with ``kind`` ``"point"`` (the
    position is the value at ``path``) or ``"normal"`` (the value at ``path``
    is the direction from ``anchor`` to the position).
    """
    handles: list[dict[str, Any]] = []

    def points(path: list, value: Any, label: str) -> None:
        if _is_points(value):
            for i, p in enumerate(value):
                handles.append({"path": [*path, i], "position": p, "kind": "point",
                                "label": f"{label}[{i}]"})
        elif _is_point(value):
            handles.append({"path": path, "position": value, "kind": "point", "label": label})

    curves = design.get("curves", {})
    if isinstance(curves, Mapping):
        for name, spec in curves.items():
            if isinstance(spec, Mapping):
                points(["curves", name, "points"], spec.get("points"), f"{name}.points")
                points(["curves", name, "center"], spec.get("center"), f"{name}.center")
    rulings = design.get("rulings", {})
    if isinstance(rulings, Mapping):
        points(["rulings", "directrix"], rulings.get("directrix"), "directrix")
        conoid = rulings.get("conoid")
        if isinstance(conoid, Mapping):
            points(["rulings", "conoid", "directrix"], conoid.get("directrix"), "directrix")
        for path, normal in ((["rulings", "director_plane"], rulings.get("director_plane")),
                             (["rulings", "conoid", "director_plane"],
                              conoid.get("director_plane") if isinstance(conoid, Mapping) else None)):
            if _is_point(normal) and mesh.n_vertices:
                n = np.asarray(normal, dtype=float)
                norm = float(np.linalg.norm(n))
                if norm > 0:
                    box = mesh.bounding_box()
                    anchor = box.mean(axis=0)
                    length = 0.35 * (mesh.diagonal() or 1.0)
                    handles.append({"path": path, "kind": "normal", "anchor": anchor.tolist(),
                                    "position": (anchor + n / norm * length).tolist(),
                                    "label": "director plane normal"})
    surface = design.get("surface", {})
    if isinstance(surface, Mapping):
        for key, value in surface.items():
            if (_is_points(value) and len(value) >= 2) or key in _POSITION_KEYS:
                points(["surface", key], value, key)
            elif isinstance(value, Mapping) and _is_point(value.get("point")):
                # an axis {point, direction}: the point, and the direction as a normal handle
                points(["surface", key, "point"], value["point"], f"{key}.point")
                _direction_handle(handles, ["surface", key, "direction"], value.get("direction"),
                                  np.asarray(value["point"], float), mesh, f"{key}.direction")
            elif isinstance(value, Mapping) and isinstance(value.get("type"), str):
                # a curve of the surface (a pipe's spine, a meridian, a translational p or q):
                # its control points and its centre or vertex
                for sub in ("points", "center", "vertex"):
                    points(["surface", key, sub], value.get(sub), f"{key}.{sub}")
        if _is_point(surface.get("direction")) and mesh.n_vertices:
            # a prism's direction, from the centre of its polygon (else of the mesh)
            base = surface.get("polygon")
            anchor = (np.asarray(base, float).mean(axis=0) if _is_points(base)
                      else mesh.bounding_box().mean(axis=0))
            _direction_handle(handles, ["surface", "direction"], surface["direction"], anchor,
                              mesh, "direction")
        _size_handles(handles, surface, mesh)
    return handles


# Length fields of catalogue surfaces with a handle: the axis it is measured along from the
# surface's centre, and the distance per unit of the field (height: half above the centre).
_SIZE_KEYS = {"R": (0, 1.0), "radius": (0, 1.0), "a": (0, 1.0), "r": (1, 1.0), "b": (1, 1.0),
              "c": (2, 1.0), "height": (2, 0.5)}


def _direction_handle(handles: list, path: list, direction: Any, anchor: np.ndarray, mesh: Mesh,
                      label: str) -> None:
    if not _is_point(direction) or not mesh.n_vertices:
        return
    n = np.asarray(direction, dtype=float)
    norm = float(np.linalg.norm(n))
    if norm > 0:
        length = 0.35 * (mesh.diagonal() or 1.0)
        handles.append({"path": path, "kind": "normal", "anchor": anchor.tolist(),
                        "position": (anchor + n / norm * length).tolist(), "label": label})


def _size_handles(handles: list, surface: Mapping, mesh: Mesh) -> None:
    """Handles for a catalogue surface's lengths (radius, R, r, a, b, c, height).

    Each is ``{"kind": "size", "anchor", "axis", "scale", "position"}``: the
    handle sits at ``anchor + value * scale * axis`` and moves along ``axis``.
    """
    if not mesh.n_vertices:
        return
    centre = mesh.bounding_box().mean(axis=0)
    for key, (axis, scale) in _SIZE_KEYS.items():
        value = surface.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value <= 0:
            continue
        unit = np.eye(3)[axis]
        anchor = centre
        big = surface.get("R")
        if key == "r" and isinstance(big, (int, float)) and not isinstance(big, bool):
            anchor, unit = centre + big * np.eye(3)[0], np.eye(3)[0]  # the tube about R
        handles.append({"path": ["surface", key], "kind": "size", "anchor": anchor.tolist(),
                        "axis": unit.tolist(), "scale": scale,
                        "position": (anchor + value * scale * unit).tolist(), "label": key})
    axes = surface.get("axes")
    if isinstance(axes, list) and _is_point(axes) and all(v > 0 for v in axes):
        # an ellipsoid's semi-axes a, b, c: one handle along X, Y and Z each
        for i, value in enumerate(axes):
            unit = np.eye(3)[i]
            handles.append({"path": ["surface", "axes", i], "kind": "size",
                            "anchor": centre.tolist(), "axis": unit.tolist(), "scale": 1.0,
                            "position": (centre + value * unit).tolist(), "label": f"axes[{i}]"})
