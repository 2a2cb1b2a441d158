"""Fabrication outputs, read back by other people's readers (csv, xml.etree, ezdxf)."""

from __future__ import annotations

import csv
import io
import json
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ruledmesh.analysis.faces import corner_angles, face_areas
from ruledmesh.cli import main
from ruledmesh.errors import GeometryError, ParameterError
from ruledmesh.fabricate import (
    congruence_classes,
    edge_schedule,
    layout,
    member_schedule,
    node_schedule,
    panel_statistics,
    unroll,
)
from ruledmesh.fabricate.hotwire import gcode, wire_paths
from ruledmesh.fabricate.output import fabricate
from ruledmesh.fabricate.unroll import polygon_edges
from ruledmesh.io import save
from ruledmesh.mesh import Mesh


def grid(p, q, with_members=True):
    """X[i, j] = p_i + q_j (planar parallelogram quads); generators along j."""
    n, m = len(p), len(q)
    x = (np.asarray(p, float)[:, None, :] + np.asarray(q, float)[None, :, :]).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(m - 1), indexing="ij")
    a = (i * m + j).ravel()
    faces = np.stack([a, a + m, a + m + 1, a + 1], axis=1)
    kw = {}
    if with_members:
        start = (np.arange(n)[:, None] * m + np.arange(m - 1)).ravel()
        kw = {"members": np.stack([start, start + 1], 1), "member_id": np.repeat(np.arange(n), m - 1)}
    return Mesh.from_faces(x, faces, **kw)


def curved_grid(n=7, m=5):
    s = np.linspace(0.0, 3.0, n)
    t = np.linspace(0.0, 2.0, m)
    return grid(np.c_[s, np.zeros(n), 0.3 * np.sin(s)], np.c_[np.zeros(m), t, 0.2 * t ** 2])


def rotation(quat):
    w, x, y, z = np.asarray(quat) / np.linalg.norm(quat)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


# A star-shaped planar polygon: sorted, well separated angles and radii bounded
# away from 0, so every edge and corner is well conditioned.
polygon_2d = st.integers(3, 8).flatmap(lambda k: st.tuples(
    st.lists(st.floats(0.15, 0.85), min_size=k, max_size=k),
    st.lists(st.floats(0.3, 1.0), min_size=k, max_size=k)))
placement = st.tuples(st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: np.linalg.norm(q) > 0.1),
                      st.tuples(*[st.floats(-100, 100)] * 3))


def _place(poly, place, scale):
    fractions, radii = poly
    k = len(fractions)
    ang = 2 * np.pi * (np.arange(k) + np.asarray(fractions)) / k
    pts = np.c_[np.asarray(radii) * np.cos(ang), np.asarray(radii) * np.sin(ang), np.zeros(k)]
    quat, shift = place
    # One scale per mesh and shifts in units of the panel size: what float64 can hold
    # (a panel 1e5 of its sizes from the origin has 3-D angles rounded beyond 1e-9 degrees).
    return scale * (pts @ rotation(quat).T + np.asarray(shift))


@settings(max_examples=200, deadline=None)
@given(st.floats(0.01, 1000.0), st.lists(st.tuples(polygon_2d, placement), min_size=1, max_size=5))
def test_unrolled_panels_keep_lengths_and_angles(scale, polys):
    """Unrolled and laid-out panels have the 3-D faces' edge lengths and angles to 1e-9."""
    faces, verts, start = [], [], 0
    for poly, place in polys:
        pts = _place(poly, place, scale)
        verts.append(pts)
        faces.append(list(range(start, start + len(pts))))
        start += len(pts)
    mesh = Mesh.from_faces(np.vstack(verts), faces)
    u = unroll(mesh)
    off = mesh.face_offsets
    len3 = polygon_edges(mesh.vertices[mesh.face_indices], off)
    for pts2 in (u.points, layout(u).points):
        np.testing.assert_allclose(polygon_edges(pts2, off), len3, rtol=0, atol=1e-9)
        flat = Mesh.from_arrays(np.c_[pts2, np.zeros(len(pts2))], off, np.arange(len(pts2)))
        np.testing.assert_allclose(corner_angles(flat), corner_angles(mesh), rtol=0, atol=1e-9)
        np.testing.assert_allclose(face_areas(flat), face_areas(mesh), rtol=1e-9, atol=1e-9)
    # The frame maps the flat panel back onto the 3-D face.
    np.testing.assert_allclose(u.to_3d(u.points), mesh.vertices[mesh.face_indices], rtol=0, atol=1e-9)


def test_unroll_refuses_bent_panel():
    mesh = curved_grid()
    v = mesh.vertices.copy()
    v[mesh.face(3)[2], 2] += 0.01
    with pytest.raises(GeometryError, match="not planar"):
        unroll(mesh.with_vertices(v))
    assert unroll(mesh.with_vertices(v), require_planar=False).out_of_plane.max() > 1e-3


def test_layout_panels_disjoint_and_on_sheet():
    mesh = curved_grid(9, 6)
    u = unroll(mesh)
    lay = layout(u, sheet=(1.6, 1.3), gap=0.02)
    assert lay.n_sheets > 1
    lo = np.array([lay.polygon(f).min(axis=0) for f in range(mesh.n_faces)])
    hi = np.array([lay.polygon(f).max(axis=0) for f in range(mesh.n_faces)])
    assert np.all(lo >= 0.02 - 1e-12) and np.all(hi <= np.array([1.6, 1.3]) - 0.02 + 1e-12)
    for s in range(lay.n_sheets):
        ids = lay.panels_on(s)
        sep = ((lo[ids][:, None] >= hi[ids][None] + 0.02 - 1e-12)
               | (hi[ids][:, None] + 0.02 - 1e-12 <= lo[ids][None])).any(axis=2)
        np.fill_diagonal(sep, True)
        assert sep.all()
    with pytest.raises(ParameterError, match=r"not fit on a 0\.3 x 0\.3 sheet .*smallest sheet that fits"):
        layout(u, sheet=(0.3, 0.3))


def test_congruence_classes_translates_and_mirrors():
    # p on a line with equal steps: quads in one column are translates; q symmetric
    # about t = 0: columns j and m - 2 - j are mirror images.
    n, m = 5, 7
    t = np.linspace(-1.0, 1.0, m)
    mesh = grid(np.c_[np.linspace(0, 2, n), np.zeros(n), np.linspace(0, 1, n)],
                np.c_[np.zeros(m), t, 0.4 * t ** 2])
    classes = congruence_classes(mesh)
    col = np.tile(np.arange(m - 1), n - 1)
    mirror = np.minimum(col, m - 2 - col)
    expected = np.unique(mirror, return_inverse=True)[1].reshape(-1)
    # same partition as the mirror-column index
    assert len(np.unique(classes)) == len(np.unique(expected)) == 3
    assert np.array_equal(classes[:, None] == classes[None], expected[:, None] == expected[None])
    assert panel_statistics(mesh)["distinct_panels"] == 3


def test_congruence_needs_order_not_just_sorted_lengths():
    a, b = 1.0, 2.0
    x = (2 * a + np.sqrt(4 * a * a - 8 * (a * a - b * b))) / 4      # |(x, x) - (a, 0)| = b
    kite = np.array([[0, 0, 0], [a, 0, 0], [x, x, 0], [0, a, 0]], float)
    # same sorted lengths (a, a, b, b) in the order a, b, a, b
    h = np.sqrt(b * b - 0.25)
    par = np.array([[0, 0, 0], [a, 0, 0], [a + 0.5, h, 0], [0.5, h, 0]], float) + [5, 0, 0]
    assert np.allclose(sorted(np.linalg.norm(np.roll(kite, -1, 0) - kite, axis=1)), [a, a, b, b])
    assert np.allclose(sorted(np.linalg.norm(np.roll(par, -1, 0) - par, axis=1)), [a, a, b, b])
    mirrored = kite * [-1, 1, 1] + [0, 0, 3]
    rotated = kite @ rotation([0.3, 0.5, -0.2, 0.7]).T + [9, 9, 9]
    nudged = kite + np.array([[0, 0, 0], [0, 0, 0], [1e-3, 0, 0], [0, 0, 0]]) + [0, 5, 0]
    mesh = Mesh.from_faces(np.vstack([kite, par, mirrored, rotated, nudged]),
                           np.arange(20).reshape(5, 4))
    c = congruence_classes(mesh)
    assert c[0] == c[2] == c[3]
    assert len({c[0], c[1], c[4]}) == 3
    assert congruence_classes(mesh, length_tol=1e-2, angle_tol=1.0)[4] == c[0]


def test_edge_schedule_bend_signs():
    # Two unit squares folded along the y axis: a ridge seen from +z (normals up).
    h = 0.5
    v = np.array([[-1, 0, -h], [0, 0, 0], [0, 1, 0], [-1, 1, -h], [1, 0, -h], [1, 1, -h]], float)
    ridge = Mesh.from_faces(v, [[0, 1, 2, 3], [1, 4, 5, 2]])
    e = edge_schedule(ridge)
    k = np.flatnonzero((e["v0"] == 1) & (e["v1"] == 2))[0]
    angle = 2 * np.degrees(np.arctan(h))
    assert e["bend_deg"][k] == pytest.approx(angle, abs=1e-12)
    assert e["dihedral_deg"][k] == pytest.approx(180 - angle, abs=1e-12)
    assert np.isnan(e["bend_deg"][np.arange(len(e["id"])) != k]).all()
    # Mirrored in z (same orientation seen from above, normals still up): a valley.
    e2 = edge_schedule(ridge.with_vertices(v * [1, 1, -1]))
    assert e2["bend_deg"][k] == pytest.approx(-angle, abs=1e-12)
    # The same valley with its faces reversed (normals down) is a ridge seen from below.
    e3 = edge_schedule(Mesh.from_faces(v * [1, 1, -1], [[3, 2, 1, 0], [2, 5, 4, 1]]))
    k3 = np.flatnonzero((e3["v0"] == 1) & (e3["v1"] == 2))[0]
    assert e3["bend_deg"][k3] == pytest.approx(angle, abs=1e-12)
    np.testing.assert_allclose(e["length"], np.linalg.norm(v[e["v1"]] - v[e["v0"]], axis=1))


def _read_csv(data):
    return list(csv.DictReader(io.StringIO(data.decode() if isinstance(data, bytes) else data)))


def test_schedules_through_csv(tmp_path):
    n, m = 6, 4
    s = np.linspace(0, 2, n)
    t = np.linspace(0, 1.5, m)
    p = np.c_[s, np.zeros(n), np.sin(s)]
    q = np.c_[np.zeros(m), t, 0.3 * t ** 2]
    mesh = grid(p, q)
    fabricate(mesh, tmp_path, dxf=False)
    nodes = _read_csv((tmp_path / "nodes.csv").read_text())
    assert len(nodes) == n * m
    coords = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in nodes])
    assert np.array_equal(coords, mesh.vertices)         # repr floats: exact
    val = np.bincount(mesh.edges().reshape(-1), minlength=mesh.n_vertices)
    assert [int(r["valence"]) for r in nodes] == val.tolist()
    members = _read_csv((tmp_path / "members.csv").read_text())
    assert len(members) == n
    for i, r in enumerate(members):
        ends = np.array([[float(r[c]) for c in ("x0", "y0", "z0")],
                         [float(r[c]) for c in ("x1", "y1", "z1")]])
        np.testing.assert_allclose(np.sort(ends, axis=0), np.sort([p[i] + q[0], p[i] + q[-1]], axis=0))
        assert float(r["length"]) == pytest.approx(np.linalg.norm(q[-1] - q[0]), rel=1e-14)
        assert int(r["segments"]) == m - 1
    edges = _read_csv((tmp_path / "edges.csv").read_text())
    assert len(edges) == len(mesh.edges())
    interior = [r for r in edges if r["face1"] != "-1"]
    assert len(interior) == (n - 2) * (m - 1) + (n - 1) * (m - 2)
    assert all(r["dihedral_deg"] == "" for r in edges if r["face1"] == "-1")
    gen_edges = [r for r in edges if r["generator"] != "-1"]
    assert len(gen_edges) == n * (m - 1)
    panels = _read_csv((tmp_path / "panels.csv").read_text())
    np.testing.assert_allclose([float(r["area"]) for r in panels], face_areas(mesh), rtol=1e-12)


def _svg_polygons(path):
    root = ET.parse(path).getroot()
    ns = {"s": "http://www.w3.org/2000/svg"}
    h = float(root.get("viewBox").split()[3])
    polys = {}
    for el in root.findall(".//s:g[@id='CUT']/s:polygon", ns):
        pts = np.array([[float(c) for c in pair.split(",")] for pair in el.get("points").split()])
        pts[:, 1] = h - pts[:, 1]
        polys[int(el.get("id").split("-")[1])] = pts
    texts = [t.text for t in root.findall(".//s:g[@id='LABEL']/s:text", ns)]
    return polys, texts


def test_svg_and_dxf_sheets_read_back(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    mesh = curved_grid(8, 5)
    summary = fabricate(mesh, tmp_path, sheet=(2.0, 1.5), unit="m")
    nsheets = summary["sheets"]["count"]
    assert nsheets >= 2
    len3 = polygon_edges(mesh.vertices[mesh.face_indices], mesh.face_offsets)
    seen = {}
    for s in range(1, nsheets + 1):
        polys, texts = _svg_polygons(tmp_path / "sheets" / f"sheet-{s:03d}.svg")
        for f, pts in polys.items():
            d = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
            np.testing.assert_allclose(d, len3[mesh.face_offsets[f]:mesh.face_offsets[f + 1]],
                                       atol=1e-9)
            assert f"P{f}" in texts
            assert f"{d[0]:.3f}" in texts
        doc = ezdxf.readfile(tmp_path / "sheets" / f"sheet-{s:03d}.dxf")
        auditor = doc.audit()
        assert not auditor.has_errors
        assert doc.header["$INSUNITS"] == 6
        cut = doc.modelspace().query('LWPOLYLINE[layer=="CUT"]')
        assert len(cut) == len(polys)
        for pl in cut:
            pts = np.array([pt[:2] for pt in pl.get_points()])
            f = min(polys, key=lambda g: np.abs(polys[g].mean(axis=0) - pts.mean(axis=0)).sum())
            np.testing.assert_allclose(pts, polys[f], atol=1e-9)
            assert pl.closed
        seen.update(polys)
    assert sorted(seen) == list(range(mesh.n_faces))


def test_hotwire_paths_lie_on_generators():
    mesh = curved_grid()
    path = wire_paths(mesh)
    assert path.span == "y" and path.up == "z"
    gens = member_schedule(mesh)
    p0 = np.c_[gens["x0"], gens["y0"], gens["z0"]]
    d = np.c_[gens["x1"], gens["y1"], gens["z1"]] - p0
    lo, hi = mesh.bounding_box()
    for pts, plane in ((path.point_a, lo[1]), (path.point_b, hi[1])):
        assert np.allclose(pts[:, 1], plane)
        assert np.allclose(np.linalg.norm(np.cross(pts - p0, d), axis=1), 0, atol=1e-12)
    # machine coordinates are the (depth, up) coordinates shifted to a zero minimum
    np.testing.assert_allclose(path.xy[:, 1], path.point_a[:, 2] - path.shift[1], atol=1e-12)
    assert path.xy.min() >= -1e-12 and path.uv.min() >= -1e-12
    # G-code cutting moves agree with the path, shifted along X/U by the lead-in only
    moves = np.array(re.findall(r"G1 X(\S+) Y(\S+) U(\S+) V(\S+)", gcode(path, decimals=6)), float)
    want = np.c_[path.xy, path.uv]
    dx = moves[0, 0] - want[0, 0]
    np.testing.assert_allclose(moves[:-1], want + [dx, 0, dx, 0], atol=1e-6)


def test_hotwire_kerf_offset_side():
    mesh = curved_grid()
    k = 0.1
    base = wire_paths(mesh)
    for side, sign in (("left", 1), ("right", -1)):
        off = wire_paths(mesh, kerf=k, kerf_side=side)
        for a, b in ((base.xy + base.shift, off.xy + off.shift), (base.uv + base.shift, off.uv + off.shift)):
            seg = np.diff(a, axis=0)
            tangent = seg / np.linalg.norm(seg, axis=1)[:, None]
            left = np.c_[-tangent[:, 1], tangent[:, 0]]
            # each offset segment lies on its original segment's line moved k/2 to the side
            for ends in (b[:-1], b[1:]):
                dist = np.einsum("ij,ij->i", ends - a[:-1], left)
                np.testing.assert_allclose(dist, sign * k / 2, atol=1e-12)


def test_hotwire_refuses_parallel_generators(tmp_path):
    mesh = curved_grid()                       # generators lie in the planes x = const
    with pytest.raises(GeometryError, match="parallel to the tower planes"):
        wire_paths(mesh, span="x")
    save(tmp_path / "m.obj", mesh)
    assert main(["fabricate", str(tmp_path / "m.obj"), "-o", str(tmp_path / "out"),
                 "--span", "x"]) == 2
    assert not (tmp_path / "out").exists()


def test_cli_fabricate(tmp_path, capsys):
    mesh = curved_grid()
    save(tmp_path / "m.obj", mesh)
    out = tmp_path / "fab"
    assert main(["fabricate", str(tmp_path / "m.obj"), "-o", str(out), "--scale", "1000",
                 "--unit", "mm", "--kerf", "1.5"]) == 0
    assert "24 panels" in capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    for name in summary["files"]:
        assert (out / name).is_file()
    assert summary["hotwire"]["kerf"] == 1.5
    assert summary["panels"]["count"] == mesh.n_faces
    g = (out / "hotwire.gcode").read_text()
    moves = [line for line in g.splitlines() if line.startswith("G1 ")]
    # lead-in to the first generator, one move per further generator, lead-out
    assert "G21" in g.splitlines() and len(moves) == len(member_schedule(mesh)["generator"]) + 1
    rows = _read_csv((out / "hotwire.csv").read_text())
    assert len(rows) == 7
    svg = (out / "sheets" / "sheet-001.svg").read_text()
    assert re.search(r'width="[0-9.]+mm"', svg)
    assert node_schedule(mesh)["id"].size == len(_read_csv((out / "nodes.csv").read_text()))
