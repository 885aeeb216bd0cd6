from os import PathLike
from typing import Any, Dict, Iterable, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

class InputError(ValueError): ...
class DeviceError(RuntimeError): ...

class DeviceInfo:
    platform_name: str
    device_name: str
    driver_version: str
    type: str
    global_mem_bytes: int
    compute_units: int

class Device:
    def __init__(self, selector: str = "") -> None: ...
    @property
    def name(self) -> str: ...

class View:
    def __init__(self, view: npt.NDArray[np.float64], projection: npt.NDArray[np.float64], clip: str = "opengl",
                 reversed_z: Optional[bool] = None, far: Optional[float] = None) -> None: ...
    @property
    def clip(self) -> str: ...

class SoftLight:
    def __init__(self, perspective: bool, size: float, near_plane: float, far_plane: float, extent: float,
                 fov_degrees: float, height: float = -1.0) -> None: ...
    @property
    def perspective(self) -> bool: ...
    @property
    def size(self) -> float: ...
    @property
    def height(self) -> float: ...
    @property
    def near_plane(self) -> float: ...
    @property
    def far_plane(self) -> float: ...
    @property
    def extent(self) -> float: ...
    @property
    def fov_degrees(self) -> float: ...

ViewLike = Union[View, Mapping[str, Any], str, PathLike]

class FrameFilter:
    def __init__(self, *, method: str = "esm", device: Union[Device, str, None] = None,
                 **options: Union[int, float, str]) -> None: ...
    @property
    def allocations(self) -> int: ...
    def __call__(self, depth: npt.ArrayLike, receivers: Optional[npt.ArrayLike] = None, *,
                 receiver_depth: Optional[npt.ArrayLike] = None) -> npt.NDArray[np.float32]: ...

def filter_frames(frames: Iterable[Any], *, method: str = "esm", device: Union[Device, str, None] = None,
                  **options: Union[int, float, str]) -> Iterator[npt.NDArray[np.float32]]: ...
def devices() -> List[DeviceInfo]: ...
def methods() -> List[str]: ...
def soft_methods() -> List[str]: ...
def options() -> List[Dict[str, Any]]: ...
def load_view(source: ViewLike) -> View: ...
def filter(depth: npt.ArrayLike, receivers: Optional[npt.ArrayLike] = None, *,
           receiver_depth: Optional[npt.ArrayLike] = None, method: str = "esm",
           device: Union[Device, str, None] = None, **options: Union[int, float, str]) -> npt.NDArray[np.float32]:
    """Visibility in [0, 1]: (h, w) for receivers (h, w, 3..5) u v d [f [ndl]], or (H, W) for
    receiver_depth (H, W). Depths linear in [0, 1] along the light's axis."""
def receivers(camera: ViewLike, camera_depth: npt.ArrayLike, light: ViewLike, *, map_size: Tuple[int, int],
              camera_depth_kind: str = "window", normals: Optional[npt.ArrayLike] = None,
              counts: Optional[Dict[str, int]] = None) -> npt.NDArray[np.float32]:
    """(h, w, 12) u, v, d, f, ndl, nx, ny, nz, dudx, dvdx, dudy, dvdy of every camera pixel in the light's map."""
def soft_light(light: Union[SoftLight, ViewLike, None] = None, *,
               light_size: Union[float, Tuple[float, float], None] = None,
               light_type: Optional[str] = None, light_near: Optional[float] = None,
               light_far: Optional[float] = None, light_fov: Optional[float] = None,
               light_extent: Optional[float] = None) -> SoftLight:
    """A rectangular area light as the soft command builds it: from a light's view and projection
    with light_size L or (W, H) (world units; W along the map's u axis), or light_type ortho
    (light_extent) | perspective (light_fov)."""
def soft(depth: npt.ArrayLike, receivers: Optional[npt.ArrayLike] = None, *,
         receiver_depth: Optional[npt.ArrayLike] = None, method: str = "pcss",
         light: Union[SoftLight, ViewLike, None] = None, light_size: Union[float, Tuple[float, float], None] = None,
         light_type: Optional[str] = None, light_near: Optional[float] = None, light_far: Optional[float] = None,
         light_fov: Optional[float] = None, light_extent: Optional[float] = None,
         device: Union[Device, str, None] = None,
         **options: Union[int, float, str, bool, Tuple[float, float]]) -> npt.NDArray[np.float32]:
    """Soft-shadow visibility in [0, 1] (pcss, cssm, ssmm, ssmm-improved), as the soft command."""
