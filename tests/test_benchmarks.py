"""Smoke tests of benchmarks/: the benchmark runs at a tiny size and its figures are sane.

No timed assertions: the times depend on the machine.  What is asserted is what
does not: the surfaces' distances are exact, ruledmesh's rows are planar and on
the quadrics, and the JSON carries the keys docs/benchmarks.md reports.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture(scope="module")
def bench():
    sys.path.insert(0, str(BENCH))
    try:
        import limits
        import peers
        import run
        import surfaces

        yield {"run": run, "surfaces": surfaces, "peers": peers, "limits": limits}
    finally:
        sys.path.remove(str(BENCH))
        for name in ("limits", "peers", "run", "surfaces"):
            sys.modules.pop(name, None)


def _normals(name: str, V: np.ndarray) -> np.ndarray:
    if name == "hyperbolic-paraboloid":
        n = np.stack([-V[:, 1], -V[:, 0], np.ones(len(V))], 1)
    else:
        n = V * np.array([1.0, 1.0 / 2.25, -1.0])
    return n / np.linalg.norm(n, axis=1)[:, None]


@pytest.mark.parametrize("name", ["hyperbolic-paraboloid", "hyperboloid"])
def test_quadric_distance_is_exact_along_the_normal(bench, name):
    s = bench["surfaces"].SURFACES[name]
    V, _ = s.naive_grid(9)
    assert s.distance(V).max() < 1e-14 * s.diagonal          # the grid lies on the quadric
    n = _normals(name, V)
    for h in (0.05, 0.3):
        # The foot point of p + h n is p (for h below the focal distance).
        assert np.allclose(s.distance(V + h * n), h, atol=1e-12)


def test_generators_lie_on_the_surfaces(bench):
    for s in bench["surfaces"].SURFACES.values():
        a, b = s.generators(7)
        t = np.linspace(0, 1, 5)
        pts = (a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]).reshape(-1, 3)
        assert s.distance(pts).max() < 1e-10 * s.diagonal, s.name


def test_ruledmesh_row_is_planar_and_on_the_quadric(bench):
    run, surfaces = bench["run"], bench["surfaces"]
    row = run.measure_ruledmesh(surfaces.SURFACES["hyperboloid"], 10)
    assert row["planarity_max"] <= 1e-12
    assert row["displacement_max"] <= 1e-10
    assert row["faces"] > 0 and row["seconds"] > 0


def test_exponent_fit_recovers_a_power_law(bench):
    x = np.array([1e3, 1e4, 1e5])
    assert bench["limits"].fit_exponent(x, 3e-7 * x**1.25) == pytest.approx(1.25)


def test_peer_failures_are_reported_not_raised(bench):
    peers = bench["peers"]

    def broken(V, F):
        raise RuntimeError("solver failed\nsecond line")

    p = peers.Peer("broken", "none", "none", "none", "default", broken)
    res = peers.run_peer(p, np.zeros((4, 3)), np.array([[0, 1, 2, 3]]), timeout=30)
    assert res == {"status": "error", "reason": "RuntimeError: solver failed"}


def test_tiny_run_writes_the_json_and_plot(bench, tmp_path, capsys):
    run = bench["run"]
    out = tmp_path / "bench.json"
    assert run.main(["--tiny", "--silent", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    for key in ("latency_100x100_ms", "ratio_1000x1000_to_bilinear", "scaling_exponent", "methods",
                "machine", "skipped"):
        assert key in data
    assert np.isfinite(data["scaling_exponent"])
    surfaces = set(bench["surfaces"].SURFACES)
    rm = [m for m in data["methods"] if m["name"] == "ruledmesh"]
    assert {m["surface"] for m in rm} == surfaces
    for m in data["methods"]:
        assert set(m) >= {"name", "surface", "size", "planarity_max", "displacement_max", "seconds"}
        assert m["surface"] in surfaces and m["seconds"] > 0
    assert all(m["planarity_max"] <= 1e-12 for m in rm)
    # Every installed peer either gave rows or is listed as failed, with a reason.
    installed = set(data["peers_installed"])
    ran = {m["tool"] for m in data["methods"]} | {f["tool"] for f in data["failures"]}
    assert installed <= ran
    assert all(f["reason"] for f in data["failures"] + data["skipped"])
    printed = capsys.readouterr().out
    assert "ruledmesh" in printed and "planarity_max" in printed
    # The page made from it has the fabricator's figures side by side with the peers'.
    import report

    notes = tmp_path / "notes.md"
    notes.write_text("## Later\n\nmeasured elsewhere\n")
    assert report.main([str(out), "--notes", str(notes), "--notes", str(notes)]) == 0
    page = capsys.readouterr().out
    assert "| quads | min ang |" in page and page.count("## Later") == 2
    for m in rm:
        assert 0.0 <= m["quad_area_share"] <= 1.0 and m["min_angle_deg"] > 0
        assert f"| {100 * m['quad_area_share']:.1f} % | {m['min_angle_deg']:.2f} |" in page
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return
    assert out.with_suffix(".png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_designer_benchmark_times_every_stage(capsys):
    """benchmarks/designer.py at one step: a figure for each stage of the server's part."""
    sys.path.insert(0, str(BENCH))
    try:
        import designer

        assert designer.main(["--steps", "1"]) == 0
    finally:
        sys.path.remove(str(BENCH))
        sys.modules.pop("designer", None)
    out = capsys.readouterr().out
    for stage in ("build (wall)", "build (CPU)", "frame_data", "Session.edit + payload",
                  "Session.edit, worker", "POST /api/edit (client)", "POST /api/edit (server)"):
        line = next(x for x in out.splitlines() if x.startswith(stage))
        median = float(line.split("median")[1].split("ms")[0])
        assert 0 < median < 60_000, line
    assert "load average" in out


def test_twisted_arcs_sweep_writes_designs_that_build(tmp_path):
    import _shared  # a helper module of tests/ (see conftest.py)

    from ruledmesh import build
    from ruledmesh.analysis.faces import area_shares, planarity

    mod = _shared.bench_module("twisted_arcs")
    assert mod.main([str(tmp_path)]) == 0
    files = sorted(tmp_path.glob("*.toml"))
    assert len(files) == 32
    # The most twisted of them, turned by 140 degrees: 78.5 % triangles before the bunched rows
    # far out on the primary were left out, 14.9 % after.
    mesh = build(tmp_path / "arcs-t140-s120-r3-h3.toml")
    assert 1.0 - area_shares(mesh)["quads"] <= 0.25
    assert planarity(mesh).max() <= 1e-12
