"""Regenerate docs/img/designer.png: the designer on examples/skew.toml in headless chromium.

Run from the project root: ``python docs/screenshot_designer.py`` (needs the ``test`` extra and
Debian's chromium at /usr/bin/chromium).
"""

import threading
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

from ruledmesh.web.server import make_server
from ruledmesh.web.session import Session

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "examples" / "skew.toml"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]


def main() -> None:
    server = make_server(Session(DESIGN.read_text(), DESIGN), port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True, args=ARGS)
            page = browser.new_page(viewport={"width": 1400, "height": 860})
            page.goto(server.url)
            page.wait_for_selector("body[data-version]", timeout=20_000)
            # closeness, coverage and the panel count are computed on request
            page.click("#slow-figures")
            page.wait_for_function(
                "document.querySelector('[data-fig=panels]').textContent.match(/^\\d+$/)",
                timeout=120_000)
            time.sleep(0.5)
            page.screenshot(path=str(ROOT / "docs" / "img" / "designer.png"))
            browser.close()
    finally:
        server.shutdown()
        server.server_close()


if __name__ == "__main__":
    main()
