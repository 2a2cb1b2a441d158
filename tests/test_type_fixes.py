"""Regression tests for the defects the type checker found (each named after its defect)."""

from __future__ import annotations

import numpy as np
import pytest

from ruledmesh.analysis.triangles import compare_tessellations
from ruledmesh.design.rulings import from_csv
from ruledmesh.errors import DesignError, GeometryError, ParameterError
from ruledmesh.mesh import Mesh
from ruledmesh.surfaces import ImplicitSurface


def test_csv_not_utf8_names_the_decoding_error(tmp_path):
    # a UnicodeDecodeError has no strerror: reading it raised AttributeError
    bad = tmp_path / "latin1.csv"
    bad.write_bytes("x0,y0,z0,x1,y1,z1\n0,0,0,1,1,1 \xe9\n".encode("latin-1"))
    with pytest.raises(DesignError, match=r"latin1\.csv: cannot read the file: 'utf-8' codec"):
        from_csv(bad)


def test_compare_tessellations_of_a_faceless_mesh_is_refused():
    # mesh_triangle_quality returns None without faces; this unpacked it
    empty = Mesh.from_arrays(np.zeros((3, 3)), [0], np.zeros(0, dtype=np.int64))
    with pytest.raises(ParameterError, match="mesh: a mesh without faces"):
        compare_tessellations(empty, lambda u, t: np.zeros((np.size(u), 3)))


def test_implicit_surface_without_distance_or_value_says_so():
    # the Newton steps were called with None for the value and the gradient
    ref = ImplicitSurface("nothing", None, None)
    with pytest.raises(GeometryError, match="neither a distance nor a value and gradient"):
        ref.distance(np.zeros((2, 3)))


def test_planarity_of_quads_at_huge_coordinates_does_not_overflow():
    # products of squared diagonal lengths overflowed (RuntimeWarning) beyond ~1e77; found by
    # test_fuzz_malformed_values_in_examples on an elliptic paraboloid with a = 1.39e77
    from ruledmesh.analysis.faces import quad_diagonal_crossing, quad_planarity

    square = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.1]]], float)
    for size in (1.0, 1e-100, 1e77, 1e150):
        assert quad_planarity(square * size)[0] == pytest.approx(quad_planarity(square)[0], rel=1e-12)
        gap = quad_diagonal_crossing(square * size)[2][0]
        assert gap == pytest.approx(quad_diagonal_crossing(square)[2][0] * size, rel=1e-12)
