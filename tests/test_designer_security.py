"""The designer under attack on loopback: token, origin, smuggling, paths, limits, sockets.

Every test runs a real server (Starlette on uvicorn, the build worker process)
on 127.0.0.1 and talks to it with raw sockets or ``http.client``; the user's
design file must stay untouched and nothing may be written outside its folder.
"""

from __future__ import annotations

import http.client
import json
import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import _shared  # a helper module of tests/ (see conftest.py)
import pytest

from ruledmesh.web.server import MAX_BODY, Limits, make_server
from ruledmesh.web.session import MAX_CONTROL_POINTS, Session


def decode(data: bytes) -> tuple[dict, bytes]:
    """The JSON header of a designer state message (and the array bytes after it)."""
    n = int.from_bytes(data[:4], "little")
    return json.loads(data[4:4 + n].decode("utf-8")), data[4 + n:]


SMALL = _shared.SMALL_DESIGN
# The small design with its own nine generators (one mesh a build, not about thirty): the
# servers of these tests are about safety, not the refinement.
QUICK = SMALL + "refine = false\n"


def tree(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` with its bytes (links as their target)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_symlink():
            out[str(p.relative_to(folder))] = b"-> " + os.readlink(p).encode()
        elif p.is_file():
            out[str(p.relative_to(folder))] = p.read_bytes()
    return out


class Designer:
    """A running designer over ``folder/user.toml`` and an ``outside`` folder next to it."""

    def __init__(self, root: Path, limits: Limits | None = None, design: str | None = QUICK):
        self.folder = root / "work"
        self.outside = root / "outside"
        self.folder.mkdir()
        self.outside.mkdir()
        (self.outside / "secret.txt").write_text("root:x:0:0:SECRET-LINE\n")
        self.path = self.folder / "user.toml"
        if design is not None:
            self.path.write_text(design)
            session = Session(design, self.path)
        else:
            session = Session(base_dir=self.folder)
        self.server = make_server(session, port=0, limits=limits)
        self.host, self.port = self.server.server_address[:2]
        self.token = self.server.token
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()
        self.before = {"work": tree(self.folder), "outside": tree(self.outside)}

    @property
    def session(self) -> Session:
        return self.server.session

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()

    def request(self, method: str, path: str, body=None, headers=None, token: bool | str = True,
                timeout: float = 60):
        conn = http.client.HTTPConnection(self.host, self.port, timeout=timeout)
        hdrs = {"Content-Type": "application/json"} if body is not None else {}
        if token:
            hdrs["Authorization"] = f"Bearer {self.token if token is True else token}"
        hdrs.update(headers or {})
        data = body if isinstance(body, (bytes, str)) or body is None else json.dumps(body)
        conn.request(method, path, data, hdrs)
        resp = conn.getresponse()
        raw = resp.read()
        conn.close()
        try:
            return resp.status, json.loads(raw)
        except (UnicodeDecodeError, json.JSONDecodeError):
            return resp.status, raw

    def raw(self, data: bytes, wait: float = 3.0) -> bytes:
        """Send ``data`` on one connection; everything read until the server closes it."""
        with socket.create_connection((self.host, self.port), timeout=wait) as s:
            s.sendall(data)
            out = b""
            try:
                while chunk := s.recv(65536):
                    out += chunk
            except TimeoutError:
                pass
        return out

    def untouched(self) -> None:
        """The design file, its folder and the outside folder are as they were."""
        assert tree(self.outside) == self.before["outside"]
        assert tree(self.folder) == self.before["work"]


@pytest.fixture
def designer(tmp_path):
    d = Designer(tmp_path)
    yield d
    d.close()


API = [("GET", "/api/state", None), ("GET", "/api/figures?version=0", None),
       ("GET", "/api/download?format=.obj", None), ("GET", "/api/panel?face=0", None),
       ("POST", "/api/edit", {"changes": [[["mesh", "rows"], 13]]}),
       ("POST", "/api/design", {"toml": SMALL.replace("rows = 6", "rows = 13")}),
       ("POST", "/api/undo", {}), ("POST", "/api/save", {"path": "evil.toml"}),
       ("POST", "/api/export", {"format": ".obj", "path": "evil.obj"})]


# ---------------------------------------------------------------- live updates (WebSocket)
def ws_handshake(d: Designer, query: str, origin: str | None = "own", host: str | None = None,
                 wait: float = 5.0, extra: tuple[str, ...] = ()) -> tuple[socket.socket, bytes]:
    """Open ``/api/live`` with a raw WebSocket handshake; the socket and the first bytes read."""
    s = socket.create_connection((d.host, d.port), timeout=wait)
    lines = [f"GET /api/live{query} HTTP/1.1", f"Host: {host or f'127.0.0.1:{d.port}'}",
             "Upgrade: websocket", "Connection: Upgrade",
             "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==", "Sec-WebSocket-Version: 13", *extra]
    if origin is not None:
        lines.append(f"Origin: {f'http://127.0.0.1:{d.port}' if origin == 'own' else origin}")
    s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
    data = b""
    try:
        while b"\r\n\r\n" not in data:
            chunk = s.recv(4096)
            if not chunk:
                break
            data += chunk
    except TimeoutError:
        pass
    return s, data


@pytest.mark.parametrize(("query", "origin", "host"), [
    ("", "own", None),                                   # no token
    ("?token=wrong", "own", None),                       # a wrong token
    ("?token={token}", None, None),                      # no Origin (not a browser page)
    ("?token={token}", "http://127.0.0.1:1", None),       # another local origin
    ("?token={token}", "https://evil.example", None),     # a foreign page
    ("?token={token}", "http://evil.example", "evil.example"),  # DNS rebinding
])
def test_live_socket_needs_token_origin_and_host(designer, query, origin, host):
    s, answer = ws_handshake(designer, query.format(token=designer.token), origin, host)
    s.close()
    assert answer.startswith(b"HTTP/1.1 403"), answer[:80]
    # a refused socket learns nothing and changes nothing
    assert b"version" not in answer
    designer.untouched()


def frames(buf: bytes):
    """Complete server frames at the start of ``buf``: ``([(opcode, payload)], rest)``."""
    out = []
    while len(buf) >= 2:
        n, head = buf[1] & 0x7F, 2
        if n == 126:
            if len(buf) < 4:
                break
            n, head = int.from_bytes(buf[2:4], "big"), 4
        elif n == 127:
            if len(buf) < 10:
                break
            n, head = int.from_bytes(buf[2:10], "big"), 10
        if len(buf) < head + n:
            break
        out.append((buf[0] & 0x0F, buf[head:head + n]))
        buf = buf[head + n:]
    return out, buf


def read_versions(s: socket.socket, buf: bytes, last: int, wait: float = 20.0) -> list[dict]:
    """Headers of the states in the server's binary frames until version ``last`` arrives."""
    s.settimeout(1.0)
    deadline = time.monotonic() + wait
    states: list[dict] = []
    while time.monotonic() < deadline and last not in [h["version"] for h in states]:
        got, buf = frames(buf)
        for opcode, payload in got:
            if opcode == 2:  # a binary frame: the state message (pings and the like skipped)
                states.append(decode(payload)[0])
        if last in [h["version"] for h in states]:
            break
        try:
            chunk = s.recv(65536)
        except TimeoutError:
            continue
        if not chunk:  # closed by the server
            break
        buf += chunk
    return states


def test_live_socket_with_token_tells_every_change(designer):
    s, answer = ws_handshake(designer, f"?token={designer.token}")
    assert answer.startswith(b"HTTP/1.1 101"), answer[:80]
    rest = answer.split(b"\r\n\r\n", 1)[1]
    status, _ = designer.request("POST", "/api/edit", {"changes": [[["mesh", "rows"], 7]]})
    assert status == 200
    status, _ = designer.request("POST", "/api/undo", {})
    assert status == 200
    states = read_versions(s, rest, last=2)
    s.close()
    versions = [h["version"] for h in states]
    # the state on connecting first, then the newer ones in order, ending with the undo's
    # (versions announced while the socket was busy may be merged into the newest)
    assert versions[0] == 0 and versions[-1] == 2 and versions == sorted(set(versions)), versions
    # each frame is the whole state of its version: the design with the edit, then undone
    assert states[0]["design"]["mesh"]["rows"] == 6 and states[-1]["design"]["mesh"]["rows"] == 6
    assert all(h["figures"]["faces"] > 0 for h in states)
    if 1 in versions:
        assert states[versions.index(1)]["design"]["mesh"]["rows"] == 7


def test_live_socket_sends_uncompressed_frames(designer):
    """Offered permessage-deflate (as Chromium offers it), the server declines it.

    Compressing each state (half a megabyte at 100 x 100, mostly float32 that hardly
    compresses) cost about 50 ms per update on loopback, a tenth of slider-to-frame.
    """
    s, answer = ws_handshake(designer, f"?token={designer.token}",
                             extra=("Sec-WebSocket-Extensions: permessage-deflate; client_max_window_bits",))
    assert answer.startswith(b"HTTP/1.1 101"), answer[:80]
    head, rest = answer.split(b"\r\n\r\n", 1)
    assert b"permessage-deflate" not in head.lower()
    s.settimeout(5.0)
    while len(rest) < 2:
        rest += s.recv(65536)
    s.close()
    assert rest[0] & 0x40 == 0          # RSV1 clear: the frame is not compressed
    assert rest[0] & 0x0F == 2          # the state on connecting, a binary frame


def test_live_sockets_are_bounded(designer):
    from ruledmesh.web.server import MAX_LIVE

    socks = [ws_handshake(designer, f"?token={designer.token}") for _ in range(MAX_LIVE)]
    assert all(a.startswith(b"HTTP/1.1 101") for _, a in socks)
    extra, answer = ws_handshake(designer, f"?token={designer.token}")
    # over the limit: accepted by none (closed with "try again later" or refused)
    assert not answer.startswith(b"HTTP/1.1 101"), answer[:80]
    for s, _ in [*socks, (extra, b"")]:
        s.close()
    # the server still answers at once
    status, _ = designer.request("GET", "/api/state")
    assert status == 200


def test_shutdown_right_after_the_page_closed_its_socket():
    """A shutdown in the loop turn after the page's close frame: no second close frame.

    uvicorn answers the page's close and closes the transport, but forgets the
    connection only on the loop's next turn; its shutdown in between sent a close
    frame in wsproto's CLOSED state, which raised in the server's thread.  Driven
    here with a real transport (a socket pair) in exactly that order.
    """
    import asyncio

    import uvicorn
    from uvicorn.server import ServerState
    from wsproto import ConnectionType, WSConnection
    from wsproto.connection import ConnectionState
    from wsproto.events import AcceptConnection, CloseConnection, Request

    from ruledmesh.web.server import _ws_protocol

    async def app(scope, receive, send):
        await receive()
        await send({"type": "websocket.accept"})
        while (await receive())["type"] != "websocket.disconnect":
            pass

    async def run():
        loop = asyncio.get_running_loop()
        config = uvicorn.Config(app, ws=_ws_protocol(), lifespan="off", log_level="critical")
        config.load()
        state = ServerState()
        ours, page = socket.socketpair()
        page.setblocking(False)
        _, proto = await loop.connect_accepted_socket(
            lambda: config.ws_protocol_class(config=config, server_state=state, app_state={}), ours)
        client = WSConnection(ConnectionType.CLIENT)
        await loop.sock_sendall(page, client.send(Request(host="127.0.0.1", target="/api/live")))
        while not any(isinstance(e, AcceptConnection) for e in client.events()):
            client.receive_data(await loop.sock_recv(page, 65536))
        proto.data_received(client.send(CloseConnection(code=1000)))   # the page closes ...
        assert proto.conn.state is ConnectionState.CLOSED and proto in state.connections
        proto.shutdown()                                                 # ... and the server stops
        assert proto.transport.is_closing()
        await asyncio.sleep(0.05)
        assert proto not in state.connections
        page.close()

    asyncio.run(run())


# ---------------------------------------------------------------- token, Host, Origin
@pytest.mark.parametrize(("method", "path", "body"), API)
def test_api_needs_the_token(designer, method, path, body):
    version = designer.session.version
    status, reply = designer.request(method, path, body, token=False)
    assert status == 401 and "token" in reply["error"]
    status, reply = designer.request(method, path, body, token="not-the-token")
    assert status == 403 and reply["error"] == "refused: wrong token"
    status, _ = designer.request(method, path, body, headers={"Authorization": designer.token})
    assert status == 403  # the bare token without "Bearer" is not accepted either
    assert designer.session.version == version
    designer.untouched()


def test_static_page_without_token_but_not_from_a_foreign_host(designer):
    status, page = designer.request("GET", "/", token=False)
    assert status == 200 and b"app.js" in page
    status, reply = designer.request("GET", "/", token=False, headers={"Host": "evil.example"})
    assert status == 403 and "Host" in reply["error"]
    status, _ = designer.request("GET", "/api/state", headers={"Host": f"evil.example:{designer.port}"})
    assert status == 403


@pytest.mark.parametrize("origin", ["http://evil.example", "http://127.0.0.1:1",
                                    "http://localhost:{port}", "https://127.0.0.1:{port}", "null"])
def test_foreign_origin_refused_even_with_the_token(designer, origin):
    origin = origin.format(port=designer.port)
    for method, path, body in API:
        status, reply = designer.request(method, path, body, headers={"Origin": origin})
        assert status == 403 and origin in reply["error"], (path, reply)
    assert designer.session.version == 0
    designer.untouched()
    # the page's own origin is fine
    status, _ = designer.request("GET", "/api/state",
                                 headers={"Origin": f"http://127.0.0.1:{designer.port}"})
    assert status == 200


def test_post_must_be_json(designer):
    status, reply = designer.request("POST", "/api/undo", "{}", headers={"Content-Type": "text/plain"})
    assert status == 415 and "application/json" in reply["error"]


# ---------------------------------------------------------------- smuggling
def smuggled(designer, rows: int) -> bytes:
    """A complete, valid (token and all) HTTP request that would change rows and write files."""
    body = json.dumps({"changes": [[["mesh", "rows"], rows]]}).encode()
    inner = (f"POST /api/edit HTTP/1.1\r\nHost: 127.0.0.1:{designer.port}\r\n"
             f"Authorization: Bearer {designer.token}\r\nContent-Type: application/json\r\n"
             f"Content-Length: {len(body)}\r\n\r\n").encode() + body
    save = json.dumps({"path": "smuggled.toml"}).encode()
    inner += (f"POST /api/save HTTP/1.1\r\nHost: 127.0.0.1:{designer.port}\r\n"
              f"Authorization: Bearer {designer.token}\r\nContent-Type: application/json\r\n"
              "Connection: close\r\n"
              f"Content-Length: {len(save)}\r\n\r\n").encode() + save
    return inner


def outer(designer, headers: str, body: bytes, length: int | None = None) -> bytes:
    n = len(body) if length is None else length
    return (f"POST /api/edit HTTP/1.1\r\nHost: 127.0.0.1:{designer.port}\r\n{headers}"
            f"Content-Length: {n}\r\n\r\n").encode() + body


def test_pipelining_works_so_the_smuggling_test_can_fail(designer):
    # Control: the same bytes after an accepted request ARE executed (two answers, rows 13).
    data = (f"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:{designer.port}\r\n"
            f"Authorization: Bearer {designer.token}\r\n\r\n").encode() + smuggled(designer, 13)
    # 20 s between bytes: the first edit waits for the build worker process to start, which
    # took over 8 s on a loaded machine (the server closes the idle connection after 5 s).
    out = designer.raw(data, wait=20.0)
    assert out.count(b"HTTP/1.1 200") == 3
    assert designer.session.design["mesh"]["rows"] == 13
    assert (designer.folder / "smuggled.toml").exists()


@pytest.mark.parametrize("refusal", ["no token", "wrong token", "text/plain", "foreign origin",
                                     "too large", "bad JSON"])
def test_refused_post_body_is_never_a_second_request(designer, refusal):
    inner = smuggled(designer, 13)
    auth = f"Authorization: Bearer {designer.token}\r\n"
    json_ct = "Content-Type: application/json\r\n"
    headers, length = {
        "no token": (json_ct, None),
        "wrong token": ("Authorization: Bearer nope\r\n" + json_ct, None),
        "text/plain": (auth + "Content-Type: text/plain\r\n", None),
        "foreign origin": (auth + json_ct + "Origin: http://evil.example\r\n", None),
        "too large": (auth + json_ct, MAX_BODY + 1),
        "bad JSON": (auth + json_ct + "Connection: close\r\n", None),
    }[refusal]
    if length is not None:  # the smuggled request at the start of a body over the limit
        inner += b" " * (length - len(inner))
    out = designer.raw(outer(designer, headers, inner, length), wait=8.0)
    assert out.startswith(b"HTTP/1.1 4"), out[:200]
    assert out.count(b"HTTP/1.1 ") == 1, out      # one answer: the body was not parsed
    assert designer.session.design["mesh"]["rows"] == 6 and designer.session.version == 0
    designer.untouched()


def test_chunked_body_over_the_limit_is_refused(designer):
    chunk = b"x" * 65536
    head = (f"POST /api/edit HTTP/1.1\r\nHost: 127.0.0.1:{designer.port}\r\n"
            f"Authorization: Bearer {designer.token}\r\nContent-Type: application/json\r\n"
            "Transfer-Encoding: chunked\r\n\r\n").encode()
    # Just over the limit and without the final chunk: the server has read everything sent
    # when it answers, so closing the connection does not reset it before we read the answer.
    body = b"".join(b"%x\r\n%s\r\n" % (len(chunk), chunk) for _ in range(MAX_BODY // len(chunk) + 1))
    out = designer.raw(head + body, wait=8.0)
    assert out.startswith(b"HTTP/1.1 413") and f"{MAX_BODY:,}".encode() in out
    assert designer.session.version == 0


# ---------------------------------------------------------------- half-open connections
def test_hundreds_of_half_open_connections(tmp_path):
    import resource

    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft < 2048:
        resource.setrlimit(resource.RLIMIT_NOFILE, (min(4096, hard), hard))
    d = Designer(tmp_path, limits=Limits(request_timeout=2.0))
    socks = []
    try:
        for k in range(300):
            s = socket.create_connection((d.host, d.port), timeout=10)
            # half a request: some send nothing, some part of the headers
            if k % 2:
                s.sendall(f"POST /api/edit HTTP/1.1\r\nHost: 127.0.0.1:{d.port}\r\nX-".encode())
            socks.append(s)
        t0 = time.monotonic()
        status, _ = d.request("GET", "/api/state", timeout=10)
        answered = time.monotonic() - t0
        assert status == 200 and answered < 2.0, answered
        # a slow client sending a byte now and then does not keep its connection either
        slow = socket.create_connection((d.host, d.port), timeout=10)
        for ch in b"GET /api/state HTTP/1.1\r\n":
            try:
                slow.sendall(bytes([ch]))
            except OSError:
                break
            time.sleep(0.25)
        deadline = time.monotonic() + 10
        for s in [*socks, slow]:
            s.settimeout(max(deadline - time.monotonic(), 0.1))
            try:
                assert s.recv(1024) == b""  # closed by the server, without an answer
            except ConnectionResetError:
                pass
        freed = time.monotonic() - t0
        print(f"300 half-open connections: a normal request answered in {answered * 1000:.0f} ms, "
              f"all freed after {freed:.1f} s (deadline 2 s)")
        assert freed < 9
        assert d.request("GET", "/api/state")[0] == 200
    finally:
        for s in socks:
            s.close()
        d.close()


# ---------------------------------------------------------------- paths
BAD_PATHS = ["/tmp/evil.toml", "{outside}/evil.toml", "../outside/evil.toml", "~/evil.toml",
             "sub/../../outside/evil.toml", "link/evil.toml", "linked.toml", "nosuchdir/evil.toml",
             "..\\outside\\evil.toml"]


@pytest.mark.parametrize("endpoint", ["save", "export"])
def test_writes_outside_the_folder_are_refused(designer, endpoint):
    (designer.folder / "link").symlink_to(designer.outside, target_is_directory=True)
    (designer.folder / "linked.toml").symlink_to(designer.outside / "secret.txt")
    (designer.folder / "linked.obj").symlink_to(designer.outside / "secret.txt")
    designer.before = {"work": tree(designer.folder), "outside": tree(designer.outside)}
    for bad in BAD_PATHS:
        bad = bad.format(outside=designer.outside)
        if endpoint == "export":
            bad = bad.replace(".toml", ".obj")
            body = {"format": ".obj", "path": bad}
        else:
            body = {"path": bad}
        status, reply = designer.request("POST", f"/api/{endpoint}", body)
        assert status == 400, (bad, reply)
        assert "\n" not in reply["error"] and ("inside the design's folder" in reply["error"]
                                               or "no such folder" in reply["error"]), reply
    assert not Path("/tmp/evil.toml").exists() and not (Path.home() / "evil.toml").exists()
    designer.untouched()


def test_save_without_the_flag_never_replaces_a_file_it_did_not_open(designer):
    other = designer.folder / "mine.toml"
    other.write_text("# the user's own file\n")
    obj = designer.folder / "user.obj"
    obj.write_text("# the user's own mesh\n")
    designer.before = {"work": tree(designer.folder), "outside": tree(designer.outside)}
    for endpoint, body in (("save", {"path": "mine.toml"}), ("export", {"format": ".obj"})):
        status, reply = designer.request("POST", f"/api/{endpoint}", body)
        assert status == 409 and reply["exists"] is True and "confirm" in reply["error"]
    designer.untouched()
    # the design file the session was started with is its own: saved without asking
    designer.request("POST", "/api/edit", {"changes": [[["mesh", "rows"], 7]]})
    status, reply = designer.request("POST", "/api/save", {})
    assert status == 200 and Path(reply["path"]) == designer.path
    assert "rows = 7" in designer.path.read_text()
    # with the flag (the page asked the user), the other file is replaced
    status, reply = designer.request("POST", "/api/save", {"path": "mine.toml", "overwrite": True})
    assert status == 200 and "rows = 7" in other.read_text()
    # and from then on it is the session's own
    assert designer.request("POST", "/api/save", {"path": "mine.toml"})[0] == 200


def test_without_a_design_file_save_picks_a_free_name(tmp_path):
    d = Designer(tmp_path, design=None)
    try:
        user = d.folder / "skew.toml"
        user.write_text("# the user's skew design\n")
        (d.folder / "skew-2.toml").write_text("# another\n")
        status, reply = d.request("POST", "/api/save", {})
        assert status == 200 and Path(reply["path"]) == d.folder / "skew-3.toml"
        assert user.read_text() == "# the user's skew design\n"
        # the next Save writes the same file again
        assert Path(d.request("POST", "/api/save", {})[1]["path"]) == d.folder / "skew-3.toml"
    finally:
        d.close()


def test_referenced_files_stay_inside_and_errors_never_echo_content(designer):
    (designer.folder / "notes.csv").write_text("header\nSECRET-LINE,1,2,3,4,5\n")
    (designer.folder / "passwd.csv").symlink_to(designer.outside / "secret.txt")
    for name, why in (("/etc/passwd", "absolute"), (str(designer.outside / "secret.txt"), "absolute"),
                      ("../outside/secret.txt", ".."), ("~/.bashrc", "~"),
                      ("passwd.csv", "link"), ("notes.csv", "cell 1 is not a number")):
        design = SMALL.replace('between = ["c1", "c2"]\ndistribution = "parameter"\ncount = 9',
                               f'file = "{name}"')
        status, reply = designer.request("POST", "/api/design", {"toml": design})
        assert status == 400 and "\n" not in reply["error"], reply
        assert why in reply["error"], reply
        assert "SECRET" not in reply["error"] and "root:" not in reply["error"], reply
    assert designer.session.version == 0


# ---------------------------------------------------------------- limits
def test_huge_edit_refused_with_the_figure(designer):
    points = [[k * 1e-3, 1.0, 0.5] for k in range(700_000)]
    body = json.dumps({"changes": [[["curves", "c1", "points"], points]]})
    t0 = time.monotonic()
    status, reply = designer.request("POST", "/api/edit", body)
    assert status == 413 and f"{len(body):,} bytes" in reply["error"]
    assert f"{MAX_BODY:,}" in reply["error"] and time.monotonic() - t0 < 5
    # under the byte limit but over the control points of one curve
    many = [[k * 1e-3, 1.0, 0.5] for k in range(MAX_CONTROL_POINTS + 1)]
    status, reply = designer.request("POST", "/api/edit",
                                     {"changes": [[["curves", "c2", "points"], many]]})
    assert status == 400 and f"at most {MAX_CONTROL_POINTS:,} points" in reply["error"]
    assert "curves.c2.points" in reply["error"]
    # grid points: the budget of the command line's mesher
    from ruledmesh.pq import MAX_GRID_POINTS

    status, reply = designer.request("POST", "/api/edit", {"changes": [
        [["rulings", "count"], 60_000], [["mesh", "rows"], 1_000]]})
    assert status == 400 and f"{MAX_GRID_POINTS:,}" in reply["error"], reply
    assert designer.session.version == 0
    designer.untouched()


def slow_edit(rows: int = 50, count: int = 20_000) -> dict:
    return {"changes": [[["rulings", "count"], count], [["mesh", "rows"], rows]]}


def test_long_build_is_stopped_and_never_blocks_state_requests(tmp_path):
    # Without the refinement: the small design's own builds (9 generators refined to up to
    # 122, about 27 mesher runs: 0.3-1 s of CPU) came close to the 1.5 s limit on a loaded
    # machine, and the edit after the restart must build well inside it.
    d = Designer(tmp_path, limits=Limits(build_seconds=1.5), design=QUICK)
    try:
        d.request("POST", "/api/edit", {"changes": [[["mesh", "rows"], 7]]})  # worker warm
        result = {}
        t0 = time.monotonic()
        worker = threading.Thread(target=lambda: result.setdefault(
            "slow", d.request("POST", "/api/edit", slow_edit())))
        worker.start()
        time.sleep(0.3)
        waits = []
        while worker.is_alive():
            t = time.monotonic()
            assert d.request("GET", "/api/state", timeout=10)[0] == 200
            waits.append(time.monotonic() - t)
            time.sleep(0.05)
        took = time.monotonic() - t0
        status, reply = result["slow"]
        print(f"build stopped after {took:.1f} s (limit 1.5 s); {len(waits)} state requests "
              f"meanwhile, slowest {max(waits) * 1000:.0f} ms")
        assert status == 400 and "longer than 1.5 s" in reply["error"]
        assert took < 6 and max(waits) < 1.0
        assert d.session.design["rulings"]["count"] == 9
        # the restarted worker builds the next edit
        assert d.request("POST", "/api/edit", {"changes": [[["mesh", "rows"], 8]]})[0] == 200
    finally:
        d.close()


def test_newer_edit_supersedes_a_running_one(designer):
    designer.request("POST", "/api/edit", {"changes": [[["mesh", "rows"], 7]]})  # worker warm
    result = {}
    slow = threading.Thread(target=lambda: result.setdefault(
        "slow", designer.request("POST", "/api/edit", slow_edit())))
    slow.start()
    time.sleep(0.8)
    t0 = time.monotonic()
    status, _ = designer.request("POST", "/api/edit", {"changes": [[["mesh", "rows"], 9]]})
    took = time.monotonic() - t0
    slow.join(30)
    assert status == 200
    assert result["slow"][0] == 409 and result["slow"][1]["superseded"] is True
    design = designer.session.design
    assert design["mesh"]["rows"] == 9 and design["rulings"]["count"] == 9
    print(f"newer edit answered {took:.1f} s after it was sent (worker restarted)")
    assert took < 10


# ---------------------------------------------------------------- command line
def test_busy_port_exits_2_with_the_message(tmp_path):
    holder = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        holder.bind(("127.0.0.1", 8765))
        port = 8765
    except OSError:  # taken by someone else: still a busy port, take a free one to hold
        holder.bind(("127.0.0.1", 0))
        port = holder.getsockname()[1]
    holder.listen(1)
    try:
        proc = subprocess.run([sys.executable, "-m", "ruledmesh.cli", "design", "--port", str(port),
                               "--no-browser"], check=False, capture_output=True, text=True,
                              timeout=60,
                              cwd=tmp_path)
    finally:
        holder.close()
    assert proc.returncode == 2
    assert proc.stderr == (f"ruledmesh design: port {port} is in use; choose another with --port "
                           "or omit it\n")
    assert proc.stdout == "" and list(tmp_path.iterdir()) == []


def test_printed_url_holds_a_fresh_token(tmp_path):
    design = tmp_path / "small.toml"
    design.write_text(SMALL)
    tokens = []
    for _ in range(2):
        proc = subprocess.Popen([sys.executable, "-m", "ruledmesh.cli", "design", str(design),
                                 "--no-browser"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        try:
            line = proc.stdout.readline()
        finally:
            proc.terminate()
            assert proc.wait(timeout=30) == 0
        assert line.startswith("ruledmesh designer: http://127.0.0.1:") and "/?token=" in line
        tokens.append(line.split("?token=")[1].split()[0])
    assert tokens[0] != tokens[1] and min(len(t) for t in tokens) >= 40


def test_without_the_web_extra_one_line_names_the_install(tmp_path):
    # The import system is told the packages are absent (as in an environment without them).
    code = ("import sys; sys.modules['starlette'] = None; sys.modules['uvicorn'] = None; "
            "from ruledmesh.cli import main; sys.exit(main(['design', '--no-browser']))")
    proc = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True,
                          text=True, timeout=60, cwd=tmp_path)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr == ('ruledmesh design: needs starlette and uvicorn; '
                           'pip install "ruledmesh[web]"\n')


def test_a_linked_design_file_is_edited_where_it_lives(tmp_path):
    real = tmp_path / "projects" / "real.toml"
    real.parent.mkdir()
    real.write_text(SMALL)
    link = tmp_path / "link.toml"
    link.symlink_to(real)
    s = Session(link.read_text(), link)
    assert s.path == real and s.base_dir == real.parent
    s.edit([(["mesh", "rows"], 7)])
    assert s.save() == real and "rows = 7" in real.read_text() and link.is_symlink()
    assert s.export(".obj") == real.parent / "real.obj"
