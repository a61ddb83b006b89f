from typing import Any, Dict, NamedTuple, Optional, Union

import numpy as np
import numpy.typing as npt

from ._rtgi import (
    BATCH_RAYS as BATCH_RAYS,
    EMBREE as EMBREE,
    MISS as MISS,
    Accel as Accel,
    RequestError as RequestError,
    RtgiError as RtgiError,
    Scene as Scene,
    SceneError as SceneError,
    __version__ as __version__,
    cornell_box as cornell_box,
    experiment as experiment,
    load as load,
    names as names,
    read_exr as read_exr,
    verify as verify,
)

class Hits(NamedTuple):
    t: npt.NDArray[np.float32]
    triangle: npt.NDArray[np.uint32]
    beta: npt.NDArray[np.float32]
    gamma: npt.NDArray[np.float32]

class Rendered(NamedTuple):
    image: Optional[npt.NDArray[np.float32]]
    aovs: Dict[str, npt.NDArray[np.float32]]
    outcome: Dict[str, Any]

def render(scene: Union[Scene, str, "os.PathLike[str]", None] = None, **request: Any) -> Rendered:
    """Renders as ``rtgi render`` does; keyword arguments: ``rtgi.names("render")``."""

import os
