"""Slow figures (closeness, coverage, panel count, the full report) in a separate process.

The distance of a mesh from its smooth reference surface can take seconds on
some designs (an arc-length parametrised B-spline), and the congruence classes
of the panels a fifth of a second on a 100 x 100 mesh.  Computing them in the
server process would stall the edits behind them, so a worker process
rebuilds the design and measures it; when a newer design is asked for while
the worker is busy with an older one, the worker is killed and restarted, so
figures for a design nobody looks at any more are never finished.
"""

from __future__ import annotations

import multiprocessing as mp
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from .builder import spawn_worker, stop_worker

__all__ = ["FigureWorker"]


def _worker_main(conn) -> None:  # pragma: no cover - runs in the child process
    from ..design import Design, build_design
    from ..errors import RuledMeshError
    from .session import slow_figures

    while True:
        try:
            job = conn.recv()
        except (EOFError, OSError):
            return
        if job is None:
            return
        version, data, source, base_dir = job
        try:
            built = build_design(Design(data, source, Path(base_dir)))
            figures, per_face = slow_figures(built)
            figures["report"] = _report(built)
            reply: tuple[int, dict[str, Any], dict[str, Any] | None, str | None] = (
                version, figures, per_face, None)
        except RuledMeshError as exc:
            reply = (version, {}, None, str(exc))
        except Exception as exc:  # noqa: BLE001 - reported to the page, never a dead worker
            reply = (version, {}, None, f"internal error: {type(exc).__name__}: {exc}")
        try:
            conn.send(reply)
        except OSError:  # the server went away: nobody to answer
            return


def _report(built) -> dict[str, Any]:  # pragma: no cover - runs in the child process
    """The report of ``ruledmesh analyze`` (what ``--json`` prints), or ``{"error": ...}``."""
    from ..analysis.report import analyze
    from ..errors import RuledMeshError

    try:
        return analyze(built.mesh, reference=built.reference, extras=built.extras)
    except RuledMeshError as exc:
        return {"error": str(exc)}


class FigureWorker:
    """Computes :func:`~ruledmesh.web.session.slow_figures` for the latest design.

    :meth:`request` asks for the figures of ``version`` and waits for them;
    a later request for a newer version supersedes it (the waiting caller
    gets ``None``).
    """

    def __init__(self) -> None:
        self._ctx = mp.get_context("spawn")  # never fork a threaded server
        self._cond = threading.Condition()
        self._wanted: Any = None  # (version, data, source, base_dir)
        self._result: tuple | None = None  # (version, figures, per_face, error)
        self._closed = False
        self._proc: Any = None
        self._conn: Any = None
        self._thread = threading.Thread(target=self._run, name="figures", daemon=True)
        self._thread.start()

    # ---------------------------------------------------------------- child
    def _start(self) -> None:
        self._proc, self._conn = spawn_worker(self._ctx, _worker_main, "ruledmesh-figures")

    def _stop(self) -> None:
        stop_worker(self._proc, self._conn)
        self._proc = self._conn = None

    def _run(self) -> None:
        while True:
            with self._cond:
                while not self._closed and (self._wanted is None or (
                        self._result is not None and self._result[0] == self._wanted[0])):
                    self._cond.wait()
                if self._closed:
                    break
                job = self._wanted
            if self._proc is None or not self._proc.is_alive():
                self._start()
            try:
                self._conn.send(job)
                result = None
                while result is None:
                    if self._conn.poll(0.05):
                        result = self._conn.recv()
                        break
                    with self._cond:
                        superseded = self._closed or self._wanted[0] != job[0]
                    if superseded:
                        self._stop()
                        break
                    if not self._proc.is_alive():
                        raise EOFError
            except (EOFError, OSError, BrokenPipeError):
                self._stop()
                result = (job[0], {}, None, "the figures process stopped unexpectedly")
            if result is not None:
                with self._cond:
                    self._result = result
                    self._cond.notify_all()
        self._stop()

    # ---------------------------------------------------------------- API
    def request(self, version: int, data: dict, source: str, base_dir: str | Path,
                timeout: float = 120.0
                ) -> tuple[dict[str, Any], dict[str, np.ndarray] | None, str | None] | None:
        """Figures of design ``data`` at ``version``: ``(figures, per_face, error)``.

        ``per_face`` maps names (``"closeness"``, ``"class"``) to (F,) arrays.

        Returns ``None`` when a newer version was asked for meanwhile or the
        timeout passed.
        """
        deadline = time.monotonic() + timeout
        with self._cond:
            if self._wanted is None or self._wanted[0] < version:
                self._wanted = (version, data, source, str(base_dir))
                self._cond.notify_all()
            while True:
                if self._result is not None and self._result[0] == version:
                    return self._result[1:]
                if self._closed or self._wanted[0] != version:
                    return None
                left = deadline - time.monotonic()
                if left <= 0:
                    return None
                self._cond.wait(left)

    def close(self) -> None:
        """Stop the worker process."""
        with self._cond:
            self._closed = True
            self._cond.notify_all()
        self._thread.join(timeout=10)
