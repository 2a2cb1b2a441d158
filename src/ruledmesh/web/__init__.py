"""The interactive designer: a local web server and a three.js page.

``ruledmesh design [DESIGN.toml]`` serves it with :class:`~ruledmesh.web.server.DesignerServer`
(Starlette on uvicorn, the ``web`` extra).
The state (the current design) lives in a :class:`~ruledmesh.web.session.Session`
on the server; the page sends edits and draws what the server builds.
"""

from .session import Session

__all__ = ["Session"]
