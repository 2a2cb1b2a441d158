"""Designer builds in a worker process: a hard time limit and supersession by newer edits.

A build runs in Python code that cannot be interrupted from another thread, so
the only honest time limit is a process that can be terminated.  The server
sends each candidate design to one long-lived worker process (started with
``spawn``: a threaded server is never forked) and waits for the built result
off the event loop.  The worker is killed and restarted when

- the build takes longer than the limit (the edit is refused with the figure),
- a build asked to stop (a newer edit superseded it) does not stop within
  :data:`CANCEL_SECONDS`.

A build the server no longer wants (a newer edit superseded it, or an edit
arrives while a background refinement runs) is asked to stop with a
:data:`CANCEL` message, which the worker reads between two meshes of the
refinement: the process, its imports and its compiled kernels stay.

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
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import RuledMeshError
from ..progress import Progress, Task

__all__ = ["MAX_BUILD_SECONDS", "BuildTimeout", "BuildWorker", "InProcessBuilder", "Superseded"]

# Wall-clock limit of one designer build (the CLI has none: it is the user's own job there).
MAX_BUILD_SECONDS = 20.0
# Seconds a build asked to stop (CANCEL) may take to stop before its worker is killed: it
# stops between two meshes of the refinement (tens of milliseconds at designer sizes), and a
# killed worker costs the next edit a new process (imports and kernels, a second or more).
CANCEL_SECONDS = 2.0
# The message asking the worker to drop the build it runs.
CANCEL = "cancel"
# A long build tells the server what it is at (the refinement's mesh) at most this often.
PROGRESS_SECONDS = 0.25
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


class _Cancelled(Exception):
    """Raised inside the worker's build when the server asked it to stop (not a
    :class:`RuledMeshError`: no layer of the build reports it as the design's fault)."""


class _Listening(Progress):
    """Build progress that reads the server's messages between the stages of a build, and
    tells the server what the build is at.

    Every mesh the refinement makes is a stage (:func:`ruledmesh.design.pq._mesh`), so
    a :data:`CANCEL` stops a long build within one mesh.  A :data:`WARM_UP` that comes
    meanwhile is remembered for when the build is over.  The stage's note ("mesh 7, 60
    generators") goes to the server as ``("progress", note)``, at most every
    :data:`PROGRESS_SECONDS`.
    """

    def __init__(self, conn: Any):
        self.conn = conn
        self.warm_up = False
        self.said = time.monotonic()

    def tell(self, note: str | None) -> None:
        now = time.monotonic()
        if note and now - self.said >= PROGRESS_SECONDS:
            self.said = now
            self.conn.send(("progress", note))

    def task(self, label: str, total: int | None = None) -> Task:
        return _ListeningTask(self)

    def check(self) -> None:
        while self.conn.poll():
            message = self.conn.recv()
            if message == CANCEL:
                raise _Cancelled
            if message == WARM_UP:
                self.warm_up = True


class _ListeningTask(Task):
    def __init__(self, owner: _Listening):
        self.owner = owner

    def advance(self, n: int = 1, note: str | None = None) -> None:
        self.owner.check()
        self.owner.tell(note)


def _worker_main(conn) -> None:  # pragma: no cover - runs in the child process
    from .. import kernels
    from ..design import Design, build_design, parse_design
    from ..design.pq import keeping_meshes
    from ..registry import load_plugins
    from .session import DEFAULT_DESIGN, frame_data

    load_plugins()
    kernels.hold()
    default = parse_design(DEFAULT_DESIGN)
    frame_data(default.data, build_design(default))  # imports the mesher's modules (lazy elsewhere)
    conn.send(("ready", None))  # the time limit counts from here
    warm = False
    asked = False  # a page asked for the kernels while a build ran
    # The meshes of the last build that made just one (a quick mesh: the session builds the
    # design in full next, and its refinement starts from that mesh).
    kept: dict = {}
    while True:
        try:
            job: Any = WARM_UP if asked else None
            job = job or (None if warm or conn.poll(IDLE_BEFORE_WARM_UP) else WARM_UP)
            job = conn.recv() if job is None else job
            asked = False
            if job == CANCEL:
                continue  # the build it was meant for had already answered
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
        listening = _Listening(conn)
        made = dict(kept)
        try:
            with keeping_meshes(made):
                built = build_design(Design(data, source, Path(base_dir)), listening)
            # The page's arrays and figures are made here, while the server waits anyway: it
            # then only encodes them (and stays free for other requests meanwhile).
            frame = frame_data(data, built)
            # The smooth reference surface stays here: the server never measures with it (the
            # figures process builds its own), and the catalogue's references are closures,
            # which cannot be pickled.
            reply: tuple[str, Any] = ("ok", (dataclasses.replace(built, reference=None), frame))
        except _Cancelled:
            reply = ("cancelled", None)
        except (EOFError, OSError):
            return
        except RuledMeshError as exc:
            reply = ("error", exc)
        except MemoryError:
            reply = ("memory", None)
        except Exception as exc:  # noqa: BLE001 - reported to the page, never a dead worker
            reply = ("bug", f"{type(exc).__name__}: {exc}")
        asked = listening.warm_up
        kept = made if len(made) == 1 else {}
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
    compiling them (30-35 s on a new installation, a second from numba's
    cache) inside an edit would count against that edit's time limit and
    refuse it, which is what happened when a long session crossed
    :data:`~ruledmesh.kernels.MIN_WORK`.  One build inside
    :func:`~ruledmesh.kernels.everywhere` calls every kernel once ...
    """
    from .. import kernels

    if not kernels.load():
        return False
    with kernels.everywhere():
        build()
        # ... every kernel but the collapses', which that design may not reach.
        from ..skew.pq.collapses import warm

        warm()
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
        #: Seconds the last design built took (the wait for a worker's kernels not counted).
        self.last_seconds = 0.0

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
        return self._here(data, source, base_dir)

    def refine_frame(self, data: dict, source: str, base_dir: str | Path,
                     progress: Callable[[str], None] | None = None) -> tuple[Any, dict | None] | None:
        """Build design ``data`` here and now, as :meth:`build_frame` (nothing else waits
        for this builder, so it never gives the build up: never None; ``progress`` is not
        told anything)."""
        return self._here(data, source, base_dir)

    def _here(self, data: dict, source: str, base_dir: str | Path) -> tuple[Any, dict | None]:
        from ..design import Design, build_design

        key, hit = self.cached(data, source, base_dir)
        if hit is not None:
            return hit
        started = time.perf_counter()
        built = build_design(Design(data, source, Path(base_dir)))
        self.last_seconds = time.perf_counter() - started
        return self.remember(key, (built, None))

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
        # Edits waiting for the worker or building in it: a background build gives way to them.
        self._foreground = 0
        #: Whether the running worker builds with the compiled kernels (None: not yet known;
        #: the worker loads them at its first idle second, or at once when a page has opened,
        #: and says so with its next answer).
        self.kernels: bool | None = None

    # ---------------------------------------------------------------- process
    def _start(self) -> None:
        proc, parent = spawn_worker(self._ctx, _worker_main, "ruledmesh-build")
        self._proc, self._conn = proc, parent
        # Importing numpy and scipy takes a second or more on a busy machine, compiling the
        # kernels on a new installation 30 s or more: neither is build time.
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
        (:func:`~ruledmesh.web.session.frame_data`).  A background build
        (:meth:`refine_frame`) running meanwhile is asked to stop.

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
        with self._state:
            self._foreground += 1
        try:
            with self._run_lock:
                if self._closed:
                    raise Superseded("the designer is stopping")
                if self.superseded(generation):
                    raise Superseded("superseded by a newer edit")
                built = self._run((data, source, str(base_dir)), lambda: self.superseded(generation))
        finally:
            with self._state:
                self._foreground -= 1
        if built is None or self.superseded(generation):
            raise Superseded("superseded by a newer edit")
        return self.remember(key, built)

    def refine_frame(self, data: dict, source: str, base_dir: str | Path,
                     progress: Callable[[str], None] | None = None) -> tuple[Any, dict | None] | None:
        """Build design ``data`` in the worker when no edit waits for it: ``(built,
        frame_data)``, or None where an edit asked for the worker before it was done
        (the build was stopped, the worker kept).

        The session's background work (the full build of a design whose quick
        preview is shown): any :meth:`build_frame` goes first.  ``progress(note)``
        is told what the build is at (``"mesh 7, 60 generators"``).
        """
        key, hit = self.cached(data, source, base_dir)
        if hit is not None:
            return hit
        with self._run_lock:
            if self._closed or self._foreground:
                return None
            built = self._run((data, source, str(base_dir)), lambda: self._foreground > 0, progress)
        return None if built is None else self.remember(key, built)

    def _run(self, job: tuple, unwanted: Any, progress: Callable[[str], None] | None = None) -> Any:
        """``job``'s ``(built, frame)`` from the worker (started if need be), or None where
        ``unwanted()`` turned true and the build stopped; under the run lock."""
        if self._proc is None or not self._proc.is_alive():
            self._stop()
            self._start()
        return self._wait(job, unwanted, progress)

    def _wait(self, job: tuple, unwanted: Any, progress: Callable[[str], None] | None = None) -> Any:
        started = time.monotonic()
        # When the worker said it is compiling the kernels (0: it is not).  It says "busy" and
        # "idle" before it reads the next job, so both arrive while one edit waits.
        paused = 0.0
        cancelled = 0.0  # when the build was asked to stop (0: it was not)
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
                    if kind == "progress":
                        if progress is not None and not cancelled:
                            with contextlib.suppress(Exception):  # a listener's bug: not the build's
                                progress(str(value))
                        continue
                    break
                now = time.monotonic()
                if paused:
                    if now - paused > STARTUP_SECONDS:
                        raise EOFError
                    elapsed = max(paused, started) - started
                else:
                    elapsed = now - started
                if self._closed:
                    self._stop()
                    raise Superseded("the designer is stopping")
                if cancelled and now - cancelled > CANCEL_SECONDS:
                    self._stop()        # it did not stop between two meshes: a long mesh
                    return None
                if elapsed > self.timeout:
                    self._stop()
                    raise BuildTimeout(f"the build took longer than {self.timeout:g} s and was "
                                       "stopped; reduce the generator count or the rows")
                # Not while the kernels compile: the worker reads the request after them.
                if not cancelled and not paused and unwanted():
                    cancelled = now
                    with self._send:
                        self._conn.send(CANCEL)
                if not self._proc.is_alive():
                    raise EOFError
        except (EOFError, OSError):
            self._stop()
            raise RuledMeshError("the build process stopped unexpectedly (out of memory?); "
                                 "reduce the counts in the design") from None
        if kind == "cancelled" or unwanted():
            return None
        if kind == "ok":
            self.last_seconds = time.monotonic() - started   # started moved past the pauses
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
