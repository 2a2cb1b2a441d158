"""The Hops HTTP server: component metadata on GET, solves on POST.

Security, since it listens on a socket:

* it binds to 127.0.0.1 unless told otherwise, and answers only requests
  whose ``Host`` header names the loopback address it serves (so a web page
  cannot reach it through DNS rebinding);
* every solve needs the API key in the ``RhinoComputeKey`` header, the
  header Hops sends when an API key is set in its settings (Grasshopper >
  File > Preferences > Solver > Hops > API Key); the metadata ``GET``
  carries none (Hops sends the key only with solves) and reveals only the
  component descriptions;
* bodies are read only after the key is checked, and only up to
  :data:`MAX_BODY` bytes; inputs hold at most :data:`MAX_ITEMS` values;
  designs are built with the grid budget of design files, one at a time;
  a design cannot make the server read files;
* errors are one line for the Hops component, never a traceback.
"""

from __future__ import annotations

import hmac
import ipaddress
import json
import secrets
import threading
import time
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any
from urllib.parse import urlsplit

from ..errors import ParameterError, RuledMeshError
from .components import COMPONENTS
from .protocol import Component, metadata, output_tree, read_inputs

__all__ = ["DEFAULT_PORT", "KEY_HEADER", "MAX_BODY", "MAX_ITEMS", "HopsServer", "make_server"]

KEY_HEADER = "RhinoComputeKey"
MAX_BODY = 16 * 2**20
MAX_ITEMS = 100_000
DEFAULT_PORT = 5000
# Seconds a client may take to send a request before the connection is dropped.
READ_TIMEOUT = 30.0


class HopsServer(ThreadingHTTPServer):
    """A threading HTTP server holding the components, the key and the solve lock."""

    daemon_threads = True

    def __init__(self, address: tuple[str, int], key: str,
                 components: dict[str, Component] | None = None):
        super().__init__(address, _Handler)
        self.key = key
        self.components = dict(COMPONENTS if components is None else components)
        self.solve_lock = threading.Lock()  # one design at a time: bounded memory
        self.log: Callable[[str], None] | None = None  # one line per solve, if set
        host, port = str(self.server_address[0]), int(self.server_address[1])
        self.loopback = ipaddress.ip_address(host).is_loopback
        shown = f"[{host}]" if ":" in str(host) else host
        self.url = f"http://{shown}:{port}"
        self.hosts = {f"{shown}:{port}"}
        if self.loopback:
            self.hosts |= {f"localhost:{port}", f"127.0.0.1:{port}", f"[::1]:{port}"}


def make_server(host: str = "127.0.0.1", port: int = DEFAULT_PORT,
                key: str | None = None) -> HopsServer:
    """A Hops server on ``host:port`` (port 0: any free port).

    Parameters
    ----------
    host : str
        Address to bind; the loopback address by default.
    port : int
    key : str, optional
        The API key solves must carry; a random one by default.

    Raises
    ------
    ParameterError
        For a malformed address, port or key.
    """
    if not 0 <= port <= 65535:
        raise ParameterError(f"expected a port in 0..65535, got {port}", "--port")
    try:
        ipaddress.ip_address(host)
    except ValueError:
        raise ParameterError(f"expected an IP address, got {host!r}", "--host") from None
    if key is not None and (len(key) < 16 or not key.isprintable() or " " in key):
        raise ParameterError("expected at least 16 printable characters without spaces", "key")
    return HopsServer((host, port), key or secrets.token_urlsafe(24))


def _errors(*messages: str) -> dict[str, Any]:
    return {"values": [], "errors": list(messages), "warnings": []}


class _Handler(BaseHTTPRequestHandler):
    server: HopsServer
    timeout = READ_TIMEOUT
    server_version = "ruledmesh-hops"
    sys_version = ""

    def log_message(self, format: str, *args: Any) -> None:
        pass  # the command line prints one line per solve instead (HopsServer.log)

    def _send(self, status: int, body: Any) -> None:
        data = json.dumps(body).encode("utf-8")
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(data)

    def _host_ok(self) -> bool:
        host = self.headers.get("Host", "")
        if host in self.server.hosts or not self.server.loopback:
            return True
        self._send(421, _errors("unexpected Host header"))
        return False

    def _route(self) -> str:
        return urlsplit(self.path).path.rstrip("/") or "/"

    def do_HEAD(self) -> None:
        self.do_GET()

    def do_GET(self) -> None:
        if not self._host_ok():
            return
        route = self._route()
        if route == "/":
            self._send(200, [metadata(c) for c in self.server.components.values()])
            return
        component = self.server.components.get(route.lstrip("/"))
        if component is None:
            self._send(404, _errors(f"no component {route}; GET / lists them"))
            return
        self._send(200, metadata(component))

    def _authorised(self) -> bool:
        given = self.headers.get(KEY_HEADER, "")
        if hmac.compare_digest(given.encode("utf-8", "replace"), self.server.key.encode("utf-8")):
            return True
        self._send(401, _errors(f"missing or wrong API key: set the key printed by "
                                f"'ruledmesh hops' in the Hops settings (sent as {KEY_HEADER})"))
        return False

    def _body(self) -> dict[str, Any] | None:
        length = self.headers.get("Content-Length")
        if length is None or not length.isdigit():
            self._send(411, _errors("a Content-Length header is required"))
            return None
        if int(length) > MAX_BODY:
            self._send(413, _errors(f"request of {int(length)} bytes exceeds the limit of "
                                    f"{MAX_BODY} bytes"))
            return None
        try:
            payload = json.loads(self.rfile.read(int(length)))
        except (json.JSONDecodeError, UnicodeDecodeError):
            self._send(400, _errors("the request is not valid JSON"))
            return None
        if not isinstance(payload, dict):
            self._send(400, _errors("expected a JSON object"))
            return None
        return payload

    def do_POST(self) -> None:
        if not self._host_ok() or not self._authorised():
            self.close_connection = True
            return
        payload = self._body()
        if payload is None:
            self.close_connection = True
            return
        route = self._route()
        if route == "/solve":
            pointer = payload.get("pointer")
            route = urlsplit(pointer).path.rstrip("/") if isinstance(pointer, str) else ""
        component = self.server.components.get(route.lstrip("/"))
        if component is None:
            self._send(404, _errors(f"no component {route or '(no pointer)'}; GET / lists them"))
            return
        start = time.perf_counter()
        status, body = self._solve(component, payload)
        self._send(status, body)
        if self.server.log is not None:
            errors = body.get("errors") or []
            outcome = f"error: {errors[0]}" if errors else "ok"
            self.server.log(f"{component.name}: {outcome} ({time.perf_counter() - start:.2f} s)")

    def _solve(self, component: Component, payload: dict[str, Any]) -> tuple[int, Any]:
        try:
            inputs = read_inputs(component, payload, MAX_ITEMS)
            with self.server.solve_lock:
                outputs, warnings = component.solve(inputs)
        except RuledMeshError as exc:
            return 200, _errors(str(exc))
        except MemoryError:
            return 200, _errors("out of memory: reduce the counts")
        except Exception as exc:  # noqa: BLE001 (a bug: name it, never send a traceback)
            return 500, _errors(f"internal error: {type(exc).__name__} (run ruledmesh hops "
                                "--debug and report it)")
        values = [output_tree(p.name, outputs[p.name]) for p in component.outputs]
        return 200, {"values": values, "errors": [], "warnings": warnings}
