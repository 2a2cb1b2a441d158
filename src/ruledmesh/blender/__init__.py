"""The Blender add-on ``ruledmesh_blender``, written as an installable zip.

The add-on's source is the package ``ruledmesh.blender.ruledmesh_blender``
(it imports ``bpy``, so it runs only inside Blender); :func:`write_addon`
puts it into a zip that Blender's add-on installer takes (Edit >
Preferences > Add-ons > Install from Disk), with the add-on version set to
this ruledmesh's version and the folder of this ruledmesh installation
recorded as a fallback import path.  The add-on uses the ruledmesh installed
in Blender's Python first.
"""

from __future__ import annotations

import io
import json
import os
import re
import zipfile
from pathlib import Path

__all__ = ["ADDON_MODULE", "addon_bytes", "write_addon"]

ADDON_MODULE = "ruledmesh_blender"


def _version_tuple(version: str) -> tuple[int, int, int]:
    parts = [int(p) for p in re.findall(r"\d+", version)[:3]]
    return (*parts, *[0] * (3 - len(parts)))  # type: ignore[return-value]


def addon_bytes() -> bytes:
    """The add-on zip: ``ruledmesh_blender/__init__.py`` and ``ruledmesh_blender/config.json``."""
    from .. import __version__

    source = (Path(__file__).parent / ADDON_MODULE / "__init__.py").read_text(encoding="utf-8")
    source, n = re.subn(r'"version": \(0, 0, 0\),[^\n]*',
                        f'"version": {_version_tuple(__version__)},', source, count=1)
    if n != 1:
        raise RuntimeError("the add-on source has no version placeholder")  # a packaging bug
    config = {"ruledmesh_version": __version__,
              "ruledmesh_path": str(Path(__file__).resolve().parents[2])}
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(f"{ADDON_MODULE}/__init__.py", source)
        zf.writestr(f"{ADDON_MODULE}/config.json", json.dumps(config, indent=2) + "\n")
    return buf.getvalue()


def write_addon(path: str | os.PathLike) -> Path:
    """Write the add-on zip to ``path`` (atomically)."""
    from ..io import write_atomic

    return write_atomic(path, addon_bytes())
