"""ruledmesh: planar quad meshes of ruled surfaces, by construction.

The package follows the paper (D. Lordick, *Intuitive design and meshing of
non-developable ruled surfaces*): director curves -> discrete generators ->
PQ meshes (§4.3), hybrid HP-patch meshes (§4.1), and the exact PQ analogues of
§2-§3, plus analysis, exports and fabrication outputs.
"""

from .errors import DesignError, ExportError, GeometryError, ParameterError, RuledMeshError
from .mesh import FaceKind, Mesh
from .tolerances import DEFAULT as DEFAULT_TOLERANCES, Tolerances

__version__ = "0.1.0"

__all__ = [
    "DesignError",
    "ExportError",
    "GeometryError",
    "ParameterError",
    "RuledMeshError",
    "FaceKind",
    "Mesh",
    "Tolerances",
    "DEFAULT_TOLERANCES",
    "__version__",
]
