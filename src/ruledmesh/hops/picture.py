"""A picture of a Hops component as Grasshopper draws it, from the served metadata.

Used for ``docs/grasshopper.md`` (``python -m ruledmesh.hops.picture``): the
inputs on the left with their types and defaults, the outputs on the right,
exactly as ``GET /<name>`` describes them.  Needs matplotlib.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping
from typing import Any

__all__ = ["draw_component"]


def _label(param: Mapping[str, Any]) -> str:
    many = " (list)" if param.get("AtMost", 1) > 1 else ""
    default = f" = {param['Default']}" if "Default" in param else ""
    return f"{param['Name']}  [{param['ParamType']}{many}]{default}"


def draw_component(meta: Mapping[str, Any], path: str | os.PathLike, url: str = "") -> None:
    """Draw the component described by ``meta`` (Hops metadata) into ``path`` (PNG).

    Parameters
    ----------
    meta : mapping
        What ``GET /<name>`` returns.
    path : path-like
    url : str
        Shown as the Hops path above the component.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyBboxPatch

    ins, outs = meta["Inputs"], meta["Outputs"]
    rows = max(len(ins), len(outs))
    height = 0.5 * rows + 1.2
    fig, ax = plt.subplots(figsize=(11, height))
    ax.set_xlim(0, 11)
    ax.set_ylim(0, height)
    ax.axis("off")
    box = FancyBboxPatch((4.2, 0.3), 2.6, height - 0.9, boxstyle="round,pad=0.05,rounding_size=0.15",
                         facecolor="#d9d9d9", edgecolor="#404040", linewidth=1.5)
    ax.add_patch(box)
    ax.text(5.5, height / 2 - 0.1, f"Hops\n{meta['Name']}", ha="center", va="center",
            fontsize=12, weight="bold", rotation=90 if rows > 6 else 0)
    if url:
        ax.text(5.5, height - 0.3, url, ha="center", va="center", fontsize=9, family="monospace")

    def column(params, x_text, x_pin, align):
        step = (height - 1.2) / max(len(params), 1)
        for k, param in enumerate(params):
            y = height - 0.9 - step * (k + 0.5)
            ax.plot([x_pin, 4.2 if align == "right" else 6.8], [y, y], color="#404040", lw=1)
            ax.plot(x_pin, y, "o", color="#404040", ms=4)
            ax.text(x_text, y, _label(param), ha=align, va="center", fontsize=9)

    column(ins, 3.8, 3.95, "right")
    column(outs, 7.2, 7.05, "left")
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """``python -m ruledmesh.hops.picture NAME OUT.png``: draw a served component."""
    from .components import COMPONENTS
    from .protocol import metadata

    args = sys.argv[1:] if argv is None else argv
    name, out = args
    draw_component(metadata(COMPONENTS[name]), out, f"http://127.0.0.1:5000/{name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
