"""Meshes of the same runs assembled once (ruledmesh.skew.pq.reuse).

A design build weighs meshes of many options; where two options give the same runs, the
assembly and the passes after it run once.  What is reused must not show: every mesh is
the one the mesher makes without reuse, in its arrays and in its info.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ruledmesh.skew.pq.mesher as mesher
from ruledmesh.design import build_design, build_file, parse_design
from ruledmesh.skew.pq import pq_mesh
from ruledmesh.skew.pq.reuse import reusing_assemblies

OPTIONS = [{"primary": p, "division": d, "rows_from": r}
           for p, d, r in itertools.product(("middle", 1, 2), ("even", "graded", "bounded"), ("primary", "c1", "c2"))]


def _same(x, y) -> bool:
    arrays = ("vertices", "face_offsets", "face_indices", "face_kind", "members", "member_id")
    return all(np.array_equal(getattr(x, k), getattr(y, k)) for k in arrays) \
        and x.vertex_data.keys() == y.vertex_data.keys() \
        and all(np.array_equal(x.vertex_data[k], y.vertex_data[k]) for k in x.vertex_data) \
        and json.dumps(x.info, sort_keys=True, default=repr) == json.dumps(y.info, sort_keys=True, default=repr)


def _counting(monkeypatch, module, name: str) -> list[int]:
    """Count the calls of ``module.name`` (made through the module's global)."""
    calls = [0]
    real = getattr(module, name)

    def counted(*args, **kwargs):
        calls[0] += 1
        return real(*args, **kwargs)

    monkeypatch.setattr(module, name, counted)
    return calls


def test_options_that_give_the_same_runs_are_assembled_once(monkeypatch):
    """Five generators of z = xy: the middle is generator 2, so primary "middle" and 2 make
    the same runs (the info still says which was asked for); a graded division makes other
    runs, assembled apart."""
    u = np.linspace(-1, 1, 5)
    a = np.stack([u, -np.ones(5), -u], axis=1)
    b = np.stack([u, np.ones(5), u], axis=1)
    calls = _counting(monkeypatch, mesher, "assemble")
    with reusing_assemblies():
        middle = pq_mesh(a, b, rows=4, primary="middle")
        two = pq_mesh(a, b, rows=4, primary=2)
        assert calls[0] == 1
        graded = pq_mesh(a, b, rows=8, division="graded")
        assert calls[0] == 2
    assert middle.info["primary"] == "middle" and two.info["primary"] == 2
    assert np.array_equal(middle.vertices, two.vertices)
    assert _same(two, pq_mesh(a, b, rows=4, primary=2))
    assert _same(graded, pq_mesh(a, b, rows=8, division="graded"))
    assert calls[0] == 4                      # outside the block, nothing is kept


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.integers(4, 9), st.integers(1, 6))
def test_reused_meshes_are_the_meshes_made_without_reuse(seed, m, rows):
    """Random smooth and free line sets, every option tried by a design build: each mesh made
    while reusing is the mesh made alone, arrays and info (warnings included)."""
    rng = np.random.default_rng(seed)
    u = np.linspace(0, 1, m)[:, None]
    c = rng.normal(size=(6, 3))
    a = c[0] + u * c[1] + u * u * c[2] * 0.3
    b = c[3] + u * c[4] + u * u * c[5] * 0.3
    with reusing_assemblies() as store:
        reused = [pq_mesh(a, b, rows=rows, **o) for o in OPTIONS]
    assert 0 < len(store) < len(OPTIONS)
    for o, mesh in zip(OPTIONS, reused):
        assert _same(mesh, pq_mesh(a, b, rows=rows, **o)), o


def test_a_design_build_is_the_same_with_and_without_reuse(monkeypatch):
    """Two regression surfaces whose builds weigh options that give the same runs (a lifted
    cylinder, where most rows stop at the torsal strips, and a nearly cylindrical twisted
    surface), and a short line set: each build's mesh and info do not depend on the reuse,
    and it assembled fewer meshes than it made."""
    from pathlib import Path

    quality = Path(__file__).resolve().parents[1] / "benchmarks" / "quality"
    lines = np.stack([np.stack([np.linspace(0, 1, 6), np.zeros(6), np.zeros(6)], 1),
                      np.stack([np.linspace(0, 1, 6) ** 2, np.ones(6), np.linspace(0, 1, 6)], 1)], 1)
    text = f"[rulings]\nlines = {lines.tolist()}\n[mesh]\nrows = 3\n"

    def builds():
        return [build_file(quality / "cylinder-lift-1e-3.toml").mesh,
                build_file(quality / "near-cylinder-twist.toml").mesh,
                build_design(parse_design(text, "lines.toml")).mesh]

    import ruledmesh.design.pq as design_pq

    made = _counting(monkeypatch, design_pq, "pq_mesh")
    assembled = _counting(monkeypatch, mesher, "assemble")
    with_reuse = builds()
    assert assembled[0] < made[0]
    monkeypatch.setattr(mesher, "runs_digest", lambda *args, **kwargs: None)
    assert all(_same(x, y) for x, y in zip(with_reuse, builds(), strict=True))
