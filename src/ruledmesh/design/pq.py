"""Design-file builder for ``[mesh] method = "pq"`` (the §4.3 mesher of :mod:`ruledmesh.pq`)."""

from __future__ import annotations

import contextlib
import contextvars
import hashlib
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

from .._arrays import diagonal, member, unique
from .._validation import check_bool, check_choice, check_float, check_int, check_keys, describe
from ..budget import MAX_COUNT
from ..errors import DesignError, GeometryError
from ..registry import BuildContext, Built, mesh_method
from ..skew.pq import MAX_GRID_POINTS, PrimaryDivision, RowsFrom, pq_mesh
from ..skew.pq.reuse import reusing_assemblies
from ..tolerances import DEFAULT, SPAN_MAX_GAP, TINY

__all__ = ["MESH_KEYS", "build_pq", "keeping_meshes"]

MESH_KEYS = ("method", "rows", "primary", "option", "extend", "trim", "max_extend",
             "planarity_tolerance", "refine", "respace", "rows_from", "division", "thin")


@mesh_method("pq")
def build_pq(rulings, table: Mapping[str, Any], ctx: BuildContext) -> Built:
    """Design-file builder for ``[mesh] method = "pq"``."""
    check_keys(table, MESH_KEYS, "mesh", err=DesignError)
    rows = check_int(table.get("rows", 20), "mesh.rows", lo=1, hi=MAX_COUNT, err=DesignError)
    primary = table.get("primary", "middle")
    m = len(rulings.a)
    if isinstance(primary, str):
        if primary != "middle":
            raise DesignError(f'expected "middle" or an index, got {describe(primary)}', "mesh.primary")
    else:
        primary = check_int(primary, "mesh.primary", lo=-m, hi=m - 1, err=DesignError)
    option = check_int(table.get("option", 0), "mesh.option", lo=0, hi=1, err=DesignError)
    extend = table.get("extend", "auto")
    if extend != "auto" and extend != "full":
        if isinstance(extend, str):
            raise DesignError(f'expected "auto", "full" or a number >= 0, got {describe(extend)}',
                              "mesh.extend")
        extend = check_float(extend, "mesh.extend", lo=0.0, hi=1e3, err=DesignError)
    trim = check_bool(table.get("trim", True), "mesh.trim", err=DesignError)
    max_extend = check_float(table.get("max_extend", 20.0), "mesh.max_extend", lo=0.0, hi=1e3,
                             err=DesignError)
    # Relative, the paper's measure (analysis.planarity); 1e-12 (the default) is exact.
    ptol = check_float(table.get("planarity_tolerance", DEFAULT.planarity), "mesh.planarity_tolerance",
                       lo=0.0, hi=0.1, err=DesignError)
    refine = check_bool(table.get("refine", True), "mesh.refine", err=DesignError)
    respace = table.get("respace", "auto")
    if respace != "auto":
        respace = check_bool(respace, "mesh.respace", err=DesignError, word="auto")
    rows_from = table.get("rows_from", "auto")
    if rows_from != "auto":
        rows_from = check_choice(rows_from, RowsFrom, "mesh.rows_from", err=DesignError).value
    division = table.get("division", "auto")
    if division != "auto":
        division = check_choice(division, PrimaryDivision, "mesh.division", err=DesignError).value
    thin = table.get("thin", "auto")
    if thin != "auto":
        thin = check_bool(thin, "mesh.thin", err=DesignError, word="auto")
    options = {"rows": rows, "primary": primary, "option": option, "extend": extend,
               "trim": trim, "max_extend": max_extend, "planarity_tolerance": ptol,
               "respace": respace is True,
               "rows_from": RowsFrom.PRIMARY.value if rows_from == "auto" else rows_from,
               "division": PrimaryDivision.EVEN.value if division == "auto" else division,
               "thin": thin is True}
    token = _PROGRESS.set([ctx.task, 0]) if ctx.task is not None else None
    kept = _KEPT.get()
    made = _MADE.set(kept if kept is not None else {})
    # Only a refined build weighs more than one mesh: an unrefined one (the designer's quick
    # mesh on every edit) would hash its runs for nothing: 1.1 of 21 ms at 100 x 100.
    with reusing_assemblies() if refine else contextlib.nullcontext():
        try:
            mesh = _mesh(rulings, options)
            if refine:
                given = rulings
                rulings, kept, notes = _refined(rulings, mesh, options, respace == "auto",
                                                rows_from == "auto", division == "auto")
                # The graded division: here for explicit lines (for director curves the
                # refinement weighed it, with its own rounds).
                chosen_round, chosen = _other_rows(kept, options, free=(
                    "option" not in table, "primary" not in table, rows_from == "auto",
                    division == "auto" and _fixed_generators(given)))
                notes += chosen
                if rows_from == "auto":
                    rulings, chosen_round, notes = _rows_or_none(given, chosen_round, notes, options)
                if thin == "auto":
                    chosen_round = _with_thinned_rows(chosen_round, options)
                mesh = chosen_round[4]
                if mesh.info["rows_from"] != options["rows_from"] or mesh.info["option"] == "mixed":
                    notes.append(_rows_from_note(mesh.info))
                if mesh.info.get("thin") and not options["thin"]:
                    notes.append(_THINNED_NOTE)
                if notes:
                    mesh = mesh.with_info(warnings=list(mesh.info.get("warnings", [])) + notes)
        finally:
            _MADE.reset(made)
            if token is not None:
                _PROGRESS.reset(token)
    reference = None
    if getattr(rulings, "surface", None) is not None:
        from ..surfaces import RuledReference

        # Every vertex is a_g + t (b_g - a_g) = point(u_g, t): the closeness needs no search.
        reference = RuledReference(rulings.surface, generator_u=np.asarray(rulings.u, dtype=np.float64))
    return Built(mesh.with_info(source=ctx.source), reference, rulings, _slender(rulings))


def _slender(rulings) -> dict[str, Any]:
    """The report's ``slender`` figures of the generators meshed: the share of the patch where
    every exact face is at least a 10:1 panel (:func:`~ruledmesh.analysis.asymptotic.slender_share`)
    and the crossing angle under which that is so."""
    from ..analysis.asymptotic import SLENDER_DEG, slender_share

    if len(rulings.a) < 3:
        return {}
    return {"slender": {"share": slender_share(rulings.a, rulings.b), "rows_cross_below_deg": SLENDER_DEG}}


# The build's progress task and how many meshes it has made, while build_pq runs: the
# refinement makes up to about twenty, and a long build says which one it is at.
_PROGRESS: contextvars.ContextVar[list | None] = contextvars.ContextVar("pq_progress", default=None)


# The meshes build_pq has made, by their generators and options: the refinement's tiers
# and starts often come back to the same generators (twisted-arcs-160deg: 6 of 24 meshes,
# 2.2 of 9 s), and the same input makes the same mesh.
_MADE: contextvars.ContextVar[dict | None] = contextvars.ContextVar("pq_made", default=None)


# Where a caller keeps the meshes across builds (keeping_meshes).
_KEPT: contextvars.ContextVar[dict | None] = contextvars.ContextVar("pq_kept", default=None)


@contextlib.contextmanager
def keeping_meshes(store: dict) -> Iterator[dict]:
    """Builds inside share ``store`` for the meshes they make (by generators and options).

    For a caller that builds related designs in a row: the designer's worker builds a
    design's quick mesh (``refine = false``) and then the design itself, whose refinement
    starts from that very mesh.  The store keeps every mesh put in it; the caller bounds it.
    """
    token = _KEPT.set(store)
    try:
        yield store
    finally:
        _KEPT.reset(token)


def _mesh(rulings, options: dict):
    made = _MADE.get()
    creases, crease_generators = rulings.info.get("creases"), rulings.info.get("crease_generators")
    key = None
    if made is not None:
        h = hashlib.sha1(np.ascontiguousarray(rulings.a, dtype=np.float64).tobytes())
        h.update(np.ascontiguousarray(rulings.b, dtype=np.float64).tobytes())
        h.update(repr(sorted(options.items())).encode())
        for c in (creases, crease_generators):
            h.update(b"|" + (b"-" if c is None else np.asarray(c, dtype=np.int64).tobytes()))
        key = h.hexdigest()
        if key in made:
            return made[key]
    said = _PROGRESS.get()
    if said is not None:
        said[1] += 1
        said[0].advance(0, note=f"mesh {said[1]}, {len(rulings.a)} generators")
    mesh = pq_mesh(rulings.a, rulings.b, creases=creases, crease_generators=crease_generators, **options)
    if made is not None and key is not None:
        made[key] = mesh
    return mesh


# Rounds of adding generators, and the share of a strip's area outside quads that asks for one.
_REFINE_ROUNDS = 3
_TROUBLE_SHARE = 0.3
# ... and, once rounds at that share stop helping while the mesh still misses a goal, one
# more at this one (strips beside the border teeth and the torsal bands), kept only if it
# pays for its panels (see _refined; a second one never paid on the regression surfaces).
# Tolerance mode on the corner surface: 12.5 -> 8.6 % triangles with 106 generators instead
# of 85.  Two such rounds also where the goals are met took building-offset from 17.9 to
# 13.2 % but with a splinter, and the small test design from three builds (68 ms) to five
# (155 ms): so only while a goal is missed.
_TROUBLE_SHARE_BROAD = 0.15
# Lower shares: the rounds reach strips with less of their area outside quads.  With a
# planarity tolerance they are the only ones.  Measured with the take-back of splinters
# (_unsplintered): on 60 random two-B-spline surfaces at planarity_tolerance = 1e-3 the mean
# share in triangles 8.5 -> 7.1 %, none above 10 % (2 before) and none with a splinter (1),
# for 12 % more faces; building-offset 10.2 -> 6.0 %, the 17 tolerance-mode quality designs
# 6.4 -> 5.6 % on average (skew-bspline-b-51x30 7.5 -> 8.0 %, the only one worse).  In exact
# mode alone they took the random surfaces from 16.6 to 14.7 % but two bundled examples got
# worse (conoidal-director-plane 16.0 -> 20.5 %, skew 6.0 -> 6.9 %), so there they are a second
# chance: their rounds run as well, where the mesh kept so far has more than
# _TYPICAL_TRIANGLES of its area in triangles, from the generators (given or spanned) of the
# best mesh so far, and their best is kept where it pays (_pays).  Random surfaces 16.6 ->
# 14.9 %, 42 of 60 above 12 % instead of 54, 11 % more faces, twice the build time of the 60
# (10.9 -> 21.4 s, load 1.1; from both starts it was 14.9 % in 31 s); skew-bspline-b-51x30
# 25.7 -> 22.0 %, skew-bspline-51x30 21.5 -> 17.9 %, no bundled or quality design worse.
_TROUBLE_SHARE_LOW = 0.15
_TROUBLE_SHARE_BROAD_LOW = 0.08
# The share of the area in triangles a general skew surface should typically stay within.
# Rounds from the third on run while a mesh has more (not only while it misses a goal), and
# the mesh kept is weighed against the cheaper ones (_worth_its_panels): a cheaper mesh that
# is typical wins where the kept one does not pay the full _price of its extra generators, one
# above typical only where it does not pay this share of it.  On 60 random two-B-spline
# surfaces (40-60 generators, 20-40 rows, exact mode) the mean share in triangles 12.9 ->
# 11.8 %, the median 12.2 -> 11.4 %, 33 -> 18 above 12 %, none above 25 % or with a splinter
# either way, for 26 % more faces (78.9k -> 99.1k) and about 1.4 times the build time;
# skew-bspline-51x30 17.8 -> 13.3 % (2454 -> 3642 faces), building-offset 13.8 -> 12.2 %,
# cusp 11.9 -> 11.5 %; millimetre-scale 17.7 -> 18.4 % and corner-90deg 15.1 -> 15.3 % with
# 6 and 3 % fewer faces.  The full price everywhere gave 12.4 % for 4 % more faces, no price
# 11.7 % for 28 % more.
_TYPICAL_TRIANGLES = 0.12
_PRICE_ABOVE_TYPICAL = 0.25
# A torsal band reaches over the strips with more than this share outside quads (.torsal).
_TROUBLE_SHARE_SPAN = 0.5
_BROAD_ROUNDS = 1
# Rounds go on while each puts this share more of the area in quads.
_MIN_GAIN = 0.005
# A round whose mesh has splinters is tried once more without the generators it added within
# this many strips of them (see _unsplintered), at most this many times.  On 60 random
# two-B-spline surfaces (40-60 generators, 20-40 rows, exact mode) the mean share in
# triangles fell from 17.7 to 16.6 %, the surfaces above 25 % from 4 to 2 and those with a
# splinter from 1 to 0, for 14 % more faces and about 40 % more build time; the other
# surfaces keep their meshes.
_TAKE_BACK_STRIPS = 5
_TAKE_BACK_TIMES = 1
# A fabricator's goals for a build: no splinter, at most this share of the area in triangles
# (in exact mode; with a planarity tolerance).
_GOAL_TRIANGLES = 0.25
_GOAL_TRIANGLES_TOLERANCE = 0.10
# ... met with room: no splinter and at most this share of the goal in triangles.
_ROOM = 0.25
# Where the kept mesh misses a goal either way, a splinter counts as at least this much area
# in triangles (see _splinters).
_SPLINTER_COST = 0.01


def _refined(rulings, mesh, options: dict, respace_auto: bool = False, rows_from_auto: bool = False,
             division_auto: bool = False):
    """Add generators of the smooth surface in the strips the rows could not fill with quads.

    The §4.3 chains drift apart in proportion to the generator spacing, most
    near torsal generators; where the design gives director curves (not
    explicit lines) the discrete generators are ours to choose, so the strips
    whose area is mostly outside quads get one more generator each, at a node
    of the distribution's exact samples.  The user's generators all stay.
    Rounds go on while they put more of the area in quads, stop once the mesh
    meets the goals with room, and from the third on run only while it misses
    one; when rounds stop helping, one more adds generators to the strips
    with a smaller share outside quads (the border teeth).

    Where the twist changes sign, the same rounds also start from the
    generators with each torsal band spanned by one coplanar pair
    (:mod:`.torsal`: strip quads instead of the band's triangles; the user's
    generators inside the band are left out), and with a planarity tolerance,
    where the meshes so far miss a goal, from the exact rows too, and then from
    an extension that keeps every row (``extend = "full"``).  Of all the
    meshes made, the one kept is first by :func:`_fabricable`.
    """
    from ..rulings import dense_grid

    if _fixed_generators(rulings):
        return rulings, _round(rulings, mesh), []
    grid, _ = dense_grid(len(rulings.u))
    user = len(rulings.u) - int(rulings.info.get("inserted", 0))
    goal = _goal(options)
    rounds = _candidates(rulings, mesh, options, grid, user, goal)
    exact = {**options, "planarity_tolerance": DEFAULT.planarity}
    if options["planarity_tolerance"] > DEFAULT.planarity and \
            max(_fabricable(r, goal) for r in rounds)[0] < 2:
        # An exact mesh is within any tolerance: where the tolerance's cuts (nearly flat
        # strips) leave stretches without rows, the exact rows can do better.
        rounds += _candidates(rulings, _mesh(rulings, exact), exact, grid, user, goal)
    if options["planarity_tolerance"] > DEFAULT.planarity and options["extend"] == "auto" and \
            max(_fabricable(r, goal) for r in rounds)[0] < 2:
        # Where the rows far out on the primary bunch, the automatic extension leaves them
        # out; with a tolerance the stretches they then leave without rows can do better
        # (generators with an even division, whose triangles pair into quads within it).
        full = {**options, "extend": "full"}
        rounds += _candidates(rulings, _mesh(rulings, full), full, grid, user, goal)
    if respace_auto and max(_fabricable(r, goal) for r in rounds)[0] < 2:
        # Where the rows spread unevenly over the generators (strongly twisted surfaces: the
        # maps between generators are projective), restarts with an evened division; only
        # where they spread on the generators as given.  Elsewhere the rounds made the same
        # meshes or ones that differ where added generators happened to spread them, for
        # twice the build time: linear-directrix 29.0 -> 28.4 % in 14 s instead of 7, and
        # one of 24 random surfaces 30.6 -> 35.6 % (a cheaper mesh kept).
        spaced = {**options, "respace": True}
        first = _mesh(rulings, spaced)
        if first.info["restarts"] > mesh.info["restarts"]:
            rounds += _candidates(rulings, first, spaced, grid, user, goal)
    for graded in _graded(rulings, max(rounds, key=lambda r: _fabricable(r, goal)), options, division_auto):
        if _fabricable(graded, goal) > _fabricable(rounds[0], goal):
            rounds += _candidates(rulings, graded[4], {**options, "division": graded[4].info["division"]},
                                  grid, user, goal)
    so_far = max(rounds, key=lambda r: _fabricable(r, goal))
    if rows_from_auto and options["trim"] and _short(so_far, goal):
        # Rows through the end points on either director curve (no teeth of triangles along
        # it), and the rounds from the better of the two where its first mesh has more of its
        # area in quads than the first from the primary.  On 24 random two-B-spline designs
        # (40-60 generators, 20-40 rows) the mean share in triangles 11.9 -> 11.3 %, 7 -> 4
        # above 12 %, as many faces, twice the build time of the 24 (13 -> 26 s);
        # millimetre-scale 18.4 -> 13.9 %, examples/right-conoid-arc 17.9 -> 13.1 %,
        # skew-bspline-301x300 17.9 -> 17.3 % with 99k faces instead of 186k (9 -> 17 s).
        # The rounds from both curves, always, took twisted-arcs-120deg to 9.9 % too, for half
        # as much build time again on the quality surfaces (80 -> 117 s).
        # They never bring in a splinter (linear-directrix: 29.0 -> 25.0 % with a face at
        # 2.86 degrees, a smaller miss by _fabricable, but a new kind of panel to cut).
        tries = _through_ends(options, so_far)
        firsts = [(o, _mesh(rulings, o)) for o in tries]
        shares = [_measured(m)[0] for _, m in firsts]
        rooted, first = firsts[int(np.argmax(shares))]
        if max(shares) > rounds[0][0]:       # the first round: the mesh from the primary
            rounds += [r for r in _candidates(rulings, first, rooted, grid, user, goal) if r[1] <= so_far[1]]
    best = _worth_its_panels(max(rounds, key=lambda r: _fabricable(r, goal)), rounds, goal)
    added = int(best[3].info.get("inserted", 0)) - int(rulings.info.get("inserted", 0))
    rulings, mesh = best[3], best[4]
    notes = [_spanned_note(rulings, best[5])] if best[5] else []
    if options["planarity_tolerance"] > mesh.info.get("planarity_tolerance", DEFAULT.planarity):
        notes.append("every face is planar to rounding: the exact mesh had more of its area in "
                     "quads than one using the planarity tolerance")
    if mesh.info.get("extend") == "full" and options["extend"] == "auto":
        notes.append('every row of the extension kept (as [mesh] extend = "full"): that mesh had '
                     "more of its area in quads")
    if mesh.info.get("division") != options["division"]:
        notes.append(_graded_note(mesh.info["division"]))
    if mesh.info.get("respace") and not options["respace"]:
        notes.append("rows restarted with an even division where they had spread (as [mesh] "
                     "respace = true): that mesh had more of its area in quads")
    if added > 0:
        notes.append(f"{added} generators of the smooth surface added where the rows needed them "
                     f"({len(rulings.u)} in all, {user} given)")
    return rulings, best, notes


def _graded_note(division: str) -> str:
    """The note of a mesh kept with the primary's ``division`` graded ("graded" or "bounded")."""
    bounded = ", their steps bounded at the rims" if division == PrimaryDivision.BOUNDED.value else ""
    return (f"rows graded along the generators for faces of even shape{bounded} (as [mesh] division = "
            f"\"{division}\"): that mesh had more of its area in quads or fewer splinters")


def _graded(rulings, so_far: tuple, options: dict, auto: bool) -> list[tuple]:
    """Where the design leaves ``division`` free and the round ``so_far`` misses a goal or has
    more than the typical share of its area in triangles: the rounds of the meshes of
    ``rulings`` with the primary's division graded and bounded (:data:`_GRADINGS`,
    :mod:`ruledmesh.skew.pq.grading`), else none.

    Rows spaced evenly on the primary land unevenly elsewhere.  Between two half circles,
    the top one turned by 165 degrees (61 x 24, a hyperboloid close to its asymptotic cone),
    the even rows crowd ten to fifteen times closer than the strips are wide on the
    generators far from the primary: 58.6 % of the area in triangles, faces of 0.6 degrees
    and 15 restarts; graded, 48.4 %, none below 4.3 degrees and no restart.
    """
    if not auto or options["division"] != PrimaryDivision.EVEN.value or not _short(so_far, _goal(options)):
        return []
    return _graded_rounds(rulings, options)


# The graded divisions a design that leaves ``division`` free tries where the even one falls
# short, each with its own refinement rounds and choice of rows (not only the one whose first
# mesh is better: on twisted-bspline-arc-150deg the graded first mesh is, the bounded rounds
# end better).  Of the 125 hashed designs (examples, quality set, variants, random) three
# changed with the bounded division: twisted-bspline-arc-150deg 27.3 -> 17.2 % of the area in
# triangles (4,000 faces instead of 3,243), a steep right conoid 5.9 -> 5.6 %, a random
# surface 5.8 -> 7.1 %; 60 random two-B-spline surfaces (exact and tolerance mode) kept
# their meshes.  Chosen by the first mesh only, two Pluecker torsal-band line sets gained
# faces of 2.7 degrees; bounded everywhere, the Pluecker line sets got worse by 0.5-2 points.
_GRADINGS = (PrimaryDivision.GRADED.value, PrimaryDivision.BOUNDED.value)


def _through_ends(options: dict, so_far: tuple) -> list[dict]:
    """The options of the meshes with rows through the end points on either director curve
    or both, with the design's division and, where the best round ``so_far`` has graded or
    bounded rows, with that division too.

    The 172-degree arcs at 25 x 12 (exact) 13.5 -> 36.5 % of the area in quads; of the 125
    hashed designs two better (twisted circles of 165 degrees 32.3 -> 30.7 %, a 3D corner
    11.2 -> 10.2 %), none worse; 60 random surfaces unchanged.  With that division alone,
    instead of the design's, one random surface 9.8 -> 12.7 %.
    """
    divisions = dict.fromkeys((options["division"], so_far[4].info["division"]))
    return [{**options, "division": d, "rows_from": side.value} for d in divisions for side in _THROUGH_ENDS]


def _graded_rounds(rulings, options: dict) -> list[tuple]:
    """The rounds (:func:`_round`) of the meshes of ``rulings`` with each of :data:`_GRADINGS`
    that do not fail."""
    rounds = []
    for division in _GRADINGS:
        try:
            rounds.append(_round(rulings, _mesh(rulings, {**options, "division": division})))
        except GeometryError:
            continue
    return rounds


# The options a mesh's info names as its own, which the meshes made after it take from it.
_MADE_WITH = ("planarity_tolerance", "extend", "respace", "division")


def _with_thinned_rows(kept: tuple, options: dict) -> tuple:
    """The round ``kept`` (as :func:`_round`), or where its mesh misses a goal or has more
    than the typical share of its area in triangles (:func:`_short`) and the same mesh with
    the rows thinned where they fail towards torsal generators (``thin``: :func:`pq_mesh`)
    is more fabricable (:func:`_fabricable`), that one's round.

    Tried last, on the generators and options the refinement chose, and only where the
    mesh has a stretch that thinned rows would fill (its info's ``thinnable``): one mesh
    more.  Thinned rows leave fewer faces, so no price is weighed.  On the regression
    surfaces only skew-bspline-301x300 changed: 17.3 -> 14.6 % of the area in triangles,
    99,270 -> 78,234 faces, none below 3 degrees either way (four random two-B-spline
    surfaces at 301 x 300 kept their meshes).  Thinning in every mesh of the refinement
    changed its course: better by up to 0.5 points on some random surfaces, worse by 0.8 and
    3.9 on others.
    """
    goal = _goal(options)
    rulings, mesh = kept[3], kept[4]
    info = mesh.info
    if not _short(kept, goal) or not info.get("thinnable"):
        return kept
    opts = {**options, **{k: info[k] for k in (*_MADE_WITH, "primary")}, **_segment_options(info, len(rulings.a)),
            "thin": True}
    try:
        other = _round(rulings, _mesh(rulings, opts))
    except GeometryError:
        return kept
    return other if _fabricable(other, goal) > _fabricable(kept, goal) else kept


def _segment_options(info: Mapping[str, Any], m: int) -> dict:
    """``rows_from`` and ``option`` that make a mesh's rows again (its ``info``, as
    :func:`pq_mesh` gives it, of ``m`` generators): one value each, or one per generator from
    its ``row_segments`` where they differ ("mixed")."""
    if "mixed" not in (info["rows_from"], info["option"]):
        return {"rows_from": info["rows_from"], "option": info["option"]}
    rows_from, option = [info["row_segments"][0][2]] * m, [info["row_segments"][0][3]] * m
    for lo, hi, where, o in info["row_segments"]:
        rows_from[lo:hi + 1] = [where] * (hi - lo + 1)
        option[lo:hi + 1] = [o] * (hi - lo + 1)
    return {"rows_from": rows_from, "option": option}


_THINNED_NOTE = ("rows thinned where they fail towards a torsal generator (as [mesh] thin = true): "
                 "that mesh had more of its area in quads or fewer splinters")


def _rows_or_none(rulings, kept: tuple, notes: list[str], options: dict) -> tuple:
    """``(generators, round, notes)`` of the round ``kept`` (as :func:`_round`) and its
    ``notes``, or where its mesh misses a goal and the mesh without §4.3 rows does better
    (:func:`_fabricable`), of that mesh: the even divisions graded where the strips pinch
    (``rows_from = "none"``), refined from the given generators ``rulings`` the same way.

    Close to its asymptotic cone a hyperboloid's strips pinch at the waist, where the rows
    leave splinters: between two half circles, the top one turned by 170 degrees (41 x 20),
    67 % of the area in triangles and faces of 0.4 degrees with rows, all triangles of 9
    degrees or more without; with ``planarity_tolerance = 1e-3`` 17 % and a face of 2.7
    degrees with rows, 6 % and none below 6.7 degrees without (strip quads where the strips
    are nearly planar).  A mesh that meets both goals is kept as it is, unweighed.
    """
    goal = _goal(options)
    if sum(_goals_met(kept, goal)) == 2:
        return kept[3], kept, notes
    none = {**options, "rows_from": RowsFrom.NONE.value}
    try:
        spread, other, other_notes = _refined(rulings, _mesh(rulings, none), none)
    except GeometryError:
        return kept[3], kept, notes
    if not _more_fabricable_without_rows(other, kept, goal):
        return kept[3], kept, notes
    return spread, other, other_notes


# The mesh with rows is kept where it misses the goals by less than this share of the miss of
# the mesh without rows, even where that one meets more of them (_more_fabricable_without_rows).
_ROWS_KEPT_BELOW_MISS = 0.5


def _more_fabricable_without_rows(other: tuple, kept: tuple, goal: float) -> bool:
    """Whether the round ``other`` (its mesh without rows) is kept instead of ``kept`` (with
    rows): more fabricable (:func:`_fabricable`), unless it meets more goals only by
    missing the other one by far, at least twice as much as ``kept`` misses its two.

    Without rows every strip is triangles except where it is nearly planar, so meeting the
    splinter goal says little.  A Plücker conoid from 45 lines through both torsal
    generators, 2.7 degrees apart at its pinch points (``planarity_tolerance = 1e-3``):
    without rows no splinter but 96 % of the area in triangles (a miss of 0.86), with rows
    14 % and four faces at 2.7 degrees (0.11), and that one is kept.  Close to its
    asymptotic cone a hyperboloid (two arcs turned by 172 degrees, 25 x 12) misses by 0.75
    without rows (all triangles of 7.6 degrees or more, 912 faces), by 0.70 with them (62 %
    triangles, four faces of 0.6 degrees, 9,566 faces), and keeps the one without.
    """
    mine, theirs = _fabricable(other, goal), _fabricable(kept, goal)
    if mine[0] > theirs[0] and -theirs[1] < _ROWS_KEPT_BELOW_MISS * -mine[1]:
        return False
    return mine > theirs


def _goal(options: dict) -> float:
    """The share of the area in triangles a build may have: in exact mode, with a planarity
    tolerance."""
    return _GOAL_TRIANGLES_TOLERANCE if options["planarity_tolerance"] > DEFAULT.planarity \
        else _GOAL_TRIANGLES


def _round(rulings, mesh, pairs: tuple = ()) -> tuple:
    """``mesh`` of ``rulings`` as a round of the refinement: ``(quad share, splinters, their
    cost, rulings, mesh, pairs)``."""
    return (_measured(mesh)[0], *_splinters(mesh), rulings, mesh, pairs)


def _fixed_generators(rulings) -> bool:
    """Whether the generators are the design's own (explicit lines, or no smooth surface to
    take more from): the refinement cannot add any."""
    return getattr(rulings, "surface", None) is None or rulings.info.get("distribution") == "lines"


# The other primaries tried where a mesh misses a goal: at these shares of the generators (and the middle).
_OTHER_PRIMARIES = (1 / 3, 2 / 3)


def _other_rows(kept: tuple, options: dict, free: tuple[bool, bool, bool, bool]) -> tuple:
    """Where the mesh of the round ``kept`` (as :func:`_round`) misses a goal: ``(round, notes)``,
    the round of the more fabricable (:func:`_fabricable`) of the meshes of its generators from the paper's
    two checkerboards (``option``) and three primaries (the middle, a third and two thirds
    in), and with the primary's division graded, where the design leaves them free (``free``:
    option, primary, rows_from, division), then of
    that mesh with its rows through the end points on either director curve
    (:func:`_from_either_curve`), and a note naming the option or primary where they changed
    (``build_pq`` names where the rows start).

    The rows of §4.3 depend on both; for explicit lines they are the only freedom left.  On
    the Plücker conoid from 41 lines (``plucker-lines-a1-41``) 26.0 % of the area in
    triangles with option 0 from the middle, 23.2 % with option 1 from the third generator;
    ``twisted-arcs-160deg`` (118 generators after the refinement) 24.4 % with a face of 2.85
    degrees from the middle, 23.7 % and none below 3 from two thirds in.  The meshes are of
    the generators kept, with the options of the mesh kept (tolerance, extension, respacing).
    """
    goal = _goal(options)
    best, rulings, mesh = kept, kept[3], kept[4]
    options = {**options, **{k: mesh.info[k] for k in _MADE_WITH}}
    through = free[2] and options["trim"]      # untrimmed, a mesh has no border to cut teeth along
    other = None
    if (any(free[:2]) or free[3]) and sum(_goals_met(best, goal)) < 2:
        best = _more_fabricable(best, rulings, goal, _checkerboards(rulings, options, free))
    elif any(free[:2]) and through and not _with_room(best, goal):
        # The goals met, without room: the best of the other checkerboards and primaries is a
        # second start of the rows from either curve (twisted-arcs-120deg: 13.6 -> 5.9 % from
        # the primary 21 of 63 with the rows from c1).
        other = _more_fabricable(best, rulings, goal, _checkerboards(rulings, options, free))
    if through:
        first, best = best, _from_either_curve(best, rulings, options, goal, free[0])
        if other is not None and other is not first:
            # Weighed against the mesh it would replace: its splinters and its panels.
            second = _from_either_curve(other, rulings, options, goal, free[0])
            best = second if _replaces(second, best, best, goal, priced=True) else best
        best = _graded_chain(best, rulings, options, goal, free)
    info, was = best[4].info, mesh.info
    # A checkerboard per segment ("mixed") is named with the starts (_rows_from_note).
    named = [f"option {info['option']}"] if free[0] and info["option"] not in (was["option"], "mixed") else []
    named += [f"the primary generator {info['primary']} of {len(rulings.a)}"] if free[1] and \
        info["primary"] != was["primary"] else []
    said = [f"rows from {' and '.join(named)} (of the two checkerboards and three primary "
            f"generators tried): that mesh had more of its area in quads or fewer splinters; "
            f"[mesh] option and primary choose them"] if named else []
    if info["division"] != was["division"]:
        said.append(_graded_note(info["division"]))
    return best, said


def _graded_chain(best: tuple, rulings, options: dict, goal: float, free: tuple[bool, bool, bool, bool]) -> tuple:
    """``best``, or where it misses a goal with an even division the design leaves free
    (``free[3]``), the same choice made again with each of :data:`_GRADINGS` throughout (the
    checkerboards and primaries, then the rows through the end points), where that mesh
    replaces it (:func:`_replaces`, priced).

    The choice is greedy: the graded division is first weighed with one checkerboard and
    primary only, and the rows through the end points then start from whichever won.  On the
    Plücker conoid from 41 lines at 15 rows that kept 28.0 % of the area in triangles (rows
    from ``c1``, even), where graded rows from ``c2`` with a checkerboard per segment make
    24.0 % with fewer faces.
    """
    if not free[3] or best[4].info["division"] != PrimaryDivision.EVEN.value or sum(_goals_met(best, goal)) == 2:
        return best
    kept = best
    for start in _graded_rounds(rulings, options):
        graded = {**options, "division": start[4].info["division"]}
        start = _more_fabricable(start, rulings, goal, _checkerboards(rulings, graded, (*free[:3], False)))
        second = _from_either_curve(start, rulings, graded, goal, free[0])
        if _replaces(second, kept, best, goal, priced=True):
            kept = second
    return kept


def _checkerboards(rulings, options: dict, free: tuple[bool, bool, bool, bool]) -> list[dict]:
    """The options of the other checkerboards and primaries that ``free`` leaves open, and the
    graded division with the first's (where ``free[3]``: the division is the design's choice)."""
    m = len(rulings.a)
    first = (options["option"], options["primary"])
    graded = [{**options, "division": PrimaryDivision.GRADED.value}] \
        if free[3] and options["division"] == PrimaryDivision.EVEN.value else []
    return [{**options, "option": o, "primary": p}
            for o in ((0, 1) if free[0] else (options["option"],))
            for p in (("middle", *(int(f * m) for f in _OTHER_PRIMARIES)) if free[1]
                      else (options["primary"],))
            if (o, p) != first] + graded


def _more_fabricable(best: tuple, rulings, goal: float, tries: list[dict], priced: bool = False) -> tuple:
    """The most fabricable of ``best`` and the meshes of ``rulings`` with each of ``tries``;
    with ``priced`` none with more splinters than ``best``, and one with more faces only
    where it meets more goals or pays for its panels (:func:`_price`, as for generators)."""
    start = best
    for opts in tries:
        try:
            other = _round(rulings, _mesh(rulings, opts))
        except GeometryError:
            continue
        if _replaces(other, best, start, goal, priced):
            best = other
    return best


def _replaces(other: tuple, best: tuple, start: tuple, goal: float, priced: bool) -> bool:
    """Whether round ``other`` is kept instead of ``best`` (:func:`_more_fabricable`; ``start``
    is the round the choice began from, what ``priced`` weighs against)."""
    if _fabricable(other, goal) <= _fabricable(best, goal):
        return False
    if priced and other[1] > start[1]:
        return False
    return not (priced and other[4].n_faces > start[4].n_faces
                and sum(_goals_met(other, goal)) == sum(_goals_met(start, goal))
                and other[0] < start[0] + _price(other[4].n_faces, start[4].n_faces))


def _rows_from_note(info: Mapping[str, Any]) -> str:
    """What a note says of where a mesh's rows start (its ``info``, as :func:`pq_mesh` gives it)."""
    side = info["rows_from"]
    if side == RowsFrom.NONE.value:
        return ('no §4.3 rows (rows_from = "none": even divisions of the generators, graded where '
                "the strips pinch, closed by strip quads and triangles): the meshes with rows had "
                "splinters or more of their area in triangles; [mesh] rows_from chooses it")
    if "mixed" not in (side, info["option"]):
        on = ("both director curves (no teeth of triangles along them" if side == RowsFrom.BOTH.value
              else f"director curve {side} (no teeth of triangles along it")
        return (f"rows through the generators' end points on {on}): that mesh had more of its area "
                f"in quads or fewer splinters; [mesh] rows_from chooses it")
    ranges: dict[tuple, list[str]] = {}
    for lo, hi, where, option in sorted(info["row_segments"]):
        ranges.setdefault((where, option), []).append(f"{lo}-{hi}")
    start = {RowsFrom.PRIMARY.value: "from the primary", RowsFrom.BOTH.value: "through the end points on both curves"}
    said = "; ".join(f"{start.get(where, 'through the end points on ' + where)}, option {option}, "
                     f"for generators {', '.join(r)}" for (where, option), r in ranges.items())
    return (f"rows {said} (each stretch between torsal generators where its faces had the fewest "
            "splinters and triangles): that mesh had more of its area in quads or fewer splinters; "
            '[mesh] rows_from and option set one start and checkerboard everywhere')


def _short(round_: tuple, goal: float) -> bool:
    """Whether a round's mesh misses a goal or has more than the typical share of its area in
    triangles (:func:`_typical`)."""
    return sum(_goals_met(round_, goal)) < 2 or 1.0 - round_[0] > _typical(goal)


def _with_room(round_: tuple, goal: float) -> bool:
    """Whether a round's mesh meets the goals with room: no splinter and at most :data:`_ROOM`
    of the goal's share of its area in triangles."""
    return _no_faces_refused(round_) and 1.0 - round_[0] <= _ROOM * goal


# Where the rows may start instead of the primary's division: through the end points on
# either director curve, or on both (MEASURED below).
_THROUGH_ENDS = (RowsFrom.C1, RowsFrom.C2, RowsFrom.BOTH)


def _from_either_curve(kept: tuple, rulings, options: dict, goal: float, colours: bool = True) -> tuple:
    """Where the mesh of ``kept`` does not meet the goals with room (:func:`_with_room`): the
    more fabricable of it, its rows through the end points of the generators on director
    curve c1 or c2 (``rows_from``), with its option and primary, and the mesh of each
    segment's best start and checkerboard (:func:`_per_segment`).

    A row through a generator's end point on a director curve makes the border there edges
    of quads, so the band of teeth along that curve goes (half a row tall on average, a
    hop's climb over two strips where the rows run steeply across the generators).  On the
    Moebius band from 97 lines (``moebius-r5-w0.8-97x20``) 27.5 -> 15.5 % of the area in
    triangles, from 24 lines (``moebius-lines``) 24.8 -> 15.4 %.  The rows are then as far
    apart as the end points' rows, so a mesh with more faces is kept only where it pays for
    them (:func:`_price`).  Run only above the typical share, as at first, it left 16 of 24
    random designs at 7.7-11.9 % of the area in triangles where it now finds 3.5-9.7 %
    (``right-conoid-wide-arc`` 11.9 -> 3.4 %).
    """
    if _with_room(kept, goal):
        return kept
    mesh = kept[4]
    base = {**options, "option": mesh.info["option"], "primary": mesh.info["primary"]}
    tries = [{**base, "rows_from": side.value} for side in _THROUGH_ENDS]
    mixed = _per_segment(rulings, mesh, base, colours)
    return _more_fabricable(kept, rulings, goal, tries + ([{**base, **mixed}] if mixed else []), priced=True)


def _per_segment(rulings, mesh, base: dict, colours: bool = True) -> dict | None:
    """``rows_from`` and ``option`` per generator (as :func:`pq_mesh` takes them): for each
    segment between torsal generators, the start (the primary, c1 or c2) and checkerboard
    whose faces there have the fewest splinters, then the least area in triangles, of
    ``mesh`` and the meshes of its generators with the other five of those pairs (the other
    two starts only, without ``colours``: the design sets the checkerboard); None where that is
    ``mesh``'s own everywhere.

    Each segment takes a division of its own, so its faces hardly depend on the others' rows:
    on skew-bspline-51x30 the pick from the meshes with the kept checkerboard made 11.8 % of
    the area triangles against 12.5 % for the best of them (the best of all 81 combinations:
    10.6 %, with a face of 1.2 degrees), millimetre-scale 13.9 -> 12.9 % (the best of all);
    with either checkerboard per segment too, skew-bspline-51x30 10.9 %, building-offset
    10.8 -> 10.1 %, skew-bspline-b-51x30 21.8 -> 20.9 %, plucker-lines-a1-41 22.2 -> 21.1 %.
    """
    from ..analysis.faces import SPLINTER_DEG, face_min_angles

    segments = mesh.info.get("row_segments", [])
    own = (mesh.info["rows_from"], mesh.info["option"])
    if len(segments) < 2 or "mixed" in own:
        return None
    starts = (RowsFrom.PRIMARY, RowsFrom.C1, RowsFrom.C2)
    pairs = [own] + [(side.value, o) for o in (own[1], 1 - own[1])[:1 + colours] for side in starts
                     if (side.value, o) != own]
    meshes = [mesh]
    for side, o in pairs[1:]:
        try:
            meshes.append(_mesh(rulings, {**base, "rows_from": side, "option": o}))
        except GeometryError:
            return None
    if any([s[:2] for s in m.info["row_segments"]] != [s[:2] for s in segments] for m in meshes):
        return None
    lo = np.array([s[0] for s in segments])
    order = np.argsort(lo, kind="stable")
    scores = []
    for m in meshes:
        g = np.asarray(m.vertex_data["generator"], dtype=np.float64)
        centre = np.add.reduceat(g[m.face_indices], m.face_offsets[:-1]) / m.valences
        seg = order[np.clip(np.searchsorted(lo[order], centre, side="right") - 1, 0, len(lo) - 1)]
        thin = np.bincount(seg, weights=face_min_angles(m) < SPLINTER_DEG, minlength=len(lo))
        off = np.bincount(seg, weights=np.where(m.valences != 4, _measured(m)[1], 0.0), minlength=len(lo))
        scores.append(np.stack([thin, off], axis=1))
    pick = [min(range(len(meshes)), key=lambda k: tuple(scores[k][j])) for j in range(len(lo))]
    if all(k == 0 for k in pick):
        return None
    rows_from, option = [own[0]] * len(rulings.a), [own[1]] * len(rulings.a)
    for (a, b, *_), k in zip(segments, pick, strict=True):
        rows_from[a:b + 1] = [pairs[k][0]] * (b - a + 1)
        option[a:b + 1] = [pairs[k][1]] * (b - a + 1)
    return {"rows_from": rows_from, "option": option}


def _candidates(rulings, mesh, options: dict, grid: np.ndarray, user: int, goal: float) -> list[tuple]:
    """The rounds from ``rulings`` and its ``mesh``, and those from its torsal bands spanned.

    In exact mode at the shares :data:`_TROUBLE_SHARE` and :data:`_TROUBLE_SHARE_BROAD`, and
    also at the lower ones where the best mesh of those has more than
    :data:`_TYPICAL_TRIANGLES` of its area in triangles; with a planarity tolerance at the
    lower ones only.
    """
    measured = _measured(mesh)
    starts = [(rulings, mesh, measured, ())]
    spanned = _spanned(rulings, mesh, measured[1], options)
    if spanned is not None:
        sp_rulings, sp_mesh, sp_pairs = spanned
        starts.append((sp_rulings, sp_mesh, _measured(sp_mesh), sp_pairs))
    low = (_TROUBLE_SHARE_LOW, _TROUBLE_SHARE_BROAD_LOW)
    tiers = [low] if options["planarity_tolerance"] > DEFAULT.planarity \
        else [(_TROUBLE_SHARE, _TROUBLE_SHARE_BROAD), low]
    rounds: list[tuple] = []
    for shares in tiers:
        best = max(rounds, key=lambda r: _fabricable(r, goal)) if rounds else None
        if best is not None and 1.0 - best[0] <= _TYPICAL_TRIANGLES:
            break
        # After the first tier, from the start (given or spanned generators) of its best only.
        from_ = starts if best is None else [s for s in starts if s[3] == best[5]] or starts
        more = [r for start_rulings, start_mesh, start_measured, pairs in from_
                for r in _rounds(start_rulings, start_mesh, start_measured, options, grid, user, goal,
                                 shares, pairs)]
        if best is None or _pays(max(more, key=lambda r: _fabricable(r, goal)), best, goal):
            rounds += more
    return rounds


def _worth_its_panels(best: tuple, rounds: list[tuple], goal: float) -> tuple:
    """``best``, or the best of the meshes with fewer generators that meet the same goals, cost
    no more in splinters and against which ``best`` does not pay for its panels (:func:`_price`).

    Beyond the typical share in triangles (:func:`_typical`) the rounds add generators to get
    there, so a mesh that stays above it is preferred only where ``best`` pays not even
    :data:`_PRICE_ABOVE_TYPICAL` of its price.
    """
    def price(r: tuple) -> float:
        full = _price(len(best[3].u), len(r[3].u))
        return full if 1.0 - r[0] <= _typical(goal) else _PRICE_ABOVE_TYPICAL * full

    met = _goals_met(best, goal)
    cheaper = [r for r in rounds if len(r[3].u) < len(best[3].u)
               and _goals_met(r, goal) == met and r[2] <= best[2] and best[0] < r[0] + price(r)]
    return max(cheaper, key=lambda r: _fabricable(r, goal)) if cheaper else best


def _pays(better: tuple, best: tuple, goal: float) -> bool:
    """Whether the rounds at the lower shares, whose best mesh is ``better``, are worth their
    panels against ``best``: more goals met, or half a point more of the area in quads for
    every tenth more generators (as a broad round in :func:`_rounds`)."""
    gained, kept = _fabricable(better, goal), _fabricable(best, goal)
    if gained[0] != kept[0]:
        return gained[0] > kept[0]
    return better[0] >= best[0] + _price(len(better[3].u), len(best[3].u))


def _price(more: int, fewer: int) -> float:
    """The quad area share a mesh of ``more`` generators must gain over one of ``fewer`` to
    pay for its panels: half a point (:data:`_MIN_GAIN`) per tenth more generators, at
    least half a point."""
    return _MIN_GAIN * max(1.0, 10.0 * (more / fewer - 1.0))


def _rounds(rulings, mesh, measured: tuple[float, np.ndarray], options: dict, grid: np.ndarray,
            user: int, goal: float, shares: tuple[float, float], pairs: tuple = ()) -> list[tuple]:
    """The meshes of the refinement rounds from ``rulings`` and its ``mesh``, the first included.

    Each is ``(quad share, splinters, their cost, rulings, mesh, pairs)`` (the cost: see
    :func:`_splinters`); ``measured`` is the quad share and (F,) face areas of ``mesh``,
    ``shares`` the share of a strip's area outside quads that asks for a generator in the
    first rounds and in the broad one, ``pairs`` what :func:`_spanned` made of ``rulings``
    (empty if nothing).
    """
    cur = (*measured, rulings, mesh)
    rounds = [(cur[0], *_splinters(mesh), rulings, mesh, pairs)]
    first, broader = shares
    bars = [first] * _REFINE_ROUNDS + [broader] * _BROAD_ROUNDS
    k = 0
    while k < len(bars):
        share, area, cur_rulings, cur_mesh = cur
        # More generators are more panels: none once the mesh meets the goals with room,
        # and from the third round on only while it misses one or has more than the typical
        # share in triangles (_worth_its_panels then weighs what they cost).
        broad = bars[k] < first
        limit = _ROOM * goal if k < _REFINE_ROUNDS - 1 else _typical(goal)
        if _no_faces_refused(rounds[-1]) and 1.0 - share <= limit:
            break
        candidate = _with_generators(cur_rulings, cur_mesh, area, bars[k], grid, options["rows"])
        cand = None
        if candidate is not None:
            try:
                cand_mesh = _mesh(candidate, options)
                taken = _unsplintered(candidate, cand_mesh, cur_rulings.u, options)
            except GeometryError:
                break
            cand = (*_measured(cand_mesh), candidate, cand_mesh)
            if taken is not None:
                # One more mesh to choose from; the rounds go on from the round's own, whose
                # later rounds may lose their splinters anyway.
                rounds.append((_measured(taken[1])[0], *_splinters(taken[1]), *taken, pairs))
        # A broad round pays for its panels (see _price).
        need = _price(len(candidate.u), len(cur_rulings.u)) if broad and candidate is not None \
            else _MIN_GAIN
        if cand is None or cand[0] <= share + need:
            # Nothing to add or no gain at this share: on with the broader one, if any.
            k = next((i for i in range(k + 1, len(bars)) if bars[i] < bars[k]), len(bars))
            continue
        cur = cand
        rounds.append((cand[0], *_splinters(cand[3]), candidate, cand[3], pairs))
        k += 1
    return rounds


def _spanned(rulings, mesh, area: np.ndarray, options: dict):
    """``(rulings, mesh, pairs)`` with the torsal bands spanned by coplanar pairs, or None.

    ``pairs`` is ``((u, v), ...), left_out``: the parameters of each pair and how
    many generators of ``rulings`` were left out inside them.
    """
    from .torsal import span_torsal_bands, twist_changes

    a, d = _generators(rulings)
    scale = diagonal(np.r_[a, a + d])
    changes = twist_changes(a, d, scale)
    if changes.size == 0:
        return None
    trouble = np.zeros(len(a) - 1, bool)
    trouble[_trouble_strips(mesh, len(a), area, _TROUBLE_SHARE_SPAN)] = True
    spanned, bands, left_out = span_torsal_bands(rulings, trouble, scale, changes)
    if spanned is None:
        return None
    try:
        spanned_mesh = _mesh(spanned, options)
    except GeometryError:
        return None
    u = np.asarray(spanned.u)
    return spanned, spanned_mesh, (tuple((float(u[p]), float(u[q])) for p, q in bands), left_out)


def _spanned_note(rulings, pairs: tuple) -> str:
    """What the build says of the torsal bands spanned by coplanar pairs (final generator indices)."""
    ends, left_out = pairs
    k = np.searchsorted(np.asarray(rulings.u), np.asarray(ends))
    shown = ", ".join(f"{p}-{q}" for p, q in k.tolist())
    return (f"{len(ends)} torsal band{'s' * (len(ends) > 1)} spanned by a coplanar pair of generators "
            f"({shown}) and filled with strip quads; {left_out} given generator"
            f"{'s' * (left_out != 1)} left out inside")


def _with_generators(rulings, mesh, area: np.ndarray, bar: float, grid: np.ndarray, rows: int):
    """``rulings`` with one generator more in each strip of ``mesh`` whose share of the area
    outside quads is above ``bar``, or None (no such strip, or the grid would grow too large).

    A strip between coplanar generators gets none: it is flat, and carries strip quads."""
    from ..hop import coplanarity

    u = np.asarray(rulings.u)
    strips = _trouble_strips(mesh, len(u), area, bar)
    a, d = _generators(rulings)
    strips = strips[np.abs(coplanarity(a, d, diagonal(np.r_[a, a + d]))[strips]) > DEFAULT.degenerate]
    if strips.size == 0:
        return None
    lo = np.searchsorted(grid, u[strips], side="right")
    hi = np.searchsorted(grid, u[strips + 1], side="left") - 1
    ok = hi >= lo
    mid = grid[(lo[ok] + hi[ok]) // 2]
    if mid.size == 0 or (len(u) + mid.size) * (rows + 1) > MAX_GRID_POINTS // 4:
        return None
    return _with_u(rulings, unique(np.concatenate([u, mid])))


def _unsplintered(candidate, mesh, given_u: np.ndarray, options: dict):
    """``(rulings, mesh)``: ``candidate`` without the generators it added next to its splinters,
    or None (no splinter, or none of them next to an added generator).

    A round adds generators wherever the rows left triangles, and in a few places the
    narrower strips make slivers (the rows meet the generators at a small angle there:
    near torsal generators, or where the two chains drift); the round would then lose
    to its splinter-free predecessor as a whole.  Taking back just the generators it
    added within :data:`_TAKE_BACK_STRIPS` strips of each splinter (again, at most
    :data:`_TAKE_BACK_TIMES` times, while splinters are left) keeps its gain elsewhere.
    ``given_u`` are the generators the round started from: they always stay.
    """
    from ..analysis.faces import SPLINTER_DEG, face_min_angles

    out = None
    for _ in range(_TAKE_BACK_TIMES):
        bad = np.flatnonzero(face_min_angles(mesh) < SPLINTER_DEG) if mesh.n_faces else np.zeros(0, np.int64)
        if bad.size == 0:
            break
        u = np.asarray(candidate.u)
        first, last = (g[bad] for g in _generator_span(mesh))
        # Generators within reach of a splinter: +1 where a reach starts, -1 past its end.
        step = np.zeros(len(u) + 1, np.int64)
        np.add.at(step, np.maximum(first - _TAKE_BACK_STRIPS, 0), 1)
        np.add.at(step, np.minimum(last + _TAKE_BACK_STRIPS, len(u) - 1) + 1, -1)
        drop = (np.cumsum(step[:-1]) > 0) & ~member(u, given_u)
        if not drop.any():
            break
        candidate = _with_u(candidate, u[~drop])
        mesh = _mesh(candidate, options)
        out = candidate, mesh
    return out


def _with_u(rulings, new_u: np.ndarray):
    """``rulings`` with the generators of its smooth surface at ``new_u`` (sorted), creases kept."""
    from dataclasses import replace

    u = np.asarray(rulings.u)
    info = {**rulings.info, "inserted": int(rulings.info.get("inserted", 0)) + len(new_u) - len(u)}
    creases = rulings.info.get("crease_generators")
    if creases:
        info["crease_generators"] = np.searchsorted(new_u, u[np.asarray(creases)]).tolist()
    surface = rulings.surface
    return replace(rulings, a=surface.a(new_u), b=surface.b(new_u), u=new_u, info=info)


def _generators(rulings) -> tuple[np.ndarray, np.ndarray]:
    """The (m, 3) points and directions of the generators."""
    a = np.asarray(rulings.a)
    return a, np.asarray(rulings.b) - a


def _measured(mesh) -> tuple[float, np.ndarray]:
    """The share of the area in quads (as :func:`~ruledmesh.analysis.faces.area_shares`) and the (F,) face areas."""
    from ..analysis.faces import face_normals

    _, area = face_normals(mesh)
    total = float(area.sum()) or 1.0
    return float(area[mesh.valences == 4].sum() / total), area


def _fabricable(round_: tuple, goal: float) -> tuple[int, float, float]:
    """Order of the rounds: the more of a fabricator's two goals met (no splinter, at most
    ``goal`` of the area in triangles), then the smaller miss, then the larger quad share.

    The miss adds the area share in triangles beyond ``goal`` to the splinters' cost
    (:func:`_splinters`): of two meshes that meet one goal each, 47 % triangles and no face
    below 3 degrees misses by far more than 8 % with two faces at 2.96 degrees.
    """
    share, cost = round_[0], round_[2]
    excess = max(1.0 - share - goal, 0.0)
    return sum(_goals_met(round_, goal)), -(cost + excess), share


def _goals_met(round_: tuple, goal: float) -> tuple[bool, bool]:
    """A fabricator's two goals for a round's mesh: no face to refuse (no splinter, no triangle
    off the surface: :func:`_splinters`), at most ``goal`` of the area in triangles."""
    return _no_faces_refused(round_), 1.0 - round_[0] <= goal


def _no_faces_refused(round_: tuple) -> bool:
    """Whether a round's mesh has no splinter and no triangle farther than the gap goal off the
    generators it spans (the mesher's ``info["off_generators"]``)."""
    return round_[1] == 0 and not round_[4].info.get("off_generators")


def _typical(goal: float) -> float:
    """The share in triangles the rounds work towards: :data:`_TYPICAL_TRIANGLES`, or the goal
    where that is lower (tolerance mode)."""
    return min(goal, _TYPICAL_TRIANGLES)


def _splinters(mesh) -> tuple[int, float]:
    """How many splinters a mesh has, and what they and its triangles off the surface cost in
    area share.

    A face with a corner below the splinter bar costs :data:`_SPLINTER_COST` plus up
    to nine times as much more the further its smallest angle lies below the bar (a
    point of area share at 2.9 degrees, 8.5 points at 0.5): a fabricator can live with
    a face at 2.9 degrees, not with one at 0.5.  A triangle farther than the gap goal
    (:data:`~ruledmesh.tolerances.SPAN_MAX_GAP` of the diagonal) off the generators it
    spans (the mesher's ``info["off_generators"]``) costs the same, up to ten times at
    twice the goal: the mesh is not the surface there, as wrong as a splinter.
    """
    from ..analysis.faces import SPLINTER_DEG, face_min_angles

    angles = face_min_angles(mesh)
    below = angles[angles < SPLINTER_DEG]
    off = np.asarray(mesh.info.get("off_generators", ()), np.float64)
    cost = _SPLINTER_COST * float(np.sum(1.0 + 9.0 * (SPLINTER_DEG - below) / SPLINTER_DEG)
                                  + np.sum(1.0 + 9.0 * np.minimum(off / SPAN_MAX_GAP - 1.0, 1.0)))
    return int(below.size), cost


def _trouble_strips(mesh, m: int, area: np.ndarray, share: float = _TROUBLE_SHARE) -> np.ndarray:
    """Strips (between generators i and i + 1) with more than ``share`` of their area outside quads.

    ``area`` : (F,) the face areas of ``mesh``.
    """
    if mesh.n_faces == 0 or m < 2:
        return np.zeros(0, np.int64)
    g0, g1 = _generator_span(mesh)
    span = np.maximum(g1 - g0, 1)
    off = mesh.valences != 4
    # Faces span one or two strips: each adds its share to the strips it spans, in the
    # order of the spans (one bincount, summed as np.add.at would).
    ks = [np.flatnonzero(k < span) for k in range(int(span.max()))]
    sel = np.concatenate(ks)
    s = np.clip(g0[sel] + np.repeat(np.arange(len(ks)), [len(k) for k in ks]), 0, m - 2)
    w = area[sel] / span[sel]
    total = np.bincount(s, weights=w, minlength=m - 1)
    other = np.bincount(s, weights=np.where(off[sel], w, 0.0), minlength=m - 1)
    return np.flatnonzero(other > share * np.maximum(total, TINY))


def _generator_span(mesh) -> tuple[np.ndarray, np.ndarray]:
    """(F,) the lowest and (F,) the highest generator index among each face's corners."""
    g = np.asarray(mesh.vertex_data["generator"])[mesh.face_indices]
    return np.minimum.reduceat(g, mesh.face_offsets[:-1]), np.maximum.reduceat(g, mesh.face_offsets[:-1])
