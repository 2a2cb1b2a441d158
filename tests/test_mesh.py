"""The Mesh type: compressed-row faces, kinds, members."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ruledmesh import FaceKind, Mesh, ParameterError


@st.composite
def polygon_meshes(draw):
    nv = draw(st.integers(3, 30))
    faces = draw(st.lists(st.lists(st.integers(0, nv - 1), min_size=3, max_size=7, unique=True),
                          min_size=1, max_size=25))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    return Mesh.from_faces(rng.normal(size=(nv, 3)), faces), faces


@settings(max_examples=60, deadline=None)
@given(polygon_meshes())
def test_faces_edges_and_padding_agree_with_the_python_lists(case):
    mesh, faces = case
    assert mesh.face_list() == faces
    assert mesh.valences.tolist() == [len(f) for f in faces]
    brute = {tuple(sorted((f[k], f[(k + 1) % len(f)]))) for f in faces for k in range(len(f))}
    assert sorted(map(tuple, mesh.edges().tolist())) == sorted(brute)
    pad = mesh.padded_faces()
    for row, f in zip(pad.tolist(), faces):
        assert row[:len(f)] == f and all(x == -1 for x in row[len(f):])
    for k in range(3, 8):
        ids, arr = mesh.faces_of_valence(k)
        assert [faces[i] for i in ids] == arr.tolist()


def test_kinds_default_and_counts():
    v = np.eye(3).tolist() + [[1, 1, 1], [2, 0, 0]]
    mesh = Mesh.from_faces(v, [[0, 1, 2, 3], [0, 1, 4], [0, 2, 3, 4, 1]])
    assert mesh.count_kinds() == {"quad": 1, "polygon": 2}
    assert FaceKind.from_label("split") is FaceKind.SPLIT
    with pytest.raises(ParameterError, match="kind"):
        FaceKind.from_label("bowtie")


def test_validation_names_the_field():
    with pytest.raises(ParameterError, match="face_indices"):
        Mesh.from_faces(np.zeros((3, 3)), [[0, 1, 5]])
    with pytest.raises(ParameterError, match="face_offsets"):
        Mesh.from_arrays(np.zeros((3, 3)), [0, 2], [0, 1])
    with pytest.raises(ParameterError, match="vertices"):
        Mesh.from_faces([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])


def test_compact_merge_and_collapsed_corners():
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1, 0, 0], [9, 9, 9]], float)
    # vertex 4 duplicates vertex 1; vertex 5 is unused
    mesh = Mesh.from_faces(v, [[0, 1, 2, 3], [1, 4, 2]], members=[[0, 1], [1, 4]])
    assert mesh.compact().n_vertices == 5
    merged = mesh.merge_vertices(1e-12).drop_repeated_corners()
    assert merged.n_faces == 1 and merged.face_list() == [[0, 1, 2, 3]]
    assert merged.members.tolist() == [[0, 1]]            # the collapsed member is gone
    assert merged.euler_characteristic() == 1


def test_concatenate_offsets_vertices_and_members():
    a = Mesh.from_faces(np.eye(3), [[0, 1, 2]], members=[[0, 1]])
    b = Mesh.from_faces(np.eye(3) + 5, [[2, 1, 0]], members=[[1, 2]])
    both = Mesh.concatenate([a, b])
    assert both.face_list() == [[0, 1, 2], [5, 4, 3]]
    assert both.members.tolist() == [[0, 1], [4, 5]]


def test_derived_arrays_are_read_only_shared_and_not_pickled():
    """The valences are computed once per offsets array: a mesh made from another with the
    same offsets (a pass changing corners only) reuses them; they are read-only, and a
    copied mesh (copy and pickle, as the designer's worker sends meshes, take the same
    state) does not carry them."""
    import copy
    from dataclasses import replace

    mesh = Mesh.from_faces(np.random.default_rng(1).random((6, 3)), [[0, 1, 2, 3], [1, 2, 4], [2, 5, 4]])
    assert mesh.face_of.tolist() == [0, 0, 0, 0, 1, 1, 1, 2, 2, 2]
    assert mesh.next_corners().tolist() == [1, 2, 3, 0, 5, 6, 4, 8, 9, 7]
    valences = mesh.valences
    with pytest.raises(ValueError):
        valences[0] = 5
    same_sizes = replace(mesh, face_indices=mesh.face_indices[::-1].copy())
    assert same_sizes.valences is valences
    resized = replace(mesh, face_offsets=np.array([0, 3, 7, 10]))
    assert resized.valences.tolist() == [3, 4, 3]
    assert resized.face_of.tolist() == [0, 0, 0, 1, 1, 1, 1, 2, 2, 2]
    back = copy.deepcopy(mesh)
    assert "_cache" not in back.__dict__
    assert back.valences.tolist() == valences.tolist()
