"""Type stubs of the extension module rtgi._rtgi (re-exported by rtgi)."""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import Hits

PathLike = Union[str, "os.PathLike[str]"]
FloatRows = npt.ArrayLike  # N×3, float32 read in place (C-contiguous), other floats converted once
Bound = Union[None, float, npt.ArrayLike]  # one number for all rays, or an array of N

MISS: int
"""The triangle index of a ray that hits nothing (0xFFFFFFFF)."""
BATCH_RAYS: int
"""Rays given to one batch query at a time by the worker threads."""
EMBREE: bool
"""Whether this build has Intel Embree 3 as ``accel="embree"``."""
__version__: str

class RtgiError(Exception):
    """Base class of the errors rtgi raises, each with the library's message."""

class SceneError(RtgiError):
    """A scene could not be loaded or made: the message names the file and what is wrong."""

class RequestError(RtgiError):
    """An argument, array or request that cannot be used: the message names the argument."""

class Accel:
    """An acceleration structure, built by :meth:`Scene.build`; immutable, shareable between threads."""

    @property
    def kind(self) -> str: ...
    @property
    def build_ms(self) -> float: ...
    @property
    def stats(self) -> Dict[str, Any]:
        """variant, triangles, excluded_triangles, build_ms, nodes, leaves, depth,
        leaf_size_histogram, sah_cost, memory_bytes."""
    @property
    def params(self) -> Dict[str, Any]: ...
    def intersect(self, origins: FloatRows, directions: FloatRows, tmin: Bound = None, tmax: Bound = None) -> Hits:
        """Closest hits: t (inf on a miss), triangle (MISS on a miss), beta, gamma; releases the GIL."""
    def occluded(
        self, origins: FloatRows, directions: FloatRows, tmin: Bound = None, tmax: Bound = None
    ) -> npt.NDArray[np.bool_]:
        """Whether anything is hit, per ray (true exactly where intersect hits); releases the GIL."""

RayArrays = Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]

class Scene:
    """A scene: triangles in file order, materials, cameras, lights; immutable."""

    @staticmethod
    def from_arrays(vertices: FloatRows, triangles: npt.ArrayLike, name: str = "arrays") -> "Scene":
        """One mesh from N×3 float32 positions and M×3 uint32 indices, with a grey diffuse material."""
    @property
    def name(self) -> str: ...
    @property
    def triangle_count(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def load_ms(self) -> float: ...
    @property
    def bounds(self) -> npt.NDArray[np.float32]:
        """2×3: the smallest corner and the largest."""
    @property
    def vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def triangles(self) -> npt.NDArray[np.uint32]: ...
    @property
    def materials(self) -> List[Dict[str, Any]]: ...
    @property
    def cameras(self) -> List[Dict[str, Any]]: ...
    @property
    def lights(self) -> List[Dict[str, Any]]: ...
    @property
    def warnings(self) -> List[str]: ...
    def describe(self) -> Dict[str, Any]:
        """Everything ``rtgi info --json`` says of the scene."""
    def build(
        self,
        accel: str = "bvh8",
        *,
        leaf_size: Optional[int] = None,
        sah_bins: Optional[int] = None,
        sah_axes: Optional[str] = None,
        traversal_cost: Optional[float] = None,
        intersector: Optional[str] = None,
        traversal: Optional[str] = None,
    ) -> Accel:
        """Builds a structure (names: ``rtgi.names("accel")``); None keeps the structure's own default."""
    def box_rays(self, count: int = 1_000_000, seed: int = 0) -> RayArrays:
        """Origins uniform in the bounds, directions uniform on the sphere (``rtgi rays --kind random``)."""
    def surface_rays(self, count: int = 1_000_000, seed: int = 0) -> RayArrays:
        """Rays leaving the surfaces (``rtgi rays --kind surface``)."""
    def camera_rays(
        self,
        width: int = 512,
        height: int = 512,
        *,
        accel: Optional[Accel] = None,
        camera: Optional[int] = None,
        at: Optional[Sequence[float]] = None,
        look: Optional[Sequence[float]] = None,
        up: Optional[Sequence[float]] = None,
        fov: Optional[float] = None,
    ) -> RayArrays:
        """A ray through every pixel centre of ``rtgi render``'s view, in 4×4 tiles (``rtgi rays --kind camera``)."""

def load(path: PathLike, allow_outside: bool = False, variant: Optional[str] = None) -> Scene:
    """Loads .obj, .gltf, .glb or .toml; raises SceneError with the loader's message."""

def cornell_box() -> Scene:
    """The Cornell box built into rtgi."""

def render(scene: Union[Scene, PathLike, None] = None, **request: Any) -> Tuple[
    Optional[npt.NDArray[np.float32]], Dict[str, npt.NDArray[np.float32]], Dict[str, Any]
]: ...
def read_exr(path: PathLike) -> npt.NDArray[np.float32]:
    """An OpenEXR image as H×W×3 float32, linear RGB."""

def verify(
    scene: Union[Scene, PathLike, None] = None,
    *,
    rays: int = 100_000,
    accel: Union[None, str, Sequence[str]] = None,
    exhaustive: bool = False,
    seed: int = 0,
    linear_budget: int = 2_000_000_000,
) -> Dict[str, Any]:
    """The exactness contract checked (``rtgi verify``); the report with ``failed``."""

def experiment(
    knob: str,
    scene: Union[Scene, PathLike, None] = None,
    *,
    quick: bool = True,
    repeats: int = 5,
    width: Optional[int] = None,
    height: Optional[int] = None,
    accel: str = "bvh8",
    threads: Optional[int] = None,
) -> Dict[str, Any]:
    """A knob's experiment (``rtgi experiment KNOB``) as its JSON report."""

def names(what: str) -> List[str]:
    """The names a choice accepts: accel, intersector, traversal, sah_axes, integrator, aovs,
    sampler, bounce_sampling, direct_strategy, tonemap, denoise, knobs, render."""
