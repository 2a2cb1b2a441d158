"""The flip and pairing runs after the first weigh only the faces near what changed since.

``_fattened`` tells them where (``near``): a run there must make the mesh a run over the
whole mesh makes.  Each build below is made twice, once with every run over the whole
mesh, and compared bit for bit; the designs are ones where the local runs were first
caught missing a flip (a flip leaving a thin triangle brings its neighbours into a later
run's reach; ``moebius-curves`` showed it too).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ruledmesh.design import build_design, load_design
from ruledmesh.skew.pq import flips, mesher, pairing

QUALITY = Path(__file__).resolve().parents[1] / "benchmarks" / "quality"


def _whole(monkeypatch) -> list[bool]:
    """Make every flip and pairing run weigh the whole mesh; the list records whether a
    call had been given a region."""
    given: list[bool] = []

    def whole(real):
        def run(*args, near=None, **kwargs):
            given.append(near is not None)
            return real(*args, **kwargs)
        return run

    monkeypatch.setattr(mesher, "flip_triangles", whole(flips.flip_triangles))
    monkeypatch.setattr(mesher, "pair_triangles", whole(pairing.pair_triangles))
    return given


def _arrays(mesh):
    return (mesh.vertices, mesh.face_offsets, mesh.face_indices, mesh.face_kind, mesh.members,
            mesh.member_id)


@pytest.mark.parametrize("name", ["twisted-arcs-160deg"])
def test_local_runs_make_the_mesh_whole_runs_make(name, monkeypatch):
    local = build_design(load_design(QUALITY / f"{name}.toml")).mesh
    given = _whole(monkeypatch)
    whole = build_design(load_design(QUALITY / f"{name}.toml")).mesh
    assert any(given), "no run was local: the test compares nothing"
    for x, y in zip(_arrays(local), _arrays(whole)):
        assert np.array_equal(x, y)
    assert "_fid" not in local.vertex_data


def test_a_local_flip_run_finds_the_flips_of_a_whole_run():
    """A settled mesh, one local change (a triangle pair re-cut against the rule): the run
    near it undoes the change, as a run over the whole mesh does, and touches nothing else."""
    from ruledmesh.pq import pq_mesh

    u = np.linspace(0, 1, 41)
    a = np.c_[10 * u, np.sin(6 * u), 0 * u]
    b = np.c_[10 * u + 0.5 * np.sin(3 * u), 1 + 0.7 * np.cos(5 * u), 3 + 0 * u]
    mesh = pq_mesh(a, b, rows=30, trim=True)
    report: dict = {}
    settled, _ = flips.flip_triangles(mesh, report=report)
    assert report["settled"]
    # Re-cut the first flippable pair the wrong way: the run near it must flip it back.
    ids = np.flatnonzero(settled.valences == 3)
    tri = settled.face_indices[settled.face_offsets[ids][:, None] + np.arange(3)]
    t1, t2, pa, pb, pc, pd = pairing.adjacent_triangles(tri, settled.n_vertices)
    from ruledmesh.analysis.faces import min_corner_angles

    worse = [k for k in range(len(t1)) if min(
        min_corner_angles(settled.vertices, np.array([[pa[k], pb[k], pd[k]], [pa[k], pd[k], pc[k]]])))
        < min(min_corner_angles(settled.vertices, tri[[t1[k], t2[k]]])) - 5]
    compared = 0
    for k in worse[:40]:
        spoiled = _recut(settled, ids[t1[k]], ids[t2[k]], (pa[k], pb[k], pc[k], pd[k]))
        by_whole, n_whole = flips.flip_triangles(spoiled)
        if n_whole == 0:
            continue            # the flip back bends too far or sags: not one for this test
        near = np.zeros(spoiled.n_vertices, bool)
        near[[pa[k], pb[k], pc[k], pd[k]]] = True
        by_region, n_region = flips.flip_triangles(spoiled, near=near)
        assert n_region == n_whole
        assert np.array_equal(by_region.face_indices, by_whole.face_indices)
        compared += 1
    assert compared >= 3


def _recut(mesh, f1, f2, corners):
    """``mesh`` with triangles ``f1 = (b, c, a)``, ``f2 = (c, b, d)`` re-cut along ``a d``."""
    from dataclasses import replace

    a, b, c, d = corners
    idx = mesh.face_indices.copy()
    idx[mesh.face_offsets[f1] + np.arange(3)] = [a, b, d]
    idx[mesh.face_offsets[f2] + np.arange(3)] = [a, d, c]
    return replace(mesh, face_indices=idx)
