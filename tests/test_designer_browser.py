"""The designer in a real browser: Debian's chromium driven by Playwright.

The tests start the server themselves (a free port on 127.0.0.1) and use the
system chromium (never a downloaded one).  Skipped, with the reason, only
when ``/usr/bin/chromium`` or the ``playwright`` package is missing.
"""

from __future__ import annotations

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
