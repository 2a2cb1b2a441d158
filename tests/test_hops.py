"""The Hops server over HTTP: metadata, solves decoded with rhino3dm, and the attacks it refuses."""

import http.client
import json
import os
import socket
import subprocess
import sys
import threading
import time
import tomllib
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ruledmesh

r3 = pytest.importorskip("rhino3dm")

from ruledmesh.hops.server import KEY_HEADER, MAX_BODY, make_server  # noqa: E402 - needs rhino3dm

ROOT = Path(__file__).resolve().parents[1]
SKEW = tomllib.loads((ROOT / "examples" / "skew.toml").read_text())


@pytest.fixture(scope="module")
def server():
    srv = make_server("127.0.0.1", 0)
    thread = threading.Thread(target=srv.serve_forever, daemon=True)
    thread.start()
    yield srv
    srv.shutdown()
    srv.server_close()
    thread.join(5)


def _tree(kind, values):
    return {"{0}": [{"type": kind, "data": json.dumps(v)} for v in values]}


def _skew_curves():
    """The director curves of examples/skew.toml as Rhino curves (same geometry, exactly)."""
    c1 = SKEW["curves"]["c1"]
    c2 = SKEW["curves"]["c2"]
    a = r3.NurbsCurve.Create(False, c1["degree"], [r3.Point3d(*p) for p in c1["points"]])
    b = r3.PolylineCurve([r3.Point3d(*p) for p in c2["points"]])
    return a, b


def _payload(values, pointer=None):
    body = {"values": [{"ParamName": name, "InnerTree": tree} for name, tree in values.items()]}
    if pointer:
        body["pointer"] = pointer
    return body


def _skew_inputs():
    a, b = _skew_curves()
    return {"Curve A": _tree("Rhino.Geometry.NurbsCurve", [a.Encode()]),
            "Curve B": _tree("Rhino.Geometry.PolylineCurve", [b.Encode()]),
            "Count": _tree("System.Int32", [SKEW["rulings"]["count"]]),
            "Rows": _tree("System.Int32", [SKEW["mesh"]["rows"]])}


def _post(srv, route, body, key=True, headers=None):
    data = json.dumps(body).encode() if not isinstance(body, bytes) else body
    head = {"Content-Type": "application/json", **(headers or {})}
    if key:
        head[KEY_HEADER] = srv.key
    conn = http.client.HTTPConnection("127.0.0.1", srv.server_address[1], timeout=60)
    conn.request("POST", route, data, head)
    res = conn.getresponse()
    out = res.status, json.loads(res.read() or b"null")
    conn.close()
    return out


def _get(srv, route, headers=None):
    conn = http.client.HTTPConnection("127.0.0.1", srv.server_address[1], timeout=60)
    conn.request("GET", route, headers=headers or {})
    res = conn.getresponse()
    out = res.status, res.getheader("Content-Type"), json.loads(res.read())
    conn.close()
    return out


def _values(result):
    return {v["ParamName"]: [json.loads(i["data"]) for i in v["InnerTree"]["{0}"]]
            for v in result["values"]}


def _decode_mesh(encoded):
    mesh = r3.CommonObject.Decode(encoded)
    assert isinstance(mesh, r3.Mesh)
    return mesh


def _vertices(rmesh):
    # Point3dAt: the double-precision vertices (indexing gives the float32 copies).
    points = (rmesh.Vertices.Point3dAt(i) for i in range(len(rmesh.Vertices)))
    return np.array([[p.X, p.Y, p.Z] for p in points])


def test_metadata_of_ruled_pq(server):
    status, ctype, meta = _get(server, "/ruled_pq")
    assert status == 200 and "json" in ctype  # Hops tells a server from a file by the media type
    inputs = {p["Name"]: p for p in meta["Inputs"]}
    assert list(inputs)[:4] == ["Curve A", "Curve B", "Count", "Rows"]
    assert inputs["Curve A"]["ParamType"] == "Curve" and inputs["Count"]["ParamType"] == "Integer"
    assert inputs["Rows"]["Default"] == 40 and inputs["Distribution"]["Default"] == "arc-length"
    assert {"Primary", "Option", "Tolerance"} <= set(inputs)
    outputs = [p["Name"] for p in meta["Outputs"]]
    assert outputs == ["Mesh", "Generators", "Kinds", "Planarity", "Quad share", "Report"]
    assert meta["Uri"] == "/ruled_pq"
    status, _, listing = _get(server, "/")
    assert status == 200 and {"ruled_pq", "ruled_lines", "hybrid_lines", "design",
                              "hyperboloid"} <= {c["Name"] for c in listing}
    assert _get(server, "/nothing")[0] == 404


@pytest.mark.parametrize("route", ["/solve", "/ruled_pq"])
def test_solve_matches_the_design_file(server, route):
    pointer = f"{server.url}/ruled_pq" if route == "/solve" else None
    status, result = _post(server, route, _payload(_skew_inputs(), pointer))
    assert status == 200 and result["errors"] == [], result["errors"]
    out = _values(result)
    rmesh = _decode_mesh(out["Mesh"][0])
    built = ruledmesh.build_full(ROOT / "examples" / "skew.toml")
    kinds = built.mesh.count_kinds()
    assert rmesh.Faces.QuadCount == int(np.count_nonzero(built.mesh.valences == 4)) > 0
    # The same vertices as the design file's mesh: the NURBS curve was taken exactly.
    v = _vertices(rmesh)
    ref = built.mesh.vertices
    assert v.shape == ref.shape
    assert np.abs(np.sort(v, axis=0) - np.sort(ref, axis=0)).max() <= 1e-12 * built.mesh.diagonal()
    assert out["Kinds"].count("quad") == kinds["quad"]
    assert len(out["Kinds"]) == rmesh.Faces.Count
    lines = np.array([[[g["From"][k] for k in "XYZ"], [g["To"][k] for k in "XYZ"]]
                      for g in out["Generators"]])
    assert np.allclose(lines[:, 0], built.rulings.a, atol=1e-12)
    assert np.allclose(lines[:, 1], built.rulings.b, atol=1e-12)
    assert out["Planarity"][0] <= 1e-12
    assert 0.5 < out["Quad share"][0] <= 1
    report = json.loads(out["Report"][0])
    assert report["kinds"] == kinds


def test_rational_arc_is_exact_and_other_rational_curves_are_followed(server):
    arc = r3.NurbsCurve.CreateFromArc(r3.Arc(r3.Point3d(0, 0, 0), r3.Point3d(2, 2, 0),
                                             r3.Point3d(4, 0, 0)))
    assert arc.IsRational
    line = r3.LineCurve(r3.Point3d(0, 0, 3), r3.Point3d(4, 0, 3))
    inputs = {"Curve A": _tree("Rhino.Geometry.NurbsCurve", [arc.Encode()]),
              "Curve B": _tree("Rhino.Geometry.LineCurve", [line.Encode()]),
              "Count": _tree("System.Int32", [9]), "Rows": _tree("System.Int32", [8])}
    status, result = _post(server, "/ruled_pq", _payload(inputs))
    assert status == 200 and result["errors"] == []
    ends = np.array([[g["From"][k] for k in "XYZ"] for g in _values(result)["Generators"]])
    # Every generator starts on the circle of radius 2 about (2, 0, 0): the arc was not sampled.
    assert np.abs(np.linalg.norm(ends - [2, 0, 0], axis=1) - 2).max() < 1e-12
    assert not any("followed" in w for w in result["warnings"])
    conic = r3.NurbsCurve(3, True, 3, 3)  # a rational quadratic that is not a circle
    for i, (x, y, w) in enumerate([(0, 0, 1), (2, 2, 0.3), (4, 0, 1)]):
        conic.Points[i] = r3.Point4d(x * w, y * w, 0, w)
    for i, k in enumerate([0, 0, 1, 1]):
        conic.Knots[i] = k
    high = r3.NurbsCurve.Create(False, 7, [r3.Point3d(i, (i % 3) * 0.5, 0) for i in range(8)])
    for curve in (conic, high):
        inputs["Curve A"] = _tree("Rhino.Geometry.NurbsCurve", [curve.Encode()])
        status, result = _post(server, "/ruled_pq", _payload(inputs))
        assert status == 200 and result["errors"] == [], result["errors"]
        assert any("Curve A" in w and "followed" in w for w in result["warnings"])
        ends = np.array([[g["From"][k] for k in "XYZ"] for g in _values(result)["Generators"]])
        # The stand-in passes through points of the Rhino curve: its ends are the curve's ends.
        start, end = curve.PointAtStart, curve.PointAtEnd
        assert np.allclose(ends[[0, -1]], [[start.X, start.Y, start.Z], [end.X, end.Y, end.Z]],
                           atol=1e-12)
        middle = curve.PointAt(0.5 * (curve.Domain.T0 + curve.Domain.T1))
        gap = np.linalg.norm(ends - [middle.X, middle.Y, middle.Z], axis=1).min()
        assert gap < 0.5  # a generator near the middle of the curve (9 generators)


def test_explicit_lines_and_hybrid(server):
    text = (ROOT / "examples" / "lines-hyperboloid.toml").read_text()
    lines = tomllib.loads(text)["rulings"]["lines"]
    structs = [{"From": dict(zip("XYZ", p)), "To": dict(zip("XYZ", q))} for p, q in lines]
    status, result = _post(server, "/ruled_lines", _payload({
        "Lines": _tree("Rhino.Geometry.Line", structs), "Rows": _tree("System.Int32", [12])}))
    assert status == 200 and result["errors"] == []
    rmesh = _decode_mesh(_values(result)["Mesh"][0])
    same = ruledmesh.build({"rulings": {"lines": lines}, "mesh": {"rows": 12}})
    assert rmesh.Faces.QuadCount == int(np.count_nonzero(same.valences == 4)) > 0
    assert np.array_equal(np.sort(_vertices(rmesh), axis=0), np.sort(same.vertices, axis=0))
    status, result = _post(server, "/hybrid_lines", _payload({
        "Lines": _tree("Rhino.Geometry.Line", structs), "Divisions": _tree("System.Int32", [4])}))
    assert status == 200 and result["errors"] == []
    out = _values(result)
    assert "triangle" in out["Kinds"] and _decode_mesh(out["Mesh"][0]).Faces.QuadCount > 0


def test_catalogue_components_and_the_design_component(server):
    status, result = _post(server, "/hyperboloid", _payload({"U": _tree("System.Int32", [16])}))
    assert status == 200 and result["errors"] == []
    x, y, z = _vertices(_decode_mesh(_values(result)["Mesh"][0])).T
    assert np.abs(x**2 + y**2 - z**2 / 1.5**2 - 1).max() < 1e-9
    for name in ("hyperbolic_paraboloid", "helicoid"):
        status, result = _post(server, f"/{name}", _payload({}))
        assert status == 200 and result["errors"] == [], (name, result["errors"])
        assert _values(result)["Planarity"][0] < 1e-12
    text = (ROOT / "examples" / "fig5b-torus.toml").read_text()
    status, result = _post(server, "/design", _payload({"Design": _tree("System.String", [text])}))
    assert status == 200 and result["errors"] == []
    assert _decode_mesh(_values(result)["Mesh"][0]).Faces.QuadCount == 36 * 18


@pytest.mark.parametrize("inputs, expected", [
    ({"Count": [4.5]}, "Count: expected an integer"),
    ({"Count": [10**6], "Rows": [10**6]}, "memory"),
    ({"Distribution": ["director-plane"]}, "Distribution"),
    ({"Primary": ["first"]}, "Primary"),
    ({"Option": [7]}, "Option"),
])
def test_bad_inputs_are_one_error_naming_the_input(server, inputs, expected):
    values = _skew_inputs()
    for name, vals in inputs.items():
        values[name] = _tree("System.Int32" if name != "Distribution" else "System.String", vals)
    status, result = _post(server, "/ruled_pq", _payload(values))
    assert status == 200 and result["values"] == []
    (error,) = result["errors"]
    assert expected in error and "\n" not in error and "Traceback" not in error


def test_missing_curve_and_garbage_geometry(server):
    values = _skew_inputs()
    del values["Curve B"]
    status, result = _post(server, "/ruled_pq", _payload(values))
    assert status == 200 and "Curve B: missing" in result["errors"][0]
    values["Curve B"] = _tree("Rhino.Geometry.NurbsCurve", [{"version": 10000, "data": "AAAA"}])
    status, result = _post(server, "/ruled_pq", _payload(values))
    assert status == 200 and "Curve B: expected a curve" in result["errors"][0]


def test_solves_need_the_key(server):
    body = _payload(_skew_inputs())
    assert _post(server, "/ruled_pq", body, key=False)[0] == 401
    status, result = _post(server, "/ruled_pq", body, key=False, headers={KEY_HEADER: "x" * 32})
    assert status == 401 and "API key" in result["errors"][0]
    assert _post(server, "/solve", {**body, "pointer": "/ruled_pq"}, key=False)[0] == 401


def test_foreign_host_header_is_refused(server):
    # DNS rebinding: a web page's request names the attacker's host.
    assert _get(server, "/ruled_pq", headers={"Host": "evil.example:80"})[0] == 421
    status, _ = _post(server, "/ruled_pq", _payload(_skew_inputs()),
                      headers={"Host": "evil.example"})
    assert status == 421


def test_oversized_and_malformed_requests(server):
    port = server.server_address[1]
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        # Announce a huge body and send none: refused from the header, nothing read.
        sock.sendall(f"POST /ruled_pq HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n{KEY_HEADER}: "
                     f"{server.key}\r\nContent-Length: {MAX_BODY + 1}\r\n\r\n".encode())
        assert sock.recv(200).startswith(b"HTTP/1.0 413")
    assert _post(server, "/ruled_pq", b"{not json")[0] == 400
    assert _post(server, "/ruled_pq", b"[1, 2]")[0] == 400
    assert _post(server, "/solve", {"values": []})[0] == 404
    many = {"Lines": {"{0}": [{"type": "Rhino.Geometry.Line", "data": "{}"}] * 100_001}}
    status, result = _post(server, "/ruled_lines", _payload(many))
    assert status == 200 and "at most 100000 values" in result["errors"][0]


def test_designs_cannot_read_server_files(server, tmp_path):
    secret = tmp_path / "secret.csv"
    secret.write_text("0,0,0,1,1,1\n")
    text = f'[rulings]\nfile = "{secret}"\n[mesh]\nrows = 4\n'
    status, result = _post(server, "/design", _payload({"Design": _tree("System.String", [text])}))
    assert status == 200 and "cannot read files" in result["errors"][0]
    huge = '[surface]\nkind = "torus"\nR = 3.0\nr = 1.0\n[mesh]\nu = 1000000\nv = 1000000\n'
    status, result = _post(server, "/design", _payload({"Design": _tree("System.String", [huge])}))
    assert status == 200 and "budget" in result["errors"][0]


def _free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def test_ruledmesh_hops_command_serves_and_stops(tmp_path):
    port = _free_port()
    key = "k" * 24
    env = {**os.environ, "RULEDMESH_HOPS_KEY": key}
    proc = subprocess.Popen([sys.executable, "-m", "ruledmesh", "hops", "--port", str(port)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            cwd=tmp_path)
    try:
        first = proc.stdout.readline()
        assert f"http://127.0.0.1:{port}" in first and "ruled_pq" in first
        assert key not in proc.stdout.readline()  # a key from the environment is not echoed
        meta = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/ruled_pq", timeout=30))
        assert meta["Name"] == "ruled_pq"
        body = json.dumps(_payload(_skew_inputs(), f"http://127.0.0.1:{port}/ruled_pq")).encode()
        req = urllib.request.Request(f"http://127.0.0.1:{port}/solve", body,
                                     {"Content-Type": "application/json", KEY_HEADER: key})
        result = json.load(urllib.request.urlopen(req, timeout=120))
        assert result["errors"] == [] and _decode_mesh(_values(result)["Mesh"][0]).Faces.QuadCount
        proc.stdout.readline()  # "Ctrl+C to stop"
        assert proc.stdout.readline().startswith("ruled_pq: ok (")
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(10)
    time.sleep(0)  # nothing left listening
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), timeout=2).close()


def test_component_picture_is_drawn_from_the_metadata(server, tmp_path):
    pytest.importorskip("matplotlib")
    from ruledmesh.hops.picture import draw_component

    _, _, meta = _get(server, "/ruled_pq")
    out = tmp_path / "c.png"
    draw_component(meta, out, f"{server.url}/ruled_pq")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10_000


def _containers(inner):
    return st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)


_JSON = st.recursive(st.none() | st.booleans() | st.integers(-10**12, 10**12)
                     | st.floats(allow_nan=True) | st.text(max_size=20), _containers,
                     max_leaves=12)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(route=st.sampled_from(["/ruled_pq", "/ruled_lines", "/hybrid_lines", "/design",
                              "/helicoid"]),
       name=st.sampled_from(["Curve A", "Lines", "Count", "Rows", "Design", "U", "Flip", "x"]),
       kind=st.sampled_from(["System.Int32", "System.String", "Rhino.Geometry.Line",
                             "Rhino.Geometry.NurbsCurve", "nonsense"]),
       data=_JSON, raw=st.booleans())
def test_any_payload_gets_an_answer_never_an_internal_error(server, route, name, kind, data, raw):
    values = _skew_inputs() if route == "/ruled_pq" else {}
    item = {"type": kind, "data": data if raw else json.dumps(data)}
    values[name] = {"{0}": [item]}
    status, result = _post(server, route, _payload(values))
    assert status == 200, result
    assert isinstance(result["errors"], list)
