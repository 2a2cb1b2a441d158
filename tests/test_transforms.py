"""Transforms of §2.3: affine and projective maps keep planarity, inversion keeps
circularity and is refused for non-circular meshes; the reference follows."""

from __future__ import annotations

import _catalogue_checks as chk  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ruledmesh import constructions as C
from ruledmesh import transforms as T
from ruledmesh.analysis.faces import face_normals
from ruledmesh.design import build_design, parse_design
from ruledmesh.errors import DesignError, GeometryError, ParameterError
from ruledmesh.registry import Built

FAST = settings(max_examples=25, deadline=None)

MESHES = {
    "hp": lambda: C.hyperbolic_paraboloid_mesh(1.0, 1.5, 2.0, 8, 8, "generators"),
    "helicoid": lambda: C.helicoid_mesh(2.0, 3.0, 1.0, 16, 16),
    "torus": lambda: C.torus_mesh(3.0, 1.0, 12, 8),
    "pyramid": lambda: C.pyramid([[1, 0, 0], [0, 1, 0], [-1, 0, 0.3], [0, -1, 0]], [0, 0, 2], 3,
                                 closed=True, to_apex=True),
}


def max_planarity(mesh):
    q = chk.quads_of(mesh.vertices, mesh.face_list())
    worst = chk.planarity(q).max() if len(q) else 0.0
    for p in chk.polygons_of(mesh.vertices, mesh.face_list()):
        worst = max(worst, chk.polygon_planarity(p))
    return worst


def well_conditioned(rnd):
    rng = np.random.default_rng(rnd.randint(0, 2 ** 31))
    while True:
        A = np.eye(3) + 0.6 * rng.normal(size=(3, 3))
        if np.linalg.cond(A) < 20:
            return A, rng.normal(size=3)


@FAST
@given(st.sampled_from(sorted(MESHES)), st.randoms(use_true_random=False))
def test_affine_keeps_planarity_and_straight_members(name, rnd):
    mesh = MESHES[name]()
    A, t = well_conditioned(rnd)
    out = T.affine(mesh, A, t)
    np.testing.assert_allclose(out.vertices, mesh.vertices @ A.T + t, rtol=0, atol=1e-12)
    assert max_planarity(out) <= 1e-12
    assert np.array_equal(out.members, mesh.members)
    if len(out.members):
        mids = out.vertices[out.members].mean(axis=1)
        np.testing.assert_allclose(mids, mesh.vertices[mesh.members].mean(axis=1) @ A.T + t,
                                   atol=1e-12)


@FAST
@given(st.sampled_from(sorted(MESHES)), st.randoms(use_true_random=False))
def test_projective_keeps_planarity(name, rnd):
    mesh = MESHES[name]()
    rng = np.random.default_rng(rnd.randint(0, 2 ** 31))
    A, t = well_conditioned(rnd)
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = A, t
    # A last row that keeps w > 0 on the mesh (bounded by |v| <= 5).
    M[3, :3] = rng.uniform(-0.1, 0.1, 3)
    out = T.projective(mesh, M)
    assert max_planarity(out) <= 1e-12
    h = np.c_[mesh.vertices, np.ones(mesh.n_vertices)] @ M.T
    np.testing.assert_allclose(out.vertices, h[:, :3] / h[:, 3:], atol=1e-12)


def test_projective_refuses_vertex_at_or_across_infinity():
    mesh = C.torus_mesh(3.0, 1.0, 12, 8)
    M = np.eye(4)
    M[3] = [1.0 / 4.0, 0, 0, 0.1]  # w = x / 4 + 0.1: both signs on the torus
    with pytest.raises(GeometryError, match="across infinity"):
        T.projective(mesh, M)
    M[3] = [-1.0 / 4.0, 0, 0, 1.0]  # w = 1 - x / 4: zero at the vertex (4, 0, 0)
    with pytest.raises(GeometryError, match=r"vertex 0 .* to infinity"):
        T.projective(mesh, M)


def test_singular_maps_are_refused():
    mesh = MESHES["hp"]()
    with pytest.raises(ParameterError, match="invertible"):
        T.affine(mesh, np.diag([1.0, 1.0, 0.0]))
    with pytest.raises(ParameterError, match="matrix"):
        T.projective(mesh, np.zeros((4, 4)))


@pytest.mark.parametrize("name", ["hp", "helicoid", "pyramid"])
def test_inversion_of_non_circular_mesh_is_refused(name):
    with pytest.raises(GeometryError, match="not circular"):
        T.inversion(MESHES[name](), [0.5, 0.3, 4.0], 5.0)


@FAST
@given(st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3)), st.floats(0.5, 6),
       st.sampled_from(["torus", "rotational", "moulding", "hyperboloid"]))
def test_inversion_keeps_circular_meshes_circular(center, radius, name):
    mesh = {
        "torus": lambda: C.torus_mesh(3.0, 1.0, 16, 10),
        "rotational": lambda: C.rotational_mesh([[1, 0, -1], [2, 0, 0], [1.5, 0, 1.2]], 12),
        "moulding": lambda: C.moulding_mesh([[1, 0, 0], [1.5, 0, 1], [1.2, 0, 2]],
                                            [[0, 0, 0], [0.2, 0, 0]], [[0, 0, 1], [0.2, 0, 1]],
                                            [20, 25]),
        "hyperboloid": lambda: C.hyperboloid_mesh(1.0, 1.5, 2.0, 24, style="generators"),
    }[name]()
    c = np.asarray(center)
    if np.linalg.norm(mesh.vertices - c, axis=1).min() < 0.05:
        return  # too close to a vertex: its image would be far away, not a mesh
    out = T.inversion(mesh, c, radius)
    q = chk.quads_of(out.vertices, out.face_list())
    assert chk.circularity(q).max() <= 1e-10
    assert chk.planarity(q).max() <= 1e-12
    rel = mesh.vertices - c
    np.testing.assert_allclose(
        out.vertices, c + radius ** 2 * rel / np.einsum("ij,ij->i", rel, rel)[:, None])
    assert len(out.members) == 0


def test_inversion_refuses_centre_at_a_vertex():
    mesh = C.torus_mesh(3.0, 1.0, 12, 8)
    with pytest.raises(GeometryError, match="vertex 0"):
        T.inversion(mesh, mesh.vertices[0], 2.0)


def test_orientation_reversing_maps_keep_normals_outward():
    def outward(m):
        normals = face_normals(m)[0]
        return np.median(np.einsum("ij,ij->i", normals, chk_centroids(m) - m.vertices.mean(axis=0)))

    for mesh in (C.ellipsoid_mesh(2.0, 2.0, 1.0, 12, 8), C.torus_mesh(3.0, 1.0, 12, 8)):
        assert outward(mesh) > 0
        assert outward(T.scale(mesh, [-1.0, 1.0, 1.0])) > 0
        # Centre outside the solid: the image of the solid is bounded, normals stay outward.
        assert outward(T.inversion(mesh, [0.0, 0.0, 6.0], 4.0)) > 0


def chk_centroids(mesh):
    return np.add.reduceat(mesh.vertices[mesh.face_indices], mesh.face_offsets[:-1]) / \
        mesh.valences[:, None]


# ----------------------------------------------------------- the reference follows
def built(kind_text):
    return build_design(parse_design(kind_text))


TORUS = '[surface]\nkind = "torus"\nR = 3.0\nr = 1.0\n[mesh]\nu = 24\nv = 12\n'


def test_similarity_keeps_exact_distance_and_area():
    b = built(TORUS + '[[transform]]\ntype = "rotate"\naxis = [1, 1, 0]\nangle = 40\ncenter = [1, 2, 3]\n'
                      '[[transform]]\ntype = "scale"\nfactor = 2.0\n')
    base = built(TORUS)
    assert b.reference.area() == pytest.approx(4 * base.reference.area())
    # A point 0.1 outside the tube (along the radial direction) maps to one 0.2 outside.
    R = T.rotation_matrix([1, 1, 0], 40)
    c = np.array([1.0, 2.0, 3.0])
    p = np.array([[4.1, 0.0, 0.0]])
    q = 2 * ((p - c) @ R.T + c)
    assert b.reference.distance(q)[0] == pytest.approx(0.2, rel=1e-12)
    assert "transform_notes" not in b.extras


@FAST
@given(st.randoms(use_true_random=False))
def test_non_similar_map_keeps_closeness_honest(rnd):
    A, t = well_conditioned(rnd)
    text = ('[surface]\nkind = "hyperbolic-paraboloid"\na = 1.0\nb = 1.5\nsize = 2.0\n'
            f'[[transform]]\ntype = "affine"\nmatrix = {A.tolist()}\noffset = {t.tolist()}\n')
    b = built(text)
    assert b.reference.area() is None
    assert any("implicit" in n for n in b.extras["transform_notes"])
    verts = b.mesh.vertices
    assert b.reference.distance(verts).max() <= 1e-10 * b.mesh.diagonal()
    # A point pushed off along the new surface normal by eps is at distance eps.
    p = np.linalg.solve(A, (verts[40] - t))
    n0 = np.array([2 * p[0], -2 * p[1] / 2.25, -1.0])
    n = np.linalg.solve(A.T, n0)
    n /= np.linalg.norm(n)
    eps = 1e-4 * b.mesh.diagonal()
    assert b.reference.distance((verts[40] + eps * n)[None])[0] == pytest.approx(eps, rel=1e-3)


def test_inverted_torus_reference_is_the_cyclide():
    b = built(TORUS + '[[transform]]\ntype = "inversion"\ncenter = [0.5, 0.3, 4.0]\nradius = 5.0\n')
    assert b.reference.distance(b.mesh.vertices).max() <= 1e-10 * b.mesh.diagonal()
    far = b.mesh.vertices * 1.05
    assert b.reference.distance(far).min() > 0


def test_foreign_reference_dropped_after_non_similar_map():
    class Plane:
        def distance(self, points):
            return np.abs(points[:, 2])

        def area(self):
            return 1.0

    mesh = C.translational_mesh([[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 1, 0]])
    moved = T.transform_built(Built(mesh, Plane()), "translate", vector=[0, 0, 1])
    assert moved.reference.distance(np.array([[0.0, 0.0, 1.0]]))[0] == 0.0
    assert moved.reference.area() == 1.0
    sheared = T.transform_built(Built(mesh, Plane()), "shear", xz=0.5)
    assert sheared.reference is None
    assert "closeness dropped" in sheared.extras["transform_notes"][0]


@pytest.mark.parametrize("table, field", [
    ('type = "affine"\nmatrix = [[1, 0], [0, 1]]\n', "transform[0].matrix"),
    ('type = "affine"\nmatrix = [[1, 0, 0], [0, 1, 0], [0, 0, 0]]\n', "transform[0].matrix"),
    ('type = "projective"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0.25, 0, 0, 0.1]]\n',
     "transform[0]"),
    ('type = "rotate"\naxis = [0, 0, 0]\nangle = 3\n', "transform[0].axis"),
    ('type = "inversion"\ncenter = [0, 0, 9]\nradius = -1\n', "transform[0].radius"),
    ('type = "shear"\nxw = 1\n', "transform[0].xw"),
    ('type = "inversoin"\n', "transform[0].type"),
])
def test_transform_design_errors_name_the_field(table, field):
    with pytest.raises(DesignError) as info:
        build_design(parse_design(TORUS + "[[transform]]\n" + table, "t.toml"))
    assert f"t.toml: {field}:" in str(info.value)
