"""The exception hierarchy of ruledmesh.

Every error the library raises on purpose derives from :class:`RuledMeshError`;
the ones caused by a bad value also derive from :class:`ValueError`, so code
that already catches ``ValueError`` keeps working.  The CLI turns any of them
into a one-line message and exit code 2.
"""

from __future__ import annotations

import unicodedata

__all__ = [
    "printable",
    "RuledMeshError",
    "DesignError",
    "ParameterError",
    "GeometryError",
    "ExportError",
    "RuledMeshWarning",
]


# Longest user-supplied text (a key, a name, a value) echoed in a message.
MAX_ECHO = 80
# Longest message as a whole: one line a terminal can still show.
MAX_MESSAGE = 2000


def printable(text: str, limit: int | None = MAX_ECHO) -> str:
    """``text`` safe to print on one line: control characters escaped, cut with an ellipsis.

    Newlines, tabs, terminal escapes and invisible format characters (such as the
    right-to-left override U+202E) are shown as Python escapes (``\\n``, ``\\u202e``),
    so a message stays one line and reads the same in every terminal.

    >>> printable("a\\nb\\u202e")
    'a\\\\nb\\\\u202e'
    >>> printable("x" * 100, 10)
    'xxxxxxxxx…'
    """
    text = str(text)
    if limit is not None and len(text) > limit:
        text = text[:max(limit - 1, 0)] + "…"
    if text.isprintable():
        return text
    out = []
    for ch in text:
        if ch.isprintable() or (ch == " "):
            out.append(ch)
        elif unicodedata.category(ch) in ("Zs",):
            out.append(" ")
        else:
            out.append(ch.encode("unicode_escape").decode("ascii"))
    return "".join(out)


class RuledMeshError(Exception):
    """Base class of every error ruledmesh raises on purpose."""


class _FieldError(RuledMeshError, ValueError):
    """An error about one named field: ``source: field: detail``.

    Parameters
    ----------
    message : str
        What was expected and what was found.
    path : str, optional
        The parameter name or dotted field path, e.g. ``"rulings.count"``.
    source : str, optional
        The file name the field comes from.
    """

    def __init__(self, message: str, path: str | None = None, source: str | None = None):
        self.field = path
        self.source = source
        self.detail = message
        super().__init__(self._format())

    def _format(self) -> str:
        parts = []
        if self.source:
            parts.append(printable(self.source, 240))
        if self.field:
            parts.append(printable(self.field, 240))
        parts.append(printable(self.detail, MAX_MESSAGE))
        return ": ".join(parts)

    def with_source(self, source: str) -> _FieldError:
        """Return the same error attributed to the file ``source``."""
        return type(self)(self.detail, self.field, source)

    def within(self, prefix: str) -> _FieldError:
        """Return the same error with ``prefix`` prepended to its field path."""
        path = f"{prefix}.{self.field}" if self.field else prefix
        return type(self)(self.detail, path, self.source)


class ParameterError(_FieldError):
    """A function argument has the wrong type, shape or value.

    The message names the parameter and what was received.
    """


class DesignError(_FieldError):
    """A design file is malformed; the message names the file and the field."""


class GeometryError(RuledMeshError, ValueError):
    """The geometry cannot be meshed as asked (degenerate, out of range, ...)."""


class ExportError(RuledMeshError):
    """A mesh cannot be written in the requested format."""


class RuledMeshWarning(UserWarning):
    """A result was written but loses something the user should know about
    (e.g. float32 precision at site coordinates); the CLI prints it as a warning."""
