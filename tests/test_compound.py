"""Compound C1 surfaces of HP patches (paper §4.2): only planar quads, C1 to rounding."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import planarity
from ruledmesh.cli import main
from ruledmesh.errors import ParameterError
from ruledmesh.mesh import FaceKind
from ruledmesh.skew.compound import CompoundSurface, c1_residual, c1_step, compound_mesh, compound_net

SEED = np.array([[[0.0, 0.0, 0.0], [0.0, 1.0, 0.3]], [[1.0, 0.0, 0.0], [1.0, 1.0, -0.2]]])


# Moderate steps: in both directions each inner corner is computed from its neighbours,
# so rounding grows along the sweep (see docs/hybrid.md); a few patches stay at ~1e-14.
step = st.tuples(st.floats(0.7, 1.3), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2))


@settings(max_examples=30, deadline=None)
@given(us=st.lists(step, min_size=0, max_size=3), vs=st.lists(step, min_size=0, max_size=2),
       midpoints=st.integers(0, 3), divisions=st.integers(2, 8))
def test_only_planar_quads_and_c1(us, vs, midpoints, divisions):
    P, gap = compound_net(SEED, us, vs)
    assert P.shape == (len(us) + 2, len(vs) + 2, 3)
    assert gap <= 1e-12 * np.ptp(P.reshape(-1, 3), axis=0).max()
    assert c1_residual(P)["max"] <= 1e-12
    try:
        mesh = compound_mesh(P, midpoints, divisions)
    except ParameterError:
        CX, CY = (len(us) + 1) * (midpoints + 1), (len(vs) + 1) * divisions
        assert not any((c + r) % 2 for c in range(1, CX) for r in range(1, CY))
        return
    assert set(np.unique(mesh.face_kind).tolist()) == {FaceKind.QUAD}
    assert np.all(mesh.valences == 4)
    assert planarity(mesh).max() <= 1e-12
    assert mesh.euler_characteristic() == 1
    # Every vertex lies on the piecewise-bilinear surface: the analysis closeness is 0.
    surf = CompoundSurface(P)
    I, J = P.shape[0] - 1, P.shape[1] - 1
    uv = np.c_[mesh.vertex_data["u"] / I, mesh.vertex_data["t"] / J]
    np.testing.assert_allclose(surf.point(uv[:, 0], uv[:, 1]), mesh.vertices, atol=1e-13)


def test_c1_step_is_the_tangent_plane_condition():
    # Off the 3-parameter family the tangent planes differ: perturb the new end point
    # across the joint plane and the residual grows linearly.
    a0, b0 = SEED[0]
    a1, b1 = SEED[1]
    a2, b2 = c1_step(a0, a1, b0, b1, 0.8, 0.2, -0.1)
    P = np.stack([[a0, b0], [a1, b1], [a2, b2]])
    assert c1_residual(P)["max"] <= 1e-15
    n = np.cross(b1 - a1, a1 - a0)
    for eps in (1e-3, 1e-2):
        Q = P.copy()
        Q[2, 1] += eps * n / np.linalg.norm(n)
        assert c1_residual(Q)["max"] > eps / 10
    # Different widths at the two ends (lambda differs) also break C1.
    Q = P.copy()
    Q[2, 1] = b1 + 1.3 * (b1 - b0)
    assert c1_residual(Q)["max"] > 1e-3


def test_zero_slides_give_one_hp():
    # sigma = tau = 0 everywhere: the v-isolines run straight through the joints, the
    # whole is one hyperbolic paraboloid (the compound has no kink to show).
    P, _ = compound_net(SEED, [[1.0, 0, 0], [1.0, 0, 0]])
    a, b = P[:, 0], P[:, 1]
    for row in (a, b):
        np.testing.assert_allclose(np.diff(row, axis=0)[1:], np.diff(row, axis=0)[:-1], atol=1e-15)


def test_straddling_faces_need_c1():
    # The same mesher on a net that is not C1 gives non-planar faces on the joints.
    P, _ = compound_net(SEED, [[1.0, 0.2, -0.1]])
    P[2, 1, 2] += 0.3
    assert planarity(compound_mesh(P, 1, 8)).max() > 1e-4


def test_border_triangles_option():
    P, _ = compound_net(SEED, [[1.0, 0.2, -0.1]], [[0.9, 0.1, 0.0]])
    notched = compound_mesh(P, 1, 4)
    full = compound_mesh(P, 1, 4, border="triangles")
    assert full.count_kinds()["quad"] == notched.count_kinds()["quad"]
    assert full.count_kinds()["triangle"] > 0
    assert planarity(full).max() <= 1e-12 and full.euler_characteristic() == 1
    # With the border halves the mesh covers the whole compound.
    from ruledmesh.analysis.faces import face_areas

    np.testing.assert_allclose(face_areas(full).sum(), CompoundSurface(P).area(), rtol=0.05)


def test_errors():
    with pytest.raises(ParameterError, match="lambda > 0"):
        compound_net(SEED, [[0.0, 0, 0]])
    with pytest.raises(ParameterError, match="u_steps"):
        compound_net(SEED, [[1.0, 0]])
    with pytest.raises(ParameterError, match="seed"):
        compound_net(SEED[:1])
    with pytest.raises(ParameterError, match="border"):
        compound_mesh(compound_net(SEED)[0], border="zigzag")


@pytest.mark.parametrize("name", ["compound-hp-strip", "compound-hp-grid"])
def test_examples_via_cli(name, tmp_path, capsys):
    import json
    from pathlib import Path

    path = Path(__file__).parent.parent / "examples" / f"{name}.toml"
    out = tmp_path / "c.obj"
    assert main(["build", str(path), "-o", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    # Quads inside, planar half faces (triangles) along the border: the whole patch.
    assert set(report["kinds"]) == {"quad", "triangle"}
    assert abs(report["coverage"]["ratio"] - 1) < 0.01
    assert report["planarity"]["max"] <= 1e-12
    assert report["c1"]["max_sine"] <= 1e-12
    assert report["closeness"]["vertices_max"] <= 1e-12
    meshio = pytest.importorskip("meshio")
    m = meshio.read(out)
    assert {c.type for c in m.cells} == {"quad", "triangle"}


def test_design_errors(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[surface]\nkind = "compound-hp"\nseed = [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,1]]]\n'
                   'u_steps = [[1.0, 0.1]]\n')
    assert main(["build", str(bad), "-o", str(tmp_path / "x.obj")]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and "surface.u_steps[0]" in err
