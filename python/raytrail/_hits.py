"""The result type of :meth:`raytrail.Scene.intersect`."""

from typing import NamedTuple

import numpy as np


class Hits(NamedTuple):
    """The closest hit of each of N rays, as four arrays of length N (unpack as
    ``t, prim, u, v = scene.intersect(...)``).

    - ``t`` (float32): ray parameter of the hit point ``origin + t * direction`` (in units of the
      direction's length, which need not be 1); ``inf`` for a miss.
    - ``prim`` (int64): index of the face hit; ``-1`` for a miss, ``raytrail.REFUSED`` (-2, with
      ``t`` NaN) for a ray whose origin lies over about 4e9 times the scene's size away.
    - ``u``, ``v`` (float32): barycentric weights of the face's second and third vertex at the
      hit point (the first vertex's weight is ``1 - u - v``); 0 for a miss.
    """

    t: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray
