"""The designer in a real browser: Debian's chromium driven by Playwright.

The tests start the server themselves (a free port on 127.0.0.1) and use the
system chromium (never a downloaded one).  Skipped, with the reason, only
when ``/usr/bin/chromium`` or the ``playwright`` package is missing.
"""

from __future__ import annotations

import json
import math
import os
import re
import statistics
import subprocess
import sys
import threading
from pathlib import Path

import _shared  # a helper module of tests/ (see conftest.py)
import numpy as np
import pytest

from ruledmesh import io
from ruledmesh.analysis.report import analyze
from ruledmesh.design import build_design, parse_design
from ruledmesh.web.server import make_server
from ruledmesh.web.session import Session

CHROMIUM = "/usr/bin/chromium"
pytestmark = [
    pytest.mark.skipif(not os.path.exists(CHROMIUM),
                       reason=f"{CHROMIUM} is absent (apt-get install -y chromium)"),
]
sync_api = pytest.importorskip("playwright.sync_api",
                               reason="the playwright package is absent (pip install playwright)")

ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]

# The design's own 15 generators (no refinement): the tests pick faces by their size, their
# splinters and edits that keep the faces, which must not move whenever the refinement of
# the mesher does.
DESIGN = _shared.small_design(name="browser", count=15, rows=12) + "refine = false\n"

# Reads the WebGL canvas back through a 2-D canvas: a (h, w, 3) picture, downsampled.
PIXELS_JS = """([w, h]) => {
  const src = document.getElementById('canvas');
  const c = document.createElement('canvas');
  c.width = w; c.height = h;
  const g = c.getContext('2d');
  g.drawImage(src, 0, 0, w, h);
  return Array.from(g.getImageData(0, 0, w, h).data);
}"""


# What a designer's build worker runs when a page opens (web.builder._warm_up on the
# default design), in a process of its own so that this one keeps numpy for small builds.
_WARM_UP = """
from ruledmesh.design import parse_design, build_design
from ruledmesh.web.builder import _warm_up
from ruledmesh.web.session import DEFAULT_DESIGN, frame_data
default = parse_design(DEFAULT_DESIGN)
_warm_up(lambda: frame_data(default.data, build_design(default)))
"""


@pytest.fixture(scope="module", autouse=True)
def compiled_kernels():
    """numba's on-disk cache filled before any page opens.  A page's first edit waits for its
    server's worker to load the kernels; on a fresh checkout (CI) that is compiling them,
    30-35 s, and the first tests' 20-s waits ran out when this file ran before any other
    had compiled them."""
    subprocess.run([sys.executable, "-c", _WARM_UP], check=True, timeout=600)


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    with sync_api.sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(
            str(tmp_path_factory.mktemp("chromium-profile")), executable_path=CHROMIUM,
            headless=True, args=ARGS, viewport={"width": 1280, "height": 800})
        yield ctx
        ctx.close()


@pytest.fixture
def designer(tmp_path):
    path = tmp_path / "browser.toml"
    path.write_text(DESIGN)
    server = make_server(Session(DESIGN, path), port=0)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield server
    server.shutdown()
    server.server_close()


@pytest.fixture
def page(browser, designer):
    pg = browser.new_page()
    errors = []
    pg.on("pageerror", lambda exc: errors.append(str(exc)))
    pg.goto(designer.url)
    pg.wait_for_selector("body[data-version]", timeout=20_000)
    yield pg
    pg.close()
    assert not errors, errors


def picture(pg) -> np.ndarray:
    pg.evaluate("() => new Promise(requestAnimationFrame)")
    data = pg.evaluate(PIXELS_JS, [160, 100])
    return np.array(data, dtype=np.uint8).reshape(100, 160, 4)[..., :3].astype(np.int16)


def start_cli(*args: str):
    """``ruledmesh design ARGS --no-browser`` in its own process; returns (process, url)."""
    proc = subprocess.Popen([sys.executable, "-m", "ruledmesh.cli", "design", *args, "--no-browser"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    match = re.search(r"http://\S+", line)
    if not match:
        proc.kill()
        raise AssertionError(f"no URL printed: {line!r} {proc.stderr.read()!r}")
    return proc, match.group(0)


def wait_version(pg, above: int) -> int:
    pg.wait_for_function(f"window.designer.version > {above}", timeout=20_000)
    return pg.evaluate("window.designer.version")


def test_page_loads_and_draws(page, designer):
    pic = picture(page)
    background = np.array([250, 250, 250])
    drawn = np.any(np.abs(pic - background) > 30, axis=2)
    assert 0.05 < drawn.mean() < 0.95                      # something drawn, not everything
    assert len({tuple(c) for c in pic.reshape(-1, 3)}) > 50  # shaded faces, lines, handles
    assert page.inner_text("[data-fig=faces]") == str(designer.session.built.mesh.n_faces)
    # the slow figures and the full report are computed on request, in the worker process
    assert page.inner_text("[data-fig=panels]") == "-"
    assert page.evaluate("window.designer.figuresVersion") is None
    page.click("#slow-figures")
    page.wait_for_function("document.querySelector('[data-fig=panels]').textContent.match(/^\\d+$/)",
                           timeout=60_000)
    # the report is ruledmesh analyze's, of the mesh drawn
    report = page.evaluate("window.designer.report")
    built = designer.session.built
    expected = analyze(built.mesh, reference=build_design(parse_design(
        designer.session.toml(), "browser.toml", Path(designer.session.base_dir))).reference,
        extras=built.extras)
    assert report["faces"] == expected["faces"] and report["kinds"] == expected["kinds"]
    assert report["planarity"]["max"] == pytest.approx(expected["planarity"]["max"], rel=1e-9)
    assert report["closeness"]["centroids_max"] == pytest.approx(
        expected["closeness"]["centroids_max"], rel=1e-6)
    page.click("#report-box summary")
    assert '"faces"' in page.inner_text("#report")


def undo(page, designer) -> None:
    """Click Undo and wait until the server took the step back and the page shows it.

    The page's version alone can also move on for the full mesh of the edit before
    (shown after its quick mesh when builds are slow), so the server's history is watched.
    """
    steps = len(designer.session.history()["undo"])
    v = page.evaluate("window.designer.version")
    page.click("#undo")
    assert server_reaches(lambda: len(designer.session.history()["undo"]) == steps - 1)
    wait_version(page, v)


def server_reaches(predicate, timeout=10.0) -> bool:
    """Poll the server-side state until ``predicate`` holds (edits are applied asynchronously)."""
    import time

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.02)
    return predicate()


def test_slider_changes_mesh_and_picture(page, designer):
    before = picture(page)
    v = page.evaluate("window.designer.version")
    slider = page.locator('input[type=range][data-path="rulings.count"]')
    slider.focus()
    for _ in range(4):
        page.keyboard.press("ArrowRight")
    v = wait_version(page, v)
    page.wait_for_function("document.querySelector('[data-path=\"rulings.count\"] input.val').value === '19'")
    # The field shows the value before the server has applied the last queued edit.
    assert server_reaches(lambda: designer.session.design["rulings"]["count"] == 19)
    page.wait_for_function(f"document.querySelector('[data-fig=faces]').textContent === "
                           f"'{designer.session.built.mesh.n_faces}'")
    after = picture(page)
    assert np.count_nonzero(np.abs(after - before).sum(axis=2) > 40) > 50
    # Presses made while an earlier one was building were merged (the newest value wins, no
    # build of a value already passed): 4 presses are 2 to 4 steps. Undo goes back one.
    history = designer.session.history()
    assert 2 <= len(history["undo"]) <= 4 and history["current"] == "rulings.count = 19"
    previous = int(history["undo"][-1].rsplit("= ", 1)[1])  # the step before the last
    assert 15 < previous < 19
    page.click("#undo")
    page.wait_for_function("document.querySelector('[data-path=\"rulings.count\"] input.val')"
                           f".value === '{previous}'")
    assert server_reaches(lambda: designer.session.design["rulings"]["count"] == previous)


def test_updates_compile_no_shaders_and_log_no_errors(page, designer):
    """Updates redraw the handles and the construction without compiling a shader again.

    The layers' old materials are freed after the new ones are drawn: freed first, three
    deleted the shader programs and compiled them again on every update (tens of
    milliseconds each in a software renderer).  The buffers' bounding spheres are finite
    (a NaN one made three log an error on every update).
    """
    logged = []
    page.on("console", lambda m: logged.append(m.text) if m.type == "error" else None)
    slider = page.locator('input[type=range][data-path="mesh.rows"]')
    slider.focus()
    page.keyboard.press("ArrowRight")
    v = wait_version(page, page.evaluate("window.designer.version"))
    page.evaluate("() => new Promise(requestAnimationFrame)")
    programs = page.evaluate("window.designer.programs()")
    kept = dict(page.evaluate("window.designer.kept"))
    for rows in (14, 15, 16):
        page.keyboard.press("ArrowRight")
        v = wait_version(page, v)
        page.wait_for_function(f"window.designer.design().mesh.rows === {rows}")
        page.evaluate("() => new Promise(requestAnimationFrame)")
    # the construction was drawn again (the division of the primary generator has new rows)
    assert page.evaluate("window.designer.kept").get("construction", 0) < kept.get("construction", 0) + 3
    assert sorted(page.evaluate("window.designer.programs()")) == sorted(programs)
    assert not logged, logged


def test_dragging_a_control_point_changes_mesh_and_picture(page, designer):
    before = picture(page)
    mesh_before = designer.session.built.mesh
    handles = page.evaluate("window.designer.handles()")
    h = next(x for x in handles if x["label"] == "c2.points[2]")
    v = page.evaluate("window.designer.version")
    page.mouse.move(h["x"], h["y"])
    page.mouse.down()
    for k in range(1, 11):
        page.mouse.move(h["x"] + 6 * k, h["y"] - 8 * k)
    page.mouse.up()
    wait_version(page, v)
    page.wait_for_function("!window.designer.busy()")
    moved = designer.session.design["curves"]["c2"]["points"][2]
    assert np.linalg.norm(np.subtract(moved, [6, 3, 3])) > 0.3
    assert designer.session.built.mesh.vertices.shape != mesh_before.vertices.shape or \
        not np.allclose(designer.session.built.mesh.vertices, mesh_before.vertices)
    after = picture(page)
    assert np.count_nonzero(np.abs(after - before).sum(axis=2) > 40) > 50
    # one drag is one undo step
    page.click("#undo")
    page.wait_for_function("document.querySelector('#undo').disabled")
    assert designer.session.design["curves"]["c2"]["points"][2] == [6, 3, 3]


def test_bad_edit_shows_error_and_keeps_design(page, designer):
    field = page.locator('[data-path="rulings.count"] input.val')
    field.fill("1")
    field.press("Enter")
    page.wait_for_selector("#error:not([hidden])")
    assert "rulings.count" in page.inner_text("#error")
    assert designer.session.design["rulings"]["count"] == 15
    page.wait_for_function("document.querySelector('[data-path=\"rulings.count\"] input.val').value === '15'")


def test_export_writes_a_file_the_core_reads(page, designer, tmp_path):
    for ext in (".obj", ".ply", ".json"):
        page.select_option("#export-format", ext)
        page.click("#export")
        page.wait_for_function(f"document.querySelector('#status').textContent.endsWith('{ext}')")
        path = tmp_path / f"browser{ext}"
        assert page.inner_text("#status") == f"wrote {path}"
        back = io.load(path)
        mesh = designer.session.built.mesh
        assert back.n_faces == mesh.n_faces
        np.testing.assert_allclose(back.vertices, mesh.vertices, atol=1e-9 * mesh.diagonal())


def test_saved_design_rebuilds_the_same_mesh(page, designer, tmp_path):
    slider = page.locator('input[type=range][data-path="mesh.rows"]')
    v = page.evaluate("window.designer.version")
    slider.focus()
    page.keyboard.press("ArrowLeft")
    wait_version(page, v)
    page.fill("#save-path", "saved.toml")
    page.click("#save")
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('saved')")
    path = tmp_path / "saved.toml"
    rebuilt = build_design(parse_design(path.read_text(), path.name, tmp_path))
    mesh = designer.session.built.mesh
    assert designer.session.design["mesh"]["rows"] == 11
    assert np.array_equal(rebuilt.mesh.vertices, mesh.vertices)
    assert np.array_equal(rebuilt.mesh.face_indices, mesh.face_indices)


def wait_frame(pg, count: int) -> dict:
    """The page's record of the next slider-to-frame measurement after ``count`` of them."""
    pg.wait_for_function(f"window.designer.frameLog.length > {count}", timeout=60_000)
    return pg.evaluate(f"window.designer.frameLog[{count}]")


DRAWN_JS = """() => {
  const d = window.designer.drawn();
  return {version: window.designer.version, design: window.designer.design(), ...d};
}"""


def test_update_latency_100_by_100(browser, tmp_path):
    """Slider step to the next frame for a 100 x 100 mesh: measured and printed, not asserted.

    The server runs as a user starts it (``ruledmesh design``, its own process).  The
    time runs from the input event to the animation frame after the new state was
    written into the buffers (the page's performance marks).  Two kinds of step: the
    rows slider, each step a new value (new faces: the face arrays travel), and typed
    coordinates of a control point (the faces usually stay: only the vertices travel,
    written into the buffers in place).  What is asserted is that each measured frame
    shows what was asked for: the design with the new value and the mesh built from it.
    """
    design = tmp_path / "big.toml"
    text = DESIGN.replace("count = 15", "count = 101").replace("rows = 12", "rows = 100")
    design.write_text(text)
    proc, url = start_cli(str(design))
    pg = browser.new_page()
    drawn = []
    try:
        pg.goto(url)
        pg.wait_for_selector("body[data-version]", timeout=30_000)
        pg.wait_for_function("window.designer.live && window.designer.liveFrames > 0")
        slider = pg.locator('input[type=range][data-path="mesh.rows"]')
        slider.focus()
        count = pg.evaluate("window.designer.frameLog.length")
        for _ in range(12):  # 101, 102, ...: each a new design (none answered from the cache)
            pg.keyboard.press("ArrowRight")
            wait_frame(pg, count)
            count += 1
            pg.wait_for_timeout(100)
            drawn.append(pg.evaluate(DRAWN_JS))
        steps = pg.evaluate("window.designer.breakdown.slice(-12)")
        frames = pg.evaluate("window.designer.frameTimes.slice(-12)")
        faces = int(pg.inner_text("[data-fig=faces]"))
        # typed coordinates of a control point
        h = next(x for x in pg.evaluate("window.designer.handles()") if x["label"] == "c2.points[2]")
        pg.mouse.click(h["x"], h["y"])
        pg.wait_for_function("window.designer.selection().length === 1")
        same0 = pg.evaluate("window.designer.sameTopology")
        reused = []
        for k in range(12):
            pg.fill("#sel-z", str(3 + 0.01 * (k + 1)))
            pg.press("#sel-z", "Enter")
            wait_frame(pg, count)
            count += 1
            pg.wait_for_timeout(100)
            reused.append(pg.evaluate("window.designer.reused"))
            drawn.append(pg.evaluate(DRAWN_JS))
        moves = pg.evaluate("window.designer.frameTimes.slice(-12)")
        move_steps = pg.evaluate("window.designer.breakdown.slice(-12)")
        same = pg.evaluate("window.designer.sameTopology") - same0
        kept = pg.evaluate("window.designer.kept")
        # the page alone: the last answer decoded and drawn again, to the next frame
        replays = [pg.evaluate("window.designer.replay()") for _ in range(12)]
        draws = pg.evaluate("window.designer.drawTimes")
        # one render of the scene to its last pixel (a pixel read back waits for it)
        render = pg.evaluate("window.designer.renderMs(5)")
    finally:
        pg.close()
        proc.terminate()
        proc.wait(timeout=30)
    load = os.getloadavg()[0]

    def med(rows, key):
        return statistics.median(r[key] for r in rows)

    print(f"\n100 x 100 ({faces} faces), input to frame: rows slider median "
          f"{statistics.median(frames):.0f} ms (server {med(steps, 'server'):.0f} ms, page "
          f"{med(steps, 'page'):.0f} ms, min {min(frames):.0f} ms); control point typed: median "
          f"{statistics.median(moves):.0f} ms (server {med(move_steps, 'server'):.0f} ms, page "
          f"{med(move_steps, 'page'):.0f} ms, min {min(moves):.0f} ms, buffers reused "
          f"{sum(reused)}/{len(reused)}, frames without the faces {same}, layers kept {kept}); "
          f"page alone (decode, draw, frame): median {statistics.median(replays):.0f} ms, "
          f"min {min(replays):.0f} ms (last: " + ", ".join(f"{k} {v:.0f}" for k, v in draws.items())
          + f" ms); one render to the last pixel {render:.0f} ms; server done to frame arrived: "
          f"median {statistics.median(r['arrived'] - r['server'] for r in steps + move_steps):.0f} ms"
          f"; load {load:.1f}")
    assert faces > 5000 and len(frames) == 12 and len(moves) == 12
    # Each measured frame shows the value asked for: its design has it, and what is drawn is
    # the mesh ruledmesh builds from that design (face count, triangles, vertices).
    for k, state in enumerate(drawn):
        if k < 12:
            assert state["design"]["mesh"]["rows"] == 101 + k
        else:
            assert state["design"]["curves"]["c2"]["points"][2][2] == pytest.approx(3 + 0.01 * (k - 11))
        mesh = build_design(parse_design(_toml(state["design"]), "big.toml", tmp_path)).mesh
        assert state["faces"] == mesh.n_faces
        assert state["triangles"] == int(np.maximum(mesh.valences - 2, 0).sum())
        assert state["vertices"] == mesh.n_vertices
        assert state["vertexSum"] == pytest.approx(float(mesh.vertices.astype(np.float32).sum()),
                                                   rel=1e-5)


def test_fast_slider_input_builds_only_the_newest_value(browser, tmp_path):
    """Ten key presses on the rows slider of a slow design: the newest value wins.

    Presses made while a build runs replace each other in the page's queue, so the
    server builds far fewer designs than there were presses (no backlog of values
    already passed), and the last frame shows the last value.
    """
    server = serve_text(DESIGN.replace("count = 15", "count = 101").replace("rows = 12", "rows = 100"),
                        tmp_path / "big.toml")
    pg = browser.new_page()
    try:
        pg.goto(server.url)
        pg.wait_for_selector("body[data-version]", timeout=30_000)
        pg.wait_for_function("window.designer.live && window.designer.liveFrames > 0")
        builder = server.session._builder
        before = builder.builds
        pg.locator('input[type=range][data-path="mesh.rows"]').focus()
        for _ in range(10):
            pg.keyboard.press("ArrowRight")
        pg.wait_for_function("!window.designer.busy() && window.designer.design().mesh.rows === 110",
                             timeout=60_000)
        pg.wait_for_timeout(200)
        built = builder.builds - before
        assert server.session.design["mesh"]["rows"] == 110
        assert 1 <= built < 10, built
        state = pg.evaluate(DRAWN_JS)
        mesh = server.session.built.mesh
        assert state["faces"] == mesh.n_faces and state["vertices"] == mesh.n_vertices
        assert state["vertexSum"] == pytest.approx(float(mesh.vertices.astype(np.float32).sum()),
                                                   rel=1e-5)
        print(f"\n10 presses, {built} builds")
    finally:
        pg.close()
        server.shutdown()
        server.server_close()


def _toml(design: dict) -> str:
    from ruledmesh.web.toml_writer import dumps

    return dumps(design)


# ---------------------------------------------------------------- token and files in the page
def test_page_without_the_token_says_where_to_find_it(browser, designer):
    pg = browser.new_page()
    try:
        pg.goto(designer.base_url)
        pg.wait_for_selector("#error:not([hidden])")
        assert "?token=" in pg.inner_text("#error")
        assert designer.session.version == 0
    finally:
        pg.close()


def test_save_asks_before_replacing_a_file_it_did_not_open(page, designer, tmp_path):
    other = tmp_path / "other.toml"
    other.write_text("# the user's own file\n")
    page.fill("#save-path", "other.toml")
    dialogs = []

    def dismiss(dialog):
        dialogs.append(dialog.message)
        dialog.dismiss()

    page.on("dialog", dismiss)
    page.click("#save")
    page.wait_for_selector("#error:not([hidden])")
    assert "confirm" in page.inner_text("#error") and "other.toml" in dialogs[0]
    assert other.read_text() == "# the user's own file\n"
    page.remove_listener("dialog", dismiss)
    page.once("dialog", lambda dialog: dialog.accept())
    page.click("#save")
    page.wait_for_function("document.querySelector('#status').textContent.startsWith('saved')")
    rebuilt = build_design(parse_design(other.read_text(), other.name, tmp_path))
    assert rebuilt.mesh.n_faces == designer.session.built.mesh.n_faces


def test_download_sends_the_token(page, designer):
    page.select_option("#export-format", ".obj")
    with page.expect_download() as info:
        page.click("#download")
    download = info.value
    assert download.suggested_filename == "browser.obj"
    text = Path(download.path()).read_text()
    assert sum(line.startswith("f ") for line in text.splitlines()) == \
        designer.session.built.mesh.n_faces


# ---------------------------------------------------------------- attacks from another page
ATTACK_PAGE = """<!doctype html><html><body>
<iframe name="f1"></iframe><iframe name="f2"></iframe><iframe name="f3"></iframe>
<script>
const target = %(target)s;
const requests = %(requests)s;   // [path, body] pairs, each body a smuggled request
let pending = 0;
function done() { if (--pending === 0) document.title = 'done'; }
requests.forEach(([path, body], k) => {
  // 1. an auto-submitted HTML form (text/plain: the body is "name=value")
  if (k < 3) {
    const form = document.createElement('form');
    form.method = 'POST'; form.action = target + path; form.enctype = 'text/plain';
    form.target = 'f' + (k + 1);
    const cut = body.lastIndexOf('=');
    const input = document.createElement('input');
    input.name = body.slice(0, cut); input.value = body.slice(cut + 1);
    form.append(input);
    document.body.append(form);
    pending++;
    document.getElementsByName('f' + (k + 1))[0].onload = done;
    form.submit();
  }
  // 2. a no-cors text/plain fetch (no preflight) with the same body
  pending++;
  fetch(target + path, { method: 'POST', mode: 'no-cors', body,
                         headers: { 'Content-Type': 'text/plain' } }).then(done, done);
});
</script></body></html>"""


def smuggled_body(port: int, token: str, path: str, payload: dict) -> str:
    """A complete API request (with the right token, as if stolen) carried in a body.

    It ends in ``"x": "="}`` so that a form's ``name=value`` encoding reproduces it.
    """
    data = json.dumps({**payload, "x": "="})
    return (f"POST {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nAuthorization: Bearer {token}\r\n"
            f"Content-Type: application/json\r\nContent-Length: {len(data)}\r\n\r\n{data}")


def test_cross_origin_form_and_no_cors_fetch_change_nothing(browser, designer, tmp_path,
                                                             tmp_path_factory):
    import http.server

    outside = tmp_path_factory.mktemp("outside")
    port = designer.server_address[1]
    token = designer.token
    requests = [
        ["/api/edit", smuggled_body(port, token, "/api/edit",
                                    {"changes": [[["mesh", "rows"], 3]]})],
        ["/api/save", smuggled_body(port, token, "/api/save",
                                    {"path": str(outside / "evil.toml")})],
        ["/api/export", smuggled_body(port, token, "/api/export",
                                      {"format": ".obj", "path": str(outside / "evil.obj")})],
        ["/api/save", smuggled_body(port, token, "/api/save", {"path": "browser.toml"})],
        ["/api/edit", json.dumps({"changes": [[["mesh", "rows"], 3]]})],
        ["/api/export", json.dumps({"format": ".obj"})],
    ]
    html = ATTACK_PAGE % {"target": json.dumps(f"http://127.0.0.1:{port}"),
                          "requests": json.dumps(requests)}

    class Attacker(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            body = html.encode()
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    evil = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Attacker)
    threading.Thread(target=evil.serve_forever, daemon=True).start()
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    pg = browser.new_page()
    try:
        pg.goto(f"http://127.0.0.1:{evil.server_address[1]}/")
        pg.wait_for_function("document.title === 'done'", timeout=30_000)
        # the forms reached the designer and were refused (what the frames show)
        answers = [f.content() for f in pg.frames[1:]]
        assert len(answers) == 3 and all("refused" in a for a in answers), answers
    finally:
        pg.close()
        evil.shutdown()
        evil.server_close()
    assert designer.session.version == 0 and designer.session.design["mesh"]["rows"] == 12
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    assert list(outside.iterdir()) == []


# ---------------------------------------------------------------- the designer as a tool
SHOTS = Path(os.environ.get("RULEDMESH_SHOTS", "")) if os.environ.get("RULEDMESH_SHOTS") else None


def shot(pg, name: str) -> None:
    """Save a screenshot for a person to look at (``RULEDMESH_SHOTS=folder``)."""
    if SHOTS is not None:
        SHOTS.mkdir(parents=True, exist_ok=True)
        pg.evaluate("() => new Promise(requestAnimationFrame)")
        pg.screenshot(path=str(SHOTS / f"{name}.png"))


def set_field(pg, path: str, value) -> None:
    v = pg.evaluate("window.designer.version")
    field = pg.locator(f'[data-path="{path}"] input.val')
    field.fill(str(value))
    field.press("Enter")
    wait_version(pg, v)
    pg.wait_for_function("!window.designer.busy()")


def click_handle(pg, label: str, shift: bool = False) -> None:
    h = next(x for x in pg.evaluate("window.designer.handles()") if x["label"] == label)
    if shift:
        pg.keyboard.down("Shift")
    pg.mouse.click(h["x"], h["y"])
    if shift:
        pg.keyboard.up("Shift")


def test_quads_edges_generators_and_colourings_with_figures(page, designer):
    from ruledmesh.fabricate import panel_table

    mesh = designer.session.built.mesh
    # face edges are their own layer, exactly the mesh's edges; generators a dashed layer,
    # on while there are few of them
    n_edges = page.evaluate("window.designer.edgeCount()")
    assert n_edges == len(mesh.edges())
    assert page.evaluate("window.designer.layer('generators')")
    assert page.evaluate("window.designer.generatorsDashed()")
    # planarity: the legend counts the faces over the tolerance from the same figures
    legend = page.evaluate("window.designer.legend")
    from ruledmesh.analysis.planar import face_planarity
    plan = face_planarity(mesh)
    tol = 1e-12  # the default planarity tolerance (ruledmesh.tolerances)
    assert legend["over"] == int(np.count_nonzero(plan.astype(np.float32) > tol))
    assert legend["max"] == pytest.approx(float(plan.max()), rel=1e-5, abs=1e-30)
    assert "tolerance 1e-12" in page.inner_text("#legend")
    assert page.locator("#legend .mark").count() == 1
    shot(page, "colour-planarity")
    # kind: counts per kind
    page.select_option("#colour", "kind")
    text = page.inner_text("#legend")
    for kind, n in mesh.count_kinds().items():
        if n:
            assert f"{kind} {n}" in text, (kind, n, text)
    shot(page, "colour-kind")
    # panel size: the legend's range is the schedule's area range
    page.select_option("#colour", "area")
    legend = page.evaluate("window.designer.legend")
    areas = panel_table(mesh)["area"]
    assert legend["min"] == pytest.approx(abs(areas).min(), rel=1e-4)
    assert legend["max"] == pytest.approx(abs(areas).max(), rel=1e-4)
    shot(page, "colour-area")
    # congruence classes arrive with the slow figures
    page.select_option("#colour", "class")
    page.wait_for_function("window.designer.legend && window.designer.legend.classes > 0",
                           timeout=60_000)
    assert page.evaluate("window.designer.legend.classes") == int(page.inner_text("[data-fig=panels]"))
    shot(page, "colour-class")
    # labels on demand: the fabrication labels of the faces on screen
    page.check('[data-layer="labels"]')
    page.wait_for_function("window.designer.labels > 0")
    labels = page.locator("#labels span").all_inner_texts()
    assert set(labels) <= {f"P{f}" for f in range(mesh.n_faces)} and len(labels) > 10
    shot(page, "labels")
    # more generators than the limit: the generators layer goes off by itself
    page.uncheck('[data-layer="labels"]')
    set_field(page, "rulings.count", 45)
    assert not page.evaluate("window.designer.layer('generators')")
    assert page.evaluate("window.designer.edgeCount()") == len(designer.session.built.mesh.edges())
    shot(page, "45-generators")


# Counts the pixels of colour `rgb` (within `tol`) in a (2r+1)-square of the canvas around
# the page point (x, y).
PIXELS_NEAR_JS = """([x, y, r, rgb, tol]) => {
  const src = document.getElementById('canvas');
  const box = src.getBoundingClientRect();
  const c = document.createElement('canvas');
  c.width = c.height = 2 * r + 1;
  const g = c.getContext('2d');
  const sx = src.width / box.width, sy = src.height / box.height;
  g.drawImage(src, (x - box.left - r) * sx, (y - box.top - r) * sy, (2 * r + 1) * sx, (2 * r + 1) * sy,
              0, 0, 2 * r + 1, 2 * r + 1);
  const d = g.getImageData(0, 0, 2 * r + 1, 2 * r + 1).data;
  let n = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (Math.abs(d[i] - rgb[0]) <= tol && Math.abs(d[i + 1] - rgb[1]) <= tol
        && Math.abs(d[i + 2] - rgb[2]) <= tol) n += 1;
  }
  return n;
}"""
HIGHLIGHT_RGB = [0xB0, 0x20, 0x8A]
HOVER_RGB = [0xFF, 0xD4, 0x00]


def test_panel_figures_are_analyze_s_and_show_their_faces(page, designer):
    from ruledmesh.analysis.faces import SPLINTER_DEG, face_min_angles

    built = designer.session.built
    mesh = built.mesh
    report = analyze(mesh, extras=built.extras)
    smallest = face_min_angles(mesh)
    # the figures under the legend are those of ruledmesh analyze, each at its face
    fig = page.evaluate("window.designer.panelFigures")
    assert fig["quads"] == pytest.approx(report["quality"]["area_share"]["quads"], rel=1e-12)
    assert fig["minAngle"] == pytest.approx(report["min_angle_deg"], rel=1e-12)
    assert fig["planarity"] == pytest.approx(report["planarity"]["max"], rel=1e-12)
    f = fig["minAngleFace"]
    assert f == int(np.argmin(smallest))
    assert fig["splinters"] == int(np.count_nonzero(smallest < SPLINTER_DEG)) > 0
    text = page.inner_text("#panel-figures")
    assert f"{100 * report['quality']['area_share']['quads']:.1f} %" in text
    assert f"{report['min_angle_deg']:.2f}°" in text and f"P{f}" in text
    # the face named is shown: its panel opens, its outline and centre drawn over the mesh
    page.click('[data-view="top"]')
    page.wait_for_function("window.designer.view === 'top'")
    pos = page.evaluate(f"window.designer.faceScreen({f})")
    assert page.evaluate(PIXELS_NEAR_JS, [pos["x"], pos["y"], 6, HIGHLIGHT_RGB, 40]) == 0
    page.click(f'#panel-figures a[data-face="{f}"]')
    page.wait_for_selector("#drawer:not([hidden])")
    page.wait_for_function(f"window.designer.panel && window.designer.panel.face === {f}")
    assert page.evaluate("window.designer.highlighted()") == f
    row = page.evaluate("window.designer.panel.row")
    assert row["label"] == f"P{f}"
    assert row["min_angle_deg"] == pytest.approx(smallest[f], abs=1e-6)
    page.evaluate("() => new Promise(requestAnimationFrame)")
    assert page.evaluate(PIXELS_NEAR_JS, [pos["x"], pos["y"], 6, HIGHLIGHT_RGB, 40]) > 10
    shot(page, "smallest-angle-face")
    # colour by the smallest angle: a log ramp with the splinter limit marked
    page.select_option("#colour", "angle")
    legend = page.evaluate("window.designer.legend")
    assert legend["min"] == pytest.approx(smallest.min(), rel=1e-6)
    assert legend["max"] == pytest.approx(smallest.max(), rel=1e-6)
    assert legend["below"] == int(np.count_nonzero(smallest.astype(np.float32) < SPLINTER_DEG))
    assert page.locator("#legend .mark").count() == 1 and "splinter" in page.inner_text("#legend")
    shot(page, "colour-angle")
    # the kinds with their area shares
    page.select_option("#colour", "kind")
    text = page.inner_text("#legend")
    for kind, share in report["quality"]["area_share"]["by_kind"].items():
        assert f"{kind} {mesh.count_kinds()[kind]} ({100 * share:.1f} %)" in text, (kind, text)
    # planarity of the faces that can be out of plane: triangles are grey, not counted
    page.select_option("#colour", "planarity")
    legend = page.evaluate("window.designer.legend")
    assert legend["faces"] == int(np.count_nonzero(mesh.valences > 3)) < mesh.n_faces
    # closing the panel takes the highlight away
    page.click("#drawer-close")
    assert page.evaluate("window.designer.highlighted()") is None
    page.evaluate("() => new Promise(requestAnimationFrame)")
    assert page.evaluate(PIXELS_NEAR_JS, [pos["x"], pos["y"], 6, HIGHLIGHT_RGB, 40]) == 0


def test_planarity_legend_marks_the_design_s_tolerance(page, designer):
    from ruledmesh.analysis.planar import face_planarity

    set_field(page, "mesh.planarity_tolerance", "0.001")
    built = designer.session.built
    mesh = built.mesh
    report = analyze(mesh, extras=built.extras)["planarity"]
    assert report["tolerance"] == 1e-3 and report["within_tolerance"] > 0
    polygons = int(np.count_nonzero(mesh.valences > 3))
    page.wait_for_function(f"window.designer.legend && window.designer.legend.faces === {polygons}")
    legend = page.evaluate("window.designer.legend")
    plan = face_planarity(mesh).astype(np.float32)[mesh.valences > 3]
    # exact, within and over the tolerance as analyze tells them apart (triangles left out)
    assert legend["over"] == report["above_tolerance"] == 0
    assert legend["within"] == report["within_tolerance"] == int(np.count_nonzero(plan > 1e-12))
    assert legend["exact"] == report["exact"] - int(np.count_nonzero(mesh.valences == 3))
    assert legend["max"] == pytest.approx(report["max"], rel=1e-6)
    assert "tolerance 1e-3" in page.inner_text("#legend")
    assert "(tolerance 1e-3)" in page.inner_text("#panel-figures")
    # the mark is where 1e-3 is on the ramp (1e-16 ... two decades past the tolerance)
    left = page.eval_on_selector("#legend .mark", "m => parseFloat(m.style.left)")
    assert left == pytest.approx(100 * 13 / 15)
    shot(page, "planarity-tolerance")


def test_insert_delete_points_and_type_coordinates_each_one_undo_step(page, designer):
    click_handle(page, "c1.points[1]")
    page.wait_for_function("window.designer.selection().join() === 'c1.points[1]'")
    assert page.input_value("#sel-x") == "3"
    pts = designer.session.design["curves"]["c1"]["points"]
    v = page.evaluate("window.designer.version")
    page.click("#pt-insert")
    wait_version(page, v)
    new = designer.session.design["curves"]["c1"]["points"]
    assert len(new) == 5 and new[2] == [4.5, 0, 0]  # half way to the next point
    assert page.evaluate("window.designer.selection()") == ["c1.points[2]"]
    shot(page, "inserted-point")
    # typed Z for the inserted point
    v = page.evaluate("window.designer.version")
    page.fill("#sel-z", "1.5")
    page.press("#sel-z", "Enter")
    wait_version(page, v)
    assert designer.session.design["curves"]["c1"]["points"][2] == [4.5, 0, 1.5]
    # delete the point after it
    click_handle(page, "c1.points[3]")
    page.wait_for_function("window.designer.selection().join() === 'c1.points[3]'")
    v = page.evaluate("window.designer.version")
    page.click("#pt-delete")
    wait_version(page, v)
    assert designer.session.design["curves"]["c1"]["points"] == [pts[0], pts[1], [4.5, 0, 1.5], pts[3]]
    # degree: a field like any other
    set_field(page, "curves.c1.degree", 2)
    assert designer.session.design["curves"]["c1"]["degree"] == 2
    history = page.locator("#history li").all_inner_texts()
    assert history[-4:] == ["curves.c1.points: 5 points", "curves.c1.points[2] moved",
                            "curves.c1.points: 4 points", "curves.c1.degree = 2"]
    # four edits, four undo steps, back to the start
    for _ in range(4):
        undo(page, designer)
    assert designer.session.design["curves"]["c1"]["points"] == pts
    assert designer.session.design["curves"]["c1"]["degree"] == 3
    # the history shows the undone steps still to redo
    assert page.locator("#history li.future").count() == 4


def test_multi_select_moves_together_and_snaps_to_the_grid(page, designer):
    page.click('[data-view="top"]')
    page.wait_for_function("window.designer.view === 'top'")
    click_handle(page, "c2.points[1]")
    click_handle(page, "c2.points[2]", shift=True)
    page.wait_for_function("window.designer.selection().length === 2")
    page.check("#snap-grid")
    step = page.evaluate("window.designer.grid()")
    before = [list(p) for p in designer.session.design["curves"]["c2"]["points"]]
    h = next(x for x in page.evaluate("window.designer.handles()") if x["label"] == "c2.points[2]")
    v = page.evaluate("window.designer.version")
    page.mouse.move(h["x"], h["y"])
    page.mouse.down()
    for k in range(1, 9):
        page.mouse.move(h["x"] + 7 * k, h["y"] + 5 * k)
    page.mouse.up()
    wait_version(page, v)
    page.wait_for_function("!window.designer.busy()")
    after = designer.session.design["curves"]["c2"]["points"]
    d1 = np.subtract(after[1], before[1])
    d2 = np.subtract(after[2], before[2])
    assert np.linalg.norm(d2) > 0.3
    np.testing.assert_allclose(d1, d2, atol=1e-6)       # moved together
    assert np.allclose(after[0], before[0]) and np.allclose(after[3], before[3])
    # the dragged point sits on the grid
    np.testing.assert_allclose(np.round(np.array(after[2]) / step) * step, after[2], atol=1e-6)
    shot(page, "multi-select-top")
    # one drag, one undo step
    undo(page, designer)
    assert designer.session.design["curves"]["c2"]["points"] == before


def test_view_presets_orthographic_grid_and_screenshot(page, designer):
    persp = picture(page)
    expect = {"top": [0, 0, -1], "front": [0, 1, 0], "right": [-1, 0, 0]}
    pictures = {}
    for name, direction in expect.items():
        page.click(f'[data-view="{name}"]')
        page.wait_for_function(f"window.designer.view === '{name}'")
        cam = page.evaluate("window.designer.camera()")
        assert cam["ortho"]
        np.testing.assert_allclose(cam["direction"], direction, atol=2e-3)
        pictures[name] = picture(page)
        shot(page, f"view-{name}")
    page.click('[data-view="perspective"]')
    assert not page.evaluate("window.designer.camera()")["ortho"]
    page.check("#ortho")
    assert page.evaluate("window.designer.camera()")["ortho"]
    # the views differ from each other and from the perspective
    for a, b in [("top", "front"), ("front", "right"), ("top", "right")]:
        assert np.count_nonzero(np.abs(pictures[a] - pictures[b]).sum(axis=2) > 40) > 200
    assert np.count_nonzero(np.abs(pictures["top"] - persp).sum(axis=2) > 40) > 200
    # grid and axes: a layer with a step fitting the design; off hides them
    assert page.evaluate("window.designer.grid()") == 1
    page.uncheck('[data-layer="grid"]')
    assert not page.evaluate("window.designer.layer('grid')")
    # the screenshot button downloads a PNG of the view
    with page.expect_download() as info:
        page.click("#screenshot")
    data = Path(info.value.path()).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
    assert info.value.suggested_filename == "browser.png"


def test_hover_reads_a_face_and_click_opens_its_panel(page, designer):
    from ruledmesh.fabricate import panel_table

    mesh = designer.session.built.mesh
    table = panel_table(mesh)
    page.click('[data-view="top"]')
    page.wait_for_function("window.designer.view === 'top'")
    f = int(np.argmax(np.abs(table["area"])))     # the largest face: easy to hit
    pos = page.evaluate(f"window.designer.faceScreen({f})")
    page.mouse.move(pos["x"] + 1, pos["y"] + 1)
    page.mouse.move(pos["x"], pos["y"])
    page.wait_for_function("window.designer.hover !== null")
    info = page.evaluate("window.designer.hover")
    g = info["face"]
    # the face under the pointer is outlined: its corners, drawn over the mesh
    outline = page.evaluate("window.designer.hoverOutline()")
    assert outline["visible"]
    np.testing.assert_array_equal(outline["corners"], mesh.vertices[mesh.face(g)].astype(np.float32))
    page.evaluate("() => new Promise(requestAnimationFrame)")
    # Counted over the face's box on screen (its outline runs along the box's sides).
    box = page.evaluate(BOXES_JS, mesh.vertices[mesh.face(g)].tolist())["face"]
    near = [(box["left"] + box["right"]) / 2, (box["top"] + box["bottom"]) / 2,
            int(max(box["right"] - box["left"], box["bottom"] - box["top"]) / 2) + 4]
    assert page.evaluate(PIXELS_NEAR_JS, [*near, HOVER_RGB, 40]) > 20
    assert info["label"] == f"P{g}" == table["label"][g]
    assert info["kind"] == table["kind"][g]
    assert info["area"] == pytest.approx(abs(table["area"][g]), rel=1e-4)
    assert min(info["angles"]) == pytest.approx(table["min_angle_deg"][g], abs=0.05)
    assert max(info["angles"]) == pytest.approx(table["max_angle_deg"][g], abs=0.05)
    assert page.is_visible("#readout") and f"P{g}" in page.inner_text("#readout")
    shot(page, "hover-readout")
    # a click opens the panel drawer: the unrolled outline and the schedule row
    page.mouse.click(pos["x"], pos["y"])
    page.wait_for_selector("#drawer:not([hidden])")
    panel = page.evaluate("window.designer.panel")
    assert panel["face"] == g and panel["row"]["label"] == f"P{g}"
    assert panel["row"]["area"] == pytest.approx(table["area"][g])
    assert page.locator("#drawer polygon").count() == 1
    assert len(panel["outline"]) == mesh.valences[g]
    assert f"P{g}" in page.inner_text("#drawer")
    assert page.evaluate("window.designer.highlighted()") == g
    shot(page, "panel-drawer")
    # the pointer off the view: no outline; new faces (more rows): the panel, whose number
    # now names another face, closes
    page.mouse.move(5, 5)
    assert not page.evaluate("window.designer.hoverOutline().visible")
    assert page.evaluate(PIXELS_NEAR_JS, [*near, HOVER_RGB, 40]) == 0
    set_field(page, "mesh.rows", 13)
    page.wait_for_selector("#drawer", state="hidden")
    assert page.evaluate("window.designer.highlighted()") is None
    assert page.evaluate("window.designer.panel") is None
    assert f"panel P{g} closed" in page.inner_text("#status")


# The view's box and the read-out's, in the page's pixels; the face's box from its corners as
# the server's mesh has them, each projected by the page's camera.
BOXES_JS = """(corners) => {
  const box = (e) => { const r = e.getBoundingClientRect();
    return {left: r.left, top: r.top, right: r.right, bottom: r.bottom}; };
  const pts = corners.map((p) => window.designer.screen(p));
  const xs = pts.map((p) => p.x), ys = pts.map((p) => p.y);
  return {view: box(document.getElementById('view')), readout: box(document.getElementById('readout')),
          face: {left: Math.min(...xs), top: Math.min(...ys), right: Math.max(...xs), bottom: Math.max(...ys)},
          side: window.designer.readoutSide};
}"""


def hover_boxes(pg, mesh, x: float, y: float) -> tuple[int, dict]:
    """Hover the view at (x, y) from off it; the face read out and the boxes (BOXES_JS)."""
    pg.mouse.move(5, 5)                      # over the side panel: no read-out
    pg.wait_for_function("window.designer.hover === null")
    pg.mouse.move(x + 1, y + 1)
    pg.mouse.move(x, y)
    pg.wait_for_function("window.designer.hover !== null")
    g = pg.evaluate("window.designer.hover.face")
    return g, pg.evaluate(BOXES_JS, mesh.vertices[mesh.face(g)].tolist())


def overlap(a: dict, b: dict) -> bool:
    return a["left"] < b["right"] and b["left"] < a["right"] and \
        a["top"] < b["bottom"] and b["top"] < a["bottom"]


def inside(a: dict, b: dict) -> bool:
    return b["left"] <= a["left"] and a["right"] <= b["right"] and \
        b["top"] <= a["top"] and a["bottom"] <= b["bottom"]


def on_face(pg, handles, points) -> tuple[float, float]:
    """The first of ``points`` (page pixels) on a face and not on a handle."""
    for x, y in points:
        if all(abs(hd["x"] - x) > 20 or abs(hd["y"] - y) > 20 for hd in handles) and \
                pg.evaluate(f"window.designer.faceAt({x}, {y})") is not None:
            return x, y
    raise AssertionError(f"no face at any of {points}")


def pan(pg, x: float, y: float, dy: float) -> None:
    """Drag the view up (``dy`` < 0) or down with the right button, as OrbitControls pans."""
    pg.mouse.move(x, y)
    pg.mouse.down(button="right")
    pg.mouse.move(x, y + dy, steps=5)
    pg.mouse.up(button="right")
    pg.evaluate("() => new Promise(requestAnimationFrame)")


def test_hover_read_out_never_covers_its_face(page, designer):
    """The read-out goes beside the hovered face's box on screen, inside the view, also for
    faces cut by the view's edges and in its corners (it sat 14 px below and right of the
    pointer, over the face it describes, and ran past the view's edge)."""
    mesh = designer.session.built.mesh
    view = page.evaluate("document.getElementById('view').getBoundingClientRect().toJSON()")
    centre = page.evaluate(f"window.designer.faceScreen({mesh.n_faces // 2})")
    _, boxes = hover_boxes(page, mesh, centre["x"], centre["y"])
    assert not overlap(boxes["readout"], boxes["face"]) and inside(boxes["readout"], boxes["view"])
    # Close up in plan the faces are over 150 px across and the mesh runs past the view's
    # left and right edges; panned up and down, past its top and bottom.
    page.click('[data-view="top"]')
    page.wait_for_function("window.designer.view === 'top'")
    x0, y0, x1, y1 = view["left"], view["top"], view["right"], view["bottom"]
    mx, my = (x0 + x1) / 2, (y0 + y1) / 2
    for _ in range(30):
        page.mouse.move(mx, my)
        page.mouse.wheel(0, -100)
        _, boxes = hover_boxes(page, mesh, mx, my)
        if boxes["face"]["right"] - boxes["face"]["left"] > 150:
            break
    along = [8 + 12 * k for k in range(40)]   # from a corner along an edge, 8 px inside
    spots = {
        0: {"middle": [(mx, my)], "right": [(x1 - 8, my + d) for d in along],
            "left": [(x0 + 8, my + d) for d in along]},
        -350: {"top": [(mx + d, y0 + 8) for d in along],
               "top-right": [(x1 - d, y0 + 8) for d in along],
               "top-left": [(x0 + 8, y0 + d) for d in along]},
        700: {"bottom": [(mx + d, y1 - 8) for d in along],
              "bottom-right": [(x1 - 8, y1 - d) for d in along],
              "bottom-left": [(x0 + d, y1 - 8) for d in along]},
    }
    sides = {}
    for dy, named in spots.items():
        if dy:
            pan(page, mx, my, dy)
        handles = page.evaluate("window.designer.handles()")
        for name, points in named.items():
            x, y = on_face(page, handles, points)
            _, boxes = hover_boxes(page, mesh, x, y)
            f, r = boxes["face"], boxes["readout"]
            assert f["right"] - f["left"] > 100, (name, f)
            assert not overlap(r, f), (name, boxes)
            assert inside(r, boxes["view"]), (name, boxes)
            sides[name] = boxes["side"]
            if name == "bottom-right":
                shot(page, "hover-readout-corner")
    # by the right edge it goes left of the face, by the left edge right of it
    assert sides["right"] == sides["top-right"] == sides["bottom-right"] == "left", sides
    assert sides["left"] == sides["top-left"] == sides["bottom-left"] == "right", sides


def test_panel_answer_for_faces_since_changed_is_never_shown(page, designer):
    """A panel asked for while new faces are on their way opens only if it is the face clicked.

    Its request is held (route interception) while an edit builds other faces: let through
    then, the server answers it stale (its number names another face by now, which the
    server used to send); answered before the edit but arriving after it, the page drops it.
    An answer from an older build of the same faces is that face: shown, then read again.
    A slower answer to an earlier click does not replace a later one's.
    """
    from ruledmesh.fabricate import panel_table
    from ruledmesh.web.session import topology_key

    held, hold = [], [True]

    def route(r):
        if hold[0]:
            hold[0] = False
            held.append(r)
        else:
            r.continue_()

    def next_held(n):
        for _ in range(1000):
            if len(held) >= n:
                return held[n - 1]
            page.wait_for_timeout(10)
        raise AssertionError("the panel request did not come")

    page.route(re.compile(r"/api/panel\?"), route)
    page.click('[data-view="top"]')
    page.wait_for_function("window.designer.view === 'top'")
    table = panel_table(designer.session.built.mesh)
    pos = page.evaluate(f"window.designer.faceScreen({int(np.argmax(np.abs(table['area'])))})")
    x, y = pos["x"], pos["y"]
    under = f"window.designer.faceAt({x}, {y})"

    # the same faces, moved (a point typed 0.01 higher): the older answer is the face clicked
    key = topology_key(designer.session.built.mesh)
    g = page.evaluate(under)
    page.mouse.click(x, y)
    answer = next_held(1).fetch()
    assert f"face={g}&topology={key}" in held[0].request.url
    h = next(o for o in page.evaluate("window.designer.handles()") if o["label"] == "c2.points[2]")
    page.mouse.click(h["x"], h["y"])
    page.wait_for_function("window.designer.selection().length === 1")
    v = page.evaluate("window.designer.version")
    page.fill("#sel-z", "3.01")
    page.press("#sel-z", "Enter")
    wait_version(page, v)
    assert topology_key(designer.session.built.mesh) == key
    held[0].fulfill(response=answer)
    page.wait_for_selector("#drawer:not([hidden])")
    version = designer.session.version
    page.wait_for_function(f"window.designer.panel.face === {g} && window.designer.panel.version === {version}")
    assert page.evaluate("window.designer.panel.row.area") == pytest.approx(
        panel_table(designer.session.built.mesh)["area"][g])
    page.click("#drawer-close")

    # new faces built while the request waits: the server answers stale, the page drops it
    hold[0] = True
    g = page.evaluate(under)
    page.mouse.click(x, y)
    next_held(2)
    set_field(page, "mesh.rows", 13)
    assert topology_key(designer.session.built.mesh) != key
    held[1].continue_()
    page.wait_for_function("window.designer.panelsDropped === 1")
    assert page.is_hidden("#drawer") and page.evaluate("window.designer.panel") is None
    assert page.evaluate("window.designer.highlighted()") is None
    assert f"panel P{g} not opened: the faces changed" in page.inner_text("#status")

    # answered for the faces clicked, arriving after newer ones: dropped too
    hold[0] = True
    g = page.evaluate(under)
    page.mouse.click(x, y)
    answer = next_held(3).fetch()
    set_field(page, "mesh.rows", 14)
    held[2].fulfill(response=answer)
    page.wait_for_function("window.designer.panelsDropped === 2")
    assert page.is_hidden("#drawer") and page.evaluate("window.designer.panel") is None

    # an earlier click's slower answer does not replace the later one's (a face name of the
    # panel figures, clicked while the face's answer waits)
    hold[0] = True
    first = page.evaluate(under)
    page.mouse.click(x, y)
    next_held(4)
    q = page.get_attribute("#panel-figures a.face", "data-face")
    assert int(q) != first
    page.click("#panel-figures a.face")
    page.wait_for_function(f"window.designer.panel && window.designer.panel.face === {q}")
    with page.expect_response(re.compile(r"/api/panel\?")):
        held[3].continue_()
    page.evaluate("() => new Promise((done) => setTimeout(done, 100))")  # the answer read
    assert page.evaluate("window.designer.panel.face") == int(q)
    assert page.evaluate("window.designer.panelsDropped") == 2  # left out, not counted stale


def test_two_tabs_show_the_same_design_and_history(page, designer, browser):
    other = browser.new_page()
    errors = []
    other.on("pageerror", lambda exc: errors.append(str(exc)))
    try:
        other.goto(designer.url)
        other.wait_for_selector("body[data-version]", timeout=20_000)
        other.wait_for_function("window.designer.live === true")
        page.wait_for_function("window.designer.live === true")
        v = other.evaluate("window.designer.version")
        set_field(page, "mesh.rows", 9)          # an edit in the first tab ...
        wait_version(other, v)                    # ... reaches the second by itself
        other.wait_for_function(
            "document.querySelector('[data-path=\"mesh.rows\"] input.val').value === '9'")
        assert other.inner_text("[data-fig=faces]") == str(designer.session.built.mesh.n_faces)
        v = page.evaluate("window.designer.version")
        other.click("#undo")                      # undo in the second reaches the first
        wait_version(page, v)
        page.wait_for_function(
            "document.querySelector('[data-path=\"mesh.rows\"] input.val').value === '12'")
        # one history for the session, the same list in both tabs
        assert page.locator("#history li").all_inner_texts() == \
            other.locator("#history li").all_inner_texts() == ["opened", "mesh.rows = 9"]
        shot(other, "second-tab")
    finally:
        other.close()
    assert not errors, errors


def test_construction_drawn_and_the_directrix_and_plane_handles_move(page, designer):
    drawn = page.evaluate("window.designer.construction()")
    assert "control polygon c1" in drawn                  # the B-spline's polygon
    assert "control polygon c2" not in drawn              # a polyline is its own polygon
    assert "primary generator" in drawn and "division of the primary generator" in drawn
    assert any(d.startswith("torsal generator") for d in drawn)
    v = page.evaluate("window.designer.version")
    page.select_option('select[data-path="rulings.distribution"]', "linear-directrix")
    wait_version(page, v)
    page.wait_for_function("!window.designer.busy()")
    assert "directrix" in page.evaluate("window.designer.construction()")
    labels = [h["label"] for h in page.evaluate("window.designer.handles()")]
    assert "directrix[0]" in labels and "directrix[1]" in labels
    shot(page, "linear-directrix")
    before = designer.session.design["rulings"]["directrix"][0]
    h = next(x for x in page.evaluate("window.designer.handles()") if x["label"] == "directrix[0]")
    v = page.evaluate("window.designer.version")
    page.mouse.move(h["x"], h["y"])
    page.mouse.down()
    for k in range(1, 6):
        page.mouse.move(h["x"] + 4 * k, h["y"] - 3 * k)
    page.mouse.up()
    wait_version(page, v)
    page.wait_for_function("!window.designer.busy()")
    assert designer.session.design["rulings"]["directrix"][0] != before
    v = page.evaluate("window.designer.version")
    page.select_option('select[data-path="rulings.distribution"]', "director-plane")
    wait_version(page, v)
    page.wait_for_function("!window.designer.busy()")
    assert "director plane" in page.evaluate("window.designer.construction()")
    assert "director plane normal" in [h["label"] for h in page.evaluate("window.designer.handles()")]
    shot(page, "director-plane")


def test_new_curve_by_clicking_points_and_ruling_on_it(page, designer):
    page.click('[data-view="top"]')
    page.wait_for_function("window.designer.view === 'top'")
    page.click("#new-curve")
    box = page.locator("#canvas").bounding_box()
    for k, (fx, fy) in enumerate([(0.35, 0.3), (0.5, 0.22), (0.65, 0.3)]):
        page.mouse.click(box["x"] + fx * box["width"], box["y"] + fy * box["height"])
        page.wait_for_function(f"window.designer.drawn === {k + 1}")
    v = page.evaluate("window.designer.version")
    page.keyboard.press("Enter")
    wait_version(page, v)
    assert page.inner_text("#new-curve") == "New curve"      # drawing ended
    c3 = designer.session.design["curves"]["c3"]
    assert c3["type"] == "bspline" and c3["degree"] == 2 and len(c3["points"]) == 3
    # the points lie on the construction plane (XY through the design's centre)
    zs = {round(p[2], 6) for p in c3["points"]}
    lo, hi = designer.session.built.mesh.bounding_box()
    assert len(zs) == 1 and zs.pop() == pytest.approx((lo[2] + hi[2]) / 2, abs=1e-5)
    xs = [p[0] for p in c3["points"]]
    assert xs == sorted(xs)                                 # left to right as clicked
    v = page.evaluate("window.designer.version")
    page.select_option('[data-between="1"]', "c3")
    wait_version(page, v)
    assert designer.session.design["rulings"]["between"] == ["c1", "c3"]
    shot(page, "new-curve")


def test_every_numeric_field_of_the_method_has_a_widenable_slider(page, designer):
    # pq fields left at their defaults still have controls
    for key in ("option", "max_extend", "planarity_tolerance", "respace", "rows_from", "thin"):
        assert page.locator(f'.ctl.default[data-path="mesh.{key}"]').count() == 1
    # respace and thin are "auto" or a boolean: one list of the three, the booleans sent as booleans
    v = page.evaluate("window.designer.version")
    page.select_option('select[data-path="mesh.respace"]', "true")
    wait_version(page, v)
    assert designer.session.design["mesh"]["respace"] is True
    v = page.evaluate("window.designer.version")
    page.select_option('select[data-path="mesh.thin"]', "false")
    wait_version(page, v)
    assert designer.session.design["mesh"]["thin"] is False
    # rows_from: a list of where the rows start
    v = page.evaluate("window.designer.version")
    page.select_option('select[data-path="mesh.rows_from"]', "c1")
    wait_version(page, v)
    assert designer.session.design["mesh"]["rows_from"] == "c1"
    slider = page.locator('input[type=range][data-path="rulings.count"]')
    hi = float(slider.get_attribute("max"))
    page.click('[data-widen="rulings.count"]')
    assert float(slider.get_attribute("max")) >= 2 * hi
    set_field(page, "rulings.count", int(2 * hi) - 1)   # beyond the first range
    assert designer.session.design["rulings"]["count"] == int(2 * hi) - 1
    # hybrid: its fields appear with sliders; moving one edits the design
    v = page.evaluate("window.designer.version")
    page.select_option('select[data-path="mesh.method"]', "hybrid")
    wait_version(page, v)
    page.wait_for_function("!window.designer.busy()")
    page.wait_for_selector('input[type=range][data-path="mesh.divisions"]')
    assert page.locator('input[type=range][data-path="mesh.midpoints"]').count() == 1
    set_field(page, "mesh.divisions", 5)
    assert designer.session.design["mesh"] == {"method": "hybrid", "divisions": 5}
    # 399 generators: edges a few pixels apart fade instead of drawing a black moiré
    assert page.evaluate("window.designer.edgeOpacity") < 0.5
    shot(page, "hybrid-fields")


def test_catalogue_surface_handles_drag_its_radius(browser, tmp_path):
    server = serve_example("fig5b-torus.toml", tmp_path)
    pg = browser.new_page()
    try:
        handles = open_in_top_view(pg, server)
        assert {"R", "r"} <= set(handles)
        R0 = server.session.design["surface"]["R"]
        # R = 3.0 is a decimal field (JSON writes it 3): its slider moves in fractions
        step = pg.evaluate("document.querySelector('input[type=range][data-path=\"surface.R\"]').step")
        assert 0 < float(step) < 1, step
        drag(pg, handles["R"], 48, 18)   # mostly along +x: a larger R
        R1 = server.session.design["surface"]["R"]
        assert R1 > R0 + 0.2
        # the handle sits at the new radius from the centre, on the x axis
        _, hi = server.session.built.mesh.bounding_box()
        assert hi[0] == pytest.approx(R1 + server.session.design["surface"]["r"], rel=0.02)
        shot(pg, "torus-radius")
    finally:
        pg.close()
        server.shutdown()
        server.server_close()


def test_a_catalogue_kind_built_from_its_defaults_has_fields_to_edit(browser, tmp_path):
    """A ``[surface]`` with nothing but its kind shows the kind's fields at their defaults
    (grey, decimal sliders for decimal defaults) and an edit of one writes it into the design."""
    server = serve_text('[surface]\nkind = "hyperboloid"\n', tmp_path / "plain.toml")
    pg = browser.new_page()
    try:
        pg.goto(server.url)
        pg.wait_for_selector("body[data-version]", timeout=20_000)
        grey = pg.evaluate("[...document.querySelectorAll('#controls .ctl.default')]"
                           ".map(r => [r.dataset.path, r.querySelector('input.val, select, input')?.value])")
        shown = dict(grey)
        # the builder's own defaults (a = 1, c = 1, height = 2; 32 x 16 faces)
        assert {"surface.a", "surface.c", "surface.height", "surface.style", "mesh.u", "mesh.v"} <= set(shown)
        assert float(shown["surface.height"]) == 2 and shown["surface.style"] == "circular"
        assert int(shown["mesh.u"]) == 32 and int(shown["mesh.v"]) == 16
        # height = 2.0 is decimal (JSON writes it 2): its slider moves in fractions
        step = pg.evaluate("document.querySelector('input[type=range][data-path=\"surface.height\"]').step")
        assert 0 < float(step) < 1, step
        z0 = float(np.ptp(server.session.built.mesh.vertices[:, 2]))
        assert z0 == pytest.approx(4.0)
        set_field(pg, "surface.height", 3.5)
        assert server.session.design["surface"]["height"] == 3.5
        assert float(np.ptp(server.session.built.mesh.vertices[:, 2])) == pytest.approx(7.0)
        # the field is the design's now, no longer a grey default; the others stay grey
        assert pg.evaluate("document.querySelector('.ctl[data-path=\"surface.height\"]').classList"
                           ".contains('default')") is False
        assert pg.evaluate("document.querySelector('.ctl[data-path=\"surface.c\"]').classList"
                           ".contains('default')") is True
        shot(pg, "catalogue-defaults")
        # the kind's choice fields are menus of the words its builder takes
        style = 'select[data-path="surface.style"]'
        assert pg.evaluate(f"[...document.querySelector('{style}').options].map(o => o.value)") == \
            ["circular", "generators"]
        v = pg.evaluate("window.designer.version")
        pg.select_option(style, "generators")
        wait_version(pg, v)
        pg.wait_for_function("!window.designer.busy()")
        assert server.session.design["surface"]["style"] == "generators"
    finally:
        pg.close()
        server.shutdown()
        server.server_close()


def test_apply_is_busy_at_once_and_clears_an_old_error(browser, tmp_path):
    """Apply of a design that takes a while: the page says it is building and drops the
    error an earlier refused edit left, at once, not when the build answers."""
    server = serve_text(DESIGN, tmp_path / "d.toml")
    pg = browser.new_page()
    try:
        pg.goto(server.url)
        pg.wait_for_selector("body[data-version]", timeout=20_000)
        field = pg.locator('[data-path="mesh.rows"] input.val')
        field.fill("-1")
        field.press("Enter")
        pg.wait_for_selector("#error:not([hidden])")
        v = pg.evaluate("window.designer.version")
        pg.click("#toml-pane summary")
        slow = server.session.toml().replace("count = 15", "count = 101").replace("rows = 12", "rows = 100")
        pg.fill("#toml", slow)
        # Read in the same task as the click's handler: before any answer can come back.
        seen = pg.evaluate("""() => { document.querySelector('#apply-toml').click();
            return {busy: window.designer.busy(), error: document.querySelector('#error').hidden,
                    status: document.querySelector('#status').textContent}; }""")
        assert seen == {"busy": True, "error": True, "status": "building..."}, seen
        wait_version(pg, v)
        pg.wait_for_function("!window.designer.busy()", timeout=60_000)
        assert server.session.design["rulings"]["count"] == 101
        assert pg.is_hidden("#error")
    finally:
        pg.close()
        server.shutdown()
        server.server_close()


def serve_example(name: str, tmp_path):
    return serve_text((Path(__file__).resolve().parents[1] / "examples" / name).read_text(), tmp_path / name)


def serve_text(text: str, path: Path):
    """A designer server of the design ``text``, saved as ``path``, serving in a thread."""
    path.write_text(text)
    server = make_server(Session(text, path), port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def open_in_top_view(pg, server) -> dict:
    """Open the designer's page in the top view; its handles by label (screen positions)."""
    pg.goto(server.url)
    pg.wait_for_selector("body[data-version]", timeout=20_000)
    pg.click('[data-view="top"]')
    pg.wait_for_function("window.designer.view === 'top'")
    return {h["label"]: h for h in pg.evaluate("window.designer.handles()")}


def drag(pg, h: dict, dx: float, dy: float, steps: int = 6) -> None:
    v = pg.evaluate("window.designer.version")
    pg.mouse.move(h["x"], h["y"])
    pg.mouse.down()
    for k in range(1, steps + 1):
        pg.mouse.move(h["x"] + dx * k / steps, h["y"] + dy * k / steps)
    pg.mouse.up()
    wait_version(pg, v)
    pg.wait_for_function("!window.designer.busy()")


@pytest.mark.parametrize(("example", "label", "field"), [
    ("sec2-ellipsoid.toml", "axes[0]", ("axes", 0)),           # a length in a list
    ("fig6a-prism.toml", "direction", ("direction",)),          # a direction (leashed handle)
    ("sec2-translational.toml", "p.vertex", ("p", "vertex")),  # a point of a surface's curve
])
def test_catalogue_parameters_have_handles(browser, tmp_path, example, label, field):
    server = serve_example(example, tmp_path)
    pg = browser.new_page()
    try:
        handles = open_in_top_view(pg, server)
        assert label in handles, sorted(handles)

        def value():
            v = server.session.design["surface"]
            for k in field:
                v = v[k]
            return v

        before, faces = value(), server.session.built.mesh.vertices.copy()
        drag(pg, handles[label], 50, 25)
        after = value()
        assert after != before
        if field == ("axes", 0):  # dragged outwards along +x: a longer semi-axis
            assert after > before and server.session.built.mesh.bounding_box()[1][0] == \
                pytest.approx(after, rel=0.02)
        elif field == ("direction",):  # a unit direction, turned towards +x
            assert np.linalg.norm(after) == pytest.approx(1, abs=1e-5) and after[0] > before[0] / np.linalg.norm(before)
        else:  # the vertex moved in the plan
            assert after[0] > before[0]
        mesh = server.session.built.mesh
        assert mesh.vertices.shape != faces.shape or not np.allclose(mesh.vertices, faces)
        # what the page draws is the server's new mesh
        state = pg.evaluate(DRAWN_JS)
        assert state["faces"] == mesh.n_faces and state["vertices"] == mesh.n_vertices
        shot(pg, f"handle-{label}")
    finally:
        pg.close()
        server.shutdown()
        server.server_close()


def test_a_design_that_refines_shows_its_quick_mesh_then_the_full_one(page, designer, monkeypatch):
    """The TOML pane applies the design without ``refine = false`` (built in full: the last
    full build counts as quick), then the same design at 13 rows (the last full build counts
    as slow): the page draws the quick mesh at once and says the full one is being built,
    then draws the full mesh (pushed on the live socket) and the note goes.

    The 0.15 s rule is set for each step (a loaded machine builds the small design in more
    than 0.15 s); tests/test_designer.py tests the rule itself."""
    import ruledmesh.web.session as session_module

    monkeypatch.setattr(session_module, "QUICK_AFTER_SECONDS", math.inf)
    refining = DESIGN.replace("refine = false\n", "")
    page.click("#toml-pane summary")
    page.fill("#toml", refining)
    before = page.evaluate("window.designer.version")
    page.click("#apply-toml")
    wait_version(page, before)
    assert page.is_hidden("#refining")
    assert page.inner_text("[data-fig=faces]") == str(build_design(parse_design(refining)).mesh.n_faces)
    thirteen = refining.replace("rows = 12", "rows = 13")
    full = build_design(parse_design(thirteen)).mesh
    assert full.n_faces != build_design(parse_design(thirteen + "refine = false\n")).mesh.n_faces
    page.fill("#toml", thirteen)
    monkeypatch.setattr(session_module, "QUICK_AFTER_SECONDS", 0.0)
    before = page.evaluate("window.designer.version")
    page.click("#apply-toml")
    page.wait_for_function("!document.getElementById('refining').hidden", timeout=20_000)
    assert "refining the generators" in page.inner_text("#refining")
    # The warnings shown are the quick mesh's, and the page says so above them.
    caption = page.evaluate("document.getElementById('warnings').dataset.caption")
    assert caption.startswith("warnings of the quick mesh")
    listed = page.evaluate("document.querySelectorAll('#warnings li').length")
    assert page.evaluate("document.getElementById('warnings').classList.contains('quick')") == (listed > 0)
    shot(page, "refining-quick-mesh")
    page.wait_for_function("document.getElementById('refining').hidden", timeout=60_000)
    assert page.evaluate("document.getElementById('warnings').dataset.caption") == ""
    assert not page.evaluate("document.getElementById('warnings').classList.contains('quick')")
    # The live socket told what the full build was at, as it went on.
    assert page.evaluate("window.designer.refineNotes") >= 1
    assert re.fullmatch(r"mesh \d+, \d+ generators", page.evaluate("window.designer.refineNote"))
    assert page.evaluate("window.designer.version") >= before + 2
    assert page.inner_text("[data-fig=faces]") == str(full.n_faces)
    assert page.evaluate(DRAWN_JS)["faces"] == full.n_faces
    assert designer.session.built.mesh.n_faces == full.n_faces


def refused(pg, action, field: str) -> str:
    """Do ``action``; wait for the error it shows (naming ``field``) and the page to settle."""
    pg.evaluate("document.querySelector('#error').hidden = true")
    action()
    pg.wait_for_selector("#error:not([hidden])")
    pg.wait_for_function("!window.designer.busy()")
    text = pg.inner_text("#error")
    assert field in text, text
    return text


def test_refused_input_changes_neither_the_design_nor_the_selection(page, designer):
    """What a refused value leaves behind: the design, the fields, the selection, the figures.

    ``Infinity`` and ``1e400`` are numbers to the page that JSON writes as null, which deletes
    a field; a cleared coordinate is 0 to ``Number``; a refused delete moved the selection to
    the point before; a grey default field kept the refused value; a refused edit wiped the
    figures computed for the design still shown."""
    design = designer.session.design
    page.click("#slow-figures")
    page.wait_for_function("document.querySelector('[data-fig=panels]').textContent.match(/^\\d+$/)",
                           timeout=60_000)
    panels = page.inner_text("[data-fig=panels]")
    for text in ("Infinity", "-Infinity", "1e400"):
        field = page.locator('[data-path="mesh.rows"] input.val')
        said = refused(page, lambda t=text, f=field: (f.fill(t), f.press("Enter")), "mesh.rows")
        assert text in said
        page.wait_for_function(
            "document.querySelector('[data-path=\"mesh.rows\"] input.val').value === '12'")
    # a field left at its default shows the default again
    field = page.locator('[data-path="mesh.max_extend"] input.val')
    refused(page, lambda: (field.fill("-5"), field.press("Enter")), "mesh.max_extend")
    page.wait_for_function(
        "document.querySelector('[data-path=\"mesh.max_extend\"] input.val').value === '20'")
    # the figures computed for this version stay
    assert page.inner_text("[data-fig=panels]") == panels
    # a cleared or junk coordinate is refused, the point stays where it was
    click_handle(page, "c2.points[2]")
    page.wait_for_function("window.designer.selection().join() === 'c2.points[2]'")
    for text in ("", "abc"):
        said = refused(page, lambda t=text: (page.fill("#sel-x", t), page.press("#sel-x", "Enter")),
                       "c2.points[2] x")
        assert "expected a finite number" in said
        assert page.input_value("#sel-x") == "6"
    # a refused delete keeps the point chosen (a degree-3 B-spline keeps four points)
    click_handle(page, "c1.points[3]")
    page.wait_for_function("window.designer.selection().join() === 'c1.points[3]'")
    refused(page, lambda: page.click("#pt-delete"), "curves.c1.points")
    assert page.evaluate("window.designer.selection()") == ["c1.points[3]"]
    assert page.input_value("#sel-x") == "10"
    assert designer.session.design == design
    assert page.evaluate("window.designer.version") == designer.session.version


def test_the_toml_pane_says_when_the_design_moved_on(page, designer):
    """Text typed in the pane stays while the design changes, and the pane says it is behind
    (Apply would replace the newer design); a kind's template the page wrote gives way to the
    design once a kind builds; a catalogue surface lists no fields of the ruled methods."""
    page.click("#toml-pane summary")
    page.locator("#toml").press("End")
    page.keyboard.type("\n# a note\n")
    assert page.is_hidden("#toml-stale")
    set_field(page, "mesh.rows", 11)
    page.wait_for_selector("#toml-stale:not([hidden])")
    assert "rows = 12" in page.input_value("#toml") and "# a note" in page.input_value("#toml")
    shot(page, "toml-pane-behind")
    page.click("#toml-revert")
    assert page.is_hidden("#toml-stale")
    assert page.input_value("#toml") == designer.session.toml()
    # a kind that needs fields: its template; another kind that builds: the design
    page.select_option("#kind", "torus")
    page.wait_for_selector("#error:not([hidden])")
    assert 'kind = "torus"' in page.input_value("#toml")
    v = page.evaluate("window.designer.version")
    page.select_option("#kind", "hyperboloid")
    wait_version(page, v)
    page.wait_for_function("!window.designer.busy()")
    assert designer.session.design["surface"] == {"kind": "hyperboloid"}
    assert page.input_value("#toml") == designer.session.toml()
    assert page.is_hidden("#toml-stale")
    # the kind's own [mesh] fields at their defaults, none of the ruled methods'
    assert page.evaluate("[...document.querySelectorAll('.ctl[data-path^=\"mesh.\"]')]"
                         ".map(r => r.dataset.path).sort()") == ["mesh.u", "mesh.v"]
