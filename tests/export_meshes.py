"""Test meshes for the export and triangulation tests (built here, not by the PQ mesher).

Test files import it as ``import export_meshes as E``: ``conftest.py`` makes the helper
modules of tests/ importable, since the tests run with ``--import-mode=importlib`` (the tests
folder is not on sys.path).
"""

from __future__ import annotations

import numpy as np

from ruledmesh.mesh import FaceKind, Mesh


def grid_quads(ni: int, nj: int) -> np.ndarray:
    """(ni-1)*(nj-1) quads of an ni x nj vertex grid (row-major), counter-clockwise in (i, j)."""
    i, j = np.meshgrid(np.arange(ni - 1), np.arange(nj - 1), indexing="ij")
    v = (i * nj + j).reshape(-1)
    return np.stack([v, v + nj, v + nj + 1, v + 1], axis=1)


def hp_translational(ni: int = 7, nj: int = 6, a: float = 0.4, b: float = 0.3,
                     offset=(0.0, 0.0, 0.0)) -> Mesh:
    """PQ mesh of the hyperbolic paraboloid z = a x^2 - b y^2: X[i, j] = p_i + q_j.

    Every face is a parallelogram (exactly planar up to rounding).  The grid
    rows are recorded as members (one id per row) to exercise member export.
    """
    u = np.linspace(-1.0, 1.0, ni)
    v = np.linspace(-0.8, 0.9, nj)
    p = np.stack([u, np.zeros_like(u), a * u * u], axis=1)
    q = np.stack([np.zeros_like(v), v, -b * v * v], axis=1)
    X = (p[:, None, :] + q[None, :, :]).reshape(-1, 3) + np.asarray(offset)
    idx = np.arange(ni * nj).reshape(ni, nj)
    members = np.stack([idx[:-1].reshape(-1), idx[1:].reshape(-1)], axis=1)
    member_id = np.broadcast_to(np.arange(nj), (ni - 1, nj)).reshape(-1)
    return Mesh.from_faces(X, grid_quads(ni, nj), members=members, member_id=member_id,
                           info={"construction": "hp-translational"})


def hyperboloid_point(a: float, c: float, phi: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Ruled parametrisation of x^2/a^2 + y^2/a^2 - z^2/c^2 = 1 by one regulus.

    The generator of angle ``phi`` passes through (a cos phi, a sin phi, 0)
    with direction (-a sin phi, a cos phi, c); ``s`` runs along it.
    """
    phi, s = np.broadcast_arrays(np.asarray(phi, float), np.asarray(s, float))
    return np.stack([a * (np.cos(phi) - s * np.sin(phi)), a * (np.sin(phi) + s * np.cos(phi)),
                     c * s], axis=-1)


def hyperboloid_pq(a: float = 1.0, c: float = 1.0, K: int = 12, L: int = 4,
                   h: float | None = None) -> Mesh:
    """The generator-checkerboard PQ mesh of the rotational hyperboloid (paper Fig. 7).

    The crossing of the generators of angles phi (one regulus) and psi (the
    other) is (a cos th / cos de, a sin th / cos de, c tan de) with
    th = (phi + psi) / 2, de = (phi - psi) / 2.  Taking every other crossing of
    generators spaced by 2h gives the grid th = k h, de = l h whose faces have
    both diagonals on generators: planar by construction.  Members are the
    segments of the phi-regulus generators (the 0-2 diagonals of the faces).
    """
    h = np.pi / 24 if h is None else h
    k = np.arange(K + 1)
    lv = np.arange(-L, L + 1)
    th, de = np.meshgrid(k * h, lv * h, indexing="ij")
    X = np.stack([a * np.cos(th) / np.cos(de), a * np.sin(th) / np.cos(de), c * np.tan(de)],
                 axis=-1).reshape(-1, 3)
    nj = lv.size
    quads = grid_quads(K + 1, nj)
    # Diagonal (k, l) -> (k+1, l+1) lies on the phi-generator phi = (k + l) h.
    idx = np.arange((K + 1) * nj).reshape(K + 1, nj)
    members = np.stack([idx[:-1, :-1].reshape(-1), idx[1:, 1:].reshape(-1)], axis=1)
    kk, ll = np.meshgrid(k[:-1], lv[:-1], indexing="ij")
    member_id = (kk + ll).reshape(-1) + L
    return Mesh.from_faces(X, quads, members=members, member_id=member_id,
                           info={"construction": "hyperboloid-checkerboard"})


def mixed(offset=(0.0, 0.0, 0.0)) -> Mesh:
    """Quads, border pentagons and a hexagon (corner cuts), fill triangles, and a
    concave planar 10-gon (a star cap): every FaceKind and valences 3-6 and 10."""
    base = hp_translational(offset=offset)
    V = [base.vertices]
    nv = base.n_vertices
    faces, kinds = [], []
    quads = base.padded_faces()
    for f, quad in enumerate(quads.tolist()):
        if f in (0, 7):
            # Cut corner 0 off: pentagon (BORDER) + triangle (FILL), both planar.
            p = base.vertices[quad]
            a = p[0] + 0.35 * (p[1] - p[0])
            b = p[0] + 0.6 * (p[3] - p[0])
            V.append(np.stack([a, b]))
            ia, ib = nv, nv + 1
            nv += 2
            faces += [[ia, quad[1], quad[2], quad[3], ib], [quad[0], ia, ib]]
            kinds += [FaceKind.BORDER, FaceKind.FILL]
        elif f == 12:
            # Two corners cut: hexagon.
            p = base.vertices[quad]
            cut = np.stack([p[0] + 0.3 * (p[1] - p[0]), p[1] + 0.5 * (p[2] - p[1]),
                            p[1] + 0.2 * (p[0] - p[1]), p[3] + 0.6 * (p[0] - p[3])])
            V.append(cut)
            c = list(range(nv, nv + 4))
            nv += 4
            faces.append([c[0], c[2], c[1], quad[2], quad[3], c[3]])
            kinds.append(FaceKind.BORDER)
        elif f == 20:
            # Split along the generator diagonal (SPLIT kind).
            faces += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
            kinds += [FaceKind.SPLIT, FaceKind.SPLIT]
        elif f == 21:
            faces += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
            kinds += [FaceKind.TRIANGLE, FaceKind.TRIANGLE]
        else:
            faces.append(quad)
            kinds.append(FaceKind.QUAD)
    # A concave star cap in a tilted plane beside the grid.
    ang = np.arange(10) * 2 * np.pi / 10
    r = np.where(np.arange(10) % 2 == 0, 0.5, 0.2)
    star = np.stack([2.0 + r * np.cos(ang), r * np.sin(ang), 0.3 * r * np.cos(ang)], axis=1)
    V.append(star + np.asarray(offset))
    faces.append(list(range(nv, nv + 10)))
    kinds.append(FaceKind.POLYGON)
    return Mesh.from_faces(np.concatenate(V), faces, np.array(kinds, np.uint8),
                           members=base.members, member_id=base.member_id,
                           info={"construction": "mixed-test"})


def all_meshes() -> dict[str, Mesh]:
    """The meshes every format is tested with."""
    return {
        "hp": hp_translational(),
        "hyperboloid": hyperboloid_pq(),
        "mixed": mixed(),
        "far": mixed(offset=(412_345.0, 5_801_234.0, 37.0)),
    }
