"""The ``[surface]`` kinds of the catalogue (paper §2-§3): design tables to meshes.

One builder per ``kind``, registered with :mod:`ruledmesh.registry`.  Each reads its
``[surface]`` and ``[mesh]`` tables once through :class:`~ruledmesh.design.fields.Fields`
(every message names the file and the field) and hands arrays and plain numbers to the
constructions of :mod:`ruledmesh.constructions`; what those refuse comes back as a
:class:`~ruledmesh.errors.DesignError` on the field it came from.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .._validation import describe
from ..constructions.canal import canal_mesh, torus_mesh
from ..constructions.developables import prism, pyramid, torsal_polyhedron
from ..constructions.frames import axis_frame
from ..constructions.helicoid import helicoid, helicoid_mesh
from ..constructions.hyperbolic_paraboloid import HPStyle, hyperbolic_paraboloid, hyperbolic_paraboloid_mesh
from ..constructions.hyperboloid import HyperboloidStyle, hyperboloid_mesh, one_sheet_hyperboloid
from ..constructions.moulding import moulding_mesh, pipe_mesh
from ..constructions.quadrics import (
    ellipsoid,
    ellipsoid_mesh,
    elliptic_paraboloid,
    elliptic_paraboloid_mesh,
    quadric_guarantee,
    two_sheet_hyperboloid,
    two_sheet_hyperboloid_mesh,
)
from ..constructions.rotational import meridian_coordinates, rotational_mesh
from ..constructions.strips import parallel_edge_strips, similar_strips
from ..constructions.translational import TranslationalPatch, translational_mesh
from ..errors import DesignError, GeometryError, ParameterError
from ..registry import BuildContext, Built, surface_kind
from ..surfaces import pipe_of_polyline, revolution_of_polyline, torus
from ..tolerances import PARAMETER_SLACK
from .fields import Fields, mesh_counts
from .profiles import profile_from_spec


@surface_kind("strips")
def _build_strips(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["polygon", "closed", "scales", "translations", "starts",
                                  "edge_factors"])
    mesh_counts(mesh_table, 1, None)
    closed = f.boolean("closed", False)
    poly = f.points("polygon", Fields.REQUIRED, min_count=2)
    if f.has("edge_factors") or f.has("starts"):
        if closed:
            raise DesignError("edge_factors work on open polylines only", "surface.closed")
        starts = f.points("starts", Fields.REQUIRED)
        factors = f.raw("edge_factors", Fields.REQUIRED)
        try:
            mesh = parallel_edge_strips(poly, starts, factors)
        except (ParameterError, ValueError) as exc:
            raise DesignError(str(exc), "surface.edge_factors") from None
        return Built(mesh, None, None, {"guarantee": "trapezoids (pairwise parallel edges)"})
    scales = f.floats("scales", [1.0])
    trans = f.points("translations", np.zeros((len(scales), 3)), min_count=1)
    if len(trans) != len(scales):
        raise DesignError(f"expected {len(scales)} translations (one per scale), got {len(trans)}",
                          "surface.translations")
    if np.any(scales == 0):
        raise DesignError("expected non-zero scales", "surface.scales")
    mesh = similar_strips(poly, scales, trans, closed=closed)
    # Scale 1 throughout: translated copies of one polygon (Fig. 3 middle), so
    # every face is a parallelogram, which the analysis then measures.
    claim = ("parallelograms (congruent polygons)" if np.all(np.asarray(scales) == 1.0)
             else "trapezoids (similar polygons)")
    return Built(mesh, None, None, {"guarantee": claim})


@surface_kind("prism")
def _build_prism(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["polygon", "direction", "closed"])
    u, _ = mesh_counts(mesh_table, 4, None)
    mesh = prism(f.points("polygon", Fields.REQUIRED, min_count=2),
                 f.vector("direction", [0.0, 0.0, 1.0], nonzero=True), u,
                 closed=f.boolean("closed", False))
    return Built(mesh, None, None, {"guarantee": "parallelograms (prism)"})


@surface_kind("pyramid")
def _build_pyramid(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["polygon", "apex", "closed", "to_apex"])
    u, _ = mesh_counts(mesh_table, 4, None)
    mesh = pyramid(f.points("polygon", Fields.REQUIRED, min_count=2),
                   f.vector("apex", Fields.REQUIRED), u, closed=f.boolean("closed", False),
                   to_apex=f.boolean("to_apex", False))
    return Built(mesh, None, None, {"guarantee": "trapezoids (pyramid)"})


@surface_kind("torsal-polyhedron")
def _build_torsal(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["polygon", "lengths"])
    u, _ = mesh_counts(mesh_table, 4, None)
    lengths = f.floats("lengths", [0.2, 1.0], count=2)
    if not (0 < lengths[0] < lengths[1]):
        raise DesignError(f"expected 0 < first < second, got {lengths.tolist()}",
                          "surface.lengths")
    mesh = torsal_polyhedron(f.points("polygon", Fields.REQUIRED, min_count=3), lengths, u)
    return Built(mesh, None, None, {"guarantee": "planar strips (torsal polyhedron)"})


@surface_kind("translational")
def _build_translational(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["p", "q"])
    u, v = mesh_counts(mesh_table, 16, 16)
    p = profile_from_spec(f.raw("p", Fields.REQUIRED), "surface.p")
    q = profile_from_spec(f.raw("q", Fields.REQUIRED), "surface.q")
    mesh = translational_mesh(p.sample(u), q.sample(v))
    reference = None
    if p.analytic and q.analytic:
        from ..surfaces import RuledReference

        reference = RuledReference(TranslationalPatch(p, q))
    return Built(mesh, reference, None, {"guarantee": "parallelograms"})


@surface_kind("rotational")
def _build_rotational(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["meridian", "axis", "angle"])
    u, v = mesh_counts(mesh_table, 24, 12)
    prof = profile_from_spec(f.raw("meridian", Fields.REQUIRED), "surface.meridian")
    axis_table = f.raw("axis", {})
    if not isinstance(axis_table, Mapping):
        raise DesignError("expected a table {point = [..], direction = [..]}", "surface.axis")
    af = Fields(axis_table, "surface.axis", ["point", "direction"])
    origin = af.vector("point", [0.0, 0.0, 0.0])
    direction = af.vector("direction", [0.0, 0.0, 1.0], nonzero=True)
    angle = f.number("angle", 360.0, lo=0.0, lo_open=True, hi=360.0)
    if angle == 360.0 and u < 3:
        raise DesignError(f"expected an integer >= 3 for a full turn, got {u}", "mesh.u")
    merid = prof.sample(v)
    mesh = rotational_mesh(merid, u, origin=origin, axis=direction, angle=angle)
    # The reference meridian: the profile's own points (polyline), or a fine
    # sampling that contains the mesh's samples (analytic profile).
    dense = merid if not prof.analytic else prof.sample(v * max(1, -(-2000 // v)))
    _, _, a = axis_frame(direction)
    rho, h, phi = meridian_coordinates(dense, origin, a)
    e1, e2, _ = axis_frame(a)
    phi0 = phi[np.argmax(rho > 0)]
    start = np.cos(phi0) * e1 + np.sin(phi0) * e2
    ref = revolution_of_polyline(np.stack([rho, h], axis=1), origin, a, np.radians(angle), start)
    return Built(mesh, ref, None, {"guarantee": "isosceles trapezoids, circular"})


def _axes(value, path: str):
    if not isinstance(value, list) or not value:
        raise DesignError(f"expected a list of tables {{point, direction, angle}}, got "
                          f"{describe(value)}", path)
    o, d, a = [], [], []
    for k, item in enumerate(value):
        if not isinstance(item, Mapping):
            raise DesignError(f"expected a table, got {describe(item)}", f"{path}[{k}]")
        f = Fields(item, f"{path}[{k}]", ["point", "direction", "angle"])
        o.append(f.vector("point", Fields.REQUIRED))
        d.append(f.vector("direction", Fields.REQUIRED, nonzero=True))
        a.append(f.number("angle", Fields.REQUIRED))
    return np.array(o), np.array(d), np.array(a)


@surface_kind("moulding")
def _build_moulding(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["profile", "axes", "closed"])
    _, v = mesh_counts(mesh_table, None, 12)
    prof = profile_from_spec(f.raw("profile", Fields.REQUIRED), "surface.profile")
    o, d, a = _axes(f.raw("axes", Fields.REQUIRED), "surface.axes")
    try:
        mesh = moulding_mesh(prof.sample(v), o, d, a, closed=f.boolean("closed", False))
    except GeometryError as exc:
        raise DesignError(str(exc), "surface.axes") from None
    return Built(mesh, None, None, {"guarantee": "isosceles trapezoids, circular"})


@surface_kind("pipe")
def _build_pipe(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["spine", "radius", "normal"])
    u, v = mesh_counts(mesh_table, 24, 16, min_v=3)
    spine = profile_from_spec(f.raw("spine", Fields.REQUIRED), "surface.spine").sample(u)
    radius = f.number("radius", Fields.REQUIRED, lo=0.0, lo_open=True)
    try:
        mesh = pipe_mesh(spine, radius, v, normal=f.optional_vector("normal", nonzero=True))
    except GeometryError as exc:
        raise DesignError(str(exc), "surface.spine") from None
    return Built(mesh, pipe_of_polyline(spine, radius), None,
                 {"guarantee": "isosceles trapezoids, circular; on the pipe within the "
                               "sampling error"})


@surface_kind("torus")
def _build_torus(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["R", "r"])
    u, v = mesh_counts(mesh_table, 32, 16, min_u=3, min_v=3)
    R = f.number("R", Fields.REQUIRED, lo=0.0, lo_open=True)
    r = f.number("r", Fields.REQUIRED, lo=0.0, lo_open=True)
    if r >= R:
        raise DesignError(f"expected r < R (a ring torus), got r = {r:g}, R = {R:g}", "surface.r")
    return Built(torus_mesh(R, r, u, v), torus(R, r), None,
                 {"guarantee": "isosceles trapezoids, circular"})


@surface_kind("dupin-cyclide")
def _build_cyclide(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    from .transforms import design_inversion

    f = Fields(table, "surface", ["R", "r", "center", "radius"])
    built = _build_torus({k: table[k] for k in ("R", "r") if k in table}, mesh_table, ctx)
    inv = {"center": f.raw("center", Fields.REQUIRED), "radius": f.raw("radius", Fields.REQUIRED)}
    out = design_inversion(built, inv, "surface")
    return Built(out.mesh.with_info(construction="dupin cyclide"), out.reference, None,
                 {**dict(out.extras), "guarantee": "circular (inversion of a torus)"})


@surface_kind("canal")
def _build_canal(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["spine", "radii", "radius"])
    u, v = mesh_counts(mesh_table, 24, 16, min_u=2, min_v=3)
    spine = profile_from_spec(f.raw("spine", Fields.REQUIRED), "surface.spine",
                              min_points=3).sample(u)
    if len(spine) < 3:
        raise DesignError("expected at least 3 spine points", "surface.spine")
    if f.has("radius") == f.has("radii"):
        raise DesignError("give either radius (a number) or radii (a list)", "surface.radii")
    if f.has("radius"):
        radii = np.full(len(spine), f.number("radius", lo=0.0, lo_open=True))
    else:
        given = f.floats("radii", Fields.REQUIRED, positive=True)
        if given.size == 2 and len(spine) != 2:
            # From the first to the last sphere, linear in arc length along the spine.
            arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(spine, axis=0), axis=1))])
            radii = given[0] + (given[1] - given[0]) * arc / arc[-1]
        elif given.size == len(spine):
            radii = given
        else:
            raise DesignError(f"expected 2 numbers (start, end) or one per spine point "
                              f"({len(spine)}), got {given.size}", "surface.radii")
    try:
        mesh = canal_mesh(spine, radii, v)
    except GeometryError as exc:
        raise DesignError(str(exc), "surface.spine") from None
    # Ring k lies on spheres k and k + 1: report the worst relative deviation.
    ring = mesh.vertices.reshape(len(spine) - 1, v, 3)
    dev = max(np.abs(np.linalg.norm(ring - spine[:-1, None], axis=2) - radii[:-1, None]).max(),
              np.abs(np.linalg.norm(ring - spine[1:, None], axis=2) - radii[1:, None]).max())
    return Built(mesh, None, None, {
        "guarantee": "circular (consecutive circles on one sphere)",
        "on_spheres_max": float(dev / (mesh.diagonal() or 1.0)),
    })


@surface_kind("ellipsoid")
def _build_ellipsoid(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["axes"])
    u, v = mesh_counts(mesh_table, 32, 16, min_u=3, min_v=2)
    axes = f.floats("axes", Fields.REQUIRED, count=3, positive=True)
    a, b, c = (float(x) for x in axes)
    return Built(ellipsoid_mesh(a, b, c, u, v), ellipsoid(a, b, c), None,
                 {"guarantee": quadric_guarantee(a, b)})


def _abc(f: Fields):
    a = f.number("a", 1.0, lo=0.0, lo_open=True)
    b = f.number("b", a, lo=0.0, lo_open=True)
    c = f.number("c", 1.0, lo=0.0, lo_open=True)
    return a, b, c


@surface_kind("hyperboloid-two-sheets")
def _build_two_sheets(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["a", "b", "c", "height"])
    u, v = mesh_counts(mesh_table, 32, 12, min_u=3)
    a, b, c = _abc(f)
    height = f.number("height", 3.0 * c, lo=c, lo_open=True)
    return Built(two_sheet_hyperboloid_mesh(a, b, c, height, u, v),
                 two_sheet_hyperboloid(a, b, c, height), None, {"guarantee": quadric_guarantee(a, b)})


@surface_kind("elliptic-paraboloid")
def _build_elliptic_paraboloid(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["a", "b", "height"])
    u, v = mesh_counts(mesh_table, 32, 12, min_u=3)
    a = f.number("a", 1.0, lo=0.0, lo_open=True)
    b = f.number("b", a, lo=0.0, lo_open=True)
    height = f.number("height", 1.0, lo=0.0, lo_open=True)
    return Built(elliptic_paraboloid_mesh(a, b, height, u, v),
                 elliptic_paraboloid(a, b, height), None, {"guarantee": quadric_guarantee(a, b)})


@surface_kind("hyperboloid")
def _build_hyperboloid(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["a", "b", "c", "height", "style"])
    u, v = mesh_counts(mesh_table, 32, 16, min_u=3)
    a = f.number("a", 1.0, lo=0.0, lo_open=True)
    b = f.number("b", a, lo=0.0, lo_open=True)
    c = f.number("c", 1.0, lo=0.0, lo_open=True)
    height = f.number("height", 2.0, lo=0.0, lo_open=True)
    style = f.choice("style", HyperboloidStyle, "circular")
    if style is HyperboloidStyle.GENERATORS and u < 4:
        raise DesignError(f"expected an integer >= 4 (generators per regulus), got {u}", "mesh.u")
    try:
        mesh = hyperboloid_mesh(a, c, height, u, v, b=b, style=style)
    except GeometryError as exc:
        raise DesignError(str(exc), "surface.height") from None
    z = mesh.vertices[:, 2]
    warnings = []
    if style is HyperboloidStyle.GENERATORS and "v" in mesh_table:
        warnings.append("mesh.v is not used with style = \"generators\": the crossings of the "
                        "generators fix the parallels (z = c tan(2 pi k / u))")
        mesh = mesh.with_info(warnings=warnings)
    guarantee = ("isosceles trapezoids, circular" if a == b else "trapezoids")
    if style is HyperboloidStyle.GENERATORS:
        guarantee += "; diagonals are generators of both reguli"
    reach = float(np.abs(z).max())
    if reach < height * (1 - PARAMETER_SLACK):
        # The crossings of the generators fix the parallels: the last one below
        # `height` ends the mesh.  The reference stays the designed patch, so the
        # coverage says how much is missing, and this warning says why.
        warnings.append(f"the generator crossings reach |z| = {reach:.6g}, not the height "
                        f"{height:g}: z = c tan(2 pi k / u) for whole k; set height = {reach:.6g} "
                        "or change u or c to cover the patch")
        mesh = mesh.with_info(warnings=warnings)
    return Built(mesh, one_sheet_hyperboloid(a, b, c, -height, height), None,
                 {"guarantee": guarantee})


@surface_kind("hyperbolic-paraboloid")
def _build_hyperbolic_paraboloid(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["a", "b", "angle", "size", "style", "fill"])
    u, v = mesh_counts(mesh_table, 16, 16)
    a = f.number("a", 1.0, lo=0.0, lo_open=True)
    if f.has("angle"):
        if f.has("b"):
            raise DesignError("give either b or angle (b = a tan(angle / 2)), not both",
                              "surface.angle")
        angle = f.number("angle", lo=0.0, lo_open=True, hi=179.0)
        b = a * np.tan(np.radians(angle) / 2)
    else:
        b = f.number("b", 1.0, lo=0.0, lo_open=True)
    size = f.number("size", 1.0, lo=0.0, lo_open=True)
    style = f.choice("style", HPStyle, "parabolas")
    fill = f.boolean("fill", True)
    if style is HPStyle.GENERATORS and min(u, v) < 2:
        raise DesignError(f"expected u, v >= 2 for style \"generators\", got {u}, {v}", "mesh")
    try:
        mesh = hyperbolic_paraboloid_mesh(a, b, size, u, v, style, fill=fill)
    except GeometryError as exc:
        raise DesignError(str(exc), "mesh") from None
    if style is HPStyle.PARABOLAS:
        def partials(x, y):
            return (np.stack([np.ones_like(x), 0 * x, 2 * x / a ** 2], axis=1),
                    np.stack([0 * y, np.ones_like(y), -2 * y / b ** 2], axis=1))

        ref = hyperbolic_paraboloid(a, b, partials, (-size, size), (-size, size))
        guarantee = "parallelograms"
    else:
        L = size / max(a, b)

        def partials(lam, mu):
            return (np.stack([0.5 * a + 0 * lam, 0.5 * b + 0 * lam, mu], axis=1),
                    np.stack([0.5 * a + 0 * mu, -0.5 * b + 0 * mu, lam], axis=1))

        ref = hyperbolic_paraboloid(a, b, partials, (-L, L), (-L, L))
        guarantee = "parallelograms; diagonals are generators of both reguli"
    return Built(mesh, ref, None, {"guarantee": guarantee,
                                   "plan_angle_between_reguli_deg":
                                       float(np.degrees(2 * np.arctan(b / a)))})


@surface_kind("helicoid")
def _build_helicoid(table: Mapping, mesh_table: Mapping, ctx: BuildContext) -> Built:
    f = Fields(table, "surface", ["radius", "pitch", "turns"])
    u, v = mesh_counts(mesh_table, 48, 48, min_u=2, min_v=2)
    radius = f.number("radius", 1.0, lo=0.0, lo_open=True)
    pitch = f.number("pitch", 1.0)
    if pitch == 0:
        raise DesignError("expected a non-zero number (0 is a plane), got 0", "surface.pitch")
    turns = f.number("turns", 1.0, lo=0.0, lo_open=True)
    try:
        mesh = helicoid_mesh(radius, pitch, turns, u, v)
    except GeometryError as exc:
        raise DesignError(str(exc), "mesh") from None
    return Built(mesh, helicoid(pitch, radius, turns), None, {"guarantee": "parallelograms"})
