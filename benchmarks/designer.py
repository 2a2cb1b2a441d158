"""Where the server's part of a designer step goes: a rows step of a 100 x 100 design.

    python benchmarks/designer.py [--steps N]

The design of the designer's slider-to-frame test (``tests/_shared.py``'s small design at
101 generators), stepped through ``N`` new row counts from 101 (12 by default), each
built afresh (no build cache answers).  Printed, as medians and minima over the steps,
with the load average before and after:

* in one process with the kernels loaded (as the build worker has them): the build
  (``build_design``, wall and CPU time), the page's arrays and figures (``frame_data``),
  and ``Session.edit`` plus ``Session.payload`` (checks, build, arrays, commit, encoding)
  with the build in the same thread;
* ``Session.edit`` with the designer's build worker process (the result's trip through
  the pipe included);
* ``POST /api/edit`` from a plain HTTP client to ``make_server``'s server, answered
  ``{version}`` as the page's edits are, the client's wall time and ``Server-Timing``.

With ``--refining NAME ...`` it measures instead, for bundled example designs that refine
their generators, the edit of a row count until the session has a mesh (``Session.edit``
with the build worker, warm, the kernels loaded; minimum of three edits): without quick
meshes (``previews=False``, as before), and with them until the quick mesh and until the
full one (``Session.settled``).

Wall-clock times follow the load of a shared machine: state it with every figure.  The
page's part (decoding, drawing, the frame) is measured in the browser by
``tests/test_designer_browser.py::test_update_latency_100_by_100``.
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import statistics
import sys
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from _shared import small_design  # noqa: E402


def _text(rows: int) -> str:
    return small_design(name="big", count=101, rows=rows)


def _ms(samples: list[float]) -> str:
    return f"median {statistics.median(samples):6.1f} ms, min {min(samples):6.1f} ms"


def in_process(steps: range) -> dict[str, list[float]]:
    """Stage times (ms) of each step, in this process, the kernels loaded first."""
    from ruledmesh import kernels
    from ruledmesh.design import build_design, parse_design
    from ruledmesh.web.session import Session, frame_data

    kernels.load()
    with kernels.everywhere():  # every kernel called once before the timing
        warm = parse_design(_text(100))
        frame_data(warm.data, build_design(warm))
    times: dict[str, list[float]] = {k: [] for k in (
        "build (wall)", "build (CPU)", "frame_data", "Session.edit + payload")}
    for rows in steps:
        design = parse_design(_text(rows))
        wall, cpu = time.perf_counter(), time.process_time()
        built = build_design(design)
        times["build (wall)"].append(1000 * (time.perf_counter() - wall))
        times["build (CPU)"].append(1000 * (time.process_time() - cpu))
        t = time.perf_counter()
        frame_data(design.data, built)
        times["frame_data"].append(1000 * (time.perf_counter() - t))
    session = Session(_text(100))
    for rows in steps:
        t = time.perf_counter()
        session.edit([(["mesh", "rows"], rows)])
        session.payload()
        times["Session.edit + payload"].append(1000 * (time.perf_counter() - t))
    return times


def with_worker(steps: range) -> list[float]:
    """``Session.edit`` times (ms) with the designer's build worker process."""
    from ruledmesh.web.builder import BuildWorker
    from ruledmesh.web.session import Session

    session, worker = Session(_text(100)), BuildWorker()
    worker.start()
    session.set_builder(worker)
    session.page_opened()    # the worker loads the kernels (as when a page connects)
    try:
        session.edit([(["mesh", "rows"], 99)])
        times = []
        for rows in steps:
            t = time.perf_counter()
            session.edit([(["mesh", "rows"], rows)])
            times.append(1000 * (time.perf_counter() - t))
        return times
    finally:
        worker.close()


def over_http(steps: range) -> tuple[list[float], list[float]]:
    """Client wall times and ``Server-Timing`` (ms) of ``POST /api/edit``."""
    from ruledmesh.web.server import make_server
    from ruledmesh.web.session import Session

    session = Session(_text(100))
    server = make_server(session, port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    session.page_opened()    # the server's worker loads the kernels (as when a page connects)
    conn = http.client.HTTPConnection(*server.server_address[:2], timeout=60)
    headers = {"Content-Type": "application/json", "Authorization": f"Bearer {server.token}",
               "X-Ruledmesh-Answer": "version"}
    walls, timings = [], []
    try:
        for rows in [99, *steps]:       # the first waits for the kernels; not timed
            t = time.perf_counter()
            conn.request("POST", "/api/edit",
                         json.dumps({"changes": [[["mesh", "rows"], rows]]}), headers)
            answer = conn.getresponse()
            answer.read()
            if rows != 99:
                walls.append(1000 * (time.perf_counter() - t))
                timings.append(float(answer.getheader("Server-Timing").split("dur=")[1]))
    finally:
        conn.close()
        server.shutdown()
        server.server_close()
    return walls, timings


def refining(name: str, previews: bool, edits: int = 3) -> tuple[float, float]:
    """Edit to mesh of example ``name`` (ms, minimum of ``edits`` row changes): until the
    edit returns (its mesh current) and until the full mesh is (the same without previews)."""
    import tomllib

    from ruledmesh import bundled
    from ruledmesh.web.builder import BuildWorker
    from ruledmesh.web.session import Session

    text = bundled.text(name)
    rows = tomllib.loads(text).get("mesh", {}).get("rows", 20)
    worker = BuildWorker()
    session = Session(text, builder=worker, previews=previews)
    worker.start()
    session.page_opened()                    # the worker loads the kernels
    try:
        session.edit([(["mesh", "rows"], rows + 1)])
        session.settled(600)
        first, full = [], []
        for k in range(edits):
            t = time.perf_counter()
            session.edit([(["mesh", "rows"], rows + 2 + k)])
            first.append(1000 * (time.perf_counter() - t))
            session.settled(600)
            full.append(1000 * (time.perf_counter() - t))
        return min(first), min(full)
    finally:
        worker.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=12)
    parser.add_argument("--refining", nargs="+", metavar="NAME",
                        help="bundled examples to time edits of with and without quick meshes")
    args = parser.parse_args(argv)
    steps = range(101, 101 + args.steps)
    before = os.getloadavg()
    if args.refining:
        print("| design | before: edit to mesh | now: edit to quick mesh | now: edit to full mesh |")
        print("|---|---:|---:|---:|")
        for name in args.refining:
            old, _ = refining(name, previews=False)
            quick, full = refining(name, previews=True)
            print(f"| `{name}` | {old:,.0f} ms | {quick:,.0f} ms | {full:,.0f} ms |", flush=True)
        print(f"load average {before[0]:.1f} before, {os.getloadavg()[0]:.1f} after; "
              f"{os.cpu_count()} cores")
        return 0
    for name, samples in in_process(steps).items():
        print(f"{name:24s} {_ms(samples)}")
    print(f"{'Session.edit, worker':24s} {_ms(with_worker(steps))}")
    walls, timings = over_http(steps)
    print(f"{'POST /api/edit (client)':24s} {_ms(walls)}")
    print(f"{'POST /api/edit (server)':24s} {_ms(timings)}")
    print(f"load average {before[0]:.1f} before, {os.getloadavg()[0]:.1f} after; "
          f"{os.cpu_count()} cores")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
