"""Surfaces with exact PQ analogues (paper §2-§3), one module per family.

The maths only: arrays and numbers in, a :class:`~ruledmesh.mesh.Mesh` out.
The design-file kinds (see ``docs/design-reference.md``) are read by
:mod:`ruledmesh.design.catalogue`, which calls these functions:

==========================  ===============================  =========================
kind                        function                         every face
==========================  ===============================  =========================
``strips``                  :func:`similar_strips`,          trapezoid
                            :func:`parallel_edge_strips`
``prism``                   :func:`prism`                    parallelogram
``pyramid``                 :func:`pyramid`                  trapezoid
``torsal-polyhedron``       :func:`torsal_polyhedron`        planar strip quad
``translational``           :func:`translational_mesh`       parallelogram
``rotational``              :func:`rotational_mesh`          circular
``moulding``                :func:`moulding_mesh`            circular
``pipe``                    :func:`pipe_mesh`                circular
``canal``                   :func:`canal_mesh`               circular
``torus``                   :func:`torus_mesh`               circular
``dupin-cyclide``           :func:`dupin_cyclide`            circular
``ellipsoid``               :func:`ellipsoid_mesh`           trapezoid
``hyperboloid-two-sheets``  :func:`two_sheet_hyperboloid_mesh`  trapezoid
``elliptic-paraboloid``     :func:`elliptic_paraboloid_mesh` trapezoid
``hyperboloid``             :func:`hyperboloid_mesh`         circular (a == b)
``hyperbolic-paraboloid``   :func:`hyperbolic_paraboloid_mesh`  parallelogram
``helicoid``                :func:`helicoid_mesh`            parallelogram
==========================  ===============================  =========================
"""

from .canal import canal_mesh, dupin_cyclide, torus_mesh
from .developables import prism, pyramid, torsal_polyhedron
from .helicoid import helicoid_mesh
from .hyperbolic_paraboloid import hyperbolic_paraboloid_mesh
from .hyperboloid import hyperboloid_mesh
from .moulding import moulding_mesh, pipe_mesh
from .quadrics import ellipsoid_mesh, elliptic_paraboloid_mesh, two_sheet_hyperboloid_mesh
from .rotational import rotational_mesh
from .strips import parallel_edge_strips, similar_strips
from .translational import translational_mesh

__all__ = [
    "canal_mesh",
    "dupin_cyclide",
    "elliptic_paraboloid_mesh",
    "ellipsoid_mesh",
    "helicoid_mesh",
    "hyperbolic_paraboloid_mesh",
    "hyperboloid_mesh",
    "moulding_mesh",
    "parallel_edge_strips",
    "pipe_mesh",
    "prism",
    "pyramid",
    "rotational_mesh",
    "similar_strips",
    "torsal_polyhedron",
    "torus_mesh",
    "translational_mesh",
    "two_sheet_hyperboloid_mesh",
]
