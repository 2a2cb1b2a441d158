"""The §4.3 PQ mesher: generators in, a trimmed PQ mesh out."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from enum import Enum

import numpy as np

from ..._arrays import member, unique
from ..._validation import check_bool, check_choice, check_float, check_int, check_points, describe
from ...analysis.asymptotic import SLENDER_DEG, SLENDER_ELONGATION, crossing_angles, slender_share
from ...analysis.faces import SPLINTER_DEG
from ...errors import GeometryError, ParameterError
from ...hop import coplanarity, sense_changes
from ...mesh import Mesh
from ...normalise import normalised
from ...tolerances import (
    DEFAULT,
    NEARLY_DEVELOPABLE,
    PARAMETER_SLACK,
    SPAN_HALVED_ABOVE,
    SPAN_MAX_GAP,
    TINY,
    Tolerances,
)
from .assemble import assemble
from .collapses import _border_vertices, _touching, collapse_splinters
from .corners import rezip_corners
from .flips import flip_splinters, flip_triangles
from .halving import halve_spanning_triangles
from .maps import HopMaps, hop_maps
from .pairing import pair_triangles
from .panels import split_strip_quads
from .respacing import evened, spread_generators
from .reuse import assembled, remember, runs_digest
from .runs import (
    BOTH_ENDS,
    BYTES_PER_GRID_POINT,
    MAX_GRID_POINTS,
    Division,
    Run,
    carrier,
    graded_carrier,
    matched,
    mesh_run,
)
from .splinters import open_walled_splinters, snap_to_border, trim_border_needles

__all__ = ["PrimaryDivision", "RowsFrom", "pq_mesh"]

# A run restarts on a generator where this share of its faces on the patch (and
# at least two) would not be convex; the shared generator costs one strip of
# well-shaped triangles, a bow-tie split costs two splinters per face.
_RESTART_SHARE = 0.05
# Runs shorter than this are not cut further (each cut costs a strip of triangles).
_MIN_RUN = 4
# A run most of whose faces on the patch would not be convex is not meshed as a run.
_HOPELESS_SHARE = 0.3
# A strip narrower than this share of a row step everywhere is too narrow for a zipper.
_NARROW = 0.5
# Generators closer than this share of a row step everywhere count as one.
_DOUBLE = 0.01
# A segment (between torsal strips) whose run has this share of its faces failing
# carries no rows: cutting it would leave short runs of slivers.
_NO_ROWS_SHARE = 0.5
# A build with more than this share of its area outside quads says why.
_WARN_SHARE = 0.3
# ... and names slender regions as a cause from this share of the area on.
_SAY_SLENDER = 0.05
# Tolerance mode pairs triangles into quads planar within this share of the stated tolerance.
_PAIRING_MARGIN = 0.9


@dataclass(frozen=True)
class _Segment:
    """Generators ``lo..hi`` (inclusive) meshed without crossing a torsal generator."""

    lo: int
    hi: int
    shared_lo: bool      # lo is shared with the previous segment (else a gap strip lo-1)
    shared_hi: bool


def _segments(m: int, shared: np.ndarray, gaps: np.ndarray) -> list[_Segment]:
    """Cut 0..m-1 at shared generators and at gap strips."""
    events = sorted([(int(k), 0) for k in shared] + [(int(s), 1) for s in gaps])
    out: list[_Segment] = []
    lo, lo_shared = 0, False
    for pos, kind in events:
        if kind == 0 and lo < pos:
            out.append(_Segment(lo, pos, lo_shared, True))
            lo, lo_shared = pos, True
        elif kind == 1 and lo <= pos:
            out.append(_Segment(lo, pos, lo_shared, False))
            lo, lo_shared = pos + 1, False
    if lo <= m - 1:
        out.append(_Segment(lo, m - 1, lo_shared, False))
    return out


@dataclass(frozen=True)
class _Plan:
    """Everything a segment build needs besides its range."""

    a: np.ndarray
    d: np.ndarray
    tol: Tolerances
    scale: float
    warnings: list
    # (m,) where the rows of a segment with a division of its own start (RowsFrom.ends, -1
    # for the primary's division) and its checkerboard colour, by the generator they start from.
    ends: np.ndarray
    options: np.ndarray
    crease_generators: frozenset = frozenset()
    hops: HopMaps | None = None     # of all the generators: each run takes its part
    respace: bool = False           # restart where the rows spread (.respacing)
    thin: bool = False              # thin the rows where they fail towards a torsal generator
    # [lo, hi, ends, option] of each segment built with a division of its own (_build_all).
    own: list = field(default_factory=list)
    # Generators where a stretch was left without rows that thinned rows could have taken
    # (without ``thin``: _past_hopeless), for the info's ``thinnable``.
    unthinned: list = field(default_factory=list)

    def division(self, div: Division, lo: int, hi: int, primary: int) -> Division:
        """``div`` with the end points and the colour of the segment ``lo..hi`` (rows from
        global generator ``primary``), recorded in :attr:`own`: what a segment's division
        takes from :func:`pq_mesh`'s ``rows_from`` and ``option``, not from ``div``."""
        e = int(self.ends[primary])
        div = replace(div, ends=None if e < 0 else e, option=int(self.options[primary]))
        self.own.append([lo, hi, -1 if div.ends is None else div.ends, div.option])
        return div


def _cut_at(run: Run, lo: int, primary: int, m: int, plan: _Plan, rows: int) -> tuple[int | None, int | None]:
    """Run-local generators where the run (from global generator ``lo``) must restart (right
    of, left of the primary)."""
    bad = (run.failing >= 2) & (run.failing >= _RESTART_SHARE * np.maximum(run.on_patch, 1))
    if plan.respace:
        bad |= spread_generators(run.t, run.gen, run.far, lo, m, rows)
    right = [k for k in np.flatnonzero(bad) if k >= primary + 3 and m - k >= 2]
    left = [k for k in np.flatnonzero(bad) if k <= primary - 3 and k >= 1]
    return (int(right[0]) if right else None), (int(left[-1]) if left else None)


def _uniform_t(rows: int) -> np.ndarray:
    return np.linspace(0.0, 1.0, max(rows // 2, 1) + 1)


def _hopeless(run: Run, share: float = _HOPELESS_SHARE) -> bool:
    """Most of the run's faces on the patch would fail: rows bunch (K near 0)."""
    return bool(run.failing.sum() > share * max(run.on_patch.sum(), 1))


def _bad_generators(run: Run) -> np.ndarray:
    """Run-local generators where too many faces on the patch would not be convex."""
    return np.flatnonzero((run.failing >= 2)
                          & (run.failing >= _RESTART_SHARE * np.maximum(run.on_patch, 1)))


def _even(plan: _Plan, lo: int, hi: int, rows: int, graded: bool = False) -> list[Run]:
    """Generators lo..hi carrying an even division (no hops); ``graded`` where the strips
    pinch (:func:`.runs.graded_carrier`).

    Only a mesh without rows (``rows_from = "none"``) grades its divisions.  Between the
    runs of a mesh with rows, the pinches that even stretches meet (the Plücker conoid's
    double line) are already left without splinters by the flips and collapses, and graded
    there they cost more than they gave: on the regression surfaces 8.1 -> 8.9 % of the area
    in triangles with 1.6 times the faces (plucker-conoid), 5.1 -> 5.6 %
    (skew-bspline-51x30 with a tolerance), one random design 8.3 -> 9.0 %.
    """
    if hi < lo:
        return []
    if graded:
        return [graded_carrier(plan.a, plan.d, lo, hi, _uniform_t(rows))]
    return [carrier(plan.a[lo:hi + 1], plan.d[lo:hi + 1], lo, _uniform_t(rows))]


def _build_segment(plan: _Plan, lo: int, hi: int, primary: int, div: Division,
                   budget: list[int], shared: int | None = None, home: bool = False) -> list[Run]:
    """Runs covering generators lo..hi, restarted where the chains drift apart.

    ``shared`` is the end generator (lo or hi) that the run this one continues
    already carries, or None.  Where restarting does not help (the rows bunch
    along the generators, as they do near a torsal generator), the generators
    carry an even division instead and their strips are closed by strip quads
    or triangles of good shape.
    """
    a, d = plan.a, plan.d
    if hi - lo + 1 < 3:
        t = div.matched if div.matched is not None and len(div.matched) else _uniform_t(div.rows)
        return [carrier(a[lo:hi + 1], d[lo:hi + 1], lo, t)]
    run = mesh_run(a[lo:hi + 1], d[lo:hi + 1], lo, primary, div, plan.tol, plan.scale, plan.warnings,
                   plan.hops)
    m = hi - lo + 1
    if shared is None and _hopeless(run, _NO_ROWS_SHARE):
        # Most faces would be bow-ties or slivers: from the best-twisted primary if
        # the rows did not start there; else the segment carries no rows, unless it
        # holds the primary (its runs are cut where the faces fail instead).
        better = _well_twisted(plan, lo, hi)
        if better != primary:
            return _build_segment(plan, lo, hi, better, div, budget, home=home)
        if not home or m < 2 * _MIN_RUN:
            return _even(plan, lo, hi, div.rows)
    if shared is not None and _hopeless(run):
        return _past_hopeless(plan, run, lo, hi, primary, div, budget, shared)
    cut = budget[0] > 0 and m >= 2 * _MIN_RUN
    right, left = _cut_at(run, lo, primary, m, plan, div.rows) if cut else (None, None)
    if right is None and left is None:
        return [run]
    budget[0] -= (right is not None) + (left is not None)
    new_lo = lo + (left if left is not None else 0)
    new_hi = lo + (right if right is not None else m - 1)
    run = mesh_run(a[new_lo:new_hi + 1], d[new_lo:new_hi + 1], new_lo, primary - (new_lo - lo), div,
                   plan.tol, plan.scale, plan.warnings, plan.hops)
    runs = [run]
    if right is not None:
        runs += _build_segment(plan, new_hi, hi, 0, matched(div, _handed_on(plan, run, new_hi, div)),
                               budget, shared=new_hi)
    if left is not None:
        runs += _build_segment(plan, lo, new_lo, new_lo - lo,
                               matched(div, _handed_on(plan, run, new_lo, div)), budget, shared=new_lo)
    return runs


def _past_hopeless(plan: _Plan, run: Run, lo: int, hi: int, primary: int, div: Division,
                   budget: list[int], shared: int) -> list[Run]:
    """Runs for ``lo..hi`` where ``run``, continuing another from generator ``shared`` (its
    primary), has most of its faces failing: the part next to ``shared`` where they are
    still convex, then the rest without rows (an even division).

    With ``plan.thin`` the rest keeps rows where it can.  Rows fail towards a torsal
    generator because its faces grow slender there (:mod:`ruledmesh.analysis.asymptotic`),
    and with every other row left out they are twice as long along the generators.  So
    the rest restarts with the rows thinned (:func:`_thinned`) from the farthest generator
    of that part where a seam may lie (:func:`_thinnable`), as a segment of its own, which
    thins them again where they fail again.
    """
    a, d = plan.a, plan.d
    bad = _bad_generators(run)
    outward = 1 if shared == lo else -1
    dist = (bad - primary) * outward
    dist = dist[dist > 0]
    if dist.size == 0:
        return [run]
    reach = int(dist.min())
    # The seams tried, farthest first: generators of the part kept, or ``shared`` itself.
    first = _thinned(div)
    for j in [] if first is None else [0] if reach < 3 else [*range(reach, 1, -1), 0]:
        seam = shared + outward * j
        if not _thinnable(plan, seam):
            continue
        if not plan.thin:
            plan.unthinned.append(seam)
            break
        if j == 0 and first is not None:
            return _build_segment(plan, lo, hi, primary, first, budget, shared)
        r0, r1 = (lo, seam) if shared == lo else (seam, hi)
        near = mesh_run(a[r0:r1 + 1], d[r0:r1 + 1], r0, shared - r0, div, plan.tol, plan.scale,
                        plan.warnings, plan.hops)
        if (thin := _thinned(matched(div, _handed_on(plan, near, seam, div)))) is None:
            continue
        rest = _build_segment(plan, seam, hi, 0, thin, budget, shared=seam) if shared == lo else \
            _build_segment(plan, lo, seam, seam - lo, thin, budget, shared=seam)
        return [near] + rest
    if reach < 3:
        return _even(plan, lo + 1, hi, div.rows) if shared == lo else _even(plan, lo, hi - 1, div.rows)
    k = primary + outward * reach
    r0, r1 = (lo, lo + k) if shared == lo else (lo + k, hi)
    near = mesh_run(a[r0:r1 + 1], d[r0:r1 + 1], r0, primary - (r0 - lo), div, plan.tol, plan.scale,
                    plan.warnings, plan.hops)
    rest = _even(plan, r1 + 1, hi, div.rows) if shared == lo else _even(plan, lo, r0 - 1, div.rows)
    return [near] + rest


def _thinnable(plan: _Plan, g: int) -> bool:
    """Whether the hop lines cross generator ``g`` at :data:`_THIN_MIN_DEG` or more all over
    the patch (and ``g`` has neighbours on both sides): a seam of thinned rows may lie there."""
    if not 0 < g < len(plan.a) - 1:
        return False
    near = slice(g - 1, g + 2)
    angles, _ = crossing_angles(plan.a[near], plan.a[near] + plan.d[near], _SEAM_T)
    return bool(angles.min() >= _THIN_MIN_DEG)


def _thinned(div: Division) -> Division | None:
    """``div``'s matched division with every other row left out (its end rows kept), or None
    where it would keep fewer than :data:`_MIN_THINNED` rows."""
    if div.matched is None or len(div.matched) < 2 * _MIN_THINNED:
        return None
    t = div.matched[::2] if len(div.matched) % 2 else np.r_[div.matched[:-1:2], div.matched[-1]]
    return replace(div, matched=t)


_MIN_THINNED = 6
# The triangles where thinned rows meet the others are halves of exact faces, whose smallest
# angle is about half the angle at which the face's diagonals cross: a seam keeps clear of
# the worst splinters only where the hop lines cross the generator at twice the splinter bar.
# (Not of all: the thinned side's halves are fanned at the rows left out, and a fan triangle
# can be thinner still: 2.86 degrees on a random surface.  Four times the bar left
# skew-bspline-301x300 without any thinning, and that splinter where it was.)
_THIN_MIN_DEG = 2.0 * SPLINTER_DEG
_SEAM_T = np.linspace(0.0, 1.0, 9)


def _handed_on(plan: _Plan, run: Run, g: int, div: Division) -> np.ndarray:
    """The division a restart on global generator ``g`` takes from ``run``: its vertices
    there, evened where the rows are respaced."""
    t = run.inside_t(g)
    return evened(t, div.rows) if plan.respace else t


def _torsal_cuts(a, d, scale, tol, creases, m):
    """Torsal strips: coplanar pairs (flat), the twist changing sign (change), creases."""
    twist = coplanarity(a, d, scale)
    flat = np.abs(twist) <= tol.degenerate
    change = sense_changes(twist, flat)
    crease = np.zeros(len(twist), bool)
    if creases is not None:
        cr = np.asarray(creases, dtype=np.int64).reshape(-1)
        if cr.size and (cr.min() < 0 or cr.max() >= m - 1):
            raise ParameterError(f"expected pair indices in [0, {m - 2}], got {cr.tolist()}", "creases")
        crease[cr] = True
    return flat, change, crease


def _single_generators(a: np.ndarray, d: np.ndarray, rows: int, warnings: list[str]) -> np.ndarray:
    """Indices of the generators kept: one of each run of generators that nearly coincide.

    Two generators a hundredth of a row step apart (a sample next to a kink, a
    generator given twice) bound a strip no face can fill without slivers; the
    second is left out, and every vertex still lies on a given generator.
    """
    m = len(a)
    double = _strip_gaps(a, d, rows) < _DOUBLE
    if not double.any():
        return np.arange(m)
    keep = np.r_[True, ~double]
    if not keep[-1]:
        # Keep the last generator (the border); leave out the one before it instead.
        last_kept = np.flatnonzero(keep[:-1])[-1]
        keep[-1], keep[last_kept] = True, last_kept == 0
    dropped = np.flatnonzero(~keep)
    if m - dropped.size < 3:
        return np.arange(m)
    warnings.append(f"{dropped.size} generators nearly coincide with a neighbour and were left out "
                    f"(generators {', '.join(map(str, dropped[:8].tolist()))}"
                    f"{' ...' if dropped.size > 8 else ''})")
    return np.flatnonzero(keep)


def _keep(kept: np.ndarray, a: np.ndarray, d: np.ndarray, creases, crease_generators):
    """The kept generators, and the crease indices in their numbering."""
    if kept.size == len(a):
        return a, d, creases, crease_generators

    def renumber(ks):
        return None if ks is None else np.searchsorted(kept, np.asarray(ks, np.int64), side="right") - 1

    return a[kept], d[kept], renumber(creases), renumber(crease_generators)


def _renumbered(mesh: Mesh, kept: np.ndarray) -> Mesh:
    """The mesh with generator indices of the kept generators mapped back to the given ones."""
    vdata = dict(mesh.vertex_data)
    vdata["generator"] = kept[np.asarray(vdata["generator"], np.int64)]
    return Mesh(mesh.vertices, mesh.face_offsets, mesh.face_indices, mesh.face_kind, mesh.members,
                kept[mesh.member_id], vdata, mesh.info)


def _narrow_strips(a: np.ndarray, d: np.ndarray, rows: int) -> np.ndarray:
    """(m - 1,) bool: strips whose two generators are nowhere a row step's share apart.

    Indexed like the twists (strip ``k`` between generators ``k`` and ``k + 1``)
    and padded to that length.
    """
    return _strip_gaps(a, d, rows) < _NARROW


def _strip_gaps(a: np.ndarray, d: np.ndarray, rows: int) -> np.ndarray:
    """(m - 1,) largest distance of consecutive generators (at t = 0, 1/2, 1), in row steps."""
    gap = np.max([np.linalg.norm((a[1:] + t * d[1:]) - (a[:-1] + t * d[:-1]), axis=1)
                  for t in (0.0, 0.5, 1.0)], axis=0)
    return gap / (np.linalg.norm(d[:-1], axis=1) / max(rows, 1))


def _listed(ks: np.ndarray) -> str:
    return ", ".join(f"{k}-{k + 1}" for k in ks[:8].tolist()) + (" ..." if ks.size > 8 else "")


@normalised  # meshes in a unit frame: results do not depend on scale
def pq_mesh(a, b, rows: int = 20, primary: int | str = "middle", option: int = 0,
            extend: float | str = "auto", trim: bool = True, *, max_extend: float = 20.0,
            creases=None, crease_generators=None, planarity_tolerance: float | None = None,
            respace: bool = False, rows_from: str | Sequence[str] = "primary",
            division: str = "even", thin: bool = False, tol: Tolerances = DEFAULT) -> Mesh:
    """The §4.3 PQ mesh of the ruled surface through generators ``a_i b_i``.

    Parameters
    ----------
    a, b : (m, 3) array_like
        Generator end points; ``t = 0`` at ``a`` (director curve c1), ``t = 1``
        at ``b`` (c2).  ``m >= 3``.
    rows : int
        Divisions of the primary generator between ``t = 0`` and ``t = 1``.
    primary : int or "middle"
        Index of the primary generator (negative: from the end).
    option : {0, 1} or (m,) sequence of them
        The checkerboard colour carrying the vertices (the paper's two options); as ``rows_from``.
    extend : "auto", "full" or float
        How far the division of the primary continues beyond ``[0, 1]`` (in its lengths);
        ``"auto"`` covers the patch on every generator, leaving out rows that would bunch
        (:mod:`.extension`); ``"full"`` keeps every row.
    trim : bool
        Trim the faces to the patch ``0 <= t <= 1``, every vertex staying on a generator.
    max_extend : float
        Cap of the automatic extension (in the primary's lengths).
    creases, crease_generators : (k,) int, optional
        Strips ``i`` (generators ``i`` to ``i + 1``) holding a crease (a kink of a director
        curve), closed by triangles; generators through a kink, where the rows restart with a
        matched division.
    planarity_tolerance : float, optional
        Relative planarity (the paper's measure, as :func:`ruledmesh.analysis.planarity`)
        that strip quads between nearly coplanar generators may have; default
        ``tol.planarity`` (exact to rounding).
    respace : bool
        Also restart the rows where they spread, evened there (:mod:`.respacing`).
    rows_from : {"primary", "c1", "c2", "both", "none"} or (m,) sequence of them
        Where the rows start (:class:`RowsFrom`; ``"none"``: no rows); per generator, a segment
        with a division of its own (between torsal generators) takes the value where its rows start.
    division : {"even", "graded", "bounded"}
        The primary's steps: even, or graded for faces of even shape wherever the rows land,
        or graded with the steps at the rims bounded (:class:`PrimaryDivision`).
    thin : bool
        Restart runs failing towards a torsal generator with every other row left out, not
        leaving the rest without rows (:func:`_past_hopeless`; its seams may hold splinters).
    tol : Tolerances

    Returns
    -------
    Mesh
        Faces of kind QUAD, BORDER (reaching a director curve), STRIP (between coplanar generators),
        FILL (notch, torsal, border triangles) and SPLIT (halves of quads that were not convex);
        members are the generator segments between vertices; ``vertex_data`` holds ``t`` and
        ``generator``; ``info`` the ``warnings``, ``runs``, ``restarts``, ``option``, ``primary``,
        ``division``, ``rows_from`` (``"mixed"`` if segments differ; ``row_segments``: ``[lo, hi,
        rows_from, option]`` each), ``thin``, ``thinnable`` (stretches ``thin`` would give rows),
        ``off_generators`` (:func:`_warn_off_generators`), the passes' counts (``flips``, ...).

    Raises
    ------
    ParameterError
        For bad arguments.
    GeometryError
        For zero-length generators or a grid too large to build.

    Examples
    --------
    Generators of one regulus of the hyperboloid x^2 + y^2 - z^2 = 1:

    >>> import numpy as np
    >>> phi = np.linspace(0, np.pi, 12)
    >>> a = np.stack([np.cos(phi) - np.sin(phi), np.sin(phi) + np.cos(phi), -np.ones(12)], 1)
    >>> b = np.stack([np.cos(phi) + np.sin(phi), np.sin(phi) - np.cos(phi), np.ones(12)], 1)
    >>> v = pq_mesh(a, b, rows=10).vertices
    >>> bool(np.abs(v[:, 0]**2 + v[:, 1]**2 - v[:, 2]**2 - 1).max() < 1e-12)
    True
    """
    a, b, args = _checked(a, b, rows, primary, option, extend, trim, max_extend,
                          planarity_tolerance, respace, tol, rows_from, division, thin)
    rows, ptol, d = args.rows, args.ptol, b - a
    scale = _patch_scale(a, b, d, tol)
    warnings: list[str] = []
    kept = _single_generators(a, d, rows, warnings)
    m_given, m, (a, d, creases, crease_generators) = len(a), len(kept), _keep(kept, a, d, creases, crease_generators)
    flat, torsal, cg, segs = _cut(a, d, rows, ptol, scale, tol, creases, crease_generators, warnings)
    plan = _Plan(a, d, tol, scale, warnings, args.ends[kept], args.option[kept], frozenset(cg.tolist()),
                 hop_maps(a, d), args.respace, args.thin)
    primary = int(np.searchsorted(kept, args.primary, side="right") - 1)
    parts = _build_all(plan, segs, primary, args.middle, Division(
        rows, 0, args.extend, args.max_extend, graded=args.division != "even", bounded=args.division == "bounded"), m)
    even = _even_ranges(parts, segs, warnings, exact=ptol <= tol.planarity, own=plan.own)
    known = _Causes.of(parts, segs, torsal.size, even)    # before assemble() empties parts
    meet, runs = np.r_[flat, False] | np.r_[False, flat], len(parts)    # meet: of a coplanar pair
    mesh, fattening, measured, spans = _assembled(parts, a, d, args.trim, tol, ptol, warnings, scale, meet, rows)
    _warn_share(mesh, warnings, known, m, rows, (a, d, ptol), measured)
    passes = {**fattening, "off_generators": _warn_faces(mesh, warnings, torsal, measured, (a, d), spans)}
    if kept.size < m_given:
        mesh = _renumbered(mesh, kept)
    return mesh.with_info(runs=runs, restarts=known.restarts, **_options_info(plan, args, kept), **passes)


def _assembled(parts: list[Run], a, d, trim: bool, tol: Tolerances, ptol: float, warnings: list[str],
               scale: float, meet: np.ndarray, rows: int) -> tuple[Mesh, dict[str, int], tuple | None, tuple]:
    """The runs assembled and the passes after (:func:`~.assemble.assemble`, :func:`_fattened`),
    once per distinct set of runs where a caller is reusing assemblies (:mod:`.reuse`)."""
    key = runs_digest(parts, (a, d, meet), (trim, tol, ptol, scale, rows))
    if (hit := assembled(key)) is not None:
        mesh, *rest, said = hit
        warnings.extend(said)
        return (mesh.with_info(warnings=warnings), *rest)
    n = len(warnings)
    mesh, fattening, measured, spans = _fattened(assemble(parts, a, d, trim, tol, ptol, warnings, scale, meet,
                                                          rows=rows), ptol, tol, (a, d))
    remember(key, (mesh, fattening, measured, spans, tuple(warnings[n:])))
    return mesh, fattening, measured, spans


def _options_info(plan: _Plan, args: _Args, kept: np.ndarray) -> dict:
    """The info of :func:`pq_mesh` that says how its rows were made (``kept``: the generators
    meshed, of those given)."""
    return dict(planarity_tolerance=args.ptol, extend=args.extend, respace=plan.respace,
                division=args.division, thin=plan.thin, thinnable=len(plan.unthinned),
                **_rows_from_info(plan.own, kept), primary="middle" if args.middle else args.primary)


def _cut(a, d, rows, ptol, scale, tol, creases, crease_generators, warnings):
    """Torsal strips and creases: (flat strips, torsal strips, crease generators, segments)."""
    m = len(a)
    # Torsal generators cut the generators into segments: where the twist changes
    # sign (hops across would reverse the rows), at a coplanar pair, or at a crease
    # inside a strip, that strip is left to be closed by strip quads (planar for a
    # coplanar pair) or triangles (§4.3).  The segments do not share the generator:
    # each takes its own division, and two divisions on one line would leave
    # zero-width slivers between them.
    flat, change, crease = _torsal_cuts(a, d, scale, tol, creases, m)
    if ptol > tol.planarity:
        flat = flat | _nearly_flat(a, d, rows, ptol)
    torsal = _say_cuts(flat, change, crease, warnings)
    cg = _crease_generators(crease_generators, m)
    # A sign change across a strip much narrower than a row step (the generators
    # nearly coincide) is shared instead: a zipper there would be all slivers.
    narrow = change & ~flat & ~crease & _narrow_strips(a, d, rows)
    segs = _segments(m, unique(np.r_[np.flatnonzero(narrow), cg]),
                     np.flatnonzero(flat | crease | (change & ~narrow)))
    return flat, torsal, cg, segs


def _fattened(mesh: Mesh, ptol: float, tol: Tolerances, lines: tuple[np.ndarray, np.ndarray]
              ) -> tuple[Mesh, dict[str, int], tuple | None, tuple[np.ndarray, np.ndarray]]:
    """Flip the triangles for their angles, collapse what flips cannot fatten, pair the
    triangles in tolerance mode, flip what is left; then the splinters left: corners a
    sliver from the border snapped onto it, quads walling a splinter opened, patch corners
    with a splinter re-cut (:mod:`.corners`); strip quads much larger than the other
    panels cut; last, triangles lying off the generators they span halved
    (:mod:`.halving`; ``lines``: the generators ``(a, d)``).

    The third result: the (F,) smallest angles and areas of the faces of the mesh
    returned, where the opening measured them and left the mesh as it was (else None).
    The fourth: the triangles across strips and how far each lies off the generators
    it spans (:func:`.halving.halve_spanning_triangles`).
    The caller does not keep ``mesh``, so each pass frees the mesh it replaces (a
    1000 x 1000 build's is 50 MB).

    A flip or pairing run after the first weighs only the faces near what the passes
    since changed (:class:`_Changes`): elsewhere it would find nothing new, and on a large
    mesh a whole run costs a tenth of a second or more for a collapse or two.
    """
    mesh, snapped = snap_to_border(mesh)
    mesh = replace(mesh, vertex_data={**mesh.vertex_data, _FID: np.arange(mesh.n_vertices)})
    unflipped, unpaired = _Changes(), _Changes()
    report: dict = {}
    mesh, flips = flip_triangles(mesh, report=report)
    unflipped.settle(mesh, report)
    mesh, trimmed = trim_border_needles(mesh, report=report)
    unflipped.add(mesh, report)
    mesh, collapsed = collapse_splinters(mesh, report=report)
    unflipped.add(mesh, report)
    if collapsed:
        mesh, more = flip_triangles(mesh, near=unflipped.near(mesh), report=report)
        unflipped.settle(mesh, report)
        flips += more
    mesh, paired = pair_triangles(mesh, _pairing_tolerance(ptol, tol), report=report)
    unpaired.settle(mesh, report)
    unflipped.add(mesh, report)
    if paired:
        mesh, more = flip_triangles(mesh, near=unflipped.near(mesh), report=report)
        unpaired.add(mesh, report)
        flips += more
    from ...analysis.faces import face_min_angles, face_normals

    measured = (face_min_angles(mesh), face_normals(mesh)[1]) if mesh.n_faces else None
    # Whether the mesh measured is the one returned (each pass returns its input where it
    # changes nothing), told without holding on to it: a large mesh is 50 MB.
    mesh, opened, same = _pass(open_walled_splinters, mesh, _reflipped, measured, report=report)
    if opened:
        unpaired.add(mesh, report)
        mesh, more = pair_triangles(mesh, _pairing_tolerance(ptol, tol), near=unpaired.near(mesh))
        paired += more
    mesh = replace(mesh, vertex_data={k: v for k, v in mesh.vertex_data.items() if k != _FID})
    mesh, more, kept = _pass(flip_splinters, mesh)
    flips += more
    mesh, corners, kept_corners = _pass(rezip_corners, mesh)
    mesh, cut, kept_too = _pass(split_strip_quads, mesh)
    mesh, halved, *spans = halve_spanning_triangles(mesh, lines, SPAN_HALVED_ABOVE * SPAN_MAX_GAP
                                                    * (mesh.diagonal() or 1.0))
    same = same and kept and kept_corners and kept_too and not halved
    return mesh, {"flips": flips, "collapsed": collapsed, "paired": paired, "snapped": snapped,
                  "trimmed": trimmed, "opened": opened, "corners": corners, "cut": cut, "halved": halved}, \
        (measured if same else None), (spans[0], spans[1])


# The persistent vertex id of :class:`_Changes`, dropped before the mesh leaves :func:`_fattened`.
_FID = "_fid"


class _Changes:
    """The vertices near which the mesh changed since a pass (the flips, the pairing) last
    settled, or None: anywhere (its last run ran out of rounds, so a later one must weigh
    the whole mesh).

    Vertices are named by ``vertex_data["_fid"]``: the passes between drop vertices and
    renumber the rest in order, and the vertex data goes with them.
    """

    def __init__(self) -> None:
        self.ids: np.ndarray | None = np.zeros(0, np.int64)

    def add(self, mesh: Mesh, report: dict) -> None:
        """Add the vertices ``report["touched"]`` (V,) bool of ``mesh`` marks."""
        if self.ids is not None:
            self.ids = unique(np.concatenate([self.ids, np.asarray(mesh.vertex_data[_FID])[report["touched"]]]))

    def settle(self, mesh: Mesh, report: dict) -> None:
        """The pass ran on ``mesh`` (its output); it settled everywhere if ``report["settled"]``,
        but near ``report["again"]`` (V,) bool, where its own changes make more worth weighing
        (a flip can leave a thin triangle, and a run over the whole mesh would weigh the
        triangles around it)."""
        self.ids = np.zeros(0, np.int64) if report["settled"] else None
        self.add(mesh, {"touched": report["again"]})

    def near(self, mesh: Mesh) -> np.ndarray | None:
        """(V,) bool of ``mesh``: the vertices changed; None: everywhere."""
        if self.ids is None:
            return None
        return member(np.asarray(mesh.vertex_data[_FID]), self.ids)


def _pass(step: Callable[..., tuple[Mesh, int]], mesh: Mesh, *args, **kwargs) -> tuple[Mesh, int, bool]:
    """``step(mesh, *args, **kwargs)``'s mesh and count, and whether that mesh is ``mesh`` itself."""
    out, n = step(mesh, *args, **kwargs)
    return out, n, out is mesh


def _reflipped(mesh: Mesh, frozen: np.ndarray, scale: float) -> Mesh:
    """Flips, collapses and flips again on an opened region of splinters.

    ``frozen`` (V,) bool marks, by ``vertex_data["_id"]``, the vertices that faces
    outside the region also have: faces at them stay, and they stay.  ``scale``
    is the whole mesh's diagonal, which the sag bounds are relative to.
    """
    def changeable(m: Mesh) -> np.ndarray:
        at = frozen[np.asarray(m.vertex_data["_id"])][m.face_indices]
        return np.bincount(m.face_of[at], minlength=m.n_faces) == 0

    mesh, _ = flip_triangles(mesh, changeable(mesh), scale)
    mesh, collapsed = collapse_splinters(mesh, ~frozen[np.asarray(mesh.vertex_data["_id"])], scale)
    if collapsed:
        mesh, _ = flip_triangles(mesh, changeable(mesh), scale)
    return mesh


class RowsFrom(str, Enum):
    """Where the rows of :func:`pq_mesh` start.

    ``PRIMARY``: the division of the primary generator (§4.3).  ``C1`` (``C2``): each row
    the director curve at ``t = 0`` (``t = 1``) cuts passes through a generator's end point
    there, so the border along that curve is edges of quads instead of a band of teeth; the
    rows are then as far apart as the end points' rows, and restarted runs keep their
    matched divisions (:func:`.runs._through_ends`).  ``BOTH``: rows through the end points
    on both curves (on a Moebius band, where the rows from one edge turn back before they
    reach the other over a stretch, those from the other edge fill it).  ``NONE``: no §4.3 rows; the generators
    carry an even division, graded where the strips pinch (:func:`.runs.graded_carrier`), and
    the strips are closed by strip quads (where planar within the tolerance) and triangles:
    the mesh of a nearly developable surface, or of one whose rows leave splinters.
    """

    PRIMARY = "primary"
    C1 = "c1"
    C2 = "c2"
    BOTH = "both"
    NONE = "none"

    @property
    def ends(self) -> int | None:
        """The end parameter the rows pass through (:data:`.runs.BOTH_ENDS`: both; None: the
        primary's division, or no rows)."""
        return {"primary": None, "c1": 0, "c2": 1, "both": BOTH_ENDS, "none": None}[self.value]


class PrimaryDivision(str, Enum):
    """How :func:`pq_mesh` divides the primary generator.

    ``EVEN``: ``rows`` even steps over the primary's part on the patch, as in the paper,
    continued beyond it where the rows reach the patch on other generators (and left out
    where they would bunch, :mod:`.extension`).  ``GRADED``: steps graded so that the faces
    are of about even shape on every generator the rows reach, the median generator
    carrying ``rows`` steps (:mod:`.grading`); on a hyperboloid close to its asymptotic
    cone the even division's far rows crowd into slivers.  ``BOUNDED``: graded, but no
    generator's step for square faces taken as more than :data:`.grading.BOUND` times their
    median, so that the rows stay close enough together at the rims for small teeth of
    triangles along the border.
    """

    EVEN = "even"
    GRADED = "graded"
    BOUNDED = "bounded"


@dataclass(frozen=True)
class _Args:
    """The mesher's arguments, checked."""

    rows: int
    primary: int
    middle: bool
    option: np.ndarray      # (m,) 0 or 1
    extend: float | str
    trim: bool
    max_extend: float
    ptol: float
    respace: bool
    ends: np.ndarray        # (m,) RowsFrom.ends, or -1 for the primary's division
    division: str = "even"  # the primary's division: "even", "graded" or "bounded"
    thin: bool = False      # thin the rows where they fail towards a torsal generator


def _checked(a, b, rows, primary, option, extend, trim, max_extend, planarity_tolerance, respace,
             tol: Tolerances, rows_from: str | Sequence[str] = "primary",
             division: str = "even", thin: bool = False) -> tuple[np.ndarray, np.ndarray, _Args]:
    """Validate the arguments of :func:`pq_mesh` (ParameterError naming the parameter)."""
    a = check_points(a, "a", min_count=3)
    b = check_points(b, "b", min_count=3)
    if a.shape != b.shape:
        raise ParameterError(f"expected the shape of a {a.shape}, got {b.shape}", "b")
    m = len(a)
    rows = check_int(rows, "rows", lo=1)
    option = _per_generator(option, m, "option", lambda v, name: check_int(v, name, lo=0, hi=1))
    trim = check_bool(trim, "trim")
    middle = isinstance(primary, str)
    if middle:
        if primary != "middle":
            raise ParameterError(f'expected "middle" or an index, got {describe(primary)}', "primary")
        p = m // 2
    else:
        p = check_int(primary, "primary", lo=-m, hi=m - 1) % m
    if not (isinstance(extend, str) and extend in ("auto", "full")):
        if isinstance(extend, str):
            raise ParameterError(f'expected "auto", "full" or a number >= 0, got {describe(extend)}',
                                 "extend")
        extend = check_float(extend, "extend", lo=0.0, hi=1e3)
    max_extend = check_float(max_extend, "max_extend", lo=0.0, hi=1e3)
    ptol = tol.planarity if planarity_tolerance is None else check_float(
        planarity_tolerance, "planarity_tolerance", lo=0.0, hi=0.1)
    _check_grid_budget(m, rows, extend)
    return a, b, _Args(rows, p, middle, option, extend, trim, max_extend, max(ptol, tol.planarity),
                       check_bool(respace, "respace"), _per_generator(rows_from, m, "rows_from", _end_of),
                       check_choice(division, PrimaryDivision, "division").value, check_bool(thin, "thin"))


# The per-generator code of RowsFrom.NONE (-1 is the primary's division, 0 and 1 the curves).
_NO_ROWS = -2


def _end_of(value, name: str) -> int:
    side = check_choice(value, RowsFrom, name)
    if side is RowsFrom.NONE:
        return _NO_ROWS
    return -1 if side.ends is None else side.ends


def _per_generator(value, m: int, name: str, check) -> np.ndarray:
    """(m,) int64: ``value`` (one, or one per generator) through ``check(value, name) -> int``."""
    if isinstance(value, str) or not hasattr(value, "__len__"):
        return np.full(m, check(value, name), np.int64)
    if len(value) != m:
        raise ParameterError(f"expected one value or one per generator ({m}), got {len(value)}", name)
    return np.array([check(v, f"{name}[{i}]") for i, v in enumerate(value)], np.int64)


_FROM_ENDS = {_NO_ROWS: RowsFrom.NONE.value, -1: RowsFrom.PRIMARY.value, 0: RowsFrom.C1.value,
              1: RowsFrom.C2.value, BOTH_ENDS: RowsFrom.BOTH.value}


def _rows_from_info(own: list, kept: np.ndarray) -> dict:
    """``rows_from``, ``option`` and ``row_segments`` of the info, in the given generators'
    numbering (``"mixed"`` where the segments differ)."""
    segments = [[int(kept[lo]), int(kept[hi]), _FROM_ENDS[e], int(o)] for lo, hi, e, o in own]

    def one(k: int):
        values = {s[k] for s in segments}
        return values.pop() if len(values) == 1 else "mixed"
    return {"rows_from": one(2), "option": one(3), "row_segments": segments}


def _check_grid_budget(m: int, rows: int, extend: float | str) -> None:
    """Refuse, before any allocation, a grid beyond the build budget (GeometryError).

    A numeric ``extend`` continues the division by ``extend`` primary lengths on
    both sides: ``rows (1 + 2 extend)`` rows.  ``"auto"`` is checked per run
    once the row maps say how far it reaches (:func:`.runs.mesh_run`).
    """
    height = (rows + 1) * (1.0 + 2.0 * (0.0 if isinstance(extend, str) else float(extend)))
    if m * height > MAX_GRID_POINTS:
        need = m * height * BYTES_PER_GRID_POINT / 2**30
        shown = f"{rows + 1} rows" + ("" if isinstance(extend, str) or not extend
                                      else f" x (1 + 2 x extend {float(extend):g})")
        raise GeometryError(f"{m} generators x {shown} would need about {need:.1f} GiB "
                            f"(limit {MAX_GRID_POINTS * BYTES_PER_GRID_POINT / 2**30:.0f} GiB); "
                            "reduce the generator count, the rows or the extension")


def _patch_scale(a: np.ndarray, b: np.ndarray, d: np.ndarray, tol: Tolerances) -> float:
    """Diagonal of the generators' bounding box; refuses zero-length generators."""
    lo, hi = np.minimum(a.min(0), b.min(0)), np.maximum(a.max(0), b.max(0))
    scale = float(np.linalg.norm(hi - lo))
    if scale == 0.0:
        raise GeometryError("all generator end points coincide")
    short = np.flatnonzero(np.linalg.norm(d, axis=1) <= tol.degenerate * scale)
    if short.size:
        raise GeometryError(f"generator {int(short[0])} has zero length (its end points coincide)"
                            + (f", and {short.size - 1} more" if short.size > 1 else ""))
    return scale


def _crease_generators(crease_generators, m: int) -> np.ndarray:
    cg = np.zeros(0, np.int64) if crease_generators is None else \
        np.asarray(crease_generators, dtype=np.int64).reshape(-1)
    if cg.size and (cg.min() < 1 or cg.max() > m - 2):
        raise ParameterError(f"expected generator indices in [1, {m - 2}], got {cg.tolist()}",
                             "crease_generators")
    return cg


def _say_cuts(flat: np.ndarray, change: np.ndarray, crease: np.ndarray,
              warnings: list[str]) -> np.ndarray:
    """Warn of torsal and crease strips; the torsal ones."""
    torsal = np.flatnonzero(flat | change)
    kinks = np.flatnonzero(crease & ~(flat | change))
    if torsal.size:
        warnings.append(f"{torsal.size} torsal strips (generators {_listed(torsal)}: consecutive "
                        "generators coplanar, or the twist changes sign): rows restarted there")
    if kinks.size:
        warnings.append(f"{kinks.size} crease strips (generators {_listed(kinks)}: a director curve "
                        "has a corner there): rows restarted, strips filled with triangles")
    return torsal


def _even_ranges(parts: list[Run], segs: list[_Segment], warnings: list[str],
                 exact: bool = True, own: Sequence = ()) -> list[str]:
    """Generator ranges that carry an even division without hops (not the short segments, nor
    those of ``own``, the ``[lo, hi, ends, option]`` of each segment with a division of its own,
    meshed without rows where the caller asked: ``rows_from = "none"``).

    The warning suggests a planarity tolerance only in exact mode (``exact``)."""
    short = {(s.lo, s.hi) for s in segs if s.hi - s.lo < 2}
    # Segments meshed without rows because the caller asked (rows_from = "none"): said so
    # by the rows_from note, not as rows that bunch.
    short |= {(lo, hi) for lo, hi, e, _ in own if e == _NO_ROWS}
    out = []
    for r in parts:
        if len(r.left) == 0 and r.gen.size:
            lo, hi = int(r.gen.min()), int(r.gen.max())
            if (lo, hi) not in short:
                out.append(f"{lo}-{hi}" if hi > lo else f"{lo}")
    if out:
        warnings.append(f"generators {', '.join(out[:8])}{' ...' if len(out) > 8 else ''} carry no "
                        "§4.3 rows (the rows bunch along the generators there: nearly developable, "
                        "or next to a torsal generator) and are closed by strip quads or triangles"
                        + "; planarity_tolerance = 1e-3 admits nearly planar strip quads there" * exact)
    return out


@dataclass(frozen=True)
class _Causes:
    """What the build knows of why area is not in quads (:func:`_warn_share`)."""

    torsal: int             # torsal generators
    even: list[str]         # generator ranges without rows
    restarts: int           # runs restarted where the chains drifted apart
    uncovered: int = 0      # generators the rows reach only through the primary's infinity

    @classmethod
    def of(cls, parts: list[Run], segs: list[_Segment], torsal: int, even: list[str]) -> _Causes:
        """The causes known from the runs ``parts`` of the segments ``segs`` (a run beyond one
        per segment of three generators or more is a restart), and the counts given."""
        restarts = max(len([r for r in parts if len(r.left)]) - len([s for s in segs if s.hi - s.lo >= 2]), 0)
        return cls(torsal, even, restarts, max((r.uncovered for r in parts), default=0))


def _warn_share(mesh: Mesh, warnings: list[str], known: _Causes, m: int, rows: int,
                generators: tuple | None = None, measured: tuple | None = None) -> None:
    """Say so when much of the area is not in quads: how much, where, why, and what to change.

    ``generators`` is ``(a, d, ptol)``: the generators, to count the strips that
    are nearly developable (their strip quads planar within
    :data:`~ruledmesh.tolerances.NEARLY_DEVELOPABLE`) and to measure the slender
    share of the area (:func:`~ruledmesh.analysis.asymptotic.slender_share`), and the build's planarity
    tolerance (in tolerance mode a tolerance is no advice); ``measured`` the (F,)
    smallest angles and areas of the faces, if known.
    """
    from ...analysis.faces import face_normals

    if mesh.n_faces == 0:
        return
    area = face_normals(mesh)[1] if measured is None else measured[1]
    total = float(area.sum()) or 1.0
    off = mesh.valences != 4
    share = float(area[off].sum()) / total
    if share <= _WARN_SHARE:
        return
    causes = []
    if known.torsal:
        causes.append(f"{known.torsal} torsal generator{'s' * (known.torsal > 1)}")
    if known.even:
        causes.append(f"no rows on generators {', '.join(known.even[:4])}")
    near_cone = known.uncovered >= max(3, m // 4)
    if near_cone:
        # A hyperboloid close to its asymptotic cone: the rows that far out crowd onto the
        # row through the primary's point at infinity, and beyond it no row lands.
        causes.append(f"a surface close to a cone: the rows reach {known.uncovered} generators only "
                      f"through the primary generator's point at infinity, so part of their patch "
                      f"has no rows")
    a, d, ptol = generators if generators is not None else (None, None, DEFAULT.planarity)
    exact = ptol <= DEFAULT.planarity
    flat = int(_nearly_flat(a, d, rows, NEARLY_DEVELOPABLE).sum()) \
        if a is not None and ptol < NEARLY_DEVELOPABLE else 0
    if flat:
        causes.append(f"{flat} strips nearly developable")
    slender = slender_share(a, a + d) if a is not None and len(a) >= 3 else 0.0
    if slender >= _SAY_SLENDER:
        causes.append(f"{slender:.0%} of the area slender (the rows would cross the generators at "
                      f"under {SLENDER_DEG:.1f} degrees there: exact quads at least "
                      f"{SLENDER_ELONGATION:g}:1)")
    if known.restarts:
        causes.append(f"the two chains drifted apart ({known.restarts} restarts)")
    if m < 2 * rows and not near_cone:
        causes.append(f"few generators for {rows} rows")
    warnings.append(f"{share:.0%} of the area is not in quads ({'; '.join(causes) or 'border'}; "
                    f"{_where_not_quads(mesh, area, off, total)}): more generators (rulings.count), "
                    f"fewer rows, {'[mesh] planarity_tolerance = 1e-3 for nearly developable parts, ' * exact}"
                    "or method = \"hybrid\"")


def _where_not_quads(mesh: Mesh, area: np.ndarray, off: np.ndarray, total: float) -> str:
    """Where the area outside quads lies: the border band, and the strips holding most of the rest."""
    keys, uses = mesh.edge_uses()
    at_border = _touching(mesh, _border_vertices(keys, uses, mesh.n_vertices))
    band = float(area[off & at_border].sum()) / total
    said = [f"{band:.0%} at the border"]
    gen = mesh.vertex_data.get("generator")
    inside = off & ~at_border
    if gen is not None and inside.any():
        g0 = np.minimum.reduceat(np.asarray(gen)[mesh.face_indices], mesh.face_offsets[:-1])
        per = np.bincount(g0[inside], weights=area[inside], minlength=int(g0.max()) + 1) / total
        # Strips holding at least a twentieth of the inner share, as ranges (all of them
        # where it is spread evenly).
        busy = np.flatnonzero(per >= 0.05 * per.sum())
        if busy.size == 0:
            busy = np.flatnonzero(per > 0)
        cut = np.flatnonzero(np.diff(busy) > 1)
        lo, hi = busy[np.r_[0, cut + 1]], busy[np.r_[cut, busy.size - 1]]
        top = np.argsort([-per[a:b + 1].sum() for a, b in zip(lo, hi)], kind="stable")[:3]
        ranges = ", ".join(f"{lo[k]}-{hi[k] + 1} ({per[lo[k]:hi[k] + 1].sum():.0%})" for k in sorted(top))
        said.append(f"{float(per.sum()):.0%} inside, most between generators {ranges}")
    return ", ".join(said)


def _pairing_tolerance(ptol: float, tol: Tolerances) -> float:
    """The tolerance triangle pairs are made quads within (:func:`.pairing.pair_triangles`).

    In exact mode that is within the exact bar: two halves of one planar quad
    that the cuts kept apart, or a notch half and a border triangle that happen
    to share a plane (a helicoid's border teeth, by its symmetry).
    """
    # A margin below the stated tolerance, so that rounding in another reader's
    # measure cannot push a paired quad over it.
    return _PAIRING_MARGIN * max(ptol, tol.planarity)


def _warn_splinters(mesh: Mesh, warnings: list[str], torsal: np.ndarray,
                    measured: tuple | None = None, lines: tuple | None = None) -> None:
    """Say how many faces are splinters for fabrication, where, and next to what.

    ``measured``: the (F,) smallest angles and areas of the faces, if known; ``lines``: the
    generators ``(a, d)`` (each (m, 3): a point and the direction to the other end), if known
    (then splinters whose smallest angle is that of the two generators of their strip where
    they meet are told apart, see :func:`_at_meetings`).
    """
    from ...analysis.faces import SPLINTER_DEG, face_min_angles

    if mesh.n_faces == 0:
        return
    ang = face_min_angles(mesh) if measured is None else measured[0]
    bad = np.flatnonzero(ang < SPLINTER_DEG)
    if bad.size == 0:
        return
    # The corners of the splinters only (a large mesh has few).
    val = mesh.valences[bad]
    starts = np.cumsum(val) - val
    corners = mesh.face_indices[np.repeat(mesh.face_offsets[bad] - starts, val) + np.arange(int(val.sum()))]
    gen = np.asarray(mesh.vertex_data["generator"])[corners]
    t = np.asarray(mesh.vertex_data["t"])[corners]
    g0 = np.minimum.reduceat(gen, starts)
    t_lo = np.minimum.reduceat(t, starts)
    t_hi = np.maximum.reduceat(t, starts)
    near_torsal = np.zeros(bad.size, bool)
    for k in torsal.tolist():
        near_torsal |= np.abs(g0 - k) <= 2
    border = (t_lo <= PARAMETER_SLACK) | (t_hi >= 1 - PARAMETER_SLACK)
    quads = mesh.valences[bad] == 4
    meeting = _at_meetings(ang[bad], g0, lines)
    where = []
    if meeting.any():
        where.append(f"{meeting.sum()} with their corner where two generators meet at "
                     f"{ang[bad][meeting].min():.2g} deg (no face there can be fatter)")
    near_torsal &= ~meeting
    border &= ~meeting
    quads &= ~meeting
    for count, label in ((near_torsal.sum(), "next to torsal generators"),
                         ((border & ~near_torsal).sum(), "at the border"),
                         ((quads & ~border & ~near_torsal).sum(),
                          "thin quads where the rows run nearly along the generators"),
                         ((~quads & ~border & ~near_torsal & ~meeting).sum(), "between runs of rows")):
        if count:
            where.append(f"{count} {label}")
    gs = unique(g0)
    cuts = np.flatnonzero(np.diff(gs) > 1)
    spans = [f"{lo}-{hi}" if hi > lo else f"{lo}" for lo, hi in
             zip(gs[np.r_[0, cuts + 1]].tolist(), gs[np.r_[cuts, gs.size - 1]].tolist())]
    warnings.append(
        f"{bad.size} faces have an angle below {SPLINTER_DEG:g} deg (smallest {ang[bad].min():.2g} deg; "
        f"{', '.join(where)}; generators {', '.join(spans[:6])}{' ...' if len(spans) > 6 else ''}): "
        + (f"generators at least {SPLINTER_DEG:g} deg apart where they meet give fatter ones"
           if meeting.all() else
           "strips narrow against the row step make thin panels; fewer rows, other generators "
           "(rulings.count, distribution) or [mesh] planarity_tolerance = 1e-3 give fatter ones"))


# A splinter's smallest angle within this share of the angle between its strip's generators
# is that angle, where the two lines pass within this share of their length of each other:
# its corner is where they meet (_at_meetings).
_MEETING_ANGLE_SHARE = 0.01
_MEETING_GAP = 0.01


def _warn_faces(mesh: Mesh, warnings: list[str], torsal: np.ndarray, measured: tuple | None,
                lines: tuple[np.ndarray, np.ndarray], spans: tuple[np.ndarray, np.ndarray]) -> list[float]:
    """What a build says of its faces: splinters (:func:`_warn_splinters`) and triangles off
    the generators they span (:func:`_warn_off_generators`, whose result it returns)."""
    _warn_splinters(mesh, warnings, torsal, measured, lines)
    return _warn_off_generators(mesh, warnings, *spans)


def _warn_off_generators(mesh: Mesh, warnings: list[str], tri: np.ndarray, off: np.ndarray) -> list[float]:
    """Say how many triangles lie farther than :data:`~ruledmesh.tolerances.SPAN_MAX_GAP` of
    the diagonal off the generators they span, how far at most and between which
    generators; ``tri``, ``off``: the triangles across strips and how far each lies off
    (:func:`.halving.halve_spanning_triangles`, which halved those it could).

    Returns how far each of those triangles lies, relative to the diagonal (the mesh's
    ``info["off_generators"]``: a design build weighs them as it weighs splinters).
    """
    off = off / (mesh.diagonal() or 1.0)
    far = off > SPAN_MAX_GAP
    if not far.any():
        return []
    g = np.asarray(mesh.vertex_data["generator"], np.int64)
    span = g[tri[far]]
    warnings.append(f"{int(far.sum())} triangles lie up to {off.max():.1e} of the diagonal off the "
                    f"generators they span (between generators {int(span.min())} and {int(span.max())}, "
                    f"across up to {int((span.max(axis=1) - span.min(axis=1)).max())} strips; the gap goal "
                    f"is {SPAN_MAX_GAP:g}): the smooth surface is not within the gap goal of the mesh there; "
                    "more generators (rulings.count) or fewer rows")
    return off[far].tolist()


def _at_meetings(angles: np.ndarray, g0: np.ndarray, lines: tuple | None) -> np.ndarray:
    """(k,) bool: which of ``k`` splinters (smallest angles ``angles``, lowest generators
    ``g0``) have as their smallest angle that of generators ``g0`` and ``g0 + 1``
    (``lines``: ``(a, d)``) where those two (nearly) meet.

    Where two consecutive generators meet (a Plücker conoid's pinch points, a cone's apex)
    a face with its corner there has their angle, whatever the rows: lines 2.7 degrees
    apart make 2.7-degree corners.
    """
    if lines is None or len(lines[1]) < 2:
        return np.zeros(angles.shape, bool)
    a, d = lines
    i = np.clip(g0, 0, len(d) - 2)
    u0, u1 = d[i], d[i + 1]
    n0, n1 = np.linalg.norm(u0, axis=1), np.linalg.norm(u1, axis=1)
    cos = np.einsum("ij,ij->i", u0, u1) / np.maximum(n0 * n1, TINY)
    between = np.degrees(np.arccos(np.clip(np.abs(cos), 0.0, 1.0)))
    normal = np.cross(u0, u1)
    gap = np.abs(np.einsum("ij,ij->i", a[i + 1] - a[i], normal)) / np.maximum(
        np.linalg.norm(normal, axis=1), TINY)
    return (np.abs(angles - between) <= _MEETING_ANGLE_SHARE * between) & \
        (gap <= _MEETING_GAP * np.minimum(n0, n1))


def _nearly_flat(a: np.ndarray, d: np.ndarray, rows: int, ptol: float) -> np.ndarray:
    """Strips whose strip quads (a uniform division) are planar within ``ptol``."""
    from ...analysis.faces import quad_planarity

    t = np.linspace(0.0, 1.0, max(rows // 2, 1) + 1)
    P0 = a[:-1, None, :] + t[None, :, None] * d[:-1, None, :]
    P1 = a[1:, None, :] + t[None, :, None] * d[1:, None, :]
    Q = np.stack([P0[:, :-1], P0[:, 1:], P1[:, 1:], P1[:, :-1]], axis=2)     # (m-1, k, 4, 3)
    pl = quad_planarity(Q.reshape(-1, 4, 3)).reshape(Q.shape[0], -1)
    # Half the tolerance: the matched divisions are not uniform.
    return pl.max(axis=1) <= 0.5 * ptol


def _build_all(plan: _Plan, segs: list[_Segment], p: int, middle: bool, div: Division,
               m: int) -> list[Run]:
    """Build the segment holding the primary, then its neighbours outwards, matched."""
    home = next(k for k, s in enumerate(segs) if s.lo <= p <= s.hi)
    budget = [max(4, m // 4)]
    built: dict[int, list[Run]] = {}
    s = segs[home]
    pr = (p - s.lo) if not middle else _well_twisted(plan, s.lo, s.hi)
    built[home] = _without_rows(plan, s, div, s.lo + pr) or _build_segment(
        plan, s.lo, s.hi, pr, plan.division(div, s.lo, s.hi, s.lo + pr), budget, home=True)
    for step in (1, -1):
        k = home + step
        while 0 <= k < len(segs):
            s = segs[k]
            if step > 0:
                src = s.lo if s.shared_lo else s.lo - 1
                primary = 0
            else:
                src = s.hi if s.shared_hi else s.hi + 1
                primary = s.hi - s.lo
            crease = src in plan.crease_generators
            if (none := _without_rows(plan, s, div, src if s.hi - s.lo < 2 or crease else s.lo)):
                built[k] = none
            elif s.hi - s.lo >= 2 and not crease:
                # Rows started on a torsal generator (K = 0 there) bunch and fan out:
                # each segment takes its own division from its middle; the two meet
                # on the torsal generator in a zipper.
                own = _well_twisted(plan, s.lo, s.hi)
                built[k] = _build_segment(plan, s.lo, s.hi, own,
                                          plan.division(div, s.lo, s.hi, s.lo + own), budget)
            else:
                t = _boundary_t(built[k - step], src)
                sub = matched(div, t if t.size else None)
                built[k] = _build_segment(plan, s.lo, s.hi, primary, sub, budget,
                                          shared=src if crease else None)
            k += step
    return [r for k in sorted(built) for r in built[k]]


def _without_rows(plan: _Plan, seg: _Segment, div: Division, g: int) -> list[Run]:
    """The even division of segment ``seg`` where the rows from generator ``g`` are
    :attr:`RowsFrom.NONE` (recorded in ``plan.own``), else an empty list."""
    g = min(max(g, 0), len(plan.ends) - 1)
    if plan.ends[g] != _NO_ROWS:
        return []
    plan.own.append([seg.lo, seg.hi, _NO_ROWS, int(plan.options[g])])
    return _even(plan, seg.lo, seg.hi, div.rows, graded=True)


def _well_twisted(plan: _Plan, lo: int, hi: int) -> int:
    """Run-local primary for "middle": near the middle, away from nearly torsal generators.

    The hop is ill-conditioned where consecutive generators are nearly
    coplanar (K near 0): rows started there bunch.  The primary is the
    generator whose smaller neighbouring twist volume, weighted towards the
    middle of the run, is largest.  Affine maps scale every volume by the same
    factor, so the choice commutes with them.
    """
    m = hi - lo + 1
    if m < 3:
        return m // 2
    a, d = plan.a[lo:hi + 1], plan.d[lo:hi + 1]
    vol = np.abs(np.einsum("ij,ij->i", np.cross(d[:-1], d[1:]), a[1:] - a[:-1]))
    inner = np.arange(1, m - 1)
    worst = np.minimum(vol[inner - 1], vol[inner])
    centre = 1.0 - np.abs(inner - (m - 1) / 2) / m
    score = worst * centre
    # Ties within rounding go to the middle, so the choice does not flip with scale.
    best = score >= score.max() * (1.0 - PARAMETER_SLACK)
    return int(inner[best][np.argmin(np.abs(inner[best] - (m - 1) / 2))])


def _boundary_t(runs: list[Run], g: int) -> np.ndarray:
    """Parameters of the vertices some run left on generator ``g`` inside the patch."""
    for r in runs:
        t = r.inside_t(g)
        if t.size:
            return t
    return np.zeros(0)
