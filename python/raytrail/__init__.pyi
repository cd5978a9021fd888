"""Type stubs of the raytrail package (the native Scene, InstancedScene and load, and the pure-Python parts)."""

from ._hits import AllHits as AllHits, Hits as Hits, InstanceHits as InstanceHits, Nearest as Nearest
from . import dask as dask, trimesh as trimesh

# The native module's names, described once in _raytrail.pyi.
from ._raytrail import METHODS as METHODS, REFUSED as REFUSED, Scene as Scene, InstancedScene as InstancedScene, __version__ as __version__, load as load
