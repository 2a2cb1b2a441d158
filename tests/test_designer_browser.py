"""The designer in a real browser: Debian's chromium driven by Playwright.

The tests start the server themselves (a free port on 127.0.0.1) and use the
system chromium (never a downloaded one).  Skipped, with the reason, only
when ``/usr/bin/chromium`` or the ``playwright`` package is missing.
"""

from __future__ import annotations

import json
import os
import re
import statistics
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from ruledmesh import io
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

DESIGN = """\
name = "browser"

[curves.c1]
type = "bspline"
degree = 3
points = [[0, 0, 0], [3, 1, 0], [6, -1, 0], [10, 0, 0]]

[curves.c2]
type = "polyline"
points = [[0, 2, 4], [3, 4, 5], [6, 3, 3], [10, 3, 4]]

[rulings]
between = ["c1", "c2"]
distribution = "parameter"
count = 15

[mesh]
method = "pq"
rows = 12
"""

# Reads the WebGL canvas back through a 2-D canvas: a (h, w, 3) picture, downsampled.
PIXELS_JS = """([w, h]) => {
  const src = document.getElementById('canvas');
  const c = document.createElement('canvas');
  c.width = w; c.height = h;
  const g = c.getContext('2d');
  g.drawImage(src, 0, 0, w, h);
  return Array.from(g.getImageData(0, 0, w, h).data);
}"""


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
    # the slow figures arrive from the worker process
    page.wait_for_function("document.querySelector('[data-fig=panels]').textContent.match(/^\\d+$/)",
                           timeout=60_000)


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
    # undo in the page goes back on the server
    page.click("#undo")
    page.wait_for_function("document.querySelector('[data-path=\"rulings.count\"] input.val').value === '18'")
    assert server_reaches(lambda: designer.session.design["rulings"]["count"] == 18)


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


def test_update_latency_100_by_100(browser, tmp_path):
    """Slider step to redrawn view for a 100 x 100 mesh (the issue asks for < 100 ms).

    The server runs as a user starts it (``ruledmesh design``, its own process).
    """
    design = tmp_path / "big.toml"
    design.write_text(DESIGN.replace("count = 15", "count = 101").replace("rows = 12", "rows = 100"))
    proc, url = start_cli(str(design))
    pg = browser.new_page()
    try:
        pg.goto(url)
        pg.wait_for_selector("body[data-version]", timeout=30_000)
        slider = pg.locator('input[type=range][data-path="mesh.rows"]')
        slider.focus()
        for key in ["ArrowRight", "ArrowLeft"] * 6:
            v = pg.evaluate("window.designer.version")
            pg.keyboard.press(key)
            wait_version(pg, v)
        steps = pg.evaluate("window.designer.breakdown.slice(-12)")
        faces = int(pg.inner_text("[data-fig=faces]"))
    finally:
        pg.close()
        proc.terminate()
        proc.wait(timeout=30)
    total = statistics.median(s["total"] for s in steps)
    server = statistics.median(s["server"] for s in steps)
    print(f"100 x 100 ({faces} faces) update: median {total:.0f} ms (server {server:.0f} ms), "
          f"min {min(s['total'] for s in steps):.0f} ms; load {os.getloadavg()[0]:.1f}")
    assert faces > 5000
    # A generous bound so a loaded CI machine does not fail; docs/designer.md has the figure.
    assert total < 400


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
