"""shadowfilter: pre-filtered shadow maps (ESM, VSM, EVSM, MSM, CSM, PCF) as OpenCL kernels.

Depth maps and receivers are numpy arrays (any float dtype whose values float32 holds exactly, C
or Fortran order); results are float32 arrays. Depths are linear in [0, 1] along the light's
axis, texture coordinates u, v in [0, 1] with v = 0 the first row (docs/inputs.md).
"""
from __future__ import annotations

import numpy as np

from . import _core
from ._core import DeviceError, InputError

__all__ = ["filter", "methods", "devices", "Device", "InputError", "DeviceError"]

Device = _core.Device
_default_device: "_core.Device | None" = None


def devices():
    """Every OpenCL device on every platform, in platform/device order."""
    return _core.devices()


def methods():
    """The names of the registered filtering methods, in registry order."""
    return _core.method_names()


def _device(device):
    global _default_device
    if isinstance(device, _core.Device):
        return device
    if device is not None:
        return _core.Device(str(device))
    if _default_device is None:  # one warm device for every call that names none
        _default_device = _core.Device("")
    return _default_device


def _float32(name, array, ndim):
    """array as C-contiguous float32 when the conversion is exact; InputError otherwise."""
    a = np.asarray(array)
    if a.ndim != ndim:
        raise InputError(f"{name} must have {ndim} dimensions, got shape {a.shape}")
    if a.dtype == np.float32:
        return np.ascontiguousarray(a)
    if not np.issubdtype(a.dtype, np.floating):
        raise InputError(f"{name} must be a float array, got dtype {a.dtype}")
    b = a.astype(np.float32)
    same = (b.astype(a.dtype) == a) | (np.isnan(a) & np.isnan(b))
    if not same.all():
        raise InputError(f"{name}: {a.dtype} values that float32 does not hold exactly (convert them yourself)")
    return np.ascontiguousarray(b)


def filter(depth, receivers=None, *, receiver_depth=None, method="esm", device=None, **options):
    """Filtered visibility in [0, 1] of each receiver against the depth map `depth` (H, W).

    receivers: (h, w, 3..5) u, v, d[, f[, ndl]] per camera pixel; or receiver_depth: (H, W) depth
    of a receiver per shadow-map texel. Returns (h, w) or (H, W) float32.
    """
    if (receivers is None) == (receiver_depth is None):
        raise InputError("give exactly one of receivers and receiver_depth")
    o = _core.FilterOptions()
    o.method = method
    for key, value in options.items():
        if not hasattr(o, key):
            raise InputError(f"unknown option {key}")
        setattr(o, key, value)
    dev = _device(device)
    d = _float32("depth", depth, 2)
    if receivers is not None:
        return _core.filter_points(dev, o, d, _float32("receivers", receivers, 3))
    return _core.filter_grid(dev, o, d, _float32("receiver_depth", receiver_depth, 2))
