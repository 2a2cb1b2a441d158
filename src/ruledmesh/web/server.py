"""The designer's HTTP server: the static page plus a small JSON/binary API.

A Starlette application served by uvicorn (the optional extra ``web``).  The
HTTP parsing is h11's, which never reads a second request out of a first
one's body; this module adds the designer's own rules.  The API:

==========================  ==================================================
``GET /api/state``          binary message: state, fast figures, mesh arrays
``POST /api/edit``          ``{"changes": [[path, value], ...], "coalesce"}``
``POST /api/design``        ``{"design": {...}}`` or ``{"toml": "..."}``
``POST /api/undo``, ``/api/redo``
``POST /api/save``          ``{"path", "overwrite"}`` (both optional) -> ``{"path"}``
``POST /api/export``        ``{"format": ".obj", "path", "overwrite"}`` -> ``{"path"}``
``GET /api/download?format=.glb``  the exported bytes as a download
``GET /api/figures?version=N``     binary message: closeness, coverage, panels, classes
``GET /api/panel?face=F&topology=K``  JSON: the face's unrolled outline and ``panels.csv``
                            row; ``{"stale": true}`` if the faces are no longer ``K``
``WS /api/live?token=T``    pushes the state (binary, as ``/api/state``) after every change
==========================  ==================================================

Edits answer like ``GET /api/state`` (one round trip per change).  Errors
answer ``{"error": message}``: 400 a refused edit, 401/403 no or a wrong
token, 403 a foreign ``Host`` or ``Origin``, 408 a request sent too slowly,
409 a file that would be overwritten (``"exists": true``) or an edit
superseded by a newer one (``"superseded": true``), 413 too large, 415 not
JSON, 500 a bug.  The state is unchanged and the server keeps running.

Safety (see docs/designer.md, "Security"):

- every ``/api/`` request carries ``Authorization: Bearer <token>``, a secret
  made per run and printed in the page's URL (``?token=...``);
- on a loopback address, requests whose ``Host`` is not a loopback name are
  refused (DNS rebinding); an ``Origin`` other than the page's own is refused
  even with the token; POSTs must be ``application/json``;
- a refused request's connection is closed (``Connection: close``) so an
  unread body is never looked at; bodies are limited to :data:`MAX_BODY`
  bytes and every request must arrive within :data:`REQUEST_TIMEOUT` seconds;
- builds run in a worker process with a time limit (:mod:`.builder`), off the
  event loop, so a long build never holds up other requests.

The WebSocket ``/api/live`` tells every open page when the design changed
(an edit in another tab, undo, redo), so the pages fetch the new state
instead of showing an old one.  Browsers cannot set headers on a WebSocket:
its token travels as the query parameter ``token``; its ``Origin`` must be
the page's own (browsers always send one); at most :data:`MAX_LIVE`
connections are kept.
"""

from __future__ import annotations

import asyncio
import dataclasses
import errno
import hmac
import ipaddress
import json
import secrets
import socket
import threading
import time
from collections.abc import Awaitable, Callable, MutableMapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any
from urllib.parse import parse_qsl, urlsplit

import numpy as np

from ..errors import ParameterError, RuledMeshError
from .builder import MAX_BUILD_SECONDS, BuildWorker, Superseded
from .figures import FigureWorker
from .session import DEFAULT_DESIGN, OverwriteRefused, Session, encode_message

try:
    import anyio
    import anyio.to_thread
    import uvicorn
    from starlette.applications import Starlette
    from starlette.concurrency import run_in_threadpool
    from starlette.datastructures import Headers
    from starlette.requests import Request
    from starlette.responses import JSONResponse, Response
    from starlette.routing import Mount, Route, WebSocketRoute
    from starlette.staticfiles import StaticFiles
    from starlette.websockets import WebSocket, WebSocketDisconnect
    from uvicorn.protocols.http.h11_impl import H11Protocol
except ImportError as exc:  # pragma: no cover - checked by the CLI before importing this
    raise ImportError(f"the designer needs Starlette and uvicorn ({exc.name}); "
                      'pip install "ruledmesh[web]"', name=exc.name) from None

__all__ = ["DEFAULT_HOST", "MAX_BODY", "REQUEST_TIMEOUT", "DesignerServer", "Limits",
           "PortInUse", "make_server"]

DEFAULT_HOST = "127.0.0.1"
# A request body (an edit, a design's TOML): a hand-made design is a few kB; 1 MiB is room
# for 2,000 control points per curve on several curves, and far from the 14.7 MB of an attack.
MAX_BODY = 2**20
# Seconds a client has to send one request's headers and body (slow or half-open
# connections are closed after this), and to keep an idle keep-alive connection.
REQUEST_TIMEOUT = 10.0
KEEP_ALIVE = 5
# A body over the limit but under this is read and dropped before the 413 answer (see _drain).
DRAIN_LIMIT = 64 * 2**20
# Open live-update WebSockets (one per tab): a few are normal, hundreds an attack.
MAX_LIVE = 32
_LOOPBACK_NAMES = {"localhost", "127.0.0.1", "::1", "[::1]"}
_SECURITY_HEADERS = [
    (b"cache-control", b"no-store"),
    (b"x-content-type-options", b"nosniff"),
    (b"referrer-policy", b"no-referrer"),  # the page's URL holds the token
    (b"x-frame-options", b"DENY"),
    (b"content-security-policy", b"frame-ancestors 'none'"),
]


@dataclass(frozen=True)
class Limits:
    """The designer server's limits (see docs/designer.md, "Security").

    Attributes
    ----------
    body : int
        Bytes of one request body.
    request_timeout : float
        Seconds to send one request's headers, and its body.
    build_seconds : float
        Wall-clock seconds of one build (the worker process is stopped after).
    """

    body: int = MAX_BODY
    request_timeout: float = REQUEST_TIMEOUT
    build_seconds: float = MAX_BUILD_SECONDS


class PortInUse(RuledMeshError):
    """The port asked for is taken by another program."""

    def __init__(self, port: int):
        super().__init__(f"port {port} is in use; choose another with --port or omit it")
        self.port = port


class _HttpError(Exception):
    def __init__(self, status: int, message: str, close: bool = False, **extra: Any):
        super().__init__(message)
        self.status = status
        self.close = close
        self.extra = extra

    def response(self) -> JSONResponse:
        headers = {"connection": "close"} if self.close else {}
        if self.status == 401:
            headers["www-authenticate"] = "Bearer"
        return JSONResponse({"error": str(self), **self.extra}, self.status, headers=headers)


def _static_root() -> Path:
    return Path(str(resources.files("ruledmesh.web").joinpath("static")))


def _is_loopback(host: str) -> bool:
    if host.lower() in _LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def _host_name(host: str) -> str:
    """``name`` of a ``Host`` header ``name:port`` (IPv6 in brackets kept whole)."""
    if host.startswith("["):
        return host[:host.find("]") + 1] if "]" in host else host
    return host.rsplit(":", 1)[0]


# ---------------------------------------------------------------------- connection deadline
class _DeadlineH11(H11Protocol):
    """uvicorn's h11 protocol with a deadline for each request to arrive.

    uvicorn closes idle keep-alive connections, but a connection that never
    completes its request headers (half-open, or one byte every few seconds)
    is kept forever.  Here every connection must deliver a request's headers
    within :attr:`deadline` seconds of opening or of the previous answer.
    """

    deadline = REQUEST_TIMEOUT

    def connection_made(self, transport) -> None:
        self._timer: Any = None
        self._timed_cycle: Any = None
        super().connection_made(transport)
        self._arm()

    def _arm(self) -> None:
        self._disarm()
        self._timer = self.loop.call_later(self.deadline, self._expire)

    def _disarm(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _expire(self) -> None:
        if not self.transport.is_closing():
            self.transport.close()

    def handle_events(self) -> None:
        super().handle_events()
        if self.cycle is not None and self.cycle is not self._timed_cycle:
            self._timed_cycle = self.cycle  # a request's headers arrived: its body has its own limit
            self._disarm()

    def on_response_complete(self) -> None:
        self._arm()  # before the parent, which may start a pipelined request (and disarm)
        super().on_response_complete()

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm()
        super().connection_lost(exc)


# ---------------------------------------------------------------------- checks
class _Guard:
    """ASGI middleware: security headers, ``Host``, ``Origin`` and token checks.

    Refusals close the connection, so whatever the client sent after the
    headers is never read.
    """

    def __init__(self, app: Callable[..., Awaitable[None]], token: str, loopback: bool):
        self.app = app
        self.token = token
        self.loopback = loopback

    def check(self, scope: dict, headers: Headers) -> _HttpError | None:
        host = headers.get("host", "")
        if self.loopback and not _is_loopback(_host_name(host)):
            return _HttpError(403, f"refused: Host {host!r} is not this machine", close=True)
        if not scope["path"].startswith("/api/"):
            return None
        origin = headers.get("origin")
        if origin is not None:
            parts = urlsplit(origin)
            if f"{parts.scheme}://{parts.netloc}".lower() != f"http://{host}".lower():
                return _HttpError(403, f"refused: request from {origin}", close=True)
        if scope["type"] == "websocket":
            return self.check_socket(scope, origin)
        auth = headers.get("authorization", "")
        if not auth:
            return _HttpError(401, "refused: no token; open the URL that ruledmesh design "
                              "printed (it ends in ?token=...)", close=True)
        scheme, _, given = auth.partition(" ")
        if scheme.lower() != "bearer" or not hmac.compare_digest(
                given.strip().encode(), self.token.encode()):
            return _HttpError(403, "refused: wrong token", close=True)
        if scope["method"] == "POST":
            ctype = headers.get("content-type", "").split(";")[0].strip().lower()
            if ctype != "application/json":
                return _HttpError(415, "expected Content-Type: application/json", close=True)
        return None

    def check_socket(self, scope: dict, origin: str | None) -> _HttpError | None:
        """A WebSocket needs an ``Origin`` (the page's, checked above) and ``?token=``."""
        if origin is None:
            return _HttpError(403, "refused: a WebSocket without Origin")
        query = dict(parse_qsl(scope.get("query_string", b"").decode("latin-1")))
        given = query.get("token", "")
        if not given:
            return _HttpError(401, "refused: no token")
        if not hmac.compare_digest(given.encode(), self.token.encode()):
            return _HttpError(403, "refused: wrong token")
        return None

    async def __call__(self, scope: dict, receive: Callable, send: Callable) -> None:
        if scope["type"] == "websocket":
            problem = self.check(scope, Headers(scope=scope))
            if problem is not None or not scope["path"].startswith("/api/"):
                # Closing before accepting answers the handshake with HTTP 403.
                await send({"type": "websocket.close", "code": 1008})
                return
            await self.app(scope, receive, send)
            return
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def secured(message: MutableMapping[str, Any]) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []),
                                                   *_SECURITY_HEADERS]}
            await send(message)

        problem = self.check(scope, Headers(scope=scope))
        if problem is not None:
            await problem.response()(scope, receive, secured)
            return
        await self.app(scope, receive, secured)


# ---------------------------------------------------------------------- application
@dataclass(frozen=True)
class _Call:
    """What every endpoint gets besides its arguments.

    ``topology`` is the page's ``X-Ruledmesh-Topology`` header: the fingerprint
    of the faces it has, so an answer with the same faces leaves them out.
    """

    started: float
    topology: str | None = None
    # "version": answer a change with {"version": N} only; the page has the live socket,
    # which brings the new state to it (and to every other tab) as a binary frame.
    answer: str | None = None


class _Api:
    """The endpoints; blocking work (builds, encoding, files) runs in worker threads."""

    def __init__(self, server: DesignerServer):
        self.server = server
        self.session = server.session
        self.limits = server.limits

    async def _drain(self, request: Request, size: int) -> None:
        """Read and drop a too-large body (up to :data:`DRAIN_LIMIT`), so the answer arrives.

        Closing a connection with unread data makes the kernel reset it, and the
        client would see a network error instead of the message with the limit.
        """
        if size > DRAIN_LIMIT:
            return
        with anyio.move_on_after(self.limits.request_timeout):
            async for _ in request.stream():
                pass

    async def body(self, request: Request) -> dict:
        """The JSON object of a POST, read with the size and time limits."""
        declared = request.headers.get("content-length")
        limit = self.limits.body
        if declared is not None:
            try:
                size = int(declared)
            except ValueError:
                raise _HttpError(400, "bad Content-Length", close=True) from None
            if size > limit:
                await self._drain(request, size)
                raise _HttpError(413, f"request too large: {size:,} bytes; the limit is "
                                 f"{limit:,} bytes", close=True)
        chunks, size = [], 0
        try:
            with anyio.fail_after(self.limits.request_timeout):
                async for chunk in request.stream():
                    size += len(chunk)
                    if size > limit:
                        raise _HttpError(413, f"request too large: more than {limit:,} bytes; "
                                         f"the limit is {limit:,} bytes", close=True)
                    chunks.append(chunk)
        except TimeoutError:
            raise _HttpError(408, f"request body not received within "
                             f"{self.limits.request_timeout:g} s", close=True) from None
        raw = b"".join(chunks) or b"{}"
        try:
            body = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise _HttpError(400, f"invalid JSON: {exc}") from None
        if not isinstance(body, dict):
            raise _HttpError(400, "expected a JSON object")
        return body

    def state(self, call: _Call) -> Response:
        # Server-Timing lets the page tell server time (build + encode) from its own.
        if call.answer == "version":
            ms = (time.perf_counter() - call.started) * 1000
            return JSONResponse({"version": self.session.version},
                                headers={"Server-Timing": f"app;dur={ms:.1f}"})
        body = self.session.payload(call.topology)
        ms = (time.perf_counter() - call.started) * 1000
        return Response(body, media_type="application/octet-stream",
                        headers={"Server-Timing": f"app;dur={ms:.1f}"})

    async def dispatch(self, request: Request) -> Response:
        started = time.perf_counter()
        name = request.path_params["name"]
        method = "get" if request.method == "HEAD" else request.method.lower()
        fn = getattr(self, f"{method}_{name}", None)
        try:
            if fn is None:
                raise _HttpError(404, f"no API {request.method} /api/{name}")
            arg = await self.body(request) if method == "post" else dict(request.query_params)
            call = _Call(started, request.headers.get("x-ruledmesh-topology"),
                         request.headers.get("x-ruledmesh-answer"))
            return await run_in_threadpool(fn, arg, call)
        except _HttpError as exc:
            return exc.response()
        except OverwriteRefused as exc:
            return JSONResponse({"error": str(exc), "exists": True}, 409)
        except Superseded as exc:
            return JSONResponse({"error": str(exc), "superseded": True}, 409)
        except RuledMeshError as exc:
            return JSONResponse({"error": str(exc)}, 400)
        except MemoryError:
            return JSONResponse({"error": "out of memory; reduce the counts in the design"}, 400)
        except Exception as exc:  # noqa: BLE001 - a bug must not stop the server
            return JSONResponse({"error": f"internal error: {type(exc).__name__}: {exc}"}, 500)

    # ------------------------------------------------------------ endpoints (worker threads)
    def get_state(self, query: dict, call: _Call) -> Response:
        return self.state(dataclasses.replace(call, answer=None))

    def post_edit(self, body: dict, call: _Call) -> Response:
        changes = body.get("changes")
        if not isinstance(changes, list) or not all(
                isinstance(c, list) and len(c) == 2 for c in changes):
            raise _HttpError(400, "expected changes: [[path, value], ...]")
        coalesce = body.get("coalesce")
        self.session.edit([(p, v) for p, v in changes],
                          coalesce=str(coalesce) if coalesce else None)
        return self.state(call)

    def post_design(self, body: dict, call: _Call) -> Response:
        if "toml" in body:
            if not isinstance(body["toml"], str):
                raise _HttpError(400, "expected toml: a string")
            self.session.load_text(body["toml"])
        elif body.get("default") is True:
            self.session.load_text(DEFAULT_DESIGN)
        elif isinstance(body.get("design"), dict):
            self.session.replace(body["design"])
        else:
            raise _HttpError(400, "expected design: {...} or toml: \"...\"")
        return self.state(call)

    def post_undo(self, body: dict, call: _Call) -> Response:
        self.session.undo()
        return self.state(call)

    def post_redo(self, body: dict, call: _Call) -> Response:
        self.session.redo()
        return self.state(call)

    @staticmethod
    def _name(body: dict, key: str = "path") -> str | None:
        value = body.get(key)
        if value is None or value == "":
            return None
        if not isinstance(value, str):
            raise ParameterError(f"expected a file name, got {type(value).__name__}", key)
        return value

    def post_save(self, body: dict, call: _Call) -> Response:
        path = self.session.save(self._name(body), overwrite=body.get("overwrite") is True)
        return JSONResponse({"path": str(path)})

    def post_export(self, body: dict, call: _Call) -> Response:
        fmt = body.get("format")
        if not isinstance(fmt, str) or not fmt:
            raise _HttpError(400, "expected format, e.g. \".obj\"")
        path = self.session.export(fmt, self._name(body), overwrite=body.get("overwrite") is True)
        return JSONResponse({"path": str(path)})

    def get_download(self, query: dict, call: _Call) -> Response:
        fmt = query.get("format") or ""
        if not fmt:
            raise _HttpError(400, "expected ?format=.obj")
        data = self.session.export_bytes(fmt)
        ext = fmt.lower() if fmt.startswith(".") else f".{fmt.lower()}"
        stem = self.session.save_name().rsplit(".", 1)[0].replace("/", "_")
        return Response(data, media_type="application/octet-stream",
                        headers={"Content-Disposition": f'attachment; filename="{stem}{ext}"'})

    def get_panel(self, query: dict, call: _Call) -> Response:
        try:
            face = int(query.get("face", ""))
        except ValueError:
            raise _HttpError(400, "expected face=<integer>") from None
        # The faces the page chose ``face`` among; other faces by now: answered stale.
        return JSONResponse(self.session.panel(face, query.get("topology")))

    def _stale(self, version: int) -> Response:
        return Response(encode_message({"version": version, "stale": True}, []),
                        media_type="application/octet-stream")

    def get_figures(self, query: dict, call: _Call) -> Response:
        session = self.session
        try:
            version = int(query.get("version", session.version))
        except ValueError:
            raise _HttpError(400, "expected version=<integer>") from None
        current, data = session.snapshot()
        if version != current:
            return self._stale(version)
        result = self.server.figures().request(version, data, session.source, session.base_dir)
        if result is None:
            return self._stale(version)
        figures, per_face, error = result
        dtypes = {"closeness": np.float32, "class": np.uint32}
        arrays = [(k, np.asarray(v, dtypes.get(k, np.float32)))
                  for k, v in (per_face or {}).items()]
        return Response(encode_message({"version": version, "figures": figures, "error": error},
                                       arrays), media_type="application/octet-stream")


class _Live:
    """The open live-update WebSockets: each gets the new state after every change.

    The state travels as the binary message of ``GET /api/state``
    (:meth:`Session.frame`), one WebSocket binary frame.  Each socket remembers
    the faces it sent last, so while they stay the same a frame holds only
    the vertices, planarity and the rest (``same_topology``).  A socket that
    is still sending when newer versions arrive sends only the newest.
    """

    def __init__(self, session: Session, limit: int = MAX_LIVE):
        self.session = session
        self.limit = limit
        self.queues: set[asyncio.Queue] = set()
        self.loop: asyncio.AbstractEventLoop | None = None
        self.lock = threading.Lock()

    def notify(self, version: int) -> None:
        """Called in any thread after the session changed."""
        self._put(version)

    def progress(self, version: int, note: str) -> None:
        """Called in any thread as the full build of version ``version``'s quick mesh goes on."""
        self._put(("progress", version, note))

    def _put(self, item: int | tuple[str, int, str]) -> None:
        with self.lock:
            loop, queues = self.loop, list(self.queues)
        if loop is None:
            return
        for q in queues:
            try:
                loop.call_soon_threadsafe(q.put_nowait, item)
            except RuntimeError:  # the loop closed: the server is stopping
                return

    async def _pump(self, websocket: WebSocket, queue: asyncio.Queue) -> None:
        sent: str | None = None  # the faces this socket's page has
        while True:
            items = [await queue.get()]
            while not queue.empty():  # only the newest state and note matter
                items.append(queue.get_nowait())
            try:
                if any(isinstance(item, int) for item in items):
                    # The frame is of the design current when it is encoded: never an older one.
                    data, sent = await anyio.to_thread.run_sync(self.session.frame, sent)
                    await websocket.send_bytes(data)
                if isinstance(items[-1], tuple):
                    # A text frame: what the full build of the quick mesh shown is at.
                    _, version, note = items[-1]
                    await websocket.send_text(json.dumps({"version": version, "refining": note}))
            except (WebSocketDisconnect, RuntimeError, OSError):
                return  # the page went away; the receiving side notices and ends

    async def endpoint(self, websocket: WebSocket) -> None:
        with self.lock:
            full = len(self.queues) >= self.limit
        if full:
            await websocket.close(code=1013)  # try again later
            return
        await websocket.accept()
        queue: asyncio.Queue = asyncio.Queue()
        with self.lock:
            self.loop = asyncio.get_running_loop()
            self.queues.add(queue)
        queue.put_nowait(self.session.version)  # the state on connecting
        self.session.page_opened()
        try:
            async with anyio.create_task_group() as tasks:
                tasks.start_soon(self._pump, websocket, queue)
                try:
                    while True:  # the page sends nothing; this notices when it goes away
                        message = await websocket.receive()
                        if message["type"] == "websocket.disconnect":
                            break
                finally:
                    tasks.cancel_scope.cancel()
        except (WebSocketDisconnect, RuntimeError, OSError):
            pass
        finally:
            with self.lock:
                self.queues.discard(queue)


# ---------------------------------------------------------------------- server
def _bind(host: str, port: int) -> socket.socket:
    name = host.strip("[]")
    family = socket.AF_INET6 if ":" in name else socket.AF_INET
    # proto given explicitly: asyncio turns Nagle's algorithm off only for sockets whose proto
    # is IPPROTO_TCP, and with it on every answer's body waits ~40 ms for a delayed ACK.
    sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((name, port))
        sock.listen(256)
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            raise PortInUse(port) from None
        raise
    return sock


def _ws_protocol() -> Any:
    """uvicorn's WebSocket implementation: wsproto (the ``web`` extra) as :func:`_closing_wsproto`
    mends it, else none at all."""
    try:
        import wsproto  # noqa: F401
    except ImportError:  # live updates off; the page then polls the state
        return "none"
    return _closing_wsproto()


def _closing_wsproto() -> type:
    """uvicorn's wsproto protocol, without sending a close frame at shutdown on a
    connection the page has already closed.

    When the page closes its socket (a tab closed, a reload), uvicorn answers the
    close frame and closes the transport, but drops the connection from the server's
    list only on the loop's next turn.  A shutdown in between sent a second close
    frame and wsproto raised ``LocalProtocolError`` (the close "cannot be sent in
    state CLOSED") in the server's thread (uvicorn 0.55).  Such a connection needs
    only its transport closed.
    """
    from uvicorn.protocols.websockets.wsproto_impl import WSProtocol
    from wsproto.connection import ConnectionState

    class _ClosingWSProtocol(WSProtocol):
        def shutdown(self) -> None:
            if self.conn.state is ConnectionState.CLOSED and not getattr(self, "close_sent", False):
                stop = getattr(self, "stop_keepalive", None)    # keep-alive pings: uvicorn >= 0.55
                if stop is not None:
                    stop()
                self.transport.close()
                return
            super().shutdown()

    return _ClosingWSProtocol


class _Uvicorn(uvicorn.Server):
    """uvicorn's server, stopping the worker processes before waiting for open requests.

    A figures request waits for its worker; stopping the workers first answers
    such requests at once, so shutting down does not wait out the grace period.
    """

    def __init__(self, config: uvicorn.Config, before_shutdown: Callable[[], None]):
        super().__init__(config)
        self.before_shutdown = before_shutdown

    async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
        await anyio.to_thread.run_sync(self.before_shutdown)
        await super().shutdown(sockets)


class DesignerServer:
    """The designer's server for one :class:`Session`: bound at once, serving on demand.

    Parameters
    ----------
    session : Session
        Its builds move to a :class:`~ruledmesh.web.builder.BuildWorker` process.
    host : str
        Interface to bind (default loopback only).
    port : int
        0 picks a free port; see :attr:`url`.
    token : str, optional
        The secret of the API; a new random one by default.
    limits : Limits, optional
        Bounds on requests, builds and sockets.
    previews : bool
        Show a design that refines its generators with its quick mesh at once and
        the full one when built (see :class:`Session`); on by default.

    Raises
    ------
    PortInUse
        Another program listens on ``port``.
    """

    def __init__(self, session: Session, host: str = DEFAULT_HOST, port: int = 0, *,
                 token: str | None = None, limits: Limits | None = None, previews: bool = True):
        self.session = session
        self.limits = limits or Limits()
        self.token = token or secrets.token_urlsafe(32)
        self.loopback = _is_loopback(host.strip("[]"))
        self.socket = _bind(host, port)
        self.server_address = self.socket.getsockname()
        self._figures: FigureWorker | None = None
        self._figures_lock = threading.Lock()
        self._closing = False
        self._builder = BuildWorker(self.limits.build_seconds)
        session.set_builder(self._builder, previews)
        api = _Api(self)
        self.live = _Live(session)
        session.add_listener(self.live.notify)
        session.add_progress_listener(self.live.progress)
        routes = [WebSocketRoute("/api/live", self.live.endpoint),
                  Route("/api/{name:str}", api.dispatch, methods=["GET", "HEAD", "POST"]),
                  Mount("/", StaticFiles(directory=_static_root(), html=True))]
        self.app = _Guard(Starlette(routes=routes), self.token, self.loopback)
        protocol = type("_Protocol", (_DeadlineH11,), {"deadline": self.limits.request_timeout})
        config = uvicorn.Config(self.app, http=protocol, ws=_ws_protocol(), lifespan="off",
                                ws_max_size=2**16, ws_ping_interval=20.0, ws_ping_timeout=20.0,
                                # No permessage-deflate: compressing a 100 x 100 frame (half a
                                # megabyte, mostly float32) took 50 ms per update on loopback.
                                ws_per_message_deflate=False,
                                log_level="error", access_log=False, server_header=False,
                                timeout_keep_alive=KEEP_ALIVE, timeout_graceful_shutdown=3)
        self._uvicorn = _Uvicorn(config, self._stop_workers)
        self._stopped = threading.Event()

    @property
    def base_url(self) -> str:
        """``http://host:port/`` of the page (without the token)."""
        host, port = self.server_address[:2]
        if ":" in host:
            host = f"[{host}]"
        return f"http://{host}:{port}/"

    @property
    def url(self) -> str:
        """``http://host:port/?token=...``: the page's address, as printed and opened."""
        return f"{self.base_url}?token={self.token}"

    def figures(self) -> FigureWorker:
        with self._figures_lock:
            if self._closing:
                raise Superseded("the designer is stopping")
            if self._figures is None:
                self._figures = FigureWorker()
            return self._figures

    def serve_forever(self) -> None:
        """Serve until :meth:`shutdown` (or SIGINT/SIGTERM in the main thread)."""
        # The worker imports numpy and scipy meanwhile: the page and its state do not wait.
        threading.Thread(target=self._builder.start, name="build-start", daemon=True).start()
        try:
            self._uvicorn.run(sockets=[self.socket])
        finally:
            self._stopped.set()

    def shutdown(self, timeout: float = 10.0) -> None:
        """Stop serving (from another thread) and wait for :meth:`serve_forever` to return."""
        self._uvicorn.should_exit = True
        self._stopped.wait(timeout)

    def _stop_workers(self) -> None:
        self._builder.close()
        with self._figures_lock:
            self._closing = True
            if self._figures is not None:
                self._figures.close()
                self._figures = None

    def server_close(self) -> None:
        """Close the socket and stop the worker processes."""
        self.socket.close()
        self._stop_workers()


def make_server(session: Session, host: str = DEFAULT_HOST, port: int = 0, *,
                token: str | None = None, limits: Limits | None = None,
                previews: bool = True) -> DesignerServer:
    """A :class:`DesignerServer` bound to ``host:port`` (not yet serving)."""
    return DesignerServer(session, host, port, token=token, limits=limits, previews=previews)
