"""Renders: real PNGs read back by matplotlib's reader, faces coloured as asked."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("matplotlib")
from matplotlib import colors
from matplotlib import image as mpimg

from ruledmesh.cli import main
from ruledmesh.errors import ParameterError
from ruledmesh.io import save
from ruledmesh.mesh import FaceKind, Mesh
from ruledmesh.render import face_values, render, save_render


def translational_mesh(n=7, m=5):
    """X[i, j] = p_i + q_j: every quad is a parallelogram, hence planar."""
    s = np.linspace(0.0, 3.0, n)
    t = np.linspace(0.0, 2.0, m)
    p = np.c_[s, np.zeros(n), 0.3 * np.sin(s)]
    q = np.c_[np.zeros(m), t, 0.2 * t ** 2]
    x = (p[:, None, :] + q[None, :, :]).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(m - 1), indexing="ij")
    a = (i * m + j).ravel()
    faces = np.stack([a, a + m, a + m + 1, a + 1], axis=1)
    start = (np.arange(n)[:, None] * m + np.arange(m - 1)).ravel()
    members = np.stack([start, start + 1], axis=1)
    return Mesh.from_faces(x, faces, members=members, member_id=np.repeat(np.arange(n), m - 1))


def _has_colour(img, hex_colour, tol=0.02):
    rgb = np.asarray(colors.to_rgb(hex_colour))
    return np.any(np.all(np.abs(img[..., :3] - rgb) < tol, axis=-1))


def test_png_has_size_and_content(tmp_path):
    path = save_render(tmp_path / "m.png", translational_mesh(), size=(640, 480))
    img = mpimg.imread(path)
    assert img.shape[:2] == (480, 640)
    nonwhite = np.any(img[..., :3] < 0.95, axis=-1).mean()
    assert 0.05 < nonwhite < 0.95


def test_kind_colours_drawn(tmp_path):
    mesh = translational_mesh()
    kind = mesh.face_kind.copy()
    kind[:3] = FaceKind.FILL
    mesh = Mesh.from_arrays(mesh.vertices, mesh.face_offsets, mesh.face_indices, kind,
                            members=mesh.members, member_id=mesh.member_id)
    img = mpimg.imread(save_render(tmp_path / "k.png", mesh, color="kind", edges=False))
    assert _has_colour(img, "#4c78a8")   # quads
    assert _has_colour(img, "#e45756")   # fills


def test_planarity_shows_bent_face(tmp_path):
    """A bent quad gets the top of the colour map; a planar mesh does not reach it."""
    mesh = translational_mesh()
    top = colors.to_hex(__import__("matplotlib").colormaps["viridis"](1.0))
    flat = mpimg.imread(save_render(tmp_path / "f.png", mesh, edges=False, generators=False))
    # outside the colour bar (right-most 14 %), no face is at the top colour
    assert not _has_colour(flat[:, : int(0.86 * flat.shape[1])], top, tol=0.05)
    v = mesh.vertices.copy()
    v[mesh.face(10)[2], 2] += 0.5
    bent = mpimg.imread(save_render(tmp_path / "b.png", mesh.with_vertices(v),
                                    edges=False, generators=False))
    assert _has_colour(bent[:, : int(0.86 * bent.shape[1])], top, tol=0.05)


class _Plane:
    """The plane z = height (a real reference surface: exact distances)."""

    def __init__(self, height):
        self.height = height

    def distance(self, points):
        return np.abs(points[:, 2] - self.height)


def test_closeness_values_exact():
    s = np.linspace(0, 1, 4)
    x = np.stack(np.meshgrid(s, s, indexing="ij"), -1).reshape(-1, 2)
    x = np.c_[x, np.zeros(len(x))]
    a = np.array([0, 1, 2, 4, 5, 6, 8, 9, 10])
    mesh = Mesh.from_faces(x, np.stack([a, a + 4, a + 5, a + 1], 1))
    vals = face_values(mesh, "closeness", _Plane(0.25))
    np.testing.assert_allclose(vals, 0.25 / np.sqrt(2.0), rtol=1e-15)
    with pytest.raises(ParameterError, match="closeness"):
        face_values(mesh, "closeness")
    assert render(mesh, color="closeness", reference=_Plane(0.1), fmt="svg").lstrip().startswith(b"<?xml")


@pytest.mark.parametrize("bad, match", [({"color": "planar"}, "did you mean"),
                                        ({"view": (1, 2, 3)}, "view"),
                                        ({"size": (5, 5)}, "size")])
def test_bad_options(bad, match):
    with pytest.raises(ParameterError, match=match):
        render(translational_mesh(), **bad)


def test_cli_render(tmp_path, capsys):
    save(tmp_path / "m.obj", translational_mesh())
    out = tmp_path / "m.png"
    assert main(["render", str(tmp_path / "m.obj"), "-o", str(out), "--color", "kind",
                 "--view", "40,-30", "--size", "320x200", "-q"]) == 0
    assert mpimg.imread(out).shape[:2] == (200, 320)
    assert main(["render", str(tmp_path / "m.obj"), "-o", str(tmp_path / "c.png"),
                 "--color", "closeness"]) == 2
    assert "design" in capsys.readouterr().err
    assert not (tmp_path / "c.png").exists()


def _share(img, hex_colour, tol=0.08):
    rgb = np.asarray(colors.to_rgb(hex_colour))
    return float(np.all(np.abs(img[..., :3] - rgb) < tol, axis=-1).mean())


def test_large_mesh_shows_coloured_faces_not_black():
    """Regression: a 1000 x 1000 render was solid black (outlines and generators over every face).

    90 000 faces with 300 generators at 1600 x 1200: by default the outlines are dropped
    and the generators thinned, so most of the mesh shows its face colour; forcing both
    on paints it over (which this test would catch if "auto" stopped working).
    """
    import io

    mesh = translational_mesh(301, 301)
    auto = mpimg.imread(io.BytesIO(render(mesh, color="kind", size=(1600, 1200))))
    from ruledmesh.render import _KIND_COLORS

    quad = _KIND_COLORS[FaceKind.QUAD]
    dark = float(np.all(auto[..., :3] < 0.25, axis=-1).mean())
    assert _share(auto, quad) > 0.15 and dark < 0.02
    forced = mpimg.imread(io.BytesIO(render(mesh, color="kind", size=(1600, 1200),
                                            edges="on", generators="on")))
    assert _share(forced, quad) < 0.5 * _share(auto, quad)


def test_title_is_drawn_inside_the_image():
    """Regression: --title was placed above the canvas and never seen."""
    import io

    mesh = translational_mesh()
    plain = mpimg.imread(io.BytesIO(render(mesh, size=(640, 480))))
    titled = mpimg.imread(io.BytesIO(render(mesh, size=(640, 480), title="Translational")))
    band = slice(0, int(0.07 * 480))
    assert np.all(plain[band, :, :3] > 0.95)                 # nothing at the top without a title
    assert np.any(titled[band, :, :3] < 0.3)                 # dark title text there with one


def test_generator_and_edge_switches():
    from ruledmesh.render import MIN_GENERATOR_SPACING, _generator_subset, _switch

    mesh = translational_mesh(401, 3)                        # 401 generators
    width = 800
    auto = _generator_subset(mesh, "auto", width)
    room = width * 0.8 / MIN_GENERATOR_SPACING
    drawn = np.unique(mesh.member_id[np.isin(mesh.members, auto).all(axis=1)])
    assert 0 < len(drawn) <= room + 1 and len(auto) < len(mesh.members)
    assert len(_generator_subset(mesh, "on", width)) == len(mesh.members)
    assert len(_generator_subset(mesh, True, width)) == len(mesh.members)
    assert len(_generator_subset(mesh, "off", width)) == 0
    assert len(_generator_subset(translational_mesh(), "auto", width)) == \
        len(translational_mesh().members)                    # few generators: all drawn
    assert _switch("auto", "edges", True) and not _switch("off", "edges", True)
    with pytest.raises(ParameterError, match="edges"):
        render(mesh, edges="maybe")


def test_cli_render_edges_and_generators_options(tmp_path):
    save(tmp_path / "m.obj", translational_mesh())
    for extra in (["--edges", "off"], ["--edges", "on", "--generators", "off"], ["--no-generators"],
                  ["--title", "A title"]):
        out = tmp_path / "x.png"
        assert main(["render", str(tmp_path / "m.obj"), "-o", str(out), "-q",
                     "--size", "320x240", *extra]) == 0
        assert mpimg.imread(out).shape[:2] == (240, 320)


def _svg_texts(svg: bytes) -> list[str]:
    import xml.etree.ElementTree as ET

    root = ET.fromstring(svg)
    return [t.text for t in root.iter("{http://www.w3.org/2000/svg}text") if t.text]


def _labelled_svg(mesh, **options) -> list[str]:
    from matplotlib import rc_context

    # Text as <text> elements instead of glyph paths, so the SVG can be read back.
    with rc_context({"svg.fonttype": "none"}):
        return _svg_texts(render(mesh, fmt="svg", **options))


def test_labels_are_the_schedule_labels_of_every_visible_face():
    """A sheet seen from above: every face is visible and carries its panels.csv label."""
    from ruledmesh.fabricate.labels import panel_labels
    from ruledmesh.fabricate.panels import panel_table

    mesh = translational_mesh(5, 4)
    texts = _labelled_svg(mesh, labels="on", view=(90.0, -90.0))
    labels = [t for t in texts if t.startswith("P")]
    assert sorted(labels) == sorted(panel_labels(mesh.n_faces).tolist())
    assert sorted(labels) == sorted(panel_table(mesh)["label"].tolist())
    assert not any(t.startswith("P") for t in _labelled_svg(mesh, labels="off"))


def test_labels_of_hidden_faces_are_not_drawn():
    """Two squares one above the other, seen from above and from below."""
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    verts = np.r_[np.c_[sq, np.zeros(4)], np.c_[sq, np.ones(4)]]
    mesh = Mesh.from_faces(verts, np.array([[0, 1, 2, 3], [4, 5, 6, 7]]))
    top = [t for t in _labelled_svg(mesh, labels="on", view=(90.0, 0.0)) if t.startswith("P")]
    below = [t for t in _labelled_svg(mesh, labels="on", view=(-90.0, 0.0)) if t.startswith("P")]
    side = [t for t in _labelled_svg(mesh, labels="on", view=(0.0, 0.0)) if t.startswith("P")]
    assert top == ["P1"] and below == ["P0"] and sorted(side) == ["P0", "P1"]


def test_labels_auto_follows_face_size_and_cli_option(tmp_path):
    mesh = translational_mesh(5, 4)
    assert any(t.startswith("P") for t in _labelled_svg(mesh, labels="auto"))
    dense = translational_mesh(60, 40)
    assert not any(t.startswith("P") for t in _labelled_svg(dense, labels="auto"))
    save(tmp_path / "m.obj", mesh)
    assert main(["render", str(tmp_path / "m.obj"), "-o", str(tmp_path / "m.png"), "--labels", "on",
                 "-q"]) == 0
    assert mpimg.imread(tmp_path / "m.png").shape[:2] == (800, 1000)
    with pytest.raises(ParameterError, match="labels"):
        render(mesh, labels="sometimes")
