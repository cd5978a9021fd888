"""Type stubs of the native module raytrail._raytrail."""

import os
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._hits import AllHits, Hits, InstanceHits, Nearest

__version__: str
#: "auto" and every method name the tracer knows (Scene.intersect's `method`).
METHODS: Tuple[str, ...]
#: `prim` of a ray too far from the scene to answer exactly (its `t` is NaN); a miss is -1.
REFUSED: int

_Bound = Union[float, npt.ArrayLike, None]

class Scene:
    """A triangle mesh ready to trace (the tree built once); pickles as its vertices and faces."""

    def __init__(self, vertices: npt.ArrayLike, faces: npt.ArrayLike, *, threads: Optional[int] = None) -> None: ...
    def intersect(
        self,
        origins: npt.ArrayLike,
        directions: Optional[npt.ArrayLike] = None,
        tmin: _Bound = None,
        tmax: _Bound = None,
        method: str = "auto",
    ) -> Hits:
        """Closest hits: Hits(t float32, prim int64 (-1 miss), u float32, v float32)."""
    def occluded(
        self,
        origins: npt.ArrayLike,
        directions: Optional[npt.ArrayLike] = None,
        tmin: _Bound = None,
        tmax: _Bound = None,
        method: str = "auto",
    ) -> npt.NDArray[np.bool_]:
        """Whether anything blocks each ray within [tmin, tmax]."""
    def intersect_all(
        self,
        origins: npt.ArrayLike,
        directions: Optional[npt.ArrayLike] = None,
        tmin: _Bound = None,
        tmax: _Bound = None,
        *,
        max_hits: Optional[int] = None,
        merge_equal_t: bool = False,
    ) -> AllHits:
        """Every hit along each ray, in order of t: AllHits(ray, t, prim, u, v, truncated)."""
    def nearest(self, points: npt.ArrayLike, radius: float = ...) -> Nearest:
        """The nearest point on the mesh to each point: Nearest(point, distance, prim, u, v)."""
    @property
    def vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def faces(self) -> npt.NDArray[np.int64]: ...
    @property
    def threads(self) -> Optional[int]: ...
    def __len__(self) -> int: ...

_Masks = Union[int, npt.ArrayLike, None]

class InstancedScene:
    """Meshes placed many times by affine maps, each with an id and a mask (each tree built once)."""

    def __init__(
        self,
        meshes: Sequence[Scene],
        mesh: npt.ArrayLike,
        transforms: npt.ArrayLike,
        *,
        ids: Optional[npt.ArrayLike] = None,
        masks: Optional[npt.ArrayLike] = None,
        threads: Optional[int] = None,
        method: str = "bvh8-sah",
    ) -> None: ...
    def intersect(
        self,
        origins: npt.ArrayLike,
        directions: Optional[npt.ArrayLike] = None,
        tmin: _Bound = None,
        tmax: _Bound = None,
        *,
        masks: _Masks = None,
    ) -> InstanceHits:
        """Closest hits: InstanceHits(t, prim, u, v, instance id (-1 miss))."""
    def occluded(
        self,
        origins: npt.ArrayLike,
        directions: Optional[npt.ArrayLike] = None,
        tmin: _Bound = None,
        tmax: _Bound = None,
        *,
        masks: _Masks = None,
    ) -> npt.NDArray[np.bool_]:
        """Whether anything the ray's mask admits blocks it within [tmin, tmax]."""
    @property
    def meshes(self) -> List[Scene]: ...
    @property
    def mesh(self) -> npt.NDArray[np.int64]: ...
    @property
    def transforms(self) -> npt.NDArray[np.float32]: ...
    @property
    def ids(self) -> npt.NDArray[np.int64]: ...
    @property
    def masks(self) -> npt.NDArray[np.uint32]: ...
    @property
    def threads(self) -> Optional[int]: ...
    @property
    def method(self) -> str: ...
    def __len__(self) -> int: ...

def load(path: Union[str, "os.PathLike[str]"], *, threads: Optional[int] = None) -> Scene:
    """A Scene from an OBJ, PLY, OFF, STL or glTF file (gzipped or not)."""

def _packed_rays() -> int:
    """Rays packed into a buffer of the module's own so far (a test hook)."""
