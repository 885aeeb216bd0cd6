from os import PathLike
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

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

ViewLike = Union[View, Mapping[str, Any], str, PathLike]

def devices() -> List[DeviceInfo]: ...
def methods() -> List[str]: ...
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
    """(h, w, 5) u, v, d, f, ndl of every camera pixel in the light's map."""
