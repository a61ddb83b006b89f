"""rtgi from Python: scenes, acceleration structures, ray queries, ray
generators, renders, the verifier and the experiments, on NumPy arrays.

Everything runs in rtgi's Rust libraries (the typed API, not the command
line); tracing and rendering release the GIL and run on rtgi's worker
threads.

>>> import rtgi, numpy as np
>>> scene = rtgi.Scene.from_arrays(np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], np.float32),
...                                np.array([[0, 1, 2]], np.uint32))
>>> bvh = scene.build("bvh8")
>>> hits = bvh.intersect(np.array([[0, 0, -2]], np.float32), np.array([[0, 0, 1]], np.float32))
>>> float(hits.t[0]), int(hits.triangle[0])
(2.0, 0)
"""

from typing import Any, Dict, NamedTuple, Optional

import numpy as np

from . import _rtgi
from ._rtgi import (
    BATCH_RAYS,
    EMBREE,
    MISS,
    Accel,
    RequestError,
    RtgiError,
    Scene,
    SceneError,
    __version__,
    cornell_box,
    experiment,
    load,
    names,
    read_exr,
    verify,
)

__all__ = [
    "Accel",
    "BATCH_RAYS",
    "EMBREE",
    "Hits",
    "MISS",
    "Rendered",
    "RequestError",
    "RtgiError",
    "Scene",
    "SceneError",
    "cornell_box",
    "experiment",
    "load",
    "names",
    "read_exr",
    "render",
    "verify",
]


class Hits(NamedTuple):
    """Closest hits of N rays: ``t`` (float32, ``inf`` for a miss),
    ``triangle`` (uint32, ``rtgi.MISS`` for a miss), ``beta`` and ``gamma``
    (float32 barycentrics of the triangle's second and third corners)."""

    t: np.ndarray
    triangle: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray


class Rendered(NamedTuple):
    """What ``rtgi.render`` returns: the linear H×W×3 float32 image
    (``None`` if no sample finished), the AOVs asked for (name: H×W×3
    array), and the outcome as a dict (``rtgi render --json``)."""

    image: Optional[np.ndarray]
    aovs: Dict[str, np.ndarray]
    outcome: Dict[str, Any]


def render(scene=None, **request) -> Rendered:
    """Renders ``scene`` (a :class:`Scene`, a path, or ``None`` for the
    built-in Cornell box) as ``rtgi render`` does; the keyword arguments are
    the fields of ``rtgi_job::RenderRequest`` (``rtgi.names("render")``).

    Without ``output`` nothing is written and the image is made as for an
    EXR output (not denoised unless ``denoise="on"``); with it, the files are
    written as ``rtgi render -o OUTPUT`` writes them. Raises
    :class:`RequestError` for an unknown argument or a bad value, and
    :class:`SceneError` for a scene that cannot be loaded.
    """
    return Rendered(*_rtgi.render(scene, **request))
