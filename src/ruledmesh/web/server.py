"""The designer's HTTP server: static page plus a small JSON/binary API.

Standard library only (:class:`http.server.ThreadingHTTPServer`).  The API:

==========================  ==================================================
``GET /api/state``          binary message: state, fast figures, mesh arrays
``POST /api/edit``          ``{"changes": [[path, value], ...], "coalesce"}``
``POST /api/design``        ``{"design": {...}}`` or ``{"toml": "..."}``
``POST /api/undo``, ``/api/redo``
``POST /api/save``          ``{"path": optional}`` -> ``{"path"}``
``POST /api/export``        ``{"format": ".obj", "path": optional}`` -> ``{"path"}``
``GET /api/download?format=.glb``  the exported bytes as a download
``GET /api/figures?version=N``     binary message: closeness, coverage, panels
==========================  ==================================================

Edits answer like ``GET /api/state`` (one round trip per change).  Errors
answer ``{"error": message}`` with status 400 (bad edit) or 500 (a bug); the
state is unchanged and the server keeps running.

Safety: the server binds 127.0.0.1 unless another host is given explicitly;
on a loopback address it also refuses requests whose ``Host`` header is not a
loopback name (DNS rebinding) and POSTs that are not ``application/json`` or
come from another origin (cross-site requests from other pages).
"""

from __future__ import annotations

import ipaddress
import json
import mimetypes
import threading
import time
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

import numpy as np

from ..errors import RuledMeshError
from .figures import FigureWorker
from .session import DEFAULT_DESIGN, Session, encode_message

__all__ = ["DesignerServer", "make_server", "DEFAULT_HOST", "MAX_BODY"]

DEFAULT_HOST = "127.0.0.1"
MAX_BODY = 16 * 1024 * 1024
_LOOPBACK_NAMES = {"localhost", "127.0.0.1", "::1", "[::1]"}


def _static_root() -> Path:
    return Path(str(resources.files("ruledmesh.web").joinpath("static")))


def _is_loopback(host: str) -> bool:
    if host in _LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


class DesignerServer(ThreadingHTTPServer):
    """A :class:`ThreadingHTTPServer` holding one :class:`Session`.

    Parameters
    ----------
    session : Session
    host : str
        Interface to bind (default loopback only).
    port : int
        0 picks a free port; see :attr:`url`.
    """

    daemon_threads = True
    allow_reuse_address = True

    def __init__(self, session: Session, host: str = DEFAULT_HOST, port: int = 0):
        if ":" in host.strip("[]"):
            self.address_family = __import__("socket").AF_INET6
        super().__init__((host.strip("[]"), port), _Handler)
        self.session = session
        self.loopback = _is_loopback(host)
        self.static_root = _static_root()
        self._figures: FigureWorker | None = None
        self._figures_lock = threading.Lock()

    def handle_error(self, request, client_address) -> None:
        """A client that went away mid-answer is normal (page reloaded); others go to stderr."""
        import sys

        if isinstance(sys.exc_info()[1], (BrokenPipeError, ConnectionResetError)):
            return
        super().handle_error(request, client_address)

    @property
    def url(self) -> str:
        """``http://host:port/`` of the page."""
        host, port = self.server_address[:2]
        if ":" in host:
            host = f"[{host}]"
        return f"http://{host}:{port}/"

    def figures(self) -> FigureWorker:
        with self._figures_lock:
            if self._figures is None:
                self._figures = FigureWorker()
            return self._figures

    def server_close(self) -> None:
        super().server_close()
        with self._figures_lock:
            if self._figures is not None:
                self._figures.close()
                self._figures = None


def make_server(session: Session, host: str = DEFAULT_HOST, port: int = 0) -> DesignerServer:
    """A :class:`DesignerServer` bound to ``host:port`` (not yet serving)."""
    return DesignerServer(session, host, port)


class _HttpError(Exception):
    def __init__(self, status: int, message: str):
        super().__init__(message)
        self.status = status


class _Handler(BaseHTTPRequestHandler):
    server: DesignerServer
    protocol_version = "HTTP/1.1"
    # Headers and body go out in two writes; with Nagle's algorithm the second waits for the
    # client's delayed ACK (~40 ms per request on Linux), a third of the 100 ms budget.
    disable_nagle_algorithm = True
    server_version = "ruledmesh-designer"

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 - stdlib signature
        pass  # quiet: the CLI prints the URL; per-request logs would flood the terminal

    # ------------------------------------------------------------ replies
    def _send(self, status: int, body: bytes, ctype: str, extra: dict | None = None) -> None:
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        for k, v in (extra or {}).items():
            self.send_header(k, v)
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def _json(self, status: int, obj: Any) -> None:
        self._send(status, json.dumps(obj).encode("utf-8"), "application/json")

    def _error(self, status: int, message: str) -> None:
        self._json(status, {"error": message})

    # ------------------------------------------------------------ checks
    def _check_host(self) -> None:
        if not self.server.loopback:
            return
        host = self.headers.get("Host", "")
        name = host.rsplit(":", 1)[0] if not host.endswith("]") else host
        if name.lower() not in _LOOPBACK_NAMES and not _is_loopback(name):
            raise _HttpError(HTTPStatus.FORBIDDEN, f"refused: Host {host!r} is not this machine")

    def _body(self) -> dict:
        ctype = self.headers.get("Content-Type", "").split(";")[0].strip().lower()
        if ctype != "application/json":
            raise _HttpError(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, "expected application/json")
        origin = self.headers.get("Origin")
        if origin and self.server.loopback:
            oh = urlsplit(origin).hostname or ""
            if not _is_loopback(oh):
                raise _HttpError(HTTPStatus.FORBIDDEN, f"refused: request from {origin}")
        try:
            length = int(self.headers.get("Content-Length", "0"))
        except ValueError:
            raise _HttpError(HTTPStatus.BAD_REQUEST, "bad Content-Length") from None
        if length < 0 or length > MAX_BODY:
            raise _HttpError(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, "request too large")
        raw = self.rfile.read(length) if length else b"{}"
        try:
            body = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise _HttpError(HTTPStatus.BAD_REQUEST, f"invalid JSON: {exc}") from None
        if not isinstance(body, dict):
            raise _HttpError(HTTPStatus.BAD_REQUEST, "expected a JSON object")
        return body

    # ------------------------------------------------------------ dispatch
    def _handle(self, method: str) -> None:
        self._started = time.perf_counter()
        try:
            self._check_host()
            url = urlsplit(self.path)
            if url.path.startswith("/api/"):
                name = url.path[5:]
                fn = getattr(self, f"_{method}_{name}", None)
                if fn is None:
                    raise _HttpError(HTTPStatus.NOT_FOUND, f"no API {method.upper()} {url.path}")
                if method == "post":
                    fn(self._body())
                else:
                    fn(parse_qs(url.query))
            elif method == "get":
                self._static(url.path)
            else:
                raise _HttpError(HTTPStatus.NOT_FOUND, f"no such path {url.path}")
        except _HttpError as exc:
            self._error(exc.status, str(exc))
        except RuledMeshError as exc:
            self._error(HTTPStatus.BAD_REQUEST, str(exc))
        except (BrokenPipeError, ConnectionResetError):
            pass
        except MemoryError:
            self._error(HTTPStatus.BAD_REQUEST, "out of memory; reduce the counts in the design")
        except Exception as exc:  # noqa: BLE001 - a bug must not stop the server
            self._error(HTTPStatus.INTERNAL_SERVER_ERROR,
                        f"internal error: {type(exc).__name__}: {exc}")

    def do_GET(self) -> None:  # noqa: N802 - stdlib name
        self._handle("get")

    def do_HEAD(self) -> None:  # noqa: N802 - stdlib name
        self._handle("get")

    def do_POST(self) -> None:  # noqa: N802 - stdlib name
        self._handle("post")

    # ------------------------------------------------------------ static
    def _static(self, path: str) -> None:
        if path in ("", "/"):
            path = "/index.html"
        root = self.server.static_root.resolve()
        target = (root / path.lstrip("/")).resolve()
        if not target.is_relative_to(root) or not target.is_file():
            raise _HttpError(HTTPStatus.NOT_FOUND, f"no such file {path}")
        ctype = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        if target.suffix == ".js":
            ctype = "text/javascript"
        self._send(HTTPStatus.OK, target.read_bytes(), f"{ctype}; charset=utf-8"
                   if ctype.startswith("text/") else ctype)

    # ------------------------------------------------------------ API
    def _state(self) -> None:
        body = self.server.session.payload()
        ms = (time.perf_counter() - self._started) * 1000
        # Server-Timing lets the page tell server time (build + encode) from its own.
        self._send(HTTPStatus.OK, body, "application/octet-stream",
                   {"Server-Timing": f"app;dur={ms:.1f}"})

    def _get_state(self, query: dict) -> None:
        self._state()

    def _post_edit(self, body: dict) -> None:
        changes = body.get("changes")
        if not isinstance(changes, list) or not all(
                isinstance(c, list) and len(c) == 2 for c in changes):
            raise _HttpError(HTTPStatus.BAD_REQUEST, "expected changes: [[path, value], ...]")
        coalesce = body.get("coalesce")
        self.server.session.edit([(p, v) for p, v in changes],
                                 coalesce=str(coalesce) if coalesce else None)
        self._state()

    def _post_design(self, body: dict) -> None:
        if "toml" in body:
            if not isinstance(body["toml"], str):
                raise _HttpError(HTTPStatus.BAD_REQUEST, "expected toml: a string")
            self.server.session.load_text(body["toml"])
        elif body.get("default") is True:
            self.server.session.load_text(DEFAULT_DESIGN)
        elif isinstance(body.get("design"), dict):
            self.server.session.replace(body["design"])
        else:
            raise _HttpError(HTTPStatus.BAD_REQUEST, "expected design: {...} or toml: \"...\"")
        self._state()

    def _post_undo(self, body: dict) -> None:
        self.server.session.undo()
        self._state()

    def _post_redo(self, body: dict) -> None:
        self.server.session.redo()
        self._state()

    def _post_save(self, body: dict) -> None:
        path = self.server.session.save(body.get("path") or None)
        self._json(HTTPStatus.OK, {"path": str(path)})

    def _post_export(self, body: dict) -> None:
        fmt = body.get("format")
        if not isinstance(fmt, str) or not fmt:
            raise _HttpError(HTTPStatus.BAD_REQUEST, "expected format, e.g. \".obj\"")
        path = self.server.session.export(fmt, body.get("path") or None)
        self._json(HTTPStatus.OK, {"path": str(path)})

    def _get_download(self, query: dict) -> None:
        fmt = (query.get("format") or [""])[0]
        if not fmt:
            raise _HttpError(HTTPStatus.BAD_REQUEST, "expected ?format=.obj")
        session = self.server.session
        data = session.export_bytes(fmt)
        ext = fmt.lower() if fmt.startswith(".") else f".{fmt.lower()}"
        stem = session.path.stem if session.path else str(session.design.get("name") or "design")
        safe = "".join(c for c in stem if c.isalnum() or c in "-_.") or "design"
        self._send(HTTPStatus.OK, data, "application/octet-stream",
                   {"Content-Disposition": f'attachment; filename="{safe}{ext}"'})

    def _stale(self, version: int) -> None:
        self._send(HTTPStatus.OK, encode_message({"version": version, "stale": True}, []),
                   "application/octet-stream")

    def _get_figures(self, query: dict) -> None:
        session = self.server.session
        try:
            version = int((query.get("version") or [session.version])[0])
        except ValueError:
            raise _HttpError(HTTPStatus.BAD_REQUEST, "expected version=<integer>") from None
        current, data = session.snapshot()
        if version != current:
            self._stale(version)
            return
        result = self.server.figures().request(version, data, session.source, session.base_dir)
        if result is None:
            self._stale(version)
            return
        figures, per_face, error = result
        arrays = [] if per_face is None else [("closeness", np.asarray(per_face, np.float32))]
        self._send(HTTPStatus.OK, encode_message(
            {"version": version, "figures": figures, "error": error}, arrays),
            "application/octet-stream")
