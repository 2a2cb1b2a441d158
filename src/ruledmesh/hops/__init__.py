"""Grasshopper through Hops: ruledmesh's meshers as remote Grasshopper components.

``ruledmesh hops`` serves the components of :mod:`.components` over the Hops
HTTP protocol (:mod:`.protocol`, :mod:`.server`); geometry travels as
rhino3dm objects (:mod:`.geometry`).  The protocol is spoken directly
rather than through the ``ghhops-server`` package, whose built-in server
has no place for an API-key check or a request-size limit and sends Python
tracebacks back to the client.  Needs ``rhino3dm`` (``pip install
'ruledmesh[hops]'``).  See ``docs/grasshopper.md``.
"""
