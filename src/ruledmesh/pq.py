"""PQ meshes of skew surfaces from a discrete set of generators (paper §4.3).

Divide a primary generator ``g_p``; from each division point hop across the
next generator to the next-but-one (chain *a*, generators of the primary's
parity), and from the first crossing hop likewise (chain *b*, the other
parity).  The grid point ``X[i, j]`` is the vertex of row ``j`` on ``g_i``.
The two options of the paper are the two colours of a checkerboard on that
grid: a face is centred on every grid point of the other colour,

    [X[i-1, j], X[i, j-1], X[i+1, j], X[i, j+1]],

with one diagonal on the generator ``g_i`` and the other on a hop line that
crosses ``g_i``: two intersecting lines, so every face is planar by
construction, up to rounding that does not accumulate.

The rows are computed through Moebius maps of the parameter (see
:mod:`ruledmesh.hop`): ``t[i, j] = M_i(tau_j)``, one broadcast for the whole
grid.  The maps also tell which division of the primary generator reaches the
patch ``0 <= t <= 1`` on every generator (automatic extension), and where a
row passes through infinity (the sign of the homogeneous denominator flips).
Torsal pairs of consecutive generators (coplanar, so no hop exists across
them) split the generators into runs meshed independently; the strips
between runs are filled with triangles (paper §4.3, last paragraph).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from ._validation import check_bool, check_float, check_int, check_keys, check_points, describe
from .errors import DesignError, GeometryError, ParameterError
from .hop import coplanarity, landing_maps, crossing_maps
from .mesh import FaceKind, Mesh
from .registry import BuildContext, Built, mesh_method
from .tolerances import DEFAULT, Tolerances

__all__ = ["pq_mesh", "row_maps", "MAX_GRID_POINTS"]

# Grid points (generators x rows) above which a build is refused up front, with
# the memory it would need, instead of running out of memory half-way.
MAX_GRID_POINTS = 60_000_000
# Parameters this close to 0 or 1 are on the patch border (rounding of t).
_ON_BORDER = 1e-12
_BYTES_PER_GRID_POINT = 96


@dataclass(frozen=True)
class _ChainMaps:
    """What both the composed maps and the hop-by-hop rows start from."""

    primary: int            # the a-chain's root (moved to 0 for three generators)
    root: int               # the b-chain's root, next to the primary
    fwd: np.ndarray         # (m-2, 2, 2) g_k -> g_k+2, |det| = 1
    bwd: np.ndarray         # (m-2, 2, 2) g_k+2 -> g_k, |det| = 1
    crossing: np.ndarray    # (2, 2) primary -> root, |det| = 1


def _chain_maps(a: np.ndarray, d: np.ndarray, primary: int) -> _ChainMaps:
    """Landing maps in both directions and the crossing map that roots chain *b*."""
    m = len(a)
    if primary + 2 >= m and primary - 2 < 0:
        # Three generators with the primary in the middle: no hop starts there.
        primary = 0
    # Landing maps g_k -> g_{k+2} (forward) and g_k -> g_{k-2} (backward), all at once.
    fwd = _unit_det(landing_maps(a[:-2], d[:-2], a[1:-1], d[1:-1], a[2:], d[2:]))
    bwd = _unit_det(landing_maps(a[2:], d[2:], a[1:-1], d[1:-1], a[:-2], d[:-2]))
    # Chain b starts where chain a's first hop crosses the neighbour (towards the longer side).
    root = primary + 1 if primary + 2 < m else primary - 1
    far = root + 1 if root > primary else root - 1
    C = _unit_det(crossing_maps(a[primary:primary + 1], d[primary:primary + 1], a[root:root + 1],
                                d[root:root + 1], a[far:far + 1], d[far:far + 1]))[0]
    return _ChainMaps(primary, root, fwd, bwd, C)


def _product(h: list, m: list) -> list:
    """2x2 product ``h @ m`` of nested lists, scaled to unit max-norm (a zero map stays zero)."""
    (h00, h01), (h10, h11) = h
    (m00, m01), (m10, m11) = m
    r = (h00 * m00 + h01 * m10, h00 * m01 + h01 * m11, h10 * m00 + h11 * m10, h10 * m01 + h11 * m11)
    s = max(map(abs, r)) or 1.0
    return [[r[0] / s, r[1] / s], [r[2] / s, r[3] / s]]


def _compose(maps: _ChainMaps, m: int) -> np.ndarray:
    """The maps of :func:`row_maps` from a :class:`_ChainMaps`."""
    out = [None] * m
    out[maps.primary] = [[1.0, 0.0], [0.0, 1.0]]
    out[maps.root] = _product(maps.crossing.tolist(), out[maps.primary])
    fwd, bwd = maps.fwd.tolist(), maps.bwd.tolist()
    # Sequential only along the generators (m small 2x2 products), never per vertex.
    for start in (maps.primary, maps.root):
        for i in range(start + 2, m, 2):
            out[i] = _product(fwd[i - 2], out[i - 2])
        for i in range(start - 2, -1, -2):
            out[i] = _product(bwd[i], out[i + 2])
    return np.array(out)


def row_maps(a: np.ndarray, d: np.ndarray, primary: int) -> np.ndarray:
    """Moebius maps from the primary generator's parameter to every generator's.

    Chain *a* lives on the generators of the primary's parity and starts at
    the identity; chain *b* starts where chain *a*'s first hop crosses the
    neighbouring generator (towards the longer side) and hops both ways.

    Parameters
    ----------
    a, d : (m, 3) float64
        Generator points and directions, ``m >= 3``, no torsal pair.
    primary : int
        Index of the primary generator.

    Returns
    -------
    M : (m, 2, 2) float64
        ``t_i = (M[i,0,0] tau + M[i,0,1]) / (M[i,1,0] tau + M[i,1,1])``;
        each matrix scaled to unit max-norm.
    """
    return _compose(_chain_maps(a, d, primary), len(a))


def _patch_preimage(M: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each map, the tau interval that lands on 0 <= t <= 1.

    Returns
    -------
    lo, hi : (m,) float64
        Interval ends (finite where ``bounded``).
    bounded : (m,) bool
        False where the interval passes through tau = infinity (or the map is
        degenerate), so no finite division of the primary covers that generator.
    """
    m00, m01, m10, m11 = M[:, 0, 0], M[:, 0, 1], M[:, 1, 0], M[:, 1, 1]
    # tau(t) = (m11 t - m01) / (m00 - m10 t), the inverse map, at t = 0 and t = 1.
    den0 = m00
    den1 = m00 - m10
    small = tol * np.abs(M).max(axis=(1, 2))
    finite = (np.abs(den0) > small) & (np.abs(den1) > small)
    tau0 = np.where(finite, -m01 / np.where(finite, den0, 1.0), 0.0)
    tau1 = np.where(finite, (m11 - m01) / np.where(finite, den1, 1.0), 0.0)
    lo, hi = np.minimum(tau0, tau1), np.maximum(tau0, tau1)
    # The map's pole (t = inf) inside [lo, hi] means the preimage of [0, 1] is the outside.
    pole_den = np.abs(m10) > small
    pole = np.where(pole_den, -m11 / np.where(pole_den, m10, 1.0), np.inf)
    wraps = pole_den & (pole > lo) & (pole < hi)
    return lo, hi, finite & ~wraps


def _row_range(M: np.ndarray, rows: int, extend, max_extend: float, tol: Tolerances,
               warnings: list[str]) -> tuple[int, int]:
    """Integer row range [j0, j1] (tau = j / rows) covering the patch."""
    if extend == "auto":
        lo, hi, bounded = _patch_preimage(M, tol.degenerate)
        if not np.all(bounded):
            warnings.append(f"{int((~bounded).sum())} generators cannot be covered by a finite "
                            f"division of the primary generator; extension capped at "
                            f"{max_extend:g} generator lengths")
        lo = lo[bounded].min() if bounded.any() else 0.0
        hi = hi[bounded].max() if bounded.any() else 1.0
        lo = max(min(lo, 0.0), -max_extend)
        hi = min(max(hi, 1.0), 1.0 + max_extend)
        # One row of margin on each side: a face spans two row steps.
        j0 = math.floor(lo * rows) - 2
        j1 = math.ceil(hi * rows) + 2
    else:
        e = float(extend)
        j0 = -math.ceil(e * rows)
        j1 = rows + math.ceil(e * rows)
    if (j1 - j0 + 1) % 2:
        j1 += 1
    return j0, j1


@dataclass
class _Run:
    """The checkerboard grid of one run of generators (before trimming).

    Half-faces are triangles of the zigzag strips between consecutive
    generators: the face centred at (i, j) is the union of its left half
    [X[i-1,j], X[i,j-1], X[i,j+1]] and right half [X[i,j-1], X[i+1,j], X[i,j+1]],
    coplanar because the face is planar.  The halves of centres on the first and
    last generator are the notch triangles of paper §4.3.
    """

    vertices: np.ndarray      # (V, 3)
    t: np.ndarray             # (V,) parameter on its generator
    gen: np.ndarray           # (V,) generator index (global)
    far: np.ndarray           # (V,) beyond the 'far' bound: never emitted
    left: np.ndarray          # (F, 3) left halves (-1 row where absent)
    right: np.ndarray         # (F, 3) right halves
    pole: np.ndarray          # (F,) a row passes through infinity inside the face
    centre_gen: np.ndarray    # (F,) generator index of each centre (global)


def _unit_det(H: np.ndarray) -> np.ndarray:
    """Scale 2x2 maps to |det| = 1 (rows then neither grow nor shrink on average)."""
    det = np.abs(H[:, 0, 0] * H[:, 1, 1] - H[:, 0, 1] * H[:, 1, 0])
    scale = np.sqrt(np.where(det > 0, det, np.abs(H).max(axis=(1, 2)) ** 2 + 1e-300))
    return H / scale[:, None, None]


def _propagate(maps: _ChainMaps, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Homogeneous row parameters on every generator, hop by hop.

    Each vertex is the exact image (one rounding) of its neighbour two
    generators back, so the hop-line diagonal of every face meets its generator
    to rounding, however many generators the chain crosses.  (The composed
    maps of :func:`row_maps` are used only to choose the rows: evaluated
    directly they let rounding drift between neighbours.)

    Parameters
    ----------
    maps : _ChainMaps
    tau : (m, H) float64
        Row parameter on the primary generator, per generator's row parity.

    Returns
    -------
    num, den : (m, H) float64
        ``t = num / den``; ``den`` changes sign where a row passes infinity.
    """
    m = len(tau)
    primary, root, fwd, bwd, C = maps.primary, maps.root, maps.fwd, maps.bwd, maps.crossing
    num = np.empty_like(tau)
    den = np.empty_like(tau)
    num[primary], den[primary] = tau[primary], 1.0
    num[root] = C[0, 0] * tau[root] + C[0, 1]
    den[root] = C[1, 0] * tau[root] + C[1, 1]
    # Fronts: (generator, step) for the four chain ends, advanced together.
    fronts = [(primary, 2), (root, 2), (primary, -2), (root, -2)]
    k = 0
    while True:
        src, dst, Hs = [], [], []
        for g0, step in fronts:
            g = g0 + step * (k + 1)
            if 0 <= g < m:
                src.append(g - step)
                dst.append(g)
                Hs.append(fwd[g - 2] if step > 0 else bwd[g])
        if not dst:
            break
        Hm = np.array(Hs)
        ps, qs = num[src], den[src]
        nn = Hm[:, 0, 0, None] * ps + Hm[:, 0, 1, None] * qs
        dd = Hm[:, 1, 0, None] * ps + Hm[:, 1, 1, None] * qs
        if k % 8 == 7:
            # Positive rescaling per row keeps the homogeneous pair finite and its sign.
            sc = np.maximum(np.abs(nn), np.abs(dd))
            sc[sc == 0] = 1.0
            nn /= sc
            dd /= sc
        num[dst], den[dst] = nn, dd
        k += 1
    return num, den


def _mesh_run(a: np.ndarray, d: np.ndarray, first: int, primary: int, rows: int, option: int,
              extend, max_extend: float, tol: Tolerances, scale: float,
              warnings: list[str]) -> _Run:
    """Checkerboard PQ grid on generators a, d (a run), before trimming."""
    m = len(a)
    maps = _chain_maps(a, d, primary)
    j0, j1 = _row_range(_compose(maps, m), rows, extend, max_extend, tol, warnings)
    J = j1 - j0 + 1
    if m * J > MAX_GRID_POINTS:
        need = m * J * _BYTES_PER_GRID_POINT / 2**30
        raise GeometryError(f"the grid would have {m} x {J} points (about {need:.1f} GiB); "
                            f"reduce the generator count, the rows or the extension")
    H = J // 2
    # Vertex (i, j) exists where (i + j) % 2 == option; on generator i its rows are
    # j = j0 + s_i + 2h, h = 0..H-1, with s_i the row parity of that generator.
    i_idx = np.arange(m)
    s = (option - i_idx - j0) % 2
    tau = (j0 + s[:, None] + 2 * np.arange(H)[None, :]) / rows          # (m, H)
    num, den = _propagate(maps, tau)
    # Far limit in t: tol.far patch diagonals along each generator.
    glen = np.linalg.norm(d, axis=1)
    tmax = tol.far * scale / np.maximum(glen, 1e-300)
    far = ~(np.abs(num) < tmax[:, None] * np.abs(den))
    t = np.where(far, 0.0, num / np.where(far, 1.0, den))
    X = a[:, None, :] + t[..., None] * d[:, None, :]
    vid = np.arange(m * H).reshape(m, H)
    # Centres (i, j) of the other colour on every generator g_i.
    cc = np.arange(H)
    jc = j0 + (1 - s)[:, None] + 2 * cc[None, :]                       # (m, H) centre rows
    h_lo = (jc - 1 - j0 - s[:, None]) // 2                              # vertex row j-1 on g_i
    ok = (h_lo >= 0) & (h_lo + 1 < H)
    ic = np.broadcast_to(i_idx[:, None], jc.shape)[ok]
    hl = h_lo[ok]
    hc = np.broadcast_to(cc[None, :], jc.shape)[ok]   # row j on g_{i-1} and g_{i+1}
    lo_v, hi_v = vid[ic, hl], vid[ic, hl + 1]
    has_l, has_r = ic > 0, ic < m - 1
    left = np.where(has_l[:, None],
                    np.stack([vid[np.maximum(ic - 1, 0), hc], lo_v, hi_v], axis=1), -1)
    right = np.where(has_r[:, None],
                     np.stack([lo_v, vid[np.minimum(ic + 1, m - 1), hc], hi_v], axis=1), -1)
    # A row passes through infinity inside a face when the homogeneous denominator
    # changes sign between the face's two rows on its generator g_i.  (Signs on
    # different generators are not comparable: M and -M are the same map.)
    sg = np.signbit(den)
    pole = sg[ic, hl] != sg[ic, hl + 1]
    gen = np.repeat(np.arange(first, first + m), H)
    return _Run(X.reshape(-1, 3), t.reshape(-1), gen, far.reshape(-1), left, right, pole,
                ic + first)


def pq_mesh(a, b, rows: int = 20, primary: int | str = "middle", option: int = 0,
            extend: float | str = "auto", trim: bool = True, *, max_extend: float = 20.0,
            creases=None, tol: Tolerances = DEFAULT) -> Mesh:
    """The §4.3 PQ mesh of the ruled surface through generators ``a_i b_i``.

    Parameters
    ----------
    a, b : (m, 3) array_like
        Generator end points; ``t = 0`` at ``a`` (director curve c1), ``t = 1``
        at ``b`` (c2).  ``m >= 3``.
    rows : int
        Divisions of the primary generator between ``t = 0`` and ``t = 1``.
    primary : int or "middle"
        Index of the primary generator (negative indices count from the end).
    option : {0, 1}
        Which colour of the checkerboard carries the vertices (the paper's two options).
    extend : "auto" or float
        How far the division of the primary generator continues beyond
        ``[0, 1]`` (in primary-generator lengths); ``"auto"`` takes just what
        covers the patch on every generator, found from the row maps.
    trim : bool
        Clip the faces to the patch ``0 <= t <= 1`` (clipped faces stay planar).
    max_extend : float
        Cap of the automatic extension.
    creases : (k,) int, optional
        Strips ``i`` (between generators ``i`` and ``i + 1``) across which the
        surface has a crease (a kink of a director curve); the rows restart
        there and the strip is filled with triangles.
    tol : Tolerances

    Returns
    -------
    Mesh
        Faces of kind QUAD (interior), BORDER (clipped), FILL (notch and torsal
        triangles) and SPLIT (quads that were not convex, split along their
        generator diagonal); members are the generator segments between
        consecutive vertices; ``vertex_data`` holds ``t`` and ``generator``;
        ``info["warnings"]`` says what was replaced or could not be covered.

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
    >>> mesh = pq_mesh(a, b, rows=10)
    >>> v = mesh.vertices
    >>> bool(np.abs(v[:, 0]**2 + v[:, 1]**2 - v[:, 2]**2 - 1).max() < 1e-12)
    True
    """
    a = check_points(a, "a", min_count=3)
    b = check_points(b, "b", min_count=3)
    if a.shape != b.shape:
        raise ParameterError(f"expected the shape of a {a.shape}, got {b.shape}", "b")
    m = len(a)
    rows = check_int(rows, "rows", lo=1)
    option = check_int(option, "option", lo=0, hi=1)
    trim = check_bool(trim, "trim")
    middle = isinstance(primary, str)
    if middle:
        if primary != "middle":
            raise ParameterError(f'expected "middle" or an index, got {describe(primary)}', "primary")
        p = m // 2
    else:
        p = check_int(primary, "primary", lo=-m, hi=m - 1) % m
    if not (isinstance(extend, str) and extend == "auto"):
        if isinstance(extend, str):
            raise ParameterError(f'expected "auto" or a number >= 0, got {describe(extend)}', "extend")
        extend = check_float(extend, "extend", lo=0.0, hi=1e3)
    max_extend = check_float(max_extend, "max_extend", lo=0.0, hi=1e3)
    if m * (rows + 1) > MAX_GRID_POINTS:
        need = m * (rows + 1) * _BYTES_PER_GRID_POINT / 2**30
        raise GeometryError(f"{m} generators x {rows + 1} rows would need at least "
                            f"{need:.1f} GiB; reduce the generator count or the rows")
    d = b - a
    lo, hi = np.minimum(a.min(0), b.min(0)), np.maximum(a.max(0), b.max(0))
    scale = float(np.linalg.norm(hi - lo))
    if scale == 0.0:
        raise GeometryError("all generator end points coincide")
    glen = np.linalg.norm(d, axis=1)
    short = np.flatnonzero(glen <= tol.degenerate * scale)
    if short.size:
        raise GeometryError(f"generator {int(short[0])} has zero length (its end points coincide)"
                            + (f", and {short.size - 1} more" if short.size > 1 else ""))
    warnings: list[str] = []
    # Torsal generators cut the generators into runs: a pair of consecutive
    # generators that (nearly) meet, or a change of sign of the twist between
    # pairs (a torsal generator lies between them; hops across it would reverse
    # the rows).  The strips at the cuts are filled with triangles (§4.3).
    twist = coplanarity(a, d, scale)
    flat = np.abs(twist) <= tol.degenerate
    sign = np.sign(np.where(flat, 0.0, twist))
    # Carry the last non-zero sign forward so a flat pair does not hide a change.
    idx = np.where(sign != 0, np.arange(len(sign)), 0)
    np.maximum.accumulate(idx, out=idx)
    carried = sign[idx]
    change = np.zeros(len(sign), bool)
    change[1:] = (carried[1:] != carried[:-1]) & (carried[:-1] != 0) & (sign[1:] != 0)
    # A kink of a director curve (a polyline corner, say) makes a crease along a
    # generator; the two chains of §4.3 cross it at different generators and
    # drift apart, so the rows restart across it too.  The design knows its
    # kinks exactly (see ruledmesh.design); measured angles would not commute
    # with affine maps.
    crease = np.zeros(len(sign), bool)
    if creases is not None:
        cr = np.asarray(creases, dtype=np.int64).reshape(-1)
        if cr.size and (cr.min() < 0 or cr.max() >= m - 1):
            raise ParameterError(f"expected pair indices in [0, {m - 2}], got {cr.tolist()}", "creases")
        crease[cr] = True
    cut = np.flatnonzero(flat | change | crease)
    bounds = np.concatenate([[0], cut + 1, [m]])
    def listed(ks):
        return ", ".join(f"{k}-{k + 1}" for k in ks[:8].tolist()) + (" ..." if ks.size > 8 else "")

    torsal = np.flatnonzero(flat | change)
    kinks = np.flatnonzero(crease & ~(flat | change))
    if torsal.size:
        warnings.append(f"{torsal.size} torsal strips (generators {listed(torsal)}: consecutive "
                        "generators coplanar, or the twist changes sign): filled with triangles")
    if kinks.size:
        warnings.append(f"{kinks.size} crease strips (generators {listed(kinks)}: a director curve "
                        "has a corner there): rows restarted, strips filled with triangles")
    parts = []          # one _Run per run of at least three generators
    for r0, r1 in zip(bounds[:-1], bounds[1:]):
        if r1 - r0 < 3:
            continue
        # "middle" means the middle of each run: chains drift with the number of hops.
        pr = p - r0 if (not middle and r0 <= p < r1) else (r1 - r0) // 2
        run = _mesh_run(a[r0:r1], d[r0:r1], r0, pr, rows, option, extend, max_extend, tol,
                        scale, warnings)
        parts.append(run)
    return _assemble(parts, a, d, trim, tol, warnings, scale)


def _assemble(parts, a, d, trim, tol, warnings, scale) -> Mesh:
    """Join the runs; keep convex quads and valid halves; fill the gaps; add members."""
    from .analysis.faces import quad_diagonal_crossing

    m = len(a)
    V = np.concatenate([r.vertices for r in parts]) if parts else np.zeros((0, 3))
    T = np.concatenate([r.t for r in parts]) if parts else np.zeros(0)
    G = np.concatenate([r.gen for r in parts]) if parts else np.zeros(0, np.int64)
    FAR = np.concatenate([r.far for r in parts]) if parts else np.zeros(0, bool)
    offs = np.cumsum([0] + [len(r.vertices) for r in parts])
    shift = lambda f, o: np.where(f >= 0, f + o, -1) if o else f  # noqa: E731
    L = (np.concatenate([shift(r.left, o) for r, o in zip(parts, offs)]) if parts
         else np.zeros((0, 3), np.int64))
    R = (np.concatenate([shift(r.right, o) for r, o in zip(parts, offs)]) if parts
         else np.zeros((0, 3), np.int64))
    POLE = np.concatenate([r.pole for r in parts]) if parts else np.zeros(0, bool)
    CG = np.concatenate([r.centre_gen for r in parts]) if parts else np.zeros(0, np.int64)
    # A vertex within rounding of the border counts as on it, so the decisions do
    # not flip when the design is scaled or moved (t is scale-free up to rounding).
    lo_t, hi_t = (-_ON_BORDER, 1.0 + _ON_BORDER) if trim else (-np.inf, np.inf)
    good_v = ~FAR & (T >= lo_t) & (T <= hi_t)
    cand_l = (L[:, 0] >= 0) & ~POLE & good_v[np.maximum(L, 0)].all(axis=1)
    cand_r = (R[:, 0] >= 0) & ~POLE & good_v[np.maximum(R, 0)].all(axis=1)
    ok_l, ok_r = cand_l, cand_r
    if trim:
        V, T, G, ok_l, ok_r, fill, chain, gstart = _strip_paths(V, T, G, good_v, a, d, m, L, R,
                                                                 ok_l, ok_r, CG, scale)
    else:
        chain = gstart = None
        # Untrimmed: rows must still increase along each generator inside a face.
        ok_l = cand_l & (T[np.maximum(L[:, 2], 0)] > T[np.maximum(L[:, 1], 0)])
        ok_r = cand_r & (T[np.maximum(R[:, 2], 0)] > T[np.maximum(R[:, 0], 0)])
        fill = np.zeros((0, 3), np.int64)
    both = ok_l & ok_r
    quads = np.stack([L[both, 0], L[both, 1], R[both, 1], L[both, 2]], axis=1)
    # Bow-ties: the diagonals must cross inside both; else keep the two halves.
    sq, tq, _ = quad_diagonal_crossing(V[quads])
    eps = tol.convexity
    convex = (sq > eps) & (sq < 1 - eps) & (tq > eps) & (tq < 1 - eps)
    whole = np.zeros(len(L), bool)
    whole[np.flatnonzero(both)[convex]] = True
    nsplit = int(np.count_nonzero(~convex))
    interior = (L[:, 0] >= 0) & (R[:, 0] >= 0)
    kind_half = np.where(interior, np.where(both, FaceKind.SPLIT, FaceKind.BORDER),
                         FaceKind.FILL).astype(np.uint8)
    half_l, half_r = ok_l & ~whole, ok_r & ~whole
    faces = [quads[convex], np.concatenate([L[half_l], R[half_r], fill])]
    kinds = [np.full(int(convex.sum()), FaceKind.QUAD, np.uint8),
             np.concatenate([kind_half[half_l], kind_half[half_r],
                             np.full(len(fill), FaceKind.FILL, np.uint8)])]
    if nsplit:
        warnings.append(f"{nsplit} quads were not convex (the two chains of §4.3 drifted apart) "
                        "and were kept as two triangles split along their generator diagonal; "
                        "sample the generators more finely there")
    dropped = int(np.count_nonzero(cand_l & ~ok_l) + np.count_nonzero(cand_r & ~ok_r))
    if dropped:
        warnings.append(f"{dropped} half-faces ran against the order of their strip (rows reversing "
                        "or overlapping) and were replaced by fill triangles")
    return _to_mesh(V, T, G, faces, kinds, warnings, chain, gstart, scale)


def _group_starts(keys: np.ndarray) -> np.ndarray:
    """(n,) bool: first element of each run of equal sorted keys."""
    return np.r_[True, keys[1:] != keys[:-1]] if keys.size else np.zeros(0, bool)


def _chains(V, T, G, good_v, a, d, m, scale):
    """Each generator's vertices inside the patch, with director points, sorted by t.

    Returns
    -------
    V, T, G : arrays with the director points appended
    chain : (n,) int64
        Vertex ids, generator by generator, increasing t.
    gstart : (m + 1,) int64
        Start of each generator's chain in ``chain``.
    """
    eps = _ON_BORDER
    inside = np.flatnonzero(good_v)
    gi, ti = G[inside], T[inside]
    has0 = np.zeros(m, bool)
    has1 = np.zeros(m, bool)
    has0[gi[ti <= eps]] = True
    has1[gi[ti >= 1 - eps]] = True
    new0, new1 = np.flatnonzero(~has0), np.flatnonzero(~has1)
    base = len(V)
    V = np.concatenate([V, a[new0], a[new1] + d[new1]])
    T = np.concatenate([T, np.zeros(len(new0)), np.ones(len(new1))])
    G = np.concatenate([G, new0, new1])
    # Grid vertices are stored generator by generator in row order; when t grows
    # with the row on every generator (the usual case) that order is the chain.
    same = gi[1:] == gi[:-1]
    if np.all(ti[1:][same] > ti[:-1][same]):
        counts = np.bincount(gi, minlength=m)
        first = np.cumsum(counts) - counts
        need0, need1 = (~has0).astype(np.int64), (~has1).astype(np.int64)
        clen = counts + need0 + need1
        gstart = np.zeros(m + 1, np.int64)
        np.cumsum(clen, out=gstart[1:])
        chain = np.empty(int(gstart[-1]), np.int64)
        chain[gstart[:-1][gi] + need0[gi] + np.arange(len(inside)) - first[gi]] = inside
        chain[gstart[new0]] = base + np.arange(len(new0))
        chain[gstart[new1 + 1] - 1] = base + len(new0) + np.arange(len(new1))
    else:
        ids = np.concatenate([inside, base + np.arange(len(new0) + len(new1))])
        chain = ids[np.lexsort((T[ids], G[ids]))]
        gstart = np.searchsorted(G[chain], np.arange(m + 1))
    return V, T, G, chain, gstart


def _strip_paths(V, T, G, good_v, a, d, m, L, R, ok_l, ok_r, CG, scale):
    """Make every strip between consecutive generators one conforming zipper.

    In strip s (between g_s and g_s+1) the vertices of each generator inside the
    patch, plus the director points at t = 0 and t = 1, form two chains sorted
    by t.  A triangulation of the strip is a monotone lattice path through
    (rank on g_s, rank on g_s+1); each PQ half-face is one step of it.  Steps
    that do not fit a monotone path are dropped, and every gap between the kept
    runs (and from the director curves to them) is filled by zipper steps.
    """
    V, T, G, chain, gstart = _chains(V, T, G, good_v, a, d, m, scale)
    rank = np.full(len(V), -1, np.int64)
    rank[chain] = np.arange(len(chain)) - np.repeat(gstart[:-1], np.diff(gstart))
    clen = np.diff(gstart)                       # chain length per generator (>= 2)
    # Steps: right halves [A_k, B_l, A_k+1] in strip CG; left halves [A_k, B_l, B_l+1] in CG-1.
    ir = np.flatnonzero(ok_r)
    il = np.flatnonzero(ok_l)
    rk = rank[R[ir]]
    lk = rank[L[il]]
    gr, gl = rk[:, 2] == rk[:, 0] + 1, lk[:, 2] == lk[:, 1] + 1
    ir, il, rk, lk = ir[gr], il[gl], rk[gr], lk[gl]
    st_strip = np.concatenate([CG[ir], CG[il] - 1])
    st_k = np.concatenate([rk[:, 0], lk[:, 0]])
    st_l = np.concatenate([rk[:, 1], lk[:, 1]])
    st_a = np.concatenate([np.ones(len(ir), bool), np.zeros(len(il), bool)])
    st_id = np.concatenate([ir, il])
    # Order steps along each strip's path by scattering them to their path
    # position (one slot per position; a second step claiming a slot overlaps).
    nstrip = m - 1
    plen = clen[:-1] + clen[1:] - 2                # steps in a full path of each strip
    pstart = np.zeros(nstrip + 1, np.int64)
    np.cumsum(plen, out=pstart[1:])
    slot = np.full(int(pstart[-1]), -1, np.int64)
    slot[pstart[st_strip] + st_k + st_l] = np.arange(len(st_id))
    order = slot[slot >= 0]
    st_strip, st_k, st_l, st_a, st_id = (x[order] for x in (st_strip, st_k, st_l, st_a, st_id))
    end_k = st_k + st_a
    end_l = st_l + ~st_a
    # Keep a step only if it starts at or beyond where every earlier step of its
    # strip ended (a monotone path); counting dropped steps too is conservative.
    big = np.int64(1) << 40
    prev_k = np.maximum.accumulate(st_strip * big + end_k) - st_strip * big
    prev_l = np.maximum.accumulate(st_strip * big + end_l) - st_strip * big
    first = _group_starts(st_strip)
    pk = np.where(first, -1, np.r_[-1, prev_k[:-1]])
    pl = np.where(first, -1, np.r_[-1, prev_l[:-1]])
    keep = (st_k >= pk) & (st_l >= pl)
    st_strip, st_k, st_l, st_a, st_id, end_k, end_l = (
        x[keep] for x in (st_strip, st_k, st_l, st_a, st_id, end_k, end_l))
    keep_r = np.zeros(len(R), bool)
    keep_l = np.zeros(len(L), bool)
    keep_r[st_id[st_a]] = True
    keep_l[st_id[~st_a]] = True
    # Gaps, in one sweep: before the first step of a strip, between two steps that
    # do not meet, after the last step, and whole strips without steps.
    first = _group_starts(st_strip)
    last = np.r_[first[1:], True] if len(first) else first
    between = ~first
    between[1:] &= (end_k[:-1] != st_k[1:]) | (end_l[:-1] != st_l[1:])
    btw = np.flatnonzero(between)
    fst = np.flatnonzero(first)
    lst = np.flatnonzero(last)
    empty = np.setdiff1d(np.arange(nstrip), st_strip, assume_unique=False)
    g_strip = np.concatenate([st_strip[fst], st_strip[btw], st_strip[lst], empty])
    g_k0 = np.concatenate([np.zeros(len(fst), np.int64), end_k[btw - 1], end_k[lst],
                           np.zeros(len(empty), np.int64)])
    g_l0 = np.concatenate([np.zeros(len(fst), np.int64), end_l[btw - 1], end_l[lst],
                           np.zeros(len(empty), np.int64)])
    g_k1 = np.concatenate([st_k[fst], st_k[btw], clen[st_strip[lst]] - 1, clen[empty] - 1])
    g_l1 = np.concatenate([st_l[fst], st_l[btw], clen[st_strip[lst] + 1] - 1, clen[empty + 1] - 1])
    na = np.maximum(g_k1 - g_k0, 0)
    nb = np.maximum(g_l1 - g_l0, 0)
    fill = _zippers(T, chain, gstart, g_strip, g_k0, g_l0, na, nb)
    return V, T, G, keep_l, keep_r, fill, chain, gstart


def _zippers(T, chain, gstart, strip, k0, l0, na, nb) -> np.ndarray:
    """Zipper triangles of many gaps at once.

    Gap g runs from (k0, l0) to (k0 + na, l0 + nb) in strip ``strip[g]``;
    chain A is generator ``strip``, chain B is ``strip + 1``.
    """
    ng = len(strip)
    if ng == 0 or (na.sum() + nb.sum()) == 0:
        return np.zeros((0, 3), np.int64)
    gid_a = np.repeat(np.arange(ng), na)
    gid_b = np.repeat(np.arange(ng), nb)
    ka = np.arange(gid_a.size) - np.repeat(np.cumsum(na) - na, na)   # 0..na-1 within the gap
    lb = np.arange(gid_b.size) - np.repeat(np.cumsum(nb) - nb, nb)
    A = lambda g, k: chain[gstart[strip[g]] + k]          # noqa: E731
    B = lambda g, l: chain[gstart[strip[g] + 1] + l]      # noqa: E731
    key_a = T[A(gid_a, k0[gid_a] + ka + 1)]
    key_b = T[B(gid_b, l0[gid_b] + lb + 1)]
    gid = np.concatenate([gid_a, gid_b])
    is_a = np.concatenate([np.ones(gid_a.size, bool), np.zeros(gid_b.size, bool)])
    key = np.concatenate([key_a, key_b])
    order = np.lexsort((key, gid))
    gid, is_a = gid[order], is_a[order]
    # Position before each step: gap start plus the steps of each kind already taken.
    first = _group_starts(gid)
    ca = np.cumsum(is_a) - is_a
    cb = np.cumsum(~is_a) - ~is_a
    start_idx = np.flatnonzero(first)
    run = np.cumsum(first) - 1
    ca = ca - ca[start_idx][run]
    cb = cb - cb[start_idx][run]
    k = k0[gid] + ca
    l = l0[gid] + cb
    a_k, b_l = A(gid, k), B(gid, l)
    # Evaluate each branch only where it applies (the other index may be past the chain end).
    third = np.where(is_a, A(gid, np.where(is_a, k + 1, k)), B(gid, np.where(is_a, l, l + 1)))
    return np.stack([a_k, b_l, third], axis=1)


def _to_mesh(V, T, G, faces, kinds, warnings, chain, gstart, scale) -> Mesh:
    """Mesh from fixed-valence face arrays; members along the generators."""
    off = [np.zeros(1, np.int64)]
    total = 0
    for f in faces:
        off.append(np.arange(1, len(f) + 1, dtype=np.int64) * f.shape[1] + total)
        total += f.size
    off = np.concatenate(off)
    idx = np.concatenate([f.reshape(-1) for f in faces]).astype(np.int64)
    kind = np.concatenate(kinds).astype(np.uint8)
    # Generators that share an end point (a torsal pair meeting on a director
    # curve) give coincident points at t = 0 or 1: merge those, nothing else.
    used0 = np.zeros(len(V), bool)
    used0[idx] = True
    ends = np.flatnonzero(used0 & ((T <= 1e-12) | (T >= 1 - 1e-12)))
    if len(ends) > 1:
        key = np.round(V[ends] / (1e-12 * scale)).astype(np.int64)
        _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
        if len(first) < len(ends):
            remap = np.arange(len(V))
            remap[ends] = ends[first[inv.reshape(-1)]]
            idx = remap[idx]
            if chain is not None:
                chain = remap[chain]
    used = np.zeros(len(V), bool)
    used[idx] = True
    if chain is not None:
        # Members: consecutive chain vertices of a generator, both used by faces.
        gch = np.repeat(np.arange(len(gstart) - 1), np.diff(gstart))
        pair = (gch[1:] == gch[:-1]) & used[chain[1:]] & used[chain[:-1]] & (chain[1:] != chain[:-1])
        members = np.stack([chain[:-1][pair], chain[1:][pair]], axis=1)
        member_id = gch[:-1][pair]
    else:
        ids = np.flatnonzero(used & (G >= 0))
        order = ids[np.lexsort((T[ids], G[ids]))]
        same = G[order[1:]] == G[order[:-1]]
        members = np.stack([order[:-1][same], order[1:][same]], axis=1)
        member_id = G[order[:-1][same]]
    # Renumber to the used vertices only.
    new = np.cumsum(used) - 1
    mesh = Mesh(V[used], off, new[idx], kind, new[members].astype(np.int64),
                member_id.astype(np.int64), {"t": T[used], "generator": G[used]},
                {"construction": "pq (paper §4.3)", "warnings": warnings})
    return mesh.drop_repeated_corners()


# ---------------------------------------------------------------- design files
_MESH_KEYS = ("method", "rows", "primary", "option", "extend", "trim", "max_extend")


@mesh_method("pq")
def build_pq(rulings, table: Mapping[str, Any], ctx: BuildContext) -> Built:
    """Design-file builder for ``[mesh] method = "pq"``."""
    check_keys(table, _MESH_KEYS, "mesh", err=DesignError)
    rows = check_int(table.get("rows", 20), "mesh.rows", lo=1, hi=100_000, err=DesignError)
    primary = table.get("primary", "middle")
    m = len(rulings.a)
    if isinstance(primary, str):
        if primary != "middle":
            raise DesignError(f'expected "middle" or an index, got {describe(primary)}', "mesh.primary")
    else:
        primary = check_int(primary, "mesh.primary", lo=-m, hi=m - 1, err=DesignError)
    option = check_int(table.get("option", 0), "mesh.option", lo=0, hi=1, err=DesignError)
    extend = table.get("extend", "auto")
    if extend != "auto":
        if isinstance(extend, str):
            raise DesignError(f'expected "auto" or a number >= 0, got {describe(extend)}', "mesh.extend")
        extend = check_float(extend, "mesh.extend", lo=0.0, hi=1e3, err=DesignError)
    trim = check_bool(table.get("trim", True), "mesh.trim", err=DesignError)
    max_extend = check_float(table.get("max_extend", 20.0), "mesh.max_extend", lo=0.0, hi=1e3,
                             err=DesignError)
    mesh = pq_mesh(rulings.a, rulings.b, rows=rows, primary=primary, option=option, extend=extend,
                   trim=trim, max_extend=max_extend, creases=rulings.info.get("creases"))
    reference = None
    if getattr(rulings, "surface", None) is not None:
        from .analysis.surface import RuledReference

        reference = RuledReference(rulings.surface)
    return Built(mesh.with_info(source=ctx.source), reference, rulings)
