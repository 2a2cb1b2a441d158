"""Designer builds in a worker process: a hard time limit and supersession by newer edits.

A build runs in Python code that cannot be interrupted from another thread, so
the only honest time limit is a process that can be terminated.  The server
sends each candidate design to one long-lived worker process (started with
``spawn``: a threaded server is never forked) and waits for the built result
off the event loop.  The worker is killed and restarted when

- the build takes longer than the limit (the edit is refused with the figure),
- a newer edit arrives while an older one is still building after a short
  grace period (the older one is superseded: its result would be discarded
  anyway, and finishing it would only delay the newer one).

Every edit takes a *generation* number from :meth:`BuildWorker.generation`
when it reads the design it changes; a build whose generation is older than
the newest one handed out is superseded, whether it is still waiting, running
or already finished, so only the newest edit's result can become current.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import multiprocessing as mp
import threading
import time
from collections import OrderedDict
from pathlib import Path
from typing import Any

from ..errors import RuledMeshError

__all__ = ["MAX_BUILD_SECONDS", "BuildTimeout", "BuildWorker", "InProcessBuilder", "Superseded"]

# Wall-clock limit of one designer build (the CLI has none: it is the user's own job there).
MAX_BUILD_SECONDS = 20.0
# A superseded build younger than this is left to finish (and its result dropped): a fresh
# worker process needs about a second to import numpy and scipy, most builds take milliseconds.
SUPERSEDE_GRACE = 0.3
# Seconds a fresh worker process may take to import its modules (and later to compile
# the kernels: not counted against the edit waiting meanwhile).
STARTUP_SECONDS = 120.0
# Seconds without an edit after which the worker compiles (or loads) the kernels, unless a
# page opened before (BuildWorker.warm_up: then at once).  A user moving a slider right after
# the page opened never left the worker that idle second: every build of the gesture ran in
# numpy, twice as long (100 x 100: server part 70 instead of 35 ms).
IDLE_BEFORE_WARM_UP = 1.0
# The message asking the worker to load the kernels now.
WARM_UP = "warm-up"
# Builds kept by design: undo, redo, a slider moved back and forth, the same design sent by
# two tabs are answered without building again. A 100 x 100 mesh is about 1 MB.
BUILD_CACHE = 8


def _cache_key(data: dict, source: str, base_dir: str | Path) -> str | None:
    """The key of a design's build, or None when it reads a file (which may change on disk)."""
    try:
        text = json.dumps(data, sort_keys=True, allow_nan=True)
    except (TypeError, ValueError):
        return None
    if '"file"' in text:
        return None
    return f"{source}\0{base_dir}\0{text}"


class Superseded(RuledMeshError):
    """A newer edit arrived while this one was waiting or building; it was dropped."""


class BuildTimeout(RuledMeshError):
    """A build took longer than the designer's limit and was stopped."""


def _worker_main(conn) -> None:  # pragma: no cover - runs in the child process
    from .. import kernels
    from ..design import Design, build_design, parse_design
    from ..registry import load_plugins
    from .session import DEFAULT_DESIGN, frame_data

    load_plugins()
    kernels.hold()
    default = parse_design(DEFAULT_DESIGN)
    frame_data(default.data, build_design(default))  # imports the mesher's modules (lazy elsewhere)
    conn.send(("ready", None))  # the time limit counts from here
    warm = False
    while True:
        try:
            job: Any = None if warm or conn.poll(IDLE_BEFORE_WARM_UP) else WARM_UP
            job = conn.recv() if job is None else job
            if job == WARM_UP:
                # Idle, or a page opened: compile the kernels now, telling the server,
                # which does not count this time against an edit that arrives meanwhile.
                if not warm:
                    conn.send(("busy", None))
                    conn.send(("idle", _warm_up(lambda: frame_data(default.data, build_design(default)))))
                    warm = True
                continue
        except (EOFError, OSError):
            return
        if job is None:
            return
        data, source, base_dir = job
        try:
            built = build_design(Design(data, source, Path(base_dir)))
            # The page's arrays and figures are made here, while the server waits anyway: it
            # then only encodes them (and stays free for other requests meanwhile).
            frame = frame_data(data, built)
            # The smooth reference surface stays here: the server never measures with it (the
            # figures process builds its own), and the catalogue's references are closures,
            # which cannot be pickled.
            reply: tuple[str, Any] = ("ok", (dataclasses.replace(built, reference=None), frame))
        except RuledMeshError as exc:
            reply = ("error", exc)
        except MemoryError:
            reply = ("memory", None)
        except Exception as exc:  # noqa: BLE001 - reported to the page, never a dead worker
            reply = ("bug", f"{type(exc).__name__}: {exc}")
        try:
            conn.send(reply)
        except Exception:  # noqa: BLE001 - an unpicklable error: say so instead of hanging
            if reply[0] == "ok" and reply[1][0].extras:
                with contextlib.suppress(Exception):  # the extras are for reports only
                    conn.send(("ok", (dataclasses.replace(reply[1][0], extras={}), reply[1][1])))
                    continue
            try:
                conn.send(("bug", f"cannot return the result: {reply[0]}"))
            except OSError:
                return


def _warm_up(build: Any) -> bool:
    """Compile the mesher's kernels (or load them from the cache); whether they are in use.

    ``build`` builds the default design and makes its frame.  The worker
    holds the kernels (:func:`ruledmesh.kernels.hold`) until it is idle:
    compiling them (about 15 s on a new installation, a second from numba's
    cache) inside an edit would count against that edit's time limit and
    refuse it, which is what happened when a long session crossed
    :data:`~ruledmesh.kernels.MIN_WORK`.  One build inside
    :func:`~ruledmesh.kernels.everywhere` calls every kernel once.
    """
    from .. import kernels

    if not kernels.load():
        return False
    with kernels.everywhere():
        build()
    return True


def spawn_worker(ctx: Any, target: Any, name: str) -> tuple[Any, Any]:
    """Start ``target(conn)`` in a daemon process; its process and the parent's end of the pipe."""
    parent, child = ctx.Pipe()
    proc = ctx.Process(target=target, args=(child,), daemon=True, name=name)
    proc.start()
    child.close()
    return proc, parent


def stop_worker(proc: Any, conn: Any) -> None:
    """Kill a worker process (if any) and close its pipe."""
    if proc is not None:
        proc.kill()
        proc.join(timeout=5)
        conn.close()


class InProcessBuilder:
    """Builds in the calling thread (no time limit): a :class:`Session` used as a library.

    Generations work as in :class:`BuildWorker`, so concurrent edits from
    several threads still let only the newest one become current.
    """

    def __init__(self) -> None:
        self._state = threading.Lock()
        self._issued = 0
        self._cache: OrderedDict[str, Any] = OrderedDict()
        self.builds = 0  # designs built (not answered from the cache), for the tests

    def cached(self, data: dict, source: str, base_dir: str | Path) -> tuple[str | None, Any]:
        """``(key, (built, frame))``: the cached build of this design, or ``(key, None)``."""
        key = _cache_key(data, source, base_dir)
        if key is None:
            return None, None
        with self._state:
            built = self._cache.get(key)
            if built is not None:
                self._cache.move_to_end(key)
            return key, built

    def remember(self, key: str | None, built: Any) -> Any:
        """Keep ``built`` (a ``(built, frame)`` pair) as the build of ``key``; the oldest of
        :data:`BUILD_CACHE` goes."""
        with self._state:
            self.builds += 1
            if key is not None:
                self._cache[key] = built
                while len(self._cache) > BUILD_CACHE:
                    self._cache.popitem(last=False)
        return built

    def generation(self) -> int:
        """A new generation number, newer than every one before (one per edit)."""
        with self._state:
            self._issued += 1
            return self._issued

    def superseded(self, generation: int) -> bool:
        """Whether a newer generation has been handed out (a newer edit arrived)."""
        with self._state:
            return self._issued > generation

    def build(self, generation: int, data: dict, source: str, base_dir: str | Path) -> Any:
        """Build design ``data``; returns the :class:`~ruledmesh.registry.Built`."""
        return self.build_frame(generation, data, source, base_dir)[0]

    def build_frame(self, generation: int, data: dict, source: str,
                    base_dir: str | Path) -> tuple[Any, dict | None]:
        """Build design ``data`` here and now: ``(built, None)``.

        The page's message of it (:func:`~ruledmesh.web.session.frame_data`)
        is made by the session when asked for.
        """
        from ..design import Design, build_design

        key, hit = self.cached(data, source, base_dir)
        if hit is not None:
            return hit
        return self.remember(key, (build_design(Design(data, source, Path(base_dir))), None))

    def warm_up(self) -> None:
        """Nothing to prepare: the caller's process builds."""

    def close(self) -> None:
        """Nothing to stop."""


class BuildWorker(InProcessBuilder):
    """Builds designs in a separate process with a time limit.

    Parameters
    ----------
    timeout : float
        Seconds a build may take before it is stopped (:class:`BuildTimeout`).
    """

    def __init__(self, timeout: float = MAX_BUILD_SECONDS):
        super().__init__()
        self.timeout = float(timeout)
        self._ctx = mp.get_context("spawn")
        self._run_lock = threading.Lock()  # one job in the process at a time
        self._proc: Any = None
        self._conn: Any = None
        self._closed = False
        # One writer on the pipe at a time: an edit's job, a page's warm-up request.
        self._send = threading.Lock()
        # Set when a page opened: every worker started from then on loads the kernels at once.
        self._warm_wanted = False
        #: Whether the running worker builds with the compiled kernels (None: not yet known;
        #: the worker loads them at its first idle second, or at once when a page has opened,
        #: and says so with its next answer).
        self.kernels: bool | None = None

    # ---------------------------------------------------------------- process
    def _start(self) -> None:
        proc, parent = spawn_worker(self._ctx, _worker_main, "ruledmesh-build")
        self._proc, self._conn = proc, parent
        # Importing numpy and scipy takes a second or more on a busy machine, compiling the
        # kernels on a new installation 15 s or more: neither is build time.
        try:
            deadline = time.monotonic() + STARTUP_SECONDS
            while not parent.poll(0.05):
                if self._closed or time.monotonic() > deadline or not proc.is_alive():
                    raise EOFError
            if parent.recv()[0] != "ready":
                raise EOFError
            with self._send:
                if self._warm_wanted:
                    parent.send(WARM_UP)
        except (EOFError, OSError):
            self._stop()
            raise RuledMeshError("the build process did not start") from None

    def _stop(self) -> None:
        # Stopped outside the lock: a page's warm-up request (sent from the server's event
        # loop) never waits for a process to end; one sent meanwhile meets a closed pipe.
        with self._send:
            proc, conn = self._proc, self._conn
            self._proc = self._conn = None
        stop_worker(proc, conn)

    def warm_up(self) -> None:
        """Have the worker load the compiled kernels now, and every later worker at its start
        (a page opened: edits are coming), instead of at its first idle second."""
        with self._send:
            self._warm_wanted = True
            if self._conn is not None:
                with contextlib.suppress(OSError, ValueError):
                    self._conn.send(WARM_UP)

    def start(self) -> None:
        """Start the worker process now (so the first edit does not wait for it)."""
        with self._run_lock:
            if self._proc is None and not self._closed:
                try:
                    self._start()
                except RuledMeshError:
                    pass  # the first build tries again and reports it

    # ---------------------------------------------------------------- builds
    def build_frame(self, generation: int, data: dict, source: str,
                    base_dir: str | Path) -> tuple[Any, dict | None]:
        """Build design ``data`` in the worker: ``(built, frame_data)``.

        ``built`` is the :class:`~ruledmesh.registry.Built` (without its smooth
        reference), ``frame_data`` the page's message parts made in the worker
        (:func:`~ruledmesh.web.session.frame_data`).

        Raises
        ------
        Superseded
            A newer generation asked to build meanwhile.
        BuildTimeout
            The build took longer than :attr:`timeout`; the worker was restarted.
        RuledMeshError
            The design does not build (the same error as in the process itself).
        """
        if self.superseded(generation):
            raise Superseded("superseded by a newer edit")
        key, hit = self.cached(data, source, base_dir)
        if hit is not None:
            return hit
        with self._run_lock:
            if self._closed:
                raise Superseded("the designer is stopping")
            if self.superseded(generation):
                raise Superseded("superseded by a newer edit")
            if self._proc is None or not self._proc.is_alive():
                self._stop()
                self._start()
            return self.remember(key, self._wait(generation, (data, source, str(base_dir))))

    def _wait(self, generation: int, job: tuple) -> Any:
        started = time.monotonic()
        # When the worker said it is compiling the kernels (0: it is not).  It says "busy" and
        # "idle" before it reads the next job, so both arrive while one edit waits.
        paused = 0.0
        try:
            with self._send:
                self._conn.send(job)
            while True:
                if self._conn.poll(0.02):
                    kind, value = self._conn.recv()
                    if kind == "busy":          # compiling the kernels: not this edit's time
                        paused = time.monotonic()
                        continue
                    if kind == "idle":
                        started += time.monotonic() - max(paused, started)
                        paused = 0.0
                        self.kernels = bool(value)
                        continue
                    break
                now = time.monotonic()
                if paused:
                    if now - paused > STARTUP_SECONDS:
                        raise EOFError
                    elapsed = max(paused, started) - started
                else:
                    elapsed = now - started
                if elapsed > self.timeout:
                    self._stop()
                    raise BuildTimeout(f"the build took longer than {self.timeout:g} s and was "
                                       "stopped; reduce the generator count or the rows")
                # Not while the kernels compile: a new worker would compile them again.
                if self._closed or (not paused and now - started > SUPERSEDE_GRACE
                                    and self.superseded(generation)):
                    self._stop()
                    raise Superseded("superseded by a newer edit")
                if not self._proc.is_alive():
                    raise EOFError
        except (EOFError, OSError):
            self._stop()
            raise RuledMeshError("the build process stopped unexpectedly (out of memory?); "
                                 "reduce the counts in the design") from None
        if self.superseded(generation):
            raise Superseded("superseded by a newer edit")
        if kind == "ok":
            return value
        if kind == "error":
            raise value
        if kind == "memory":
            raise MemoryError
        raise RuntimeError(value)

    def close(self) -> None:
        """Stop the worker process (a running build is abandoned)."""
        self._closed = True
        with self._run_lock:
            self._stop()
