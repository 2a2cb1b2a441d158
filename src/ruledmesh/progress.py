"""Progress reports from long library calls, shown by whoever calls them.

Library functions that can take more than a moment (building a design,
analysing a mesh, writing fabrication sheets) accept ``progress=``: an object
with a :meth:`Progress.task` method.  They announce what they are doing and
never print; the default, :data:`SILENT`, does nothing at all.  The command
line passes a :class:`TerminalProgress`, which draws `tqdm
<https://tqdm.github.io>`_ bars on stderr, and only when stderr is a terminal.

A notebook or another program can pass its own subclass of :class:`Progress`::

    class Log(Progress):
        def task(self, label, total=None):
            print("start", label)
            return Task()

Tasks are context managers; ``advance(n, note)`` moves a counted task on and
may change the text shown after its label (the current stage).

>>> with SILENT.task("build", total=3) as task:
...     task.advance(note="generators")
"""

from __future__ import annotations

import io
import os
import sys
import threading
from typing import Any, TextIO

__all__ = ["SILENT", "Progress", "Task", "TerminalProgress", "stages"]


class Task:
    """One announced piece of work; this base class ignores every report."""

    def advance(self, n: int = 1, note: str | None = None) -> None:
        """``n`` more units are done; ``note`` names what runs now (optional)."""

    def close(self) -> None:
        """The work is over (called by ``with`` on exit)."""

    def __enter__(self) -> Task:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Progress:
    """Receives progress reports; this base class ignores them (:data:`SILENT`)."""

    def task(self, label: str, total: int | None = None) -> Task:
        """Announce work called ``label`` of ``total`` units (``None``: not counted).

        Parameters
        ----------
        label : str
            What is being done, e.g. ``"build"`` or ``"sheets"``.
        total : int, optional
            Number of :meth:`Task.advance` units the work has.

        Returns
        -------
        Task
        """
        return Task()


SILENT = Progress()


def stages(progress: Progress | None, label: str, names: list[str]):
    """A counted task over named stages: ``advance(note=next)`` after each.

    Returns a :class:`Task` whose note starts at ``names[0]``; a ``None``
    ``progress`` means :data:`SILENT`.
    """
    task = (progress or SILENT).task(label, total=len(names))
    if names:
        task.advance(0, names[0])
    return task


class _BarTask(Task):
    def __init__(self, owner: TerminalProgress, bar: Any, label: str):
        self._owner, self._bar, self._label = owner, bar, label

    def advance(self, n: int = 1, note: str | None = None) -> None:
        if note is not None:
            self._bar.set_description_str(f"{self._label} ({note})", refresh=False)
        if n:
            self._bar.update(n)
        else:
            self._bar.refresh()

    def close(self) -> None:
        self._owner._forget(self._bar)
        self._bar.close()


# A counted task shows a bar; an uncounted one only its label and elapsed time.  Short
# lists of stages of unequal length get no time estimate (it would mislead).
_COUNTED = "{desc}: {percentage:3.0f}%|{bar:24}| {n_fmt}/{total_fmt} [{elapsed}<{remaining}]"
_STAGES = "{desc}: {percentage:3.0f}%|{bar:24}| {n_fmt}/{total_fmt} [{elapsed}]"
_UNCOUNTED = "{desc} [{elapsed}]"
_FEW = 8


class TerminalProgress(Progress):
    """tqdm bars on a terminal; nothing at all when the stream is not one.

    A background thread redraws the open bars twice a second, so the elapsed
    time keeps moving during a long single stage (the mesher, a big export)
    that reports nothing until it ends.

    Parameters
    ----------
    enabled : bool
        ``False`` (``-q``, ``--json``) silences it.
    stream : text stream, optional
        Where to draw (default ``sys.stderr``); nothing is drawn unless it is
        a terminal.
    """

    def __init__(self, enabled: bool = True, stream: TextIO | None = None):
        self.stream = sys.stderr if stream is None else stream
        isatty = getattr(self.stream, "isatty", None)
        self.enabled = bool(enabled and isatty is not None and isatty())
        self._bars: list[Any] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None

    def task(self, label: str, total: int | None = None) -> Task:
        if not self.enabled:
            return Task()
        from tqdm import tqdm

        # A terminal that reports no size (a fresh pseudo-terminal) would hide every bar.
        size = self._size()
        bar = tqdm(desc=label, total=total, file=self.stream, leave=False,
                   dynamic_ncols=size is None, ncols=size and size[0], nrows=size and size[1],
                   bar_format=(_UNCOUNTED if not total else _STAGES if total <= _FEW
                               else _COUNTED), mininterval=0.2)
        with self._lock:
            self._bars.append(bar)
            if self._ticker is None:
                # A fresh event per ticker: a stopping one never sees it cleared.
                self._stop = threading.Event()
                self._ticker = threading.Thread(target=self._tick, args=(self._stop,),
                                                daemon=True, name="ruledmesh-progress")
                self._ticker.start()
        return _BarTask(self, bar, label)

    def close(self) -> None:
        """Close every bar still open (work an error interrupted) and stop redrawing."""
        with self._lock:
            bars = list(self._bars)
        for bar in bars:
            self._forget(bar)
            bar.close()

    def _size(self) -> tuple[int, int] | None:
        """``None`` (follow the terminal) unless it reports a zero size, then 80 x 24."""
        try:
            size = os.get_terminal_size(self.stream.fileno())
        except (AttributeError, OSError, ValueError, io.UnsupportedOperation):
            return None
        return None if size.columns > 0 and size.lines > 0 else (80, 24)

    def _forget(self, bar: Any) -> None:
        with self._lock:
            if bar in self._bars:
                self._bars.remove(bar)
            if not self._bars and self._ticker is not None:
                self._stop.set()
                self._ticker = None

    def _tick(self, stop: threading.Event) -> None:
        while not stop.wait(0.5):
            with self._lock:
                bars = list(self._bars)
            for bar in bars:
                bar.refresh()
