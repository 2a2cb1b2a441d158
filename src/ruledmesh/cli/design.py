"""``ruledmesh design [DESIGN.toml]``: the interactive designer in the browser."""

from __future__ import annotations

import sys


def add_parser(sub) -> None:
    p = sub.add_parser(
        "design",
        help="interactive designer in the browser",
        description="Start the designer: a local web page with a 3-D view of the director "
                    "curves, generators and mesh, handles and sliders, live figures, undo/redo, "
                    "save and export. Serves on 127.0.0.1 only unless --host is given; the "
                    "printed URL holds a per-run token that the page needs. Needs the "
                    "'web' extra (pip install \"ruledmesh[web]\").",
        epilog="example: ruledmesh design examples/skew.toml --port 8765",
    )
    p.add_argument("design", nargs="?", help="design file (.toml); a skew surface if omitted "
                   "(Save then picks a free <name>.toml in the working folder)")
    p.add_argument("--port", type=int, default=0, help="port (default: a free one)")
    p.add_argument("--host", default=None,
                   help="interface to bind (default 127.0.0.1; other interfaces expose the "
                        "designer, which can write files in the design's folder, to anyone on "
                        "the network who has the token)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")
    p.set_defaults(run=run)


def _missing_web() -> str | None:
    """The one-line error when Starlette or uvicorn is not installed, else ``None``."""
    import importlib.util

    missing = [m for m in ("starlette", "uvicorn") if importlib.util.find_spec(m) is None]
    if missing:
        return (f"ruledmesh design: needs {' and '.join(missing)}; "
                'pip install "ruledmesh[web]"')
    return None


def run(args) -> int:
    from pathlib import Path

    from ..errors import ParameterError

    if not 0 <= args.port <= 65535:
        raise ParameterError(f"expected a port in 0..65535, got {args.port}", "--port")
    missing = _missing_web()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    from ..web.server import DEFAULT_HOST, PortInUse, make_server
    from ..web.session import Session

    text = path = None
    if args.design:
        path = Path(args.design)
        from .._files import MAX_DESIGN_BYTES, FileRefused, read_capped

        try:
            text = read_capped(path, MAX_DESIGN_BYTES, "a design file").decode("utf-8")
        except FileNotFoundError:
            raise ParameterError(f"no such design file: {path}", "design") from None
        except FileRefused as exc:
            raise ParameterError(f"{path}: {exc.strerror}", "design") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise ParameterError(f"cannot read {path}: {exc}", "design") from None
    # Quick meshes first: the page opens without waiting for the refinement of the design.
    session = Session(text, path, previews=True)
    host = args.host if args.host is not None else DEFAULT_HOST
    try:
        server = make_server(session, host, args.port)
    except PortInUse as exc:
        print(f"ruledmesh design: {exc}", file=sys.stderr)
        return 2
    import signal

    def stop(signum, frame):  # SIGTERM: shut down like Ctrl+C (stops the worker processes too)
        raise KeyboardInterrupt

    try:
        # Before the URL is printed: whoever reads it may stop us at once.
        previous = signal.signal(signal.SIGTERM, stop)
    except ValueError:  # not the main thread (e.g. called from a test): leave signals alone
        previous = None
    try:
        print(f"ruledmesh designer: {server.url}  (Ctrl+C to stop)", flush=True)
        if not server.loopback:
            print(f"warning: serving on {host}: anyone who can reach it and has the token in "
                  "the URL above can edit the design and write files in its folder; the "
                  "connection is not encrypted", file=sys.stderr)
        if not args.no_browser:
            import webbrowser

            webbrowser.open(server.url)
        server.serve_forever()  # uvicorn stops on SIGINT/SIGTERM, then re-raises the signal
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    print("ruledmesh designer: stopped", file=sys.stderr)
    return 0
