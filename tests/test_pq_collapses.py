"""Half-edge collapses of splinter vertices (ruledmesh.skew.pq.collapses).

Each test catches the mesh the collapses get and the one they give back inside
real builds, and checks what a collapse may and may not do: quads and their
corners untouched, only existing vertices, no new splinter, the smallest angle
never lower, a manifold with consistent sides, the removed vertices close to
the faces left, members still chains along their generators.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import face_min_angles, triangle_distances
from ruledmesh.design import build_file
from ruledmesh.pq import pq_mesh
from ruledmesh.skew.pq import collapses, mesher
from ruledmesh.tolerances import COLLAPSE_MAX_SAG, RESTART_ANGLE_DEG

QUALITY = Path(__file__).resolve().parents[1] / "benchmarks" / "quality"


@pytest.fixture
def caught(monkeypatch):
    """(before, after, collapses, scale) of every collapse_splinters call of the builds in the
    test; ``scale`` is the diagonal the sag bound is relative to: the one the caller passes
    (the whole mesh's, when only a region of it is collapsed), else the mesh's own."""
    calls: list[tuple] = []
    real = collapses.collapse_splinters

    def spy(mesh, *args, **kwargs):
        out, n = real(mesh, *args, **kwargs)
        scale = args[1] if len(args) > 1 and args[1] is not None else \
            float(np.linalg.norm(mesh.vertices.max(0) - mesh.vertices.min(0)))
        calls.append((mesh, out, n, scale))
        return out, n

    monkeypatch.setattr(mesher, "collapse_splinters", spy)
    return calls


def _faces(mesh, k):
    return mesh.face_indices[mesh.face_offsets[np.flatnonzero(mesh.valences == k)][:, None] + np.arange(k)]


def _point_keys(P):
    return {tuple(np.round(p, 12).ravel()) for p in P}


def _triangle_distance(p, P):
    return triangle_distances(np.repeat(p[None], len(P), 0), P).min()


def _defects(mesh) -> tuple[int, int]:
    idx = mesh.face_indices
    nxt = np.arange(idx.size) + 1
    nxt[mesh.face_offsets[1:] - 1] = mesh.face_offsets[:-1]
    n = mesh.n_vertices
    directed = idx.size - np.unique(idx * n + idx[nxt]).size
    und = np.unique(np.minimum(idx, idx[nxt]) * n + np.maximum(idx, idx[nxt]), return_counts=True)[1]
    return directed, int((und > 2).sum())


def check(before, after, removed, scale):
    Vb, Va = before.vertices, after.vertices
    # Only existing vertices, one fewer per collapse.
    assert after.n_vertices == before.n_vertices - removed
    assert _point_keys(Va) <= _point_keys(Vb)
    # Quads (and every face that is not a triangle) untouched, corners in order.
    for k in np.unique(before.valences[before.valences != 3]).tolist():
        assert _point_keys(Vb[_faces(before, k)]) == _point_keys(Va[_faces(after, k)])
    # No new splinter; the smallest angle never lower.
    ab, aa = face_min_angles(before), face_min_angles(after)
    assert (aa < RESTART_ANGLE_DEG).sum() <= (ab < RESTART_ANGLE_DEG).sum()
    assert aa.min() >= ab.min() - 1e-9
    # As much a manifold with consistent sides as before: directed edges used twice,
    # edges in three faces.
    assert _defects(after) <= _defects(before)
    # The removed vertices lie close to the faces left.  A point where two generators meet
    # can hold a vertex of each: one removed there, the other kept, is gone too.
    left = Counter(tuple(np.round(p, 12)) for p in Va)
    had = Counter(tuple(np.round(p, 12)) for p in Vb)
    gone = [np.array(k) for k in had if had[k] > left[k]]
    tri = Va[_faces(after, 3)]
    for p in gone:
        assert _triangle_distance(p, tri) <= COLLAPSE_MAX_SAG * scale * (1 + 1e-9)
    # Members: segments of their own generators' lines, as many as before less those joined.
    first = {int(i): k for k, i in reversed(list(enumerate(before.member_id)))}
    line = before.members[[first[int(i)] for i in after.member_id]]
    A, B = Vb[line[:, 0]], Vb[line[:, 1]]
    d = (B - A) / np.linalg.norm(B - A, axis=1, keepdims=True)
    for end in after.members.T:
        off = Va[end] - A
        assert np.abs(off - np.einsum("ij,ij->i", off, d)[:, None] * d).max(initial=0.0) <= 1e-9 * scale
    assert np.all(after.members[:, 0] != after.members[:, 1])
    # Every member away from the removed vertices is still there; those through one are
    # joined across it, or end there (a generator end point, on two generators where they
    # meet) and go.
    gone_keys = {tuple(np.round(p, 12)) for p in gone}

    def seg(V, m):
        return {tuple(sorted((tuple(np.round(V[i], 12)), tuple(np.round(V[j], 12))))) for i, j in m}

    untouched = [m for m in before.members.tolist()
                 if not ({tuple(np.round(Vb[k], 12)) for k in m} & gone_keys)]
    assert seg(Vb, untouched) <= seg(Va, after.members)
    assert len(after.members) >= len(untouched)


@pytest.mark.parametrize("name", ["plucker-conoid", "plucker-lines", "right-conoid-wide-arc"])
def test_collapses_on_conoids_where_generators_nearly_meet(caught, name):
    """Regression: the conoids kept rows of needles where consecutive generators nearly meet."""
    built = build_file(QUALITY / f"{name}.toml")
    assert caught and sum(c[2] for c in caught) > 0
    for before, after, n, scale in caught:
        check(before, after, n, scale)
    if name.startswith("plucker"):
        assert face_min_angles(built.mesh).min() >= RESTART_ANGLE_DEG


curves = st.lists(st.floats(-2.5, 2.5), min_size=5, max_size=5)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(y1=curves, y2=curves, twist=st.floats(0.0, 3.0), count=st.integers(20, 50),
       rows=st.integers(5, 24))
def test_collapses_on_random_surfaces(caught, y1, y2, twist, count, rows):
    caught.clear()
    u = np.linspace(0, 1, count)
    x = np.linspace(0, 10, 5)
    a = np.stack([10 * u, np.interp(10 * u, x, y1), np.zeros(count)], 1)
    b = np.stack([10 * u + twist * np.sin(3 * u), np.interp(10 * u, x, y2) - 1, 4 + twist * u], 1)
    pq_mesh(a, b, rows=rows)
    for before, after, n, scale in caught:
        check(before, after, n, scale)
