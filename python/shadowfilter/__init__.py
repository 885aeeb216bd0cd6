"""shadowfilter: pre-filtered shadow maps (ESM, VSM, EVSM, MSM, CSM, PCF) as OpenCL kernels.

Depth maps and receivers are numpy arrays (any float dtype whose values float32 holds exactly, C
or Fortran order); results are float32 arrays. Depths are linear in [0, 1] along the light's
axis, texture coordinates u, v in [0, 1] with v = 0 the first row (docs/inputs.md).
"""
from __future__ import annotations

import math

import numpy as np

from . import _core
from ._core import DeviceError, InputError

__all__ = ["filter", "FrameFilter", "filter_frames", "soft", "soft_light", "options", "receivers", "methods", "soft_methods", "devices", "Device", "View",
           "SoftLight", "load_view", "InputError", "DeviceError"]

Device = _core.Device
View = _core.View
SoftLight = _core.SoftLight
_default_device: "_core.Device | None" = None


def devices():
    """Every OpenCL device on every platform, in platform/device order."""
    return _core.devices()


def options():
    """Every keyword option of filter(), generated from the library's declared parameters: a list
    of dicts with keyword, flag (the CLI's), field, type, choices, default, range and help."""
    return _core.options()


def methods():
    """The names of the registered filtering methods, in registry order."""
    return _core.method_names()


def soft_methods():
    """The names of the soft-shadow techniques: pcss, cssm, ssmm, ssmm-improved (docs/soft.md)."""
    return _core.soft_methods()


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

    receivers: (h, w, 3, 4, 5, 8 or 12) u, v, d[, f[, ndl[, nx, ny, nz[, dudx, dvdx, dudy, dvdy]]]] per camera
    pixel; or receiver_depth: (H, W) depth
    of a receiver per shadow-map texel. Returns (h, w) or (H, W) float32.
    """
    if (receivers is None) == (receiver_depth is None):
        raise InputError("give exactly one of receivers and receiver_depth")
    dev = _device(device)
    d = _float32("depth", depth, 2)
    if receivers is not None:
        return _core.filter_points(dev, method, options, d, _float32("receivers", receivers, 3))
    return _core.filter_grid(dev, method, options, d, _float32("receiver_depth", receiver_depth, 2))


class FrameFilter:
    """Frames one after another on one warm device and one pipeline: what filter() does per frame,
    without allocating per frame. Buffers are allocated for the first frame and reused while the
    map's size and the receivers' count repeat; on a CPU device the frame's arrays are the kernels'
    buffers. Each call returns what filter() returns for the same arrays, bit for bit.

        batch = sf.FrameFilter(method="vsm", blur_radius=2)
        for depth, rd in frames:
            v = batch(depth, receiver_depth=rd)

    Options are filter()'s; invalid ones raise here, before any frame. `allocations` counts the
    buffer allocations so far. One thread at a time runs a FrameFilter (others wait).
    """

    def __init__(self, *, method="esm", device=None, **options):
        self._f = _core.FrameFilter(_device(device), method, options)

    @property
    def allocations(self):
        return self._f.allocations

    def __call__(self, depth, receivers=None, *, receiver_depth=None):
        if (receivers is None) == (receiver_depth is None):
            raise InputError("give exactly one of receivers and receiver_depth")
        d = _float32("depth", depth, 2)
        if receivers is not None:
            return self._f.run_points(d, _float32("receivers", receivers, 3))
        return self._f.run_grid(d, _float32("receiver_depth", receiver_depth, 2))


def filter_frames(frames, *, method="esm", device=None, **options):
    """Filters a sequence of frames on one FrameFilter, yielding each visibility in order. A frame
    is a pair (depth, receivers) or a dict with filter()'s keys (depth, receivers or
    receiver_depth)."""
    batch = FrameFilter(method=method, device=device, **options)
    for frame in frames:
        if isinstance(frame, dict):
            kwargs = dict(frame)
            yield batch(kwargs.pop("depth"), **kwargs)
        else:
            depth, receivers = frame
            yield batch(depth, receivers)


_VIEW_KEYS = {"view", "projection", "clip", "reversed_z", "far", "width", "height"}


def load_view(source):
    """A View from a camera or light file's JSON (docs/inputs.md: view, projection, clip,
    reversed_z, far; width and height are the image's and ignored here), a dict of the same keys,
    or a View itself."""
    if isinstance(source, View):
        return source
    if isinstance(source, (str, bytes)) or hasattr(source, "__fspath__"):
        import json

        with open(source, "rb") as f:
            source = json.load(f)
    if not isinstance(source, dict):
        raise InputError(f"a view is a View, a dict or a JSON file, got {type(source).__name__}")
    unknown = set(source) - _VIEW_KEYS
    if unknown:
        raise InputError(f"unknown key \"{sorted(unknown)[0]}\"; valid: view, projection, clip, reversed_z, far, width, height")
    for key in ("view", "projection"):
        if key not in source:
            raise InputError(f"needs \"view\" and \"projection\" (16 numbers each, row-major); \"{key}\" is missing")
    matrices = [np.asarray(source[k], dtype=np.float64).reshape(4, 4) if np.size(source[k]) == 16 else None
                for k in ("view", "projection")]
    if any(m is None for m in matrices):
        raise InputError("\"view\" and \"projection\" must be 16 numbers, row-major (or 4 rows of 4)")
    return View(np.ascontiguousarray(matrices[0]), np.ascontiguousarray(matrices[1]), source.get("clip", "opengl"),
                source.get("reversed_z"), source.get("far"))


def receivers(camera, camera_depth, light, *, map_size, camera_depth_kind="window", normals=None, counts=None):
    """The receivers of every camera pixel as an (h, w, 12) float32 array u, v, d, f, ndl, nx, ny, nz,
    dudx, dvdx, dudy, dvdy, ready for filter(): the surface seen through each pixel projected into
    the light's map, its normal in light space scaled to one texel, what normal_offset moves along,
    and the Jacobian of (u W, v H) over the pixel, what max_anisotropy follows (docs/inputs.md).

    camera, light: View, dict or JSON file. camera_depth: (h, w) window depth (the depth buffer,
    any clip space, reversed-Z as the projection shows), view depth or distance in world units, or
    (h, w, 3) world positions, as camera_depth_kind says. map_size: (width, height) of the light's
    map (footprints are in its texels). counts: a dict to receive background, outside, no_normal.
    """
    kind = camera_depth_kind
    d = _float32("camera_depth", camera_depth, 3 if kind == "position" else 2)
    n = None if normals is None else _float32("normals", normals, 3)
    width, height = map_size
    out, c = _core.camera_receivers(load_view(camera), d, kind, load_view(light), int(width), int(height), n)
    if counts is not None:
        counts.update(c)
    return out


_LIGHT_KEYWORDS = ("light_type", "light_near", "light_far", "light_fov", "light_extent")


def _light_sides(light_size):
    """(size, height) of light_size: L (a square; height -1) or (W, H), as --light-size L or W,H."""
    pair = isinstance(light_size, (tuple, list))
    values = tuple(light_size) if pair else (light_size,)
    try:
        sides = [float(v) for v in values]
    except (TypeError, ValueError):
        sides = []
    if len(sides) != len(values) or len(values) != (2 if pair else 1) \
            or not all(math.isfinite(v) and 0 <= v <= 3.4028234663852886e38 for v in sides):
        raise InputError("light_size: must be a finite number >= 0 (L) or two (W,H), got '%s'"
                         % ",".join(str(v) for v in values))
    return sides[0], (sides[1] if len(sides) == 2 else -1.0)


def soft_light(light=None, *, light_size=None, light_type=None, light_near=None, light_far=None, light_fov=None,
               light_extent=None):
    """A SoftLight as the `soft` command builds it, from the same names as its flags.

    light: a light's View, dict or JSON file (its projection gives the type, planes and extent or
    field of view; give light_size, the area light's side L in world units, or its sides (W, H),
    W along the map's u axis and H along v). Without it:
    light_type "ortho" (default) with light_extent (the map's width in light units) and
    light_near, light_far (view depths of d = 0 and 1; default 0 and 1), or "perspective" with
    light_near, light_far and light_fov (full field of view, degrees).
    """
    if isinstance(light, SoftLight):
        return light
    given = {k: v for k, v in zip(_LIGHT_KEYWORDS, (light_type, light_near, light_far, light_fov, light_extent))
             if v is not None}
    if light is not None:
        if given:
            raise InputError("light gives the light's type, planes and extent (its projection); drop "
                             + ", ".join(sorted(given)))
        if light_size is None:
            raise InputError("light has no area light size: give light_size (world units)")
        return _core.soft_light(load_view(light), *_light_sides(light_size))
    if light_size is None:
        raise InputError("give light_size (the area light's width, world units) and the light's projection "
                         "(light=, or light_type with light_extent or light_fov)")
    kind = {"orthographic": "ortho"}.get(light_type, light_type) or "ortho"
    if kind not in ("ortho", "perspective"):
        raise InputError(f"light_type must be ortho or perspective, got '{light_type}'")
    if kind == "perspective":
        if light_near is None or light_far is None or light_fov is None:
            raise InputError("a perspective light needs light_near, light_far and light_fov")
    elif light_extent is None:
        raise InputError("an orthographic light needs the map's width in light units (light_extent)")
    near = 0.0 if light_near is None else light_near
    far = 1.0 if light_far is None else light_far
    size, height = _light_sides(light_size)
    return SoftLight(kind == "perspective", size, float(near), float(far),
                     float(light_extent if light_extent is not None else 1.0),
                     float(light_fov if light_fov is not None else 0.0), height)


def soft(depth, receivers=None, *, receiver_depth=None, method="pcss", light=None, light_size=None, light_type=None,
         light_near=None, light_far=None, light_fov=None, light_extent=None, device=None, **options):
    """Soft-shadow visibility in [0, 1] of each receiver from a rectangular area light (docs/soft.md):
    method pcss, cssm, ssmm or ssmm-improved, on the light's depth map `depth` (H, W).

    receivers / receiver_depth as filter() takes them. The light as soft_light() builds it (light=
    a View or light file with light_size, or light_type, light_extent | light_fov, light_near,
    light_far, light_size). Keyword options are the `soft` command's flags (soft_bias,
    cssm_order, lookup="mips"|"sat", cssm_sharpen=(A, B), cssm_storage="f16", ssmm_n, slope_bias, ...), with its
    messages. Returns (h, w) or (H, W) float32, equal to the command's output.
    """
    if (receivers is None) == (receiver_depth is None):
        raise InputError("give exactly one of receivers and receiver_depth")
    L = soft_light(light, light_size=light_size, light_type=light_type, light_near=light_near, light_far=light_far,
                   light_fov=light_fov, light_extent=light_extent)
    dev = _device(device)
    d = _float32("depth", depth, 2)
    if receivers is not None:
        return _core.soft_points(dev, method, options, L, d, _float32("receivers", receivers, 3))
    return _core.soft_grid(dev, method, options, L, d, _float32("receiver_depth", receiver_depth, 2))
