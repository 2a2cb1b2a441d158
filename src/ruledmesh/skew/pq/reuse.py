"""Meshes of the same runs assembled once.

A design build weighs many meshes of one set of generators: two checkerboards, three
primaries, the even, graded and bounded divisions, rows from either director curve
(:mod:`ruledmesh.design.pq`).  Options that differ often give the same runs: on a
short line set the middle generator is a third of the way in, the bound on the graded
division is not reached, the rows through the end points are the rows from the
primary.  Of 2,373 meshes that 150 random line sets of 3-9 generators made, 1,487 were
the same as one made before from other options.  Assembling the runs and the passes
that follow (:func:`~.assemble.assemble`, ``_fattened``) is about two thirds of a
mesh's time and depends on the runs alone, so inside :func:`reusing_assemblies` it is
done once per distinct set of runs.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import hashlib
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

# Digest of the runs and the other inputs -> (mesh, fattening counts, measured, spans,
# warnings the stage added), while a caller keeps them (reusing_assemblies).
_ASSEMBLED: contextvars.ContextVar[dict[str, tuple] | None] = contextvars.ContextVar(
    "pq_assembled", default=None)


@contextlib.contextmanager
def reusing_assemblies() -> Iterator[dict[str, tuple]]:
    """Meshers called inside assemble each distinct set of runs once.

    The store lives as long as the block: a design build holds the meshes it weighs
    anyway, and the store holds nothing else of size.
    """
    store: dict[str, tuple] = {}
    token = _ASSEMBLED.set(store)
    try:
        yield store
    finally:
        _ASSEMBLED.reset(token)


def runs_digest(parts: Sequence[Any], arrays: Sequence[np.ndarray], values: Sequence[Any]) -> str | None:
    """The key of an assembly: every field of every run (:class:`~.runs.Run`), the
    ``arrays`` (bytes, dtype and shape) and the ``values`` (by ``repr``); ``None`` outside
    :func:`reusing_assemblies`.

    Every field is hashed, whatever the run holds, so a field added to the runs later
    cannot be missed by the key.
    """
    if _ASSEMBLED.get() is None:
        return None
    h = hashlib.blake2b(digest_size=20)
    for part in parts:
        h.update(type(part).__name__.encode())
        for f in dataclasses.fields(part):
            _update(h, getattr(part, f.name))
    for x in arrays:
        _update(h, x)
    h.update(repr(tuple(values)).encode())
    return h.hexdigest()


def _update(h: Any, x: Any) -> None:
    if isinstance(x, np.ndarray):
        h.update(f"{x.dtype.str}{x.shape}".encode())
        h.update(np.ascontiguousarray(x).tobytes())
    else:
        h.update(repr(x).encode())
    h.update(b"|")


def assembled(key: str | None) -> tuple | None:
    """What :func:`remember` kept under ``key``, if anything."""
    store = _ASSEMBLED.get()
    return None if store is None or key is None else store.get(key)


def remember(key: str | None, result: tuple) -> None:
    """Keep ``result`` under ``key`` while a caller is :func:`reusing_assemblies`."""
    store = _ASSEMBLED.get()
    if store is not None and key is not None:
        store[key] = result
