"""``ruledmesh hops [--port P]``: serve ruledmesh as Grasshopper Hops components."""

from __future__ import annotations

import os
import sys

KEY_VARIABLE = "RULEDMESH_HOPS_KEY"


def add_parser(sub) -> None:
    import argparse

    p = sub.add_parser(
        "hops",
        help="serve PQ meshes to Grasshopper through Hops components",
        description="Serve ruledmesh as Hops components on http://127.0.0.1:PORT: ruled_pq (two "
                    "director curves), ruled_lines and hybrid_lines (explicit lines), design "
                    "(TOML text) and catalogue surfaces. Solves need the API key printed at "
                    f"start (or taken from ${KEY_VARIABLE}); set it in the Hops settings. See "
                    "docs/grasshopper.md. Needs rhino3dm: pip install 'ruledmesh[hops]'.",
        epilog="examples:\n  ruledmesh hops\n  ruledmesh hops --port 5001\n"
               "  then in Grasshopper: a Hops component with the path http://127.0.0.1:5000/ruled_pq",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--port", type=int, default=5000, help="port (default 5000; 0: a free one)")
    p.add_argument("--host", default="127.0.0.1",
                   help="interface to bind (default 127.0.0.1; others expose the server to the "
                        "network, the API key still required)")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..hops.geometry import rhino3dm
    from ..hops.server import KEY_HEADER, make_server

    rhino3dm()  # fail now, with the extra to install, not at the first solve
    server = make_server(args.host, args.port, os.environ.get(KEY_VARIABLE) or None)
    names = ", ".join(server.components)
    print(f"ruledmesh hops: {server.url}  components: {names}", flush=True)
    if os.environ.get(KEY_VARIABLE):
        print(f"API key: taken from ${KEY_VARIABLE} (sent as {KEY_HEADER})", flush=True)
    else:
        print(f"API key: {server.key}  (Hops settings > API Key; sent as {KEY_HEADER})", flush=True)
    print("Ctrl+C to stop", flush=True)
    server.log = lambda line: print(line, flush=True)
    if not server.loopback:
        print(f"warning: serving on {args.host}: reachable from the network", file=sys.stderr)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        print("ruledmesh hops: stopped", file=sys.stderr)
    finally:
        server.server_close()
    return 0
