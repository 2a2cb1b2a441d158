"""Runs of the §4.3 mesher: checkerboard grids on consecutive generators.

A *run* is a range of generators meshed by one pair of chains.  Runs end at
torsal generators (the twist changes sign, hops across would reverse the rows)
and where the two chains have drifted too far apart for convex quads.  A run
that starts where another ends takes that run's vertices on the shared
generator as the division of its primary (a *matched division*), so the two
runs meet in well-shaped triangles along one generator instead of a band of
splinters, and the rows carry on across it.

Chain *b*'s rows are free to start anywhere between chain *a*'s: each row is
rooted in the middle of the interval of root parameters that keeps every face
of the row convex on every generator it reaches.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...budget import MAX_GRID_POINTS, PQ_BYTES_PER_GRID_POINT
from ...errors import GeometryError
from ...kernels import wanted
from ...tolerances import (
    EVEN_MAX_ADDED,
    EVEN_MAX_HALVINGS,
    EVEN_PINCH_SHARE,
    EVEN_PINCH_STEP_PER_WIDTH,
    EVEN_STEP_PER_WIDTH,
    INTERIOR,
    RESTART_ANGLE_DEG,
    ROUNDING,
    TINY,
    Tolerances,
)
from .extension import LANDING_SLACK, thinned_rows
from .grading import graded_rows
from .maps import (
    ChainMaps,
    HopMaps,
    apply,
    chain_maps,
    compose,
    drift_maps,
    hop_maps,
    inverse,
    patch_preimage,
    propagate,
)

__all__ = ["BOTH_ENDS", "MAX_GRID_POINTS", "Division", "Run", "carrier", "graded_carrier", "matched", "mesh_run"]

# The grid-point limit and the memory per point: ruledmesh.budget.
BYTES_PER_GRID_POINT = PQ_BYTES_PER_GRID_POINT


@dataclass(frozen=True)
class Division:
    """How the primary generator of a run is divided.

    Either uniform (``rows`` steps over [0, 1], extended automatically or by
    ``extend``, checkerboard colour ``option``), or *matched*: the given
    parameters ``matched`` (increasing, the vertices another run left on this
    generator), extended by their end spacings as far as the run needs.
    ``ends`` (0 or 1; a uniform division only) also puts a row through the end
    point ``t = ends`` of every generator the rows cross there (:func:`_through_ends`);
    :data:`BOTH_ENDS` through the end points at both ends.
    ``graded`` (not matched) spaces the rows for faces of about even shape on
    every generator they reach instead of evenly on the primary (:func:`_graded_rows`);
    ``bounded`` with no square step above :data:`.grading.BOUND` medians.
    """

    rows: int
    option: int = 0
    extend: float | str = "auto"
    max_extend: float = 20.0
    matched: np.ndarray | None = None
    ends: int | None = None
    graded: bool = False
    bounded: bool = False


@dataclass
class Run:
    """The checkerboard grid of one run of generators (before trimming).

    Half-faces are triangles of the zigzag strips between consecutive
    generators: the face centred at (i, r) is the union of its left half
    [X[i-1,r], X[i,r-1], X[i,r+1]] and right half [X[i,r-1], X[i+1,r], X[i,r+1]],
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
    failing: np.ndarray       # (m,) faces on the patch not convex or too thin, per generator
    on_patch: np.ndarray      # (m,) faces on the patch, per generator
    # Generators whose patch the rows reach only through the primary's point at infinity
    # (no finite division covers it: patch_preimage), for the build's warning.
    uncovered: int = 0

    def inside_t(self, g: int) -> np.ndarray:
        """Increasing parameters of this run's vertices on global generator ``g`` in [0, 1]."""
        # Within rounding of the border counts as on it, so the division handed on
        # does not change with the scale of the design.
        eps = ROUNDING
        sel = (self.gen == g) & ~self.far & (self.t >= -eps) & (self.t <= 1.0 + eps)
        return np.sort(self.t[sel])


def _uniform_rows(M: np.ndarray, div: Division, primary_global: int, preimage: tuple,
                  warnings: list[str]) -> np.ndarray:
    """Root parameters of all rows, uniform in ``1 / rows``; even entries on the primary
    (``preimage``: :func:`~.maps.patch_preimage` of ``M``).

    Beyond the primary's part the rows that would bunch on every generator are
    left out (:func:`~ruledmesh.skew.pq.extension.thinned_rows`).
    """
    rows = div.rows
    if isinstance(div.extend, str):         # "auto" or "full": what covers the patch
        lo_v, hi_v = _covering(preimage, div, warnings)
        # Two rows of margin on each side: a face spans two row steps.
        j0 = math.floor(lo_v * rows) - 2
        j1 = math.ceil(hi_v * rows) + 2
    else:
        e = float(div.extend)
        j0 = -math.ceil(e * rows)
        j1 = rows + math.ceil(e * rows)
    # The primary carries the rows of the colour `option` (global i + j parity).
    if (primary_global + j0 - div.option) % 2:
        j0 -= 1
    count = j1 - j0 + 1
    count += count % 2
    tau = (j0 + np.arange(count)) / rows
    return thinned_rows(M, tau, (0.0, 1.0), rows) if div.extend == "auto" else tau


def _covering(preimage: tuple, div: Division, warnings: list[str]) -> tuple[float, float]:
    """The range of the primary's parameter whose rows cover the patch on every generator
    (with [0, 1]), capped at ``div.max_extend``; a warning where no finite range does.
    ``preimage``: the row maps' :func:`~.maps.patch_preimage`."""
    lo, hi, bounded = preimage
    if not np.all(bounded):
        warnings.append(f"{int((~bounded).sum())} generators cannot be covered by a finite "
                        f"division of the primary generator; extension capped at "
                        f"{div.max_extend:g} generator lengths")
    lo_v = lo[bounded].min() if bounded.any() else 0.0
    hi_v = hi[bounded].max() if bounded.any() else 1.0
    return max(min(lo_v, 0.0), -div.max_extend), min(max(hi_v, 1.0), 1.0 + div.max_extend)


def matched(div: Division, t: np.ndarray | None) -> Division:
    """The division of a run continuing ``div``'s on a generator whose vertices are ``t``.

    Its extension is automatic; bunched rows beyond ``t`` are left out unless ``div``
    keeps every row (``extend = "full"``).
    """
    return Division(div.rows, div.option, "full" if div.extend == "full" else "auto",
                    div.max_extend, t)


def _with_middles(a_rows: np.ndarray, last_step: float) -> np.ndarray:
    """Root parameters of a-rows ``a_rows`` with the b-rows at their middles, and one more
    b-row half ``last_step`` beyond the last a-row."""
    out = np.empty(2 * len(a_rows))
    out[0::2] = a_rows
    out[1:-1:2] = 0.5 * (a_rows[1:] + a_rows[:-1])
    out[-1] = a_rows[-1] + 0.5 * last_step
    return out


def _matched_rows(M: np.ndarray, div: Division, preimage: tuple) -> np.ndarray:
    """Root parameters from a matched division, extended by the end spacings
    (``preimage``: :func:`~.maps.patch_preimage` of ``M``).

    Beyond the given rows those that would bunch on every generator are left out
    (unless ``div.extend`` is ``"full"``).
    """
    given = np.asarray(div.matched, dtype=np.float64)
    lo, hi, bounded = preimage
    lo_v = max(lo[bounded].min() if bounded.any() else 0.0, -div.max_extend)
    hi_v = min(hi[bounded].max() if bounded.any() else 1.0, 1.0 + div.max_extend)
    if given.size == 1:
        step = 2.0 / div.rows
        s0 = s1 = step
    else:
        floor = INTERIOR / div.rows
        s0, s1 = max(given[1] - given[0], floor), max(given[-1] - given[-2], floor)
    # Two A-row steps of margin beyond what covers the patch (a face spans two steps).
    n0 = max(math.ceil((given[0] - lo_v) / s0) + 2, 2)
    n1 = max(math.ceil((hi_v - given[-1]) / s1) + 2, 2)
    n0, n1 = min(n0, 100_000), min(n1, 100_000)
    a_rows = np.concatenate([given[0] - s0 * np.arange(n0, 0, -1), given,
                             given[-1] + s1 * np.arange(1, n1 + 1)])
    out = _with_middles(a_rows, s1)
    if div.extend == "full":
        return out
    return thinned_rows(M, out, (float(given[0]), float(given[-1])), div.rows)


# Division.ends for rows through the end points on both director curves.
BOTH_ENDS = 2


def _sides(ends: int) -> tuple[float, ...]:
    """The end parameters ``t`` the rows of :attr:`Division.ends` pass through."""
    return (0.0, 1.0) if ends == BOTH_ENDS else (float(ends),)


def _roots_through(M: np.ndarray, sides: tuple[float, ...], lo: float, hi: float, mine: np.ndarray) -> np.ndarray:
    """Increasing root parameters in ``(lo, hi)`` of the rows through the end points ``t`` in
    ``sides`` of the generators ``mine`` (m,) bool."""
    roots = np.concatenate([_end_roots(M, side, lo, hi)[mine] for side in sides])
    return np.sort(roots[np.isfinite(roots)])


# Rows through the end points: of two roots closer than this share of an a-row step
# (2 / rows), the second is left out (a row that meets the curve twice, on either side of
# a turn, would otherwise be there twice) ...
_ENDS_MIN_GAP = 0.2
# ... and a b-row goes through an end point only where that root lies this far inside its
# a-rows' bracket (else it keeps its convex root).
_ENDS_B_MARGIN = 0.1


def _end_roots(M: np.ndarray, side: float, lo: float, hi: float) -> np.ndarray:
    """(m,) root parameters of the rows through each generator's point ``t = side`` (NaN
    where that is at a pole or outside ``(lo, hi)``)."""
    r = apply(inverse(M), np.full(len(M), side))
    return np.where(np.isfinite(r) & (r > lo) & (r < hi), r, np.nan)


def _through_ends(M: np.ndarray, tau: np.ndarray, parity: np.ndarray, sides: tuple[float, ...],
                  rows: int) -> np.ndarray:
    """Chain *a*'s roots moved so that a row passes through the end point ``t = side`` of
    every a-generator, for each of ``sides`` (b-rows at the middles, rooted afterwards).

    Where every row the border cuts passes through a generator's end point, the
    border edges are edges of quads (the hop from one end point lands on the
    next-but-one generator inside the patch, the other chain ends on the border
    between): no teeth of triangles along that director curve.  Beyond the
    range of these roots the uniform rows stay (rows that never reach the curve).
    """
    step = 2.0 / rows
    ends = _roots_through(M, sides, tau[0], tau[-1], parity == 0)
    if ends.size < 2:
        return tau
    # A row close to one kept before is left out (a run of close roots keeps its first).
    kept = [ends[0]]
    for r in ends[1:]:
        if r - kept[-1] > _ENDS_MIN_GAP * step:
            kept.append(r)
    a_rows = tau[0::2]
    outside = a_rows[(a_rows < kept[0] - 0.5 * step) | (a_rows > kept[-1] + 0.5 * step)]
    a_rows = np.sort(np.concatenate([outside, kept]))
    if a_rows.size < 2:     # one row through the ends and none beside it (a graded division
        return tau          # that lies wholly within the end points' roots): as it was
    return _with_middles(a_rows, a_rows[-1] - a_rows[-2])


def _b_through_ends(M: np.ndarray, tau: np.ndarray, parity: np.ndarray,
                    sides: tuple[float, ...]) -> np.ndarray:
    """Chain *b*'s roots moved onto the end points ``t`` in ``sides`` of the b-generators: in
    each bracket of a-rows the end point's root nearest its middle, where one lies inside."""
    ends = _roots_through(M, sides, tau[0], tau[-1], parity == 1)
    if ends.size == 0:
        return tau
    lo, hi = tau[0:-2:2], tau[2::2]
    mid = 0.5 * (lo + hi)
    k = np.clip(np.searchsorted(ends, mid), 1, ends.size - 1) if ends.size > 1 else np.zeros(len(mid), int)
    near = ends[k]
    if ends.size > 1:
        other = ends[k - 1]
        near = np.where(np.abs(other - mid) < np.abs(near - mid), other, near)
    margin = _ENDS_B_MARGIN * (hi - lo)
    inside = (near > lo + margin) & (near < hi - margin)
    out = tau.copy()
    out[1:-1:2] = np.where(inside, near, tau[1:-1:2])
    return out


def _root_b_rows(M: np.ndarray, N: np.ndarray, tau: np.ndarray, primary: int,
                 parity: np.ndarray) -> np.ndarray:
    """Chain *b*'s roots, each in the middle of the interval that keeps its faces convex.

    For b-row ``h`` between a-rows ``tau[2h]`` and ``tau[2h+2]`` every face it
    takes part in gives an interval of admissible roots:
    ``N_i^-1`` of the a-rows on a-generators, ``N_i`` of them on b-generators.
    The intervals are intersected from the primary outwards, as far as the
    intersection stays non-empty; the root is its middle.
    """
    m = len(M)
    a_lo, a_hi, sigma0 = tau[0:-2:2], tau[2::2], tau[1:-1:2]
    H = len(a_lo)
    if m < 3 or H == 0:
        return tau
    inner = np.arange(1, m - 1)
    Ni = N[inner]
    maps = np.where((parity[inner] == 0)[:, None, None], inverse(Ni), Ni)
    lo = apply(maps, np.broadcast_to(a_lo, (len(inner), H)).copy())
    hi = apply(maps, np.broadcast_to(a_hi, (len(inner), H)).copy())
    lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
    # Only faces on the patch constrain a row.
    t_mid = apply(M[inner], np.broadcast_to(sigma0, (len(inner), H)).copy())
    relevant = (np.isfinite(lo) & np.isfinite(hi) & (t_mid > -LANDING_SLACK)
                & (t_mid < 1.0 + LANDING_SLACK))
    lo = np.where(relevant, lo, -np.inf)
    hi = np.where(relevant, hi, np.inf)
    order = np.argsort(np.abs(inner - primary - 0.5), kind="stable")
    cum_lo = np.maximum.accumulate(lo[order], axis=0)
    cum_hi = np.minimum.accumulate(hi[order], axis=0)
    ok = cum_lo < cum_hi
    # Last feasible prefix per row (rows infeasible from the start keep their default).
    reach = np.where(ok.all(axis=0), len(order), np.argmin(ok, axis=0))
    has = reach > 0
    k = np.maximum(reach - 1, 0)
    L = cum_lo[k, np.arange(H)]
    U = cum_hi[k, np.arange(H)]
    bounded = has & np.isfinite(L) & np.isfinite(U)
    Lf, Uf = np.where(np.isfinite(L), L, a_lo), np.where(np.isfinite(U), U, a_hi)
    sigma = np.where(bounded, 0.5 * (Lf + Uf), sigma0)
    # One-sided intervals: keep the default where it is inside, else move just inside.
    sigma = np.where(has & ~bounded & np.isfinite(L) & (sigma0 <= Lf), Lf + 0.5 * (a_hi - Lf), sigma)
    sigma = np.where(has & ~bounded & np.isfinite(U) & (sigma0 >= Uf), Uf - 0.5 * (Uf - a_lo), sigma)
    # Never leave the a-rows' bracket on the primary, and keep the rows in order.
    sigma = np.clip(sigma, a_lo + INTERIOR * (a_hi - a_lo), a_hi - INTERIOR * (a_hi - a_lo))
    out = tau.copy()
    out[1:-1:2] = sigma
    return out


def mesh_run(a: np.ndarray, d: np.ndarray, first: int, primary: int, div: Division,
             tol: Tolerances, scale: float, warnings: list[str], hops: HopMaps | None = None) -> Run:
    """Checkerboard PQ grid on generators a, d (a run), before trimming.

    Parameters
    ----------
    a, d : (m, 3) float64
        The run's generators, ``m >= 3``.
    first : int
        Global index of the run's first generator.
    primary : int
        Run-local index of the primary generator.
    div : Division
    tol : Tolerances
    scale : float
        Patch diagonal.
    warnings : list of str
        Appended to.
    hops : HopMaps, optional
        The hop maps of all the generators that ``a``, ``d`` are a run of
        (from index ``first``), if measured already.
    """
    m = len(a)
    hops = hops.part(first, m) if hops is not None else hop_maps(a, d)
    maps = chain_maps(a, d, primary, hops)
    primary = maps.primary
    M = compose(maps, m)
    preimage = patch_preimage(M, tol.degenerate)
    if div.matched is not None and len(div.matched):
        tau = _matched_rows(M, div, preimage)
    elif div.graded and m >= 3:
        lo, hi = _covering(preimage, div, warnings) if isinstance(div.extend, str) else \
            (-float(div.extend), 1.0 + float(div.extend))
        tau = graded_rows(a, d, M, lo, hi, div.rows, bool((first + primary - div.option) % 2), div.bounded)
    else:
        tau = _uniform_rows(M, div, first + primary, preimage, warnings)
    parity = (np.arange(m) - primary) % 2                     # 0: chain a, 1: chain b
    sides = None if div.ends is None or div.matched is not None else _sides(div.ends)
    if sides is not None:
        tau = _through_ends(M, tau, parity, sides, div.rows)
    H = len(tau) // 2
    if m * 2 * H > MAX_GRID_POINTS:
        need = m * 2 * H * BYTES_PER_GRID_POINT / 2**30
        raise GeometryError(f"the grid would have {m} x {2 * H} points (about {need:.1f} GiB); "
                            f"reduce the generator count, the rows or the extension")
    N = drift_maps(a, d, M, hops.crossing)
    tau = _root_b_rows(M, N, tau, primary, parity)
    if sides is not None:
        tau = _b_through_ends(M, tau, parity, sides)
    run = _grid(a, d, first, maps, tau, parity, tol, scale, hops.crossing)
    run.uncovered = int(np.count_nonzero(~preimage[2]))
    return run


def _grid(a: np.ndarray, d: np.ndarray, first: int, maps: ChainMaps, tau: np.ndarray,
          parity: np.ndarray, tol: Tolerances, scale: float, Xc: np.ndarray) -> Run:
    """Vertices and half-faces of a run from its rows' root parameters."""
    m = len(a)
    H = len(tau) // 2
    roots = tau[parity[:, None] + 2 * np.arange(H)[None, :]]          # (m, H)
    glen = np.linalg.norm(d, axis=1)
    tmax = tol.far * scale / np.maximum(glen, TINY)
    kern = wanted(m * H, "grid")
    if kern is not None:
        # One pass per stage, the same arithmetic (ruledmesh.kernels.grid).
        num, den = kern.propagate(maps.primary, maps.root, maps.fwd, maps.bwd, maps.crossing, roots)
        X, t, far, left, right, pole, cg, failing, on_patch = kern.grid(
            a, d, num, den, tmax, parity, Xc, first, RESTART_ANGLE_DEG)
        gen = np.repeat(np.arange(first, first + m), H)
        return Run(X, t, gen, far, left, right, pole, cg, failing, on_patch)
    num, den = propagate(maps, roots)
    far = ~(np.abs(num) < tmax[:, None] * np.abs(den))
    t = np.where(far, 0.0, num / np.where(far, 1.0, den))
    X = a[:, None, :] + t[..., None] * d[:, None, :]
    vid = np.arange(m * H).reshape(m, H)
    # Faces centred on g_i at the rows of the other colour: c = 0..H-1, with the
    # vertices h_lo = c - parity, h_lo + 1 on g_i and h = c on g_i-1 and g_i+1.
    cc = np.broadcast_to(np.arange(H)[None, :], (m, H))
    h_lo = cc - parity[:, None]
    ok = (h_lo >= 0) & (h_lo + 1 < H)
    i_idx = np.arange(m)
    ic = np.broadcast_to(i_idx[:, None], (m, H))[ok]
    hl = h_lo[ok]
    hc = cc[ok]
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
    failing, on_patch = _failing_faces(a, d, t, far, ic, hl, hc, pole, m, Xc)
    gen = np.repeat(np.arange(first, first + m), H)
    return Run(X.reshape(-1, 3), t.reshape(-1), gen, far.reshape(-1), left, right, pole,
               ic + first, failing, on_patch)


def _failing_faces(a, d, t, far, ic, hl, hc, pole, m, X) -> tuple[np.ndarray, np.ndarray]:
    """Per generator: faces centred on it on the patch that fail, and all on the patch.

    A face fails when its crossing misses its generator diagonal (a bow-tie) or
    when it is a sliver (:func:`_thin`).  ``X`` (m-2, 2, 2): the crossing maps of
    the inner generators.
    """
    inner = (ic > 0) & (ic < m - 1)
    failing = np.zeros(m, np.int64)
    counted = np.zeros(m, np.int64)
    if m < 3 or not inner.any():
        return failing, counted
    i, lo, c = ic[inner], hl[inner], hc[inner]
    ts = t[i - 1, c]
    k = i - 1
    num = X[k, 0, 0] * ts + X[k, 0, 1]
    den = X[k, 1, 0] * ts + X[k, 1, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        tc = num / den
    t0, t1 = t[i, lo], t[i, lo + 1]
    on_patch = np.isfinite(tc) & (tc > 0.0) & (tc < 1.0) & ~pole[inner] \
        & ~far[i, lo] & ~far[i, lo + 1] & ~far[i - 1, c] & ~far[i + 1, c]
    between = (tc - t0) * (tc - t1) < 0
    np.add.at(failing, i[on_patch & (~between | _thin(a, d, t, i, lo, c))], 1)
    np.add.at(counted, i[on_patch], 1)
    _thin_ends(a, d, t, far, ic, hl, hc, m, failing, counted)
    return failing, counted


def _thin_ends(a, d, t, far, ic, hl, hc, m, failing, counted) -> None:
    """Count the notch halves on the run's end generators that are slivers (in place).

    A face centred on an end generator keeps one half, which is a triangle of
    the mesh; a sliver there counts against the generator next to the end, so
    the run is cut before it.
    """
    # Both ends' halves measured in one call (the angles are per face): this runs on a
    # few faces per run.
    found = []
    for end, side, inner in ((0, 1, 1), (m - 1, -1, m - 2)):
        sel = np.flatnonzero(ic == end)
        if sel.size == 0:
            continue
        lo, c = hl[sel], hc[sel]
        ok = ~far[end, lo] & ~far[end, lo + 1] & ~far[end + side, c] \
            & (t[end, lo] >= 0.0) & (t[end, lo + 1] <= 1.0)
        P = np.stack([a[end] + t[end, lo][:, None] * d[end],
                      a[end + side] + t[end + side, c][:, None] * d[end + side],
                      a[end] + t[end, lo + 1][:, None] * d[end]], axis=1)
        found.append((inner, ok, P))
    if not found:
        return
    thin = _sliver(np.concatenate([P for _, _, P in found]))
    start = 0
    for inner, ok, _ in found:
        failing[inner] += int(np.count_nonzero(ok & thin[start:start + ok.size]))
        counted[inner] += int(np.count_nonzero(ok))
        start += ok.size


def _thin(a, d, t, i, lo, c) -> np.ndarray:
    """Faces centred on ``g_i`` whose smallest corner angle is below :data:`RESTART_ANGLE_DEG`.

    Near a torsal generator the second asymptotic direction turns into the
    generator: the rows run nearly along it and every face there is a sliver,
    however the rows are rooted.  Such faces count as failing, so the run
    ends before them and the band is closed by triangles of good shape.
    """
    P = np.stack([a[i - 1] + t[i - 1, c][:, None] * d[i - 1], a[i] + t[i, lo][:, None] * d[i],
                  a[i + 1] + t[i + 1, c][:, None] * d[i + 1], a[i] + t[i, lo + 1][:, None] * d[i]],
                 axis=1)
    return _sliver(P)


def _sliver(P: np.ndarray) -> np.ndarray:
    """(F,) bool: polygons ``P`` (F, k, 3) with a corner angle below :data:`RESTART_ANGLE_DEG`."""
    from ...analysis.faces import polygon_angles

    return polygon_angles(P).min(axis=1) < RESTART_ANGLE_DEG


def carrier(a: np.ndarray, d: np.ndarray, first: int, t: np.ndarray) -> Run:
    """Vertices at parameters ``t`` on each of a few generators, no faces (too few to hop)."""
    m = len(a)
    tt = np.tile(np.asarray(t, dtype=np.float64), m)
    gen = np.repeat(np.arange(first, first + m), len(t))
    return _carried(a, d, first, tt, gen)


def _carried(a: np.ndarray, d: np.ndarray, first: int, tt: np.ndarray, gen: np.ndarray) -> Run:
    """The :class:`Run` of vertices at parameters ``tt`` on global generators ``gen`` (no faces)."""
    m = len(a)
    X = a[gen - first] + tt[:, None] * d[gen - first]
    none = np.zeros((0, 3), np.int64)
    return Run(X, tt, gen, np.zeros(len(tt), bool), none, none, np.zeros(0, bool),
               np.zeros(0, np.int64), np.zeros(m, np.int64), np.zeros(m, np.int64))


def graded_carrier(a: np.ndarray, d: np.ndarray, lo: int, hi: int, t: np.ndarray) -> Run:
    """Vertices of an even division ``t`` on generators ``lo..hi``, graded where the strips pinch.

    A strip without rows is closed by zipper triangles between the divisions of its two
    generators; where the strip is much narrower than a step of the division (a
    hyperboloid's waist near its asymptotic cone, where every generator passes close to
    its neighbours), those triangles are splinters.  So each step of a generator's
    division longer than :data:`~ruledmesh.tolerances.EVEN_PINCH_STEP_PER_WIDTH` times the
    least distance to a neighbouring generator line over that step (a splinter's worth) is
    halved, and its halves again while longer than
    :data:`~ruledmesh.tolerances.EVEN_STEP_PER_WIDTH` times theirs, at most
    :data:`~ruledmesh.tolerances.EVEN_MAX_HALVINGS` times and while the vertices added stay
    within :data:`~ruledmesh.tolerances.EVEN_MAX_ADDED` times the division's: the steps
    shrink geometrically towards the pinch.  Where no strip pinches, the division is ``t``
    on every generator.

    Parameters
    ----------
    a, d : (m, 3) float64
        All the generators (the neighbours of ``lo`` and ``hi`` bound strips too).
    lo, hi : int
        The generators carrying the division.
    t : (k,) float64
        Increasing parameters of the even division.

    Returns
    -------
    Run
        Its vertices only (global generator indices ``lo..hi``).
    """
    m = len(a)
    t = np.asarray(t, dtype=np.float64)
    gens = np.arange(lo, hi + 1)
    t0 = np.tile(t[:-1], len(gens))
    t1 = np.tile(t[1:], len(gens))
    g = np.repeat(gens, len(t) - 1)
    extra_t, extra_g = [], []
    # Only the steps that would leave a splinter where the strip pinches are graded.  Strips
    # narrow from end to end (generators added close together) stay: the collapses join
    # their triangles across several strips.
    least, widest = _widths(a, d, g, t0, t1, m)
    pinched = (_step_length(d, g, t0, t1) > EVEN_PINCH_STEP_PER_WIDTH * least) \
        & (least < EVEN_PINCH_SHARE * widest)
    g, t0, t1 = g[pinched], t0[pinched], t1[pinched]
    budget, added = EVEN_MAX_ADDED * len(t) * len(gens), 0
    for _ in range(EVEN_MAX_HALVINGS):
        split = _step_length(d, g, t0, t1) > EVEN_STEP_PER_WIDTH * _widths(a, d, g, t0, t1, m)[0]
        added += int(split.sum())
        if not split.any() or added > budget:
            break
        g, t0, t1 = g[split], t0[split], t1[split]
        mid = 0.5 * (t0 + t1)
        extra_t.append(mid)
        extra_g.append(g)
        g, t0, t1 = np.r_[g, g], np.r_[t0, mid], np.r_[mid, t1]
    tt = np.tile(t, len(gens))
    gen = np.repeat(gens, len(t))
    if extra_t:
        tt, gen = np.concatenate([tt, *extra_t]), np.concatenate([gen, *extra_g])
        order = np.lexsort((tt, gen))
        tt, gen = tt[order], gen[order]
    return _carried(a[lo:hi + 1], d[lo:hi + 1], lo, tt, gen)


def _step_length(d: np.ndarray, g: np.ndarray, t0: np.ndarray, t1: np.ndarray) -> np.ndarray:
    """(n,) length of the steps ``[t0, t1]`` on generators ``g``."""
    return np.linalg.norm(d[g], axis=1) * (t1 - t0)


def _widths(a: np.ndarray, d: np.ndarray, g: np.ndarray, t0: np.ndarray, t1: np.ndarray,
            m: int) -> tuple[np.ndarray, np.ndarray]:
    """(n,) the least distance from the points of generator ``g`` with ``t0 <= t <= t1`` to a
    neighbouring generator line, and (n,) the width of the narrower strip at its wider end:
    over both neighbours, the smaller of the larger distances at ``t = 0`` and ``t = 1`` (the
    distance is convex in ``t``: the widest of the patch is at an end)."""
    least = np.full(len(g), np.inf)
    widest = np.full(len(g), np.inf)
    for step in (-1, 1):
        j = g + step
        has = (j >= 0) & (j < m)
        gi, gj = g[has], j[has]
        u = d[gj] / np.maximum(np.linalg.norm(d[gj], axis=1, keepdims=True), TINY)
        # The distance from a_i + t d_i to the line j is |c0 + t c1|: least at t* (clamped).
        c0 = np.cross(a[gi] - a[gj], u)
        c1 = np.cross(d[gi], u)
        cc = np.einsum("ij,ij->i", c1, c1)
        ts = np.where(cc > 0, -np.einsum("ij,ij->i", c0, c1) / np.where(cc > 0, cc, 1.0), t0[has])
        w = np.linalg.norm(c0 + np.clip(ts, t0[has], t1[has])[:, None] * c1, axis=1)
        ends = np.maximum(np.linalg.norm(c0, axis=1), np.linalg.norm(c0 + c1, axis=1))
        least[has] = np.minimum(least[has], w)
        widest[has] = np.minimum(widest[has], ends)
    return least, widest
