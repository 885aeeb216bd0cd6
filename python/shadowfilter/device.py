"""shadowfilter on pyopencl objects: a Pipeline and the single kernels on the caller's context,
queue and buffers (or pyopencl.array.Array), with wait lists and returned events as pyopencl
events. No host round trip and no copy: the caller's buffers are read and written in place, and
the caller orders its own commands against the returned events, in-order or out-of-order queues
alike. kernel_prelude() gives a caller's own kernel the method's OpenCL C (docs/python.md)."""
from __future__ import annotations

from typing import NamedTuple

import pyopencl as cl

from . import _core

__all__ = ["Pipeline", "KernelPrelude", "kernel_prelude", "basis_shape", "enqueue_transform", "enqueue_blur",
           "enqueue_reconstruct_points", "enqueue_reconstruct_grid"]

_runtimes = {}  # (context, queue) handles -> Runtime: one program cache per queue


def _runtime(queue):
    key = (queue.context.int_ptr, queue.int_ptr)
    if key not in _runtimes:
        _runtimes[key] = (_core.Runtime.on_queue(queue.context.int_ptr, queue.int_ptr), queue)
    return _runtimes[key][0]


def _handle(buf, name, raw=False):
    """The cl_mem handle of a Buffer or Array (0 for None). raw: the buffer holds the basis in its
    storage format, of any element type; otherwise an Array must be float32."""
    if buf is None:
        return 0
    if hasattr(buf, "base_data"):  # pyopencl.array.Array
        if buf.offset:
            raise _core.InputError(f"{name}: an Array with an offset (take buf.base_data.get_sub_region)")
        if not raw and (buf.dtype.itemsize != 4 or buf.dtype.kind != "f"):
            raise _core.InputError(f"{name}: must be float32, got {buf.dtype}")
        buf = buf.base_data
    if not isinstance(buf, cl.MemoryObjectHolder):
        raise _core.InputError(f"{name}: a pyopencl Buffer or Array, got {type(buf).__name__}")
    return buf.int_ptr


def _waits(wait_for):
    return [e.int_ptr for e in (wait_for or [])]


def _event(handle):
    return cl.Event.from_int_ptr(handle, retain=False)


def _buffer(handle):
    """A library buffer as a pyopencl Buffer holding its own reference (None for none)."""
    return cl.Buffer.from_int_ptr(handle, retain=True) if handle else None


def _count(buf):
    """Elements of a float32 Buffer or Array."""
    return buf.size if hasattr(buf, "base_data") else buf.size // 4


class Pipeline:
    """The filtering pipeline on a pyopencl queue, for width x height depth maps.

    prefilter(depth) transforms and blurs a map (float32, linear [0, 1]); reconstruct(u, v, d,
    visibility) writes the visibility of receivers (float32 buffers of equal length), or
    reconstruct_grid(d, visibility) of one receiver per map texel. Each returns its pyopencl
    Event; pass it in the next call's wait_for. Keyword options as shadowfilter.filter takes them.
    """

    def __init__(self, queue, width, height, method="esm", **options):
        self.queue = queue
        self.width, self.height = int(width), int(height)
        self._p = _core.DevicePipeline(_runtime(queue), method, options, self.width, self.height)

    @property
    def device_bytes(self):
        return self._p.device_bytes

    def prefilter(self, depth, wait_for=None):
        return _event(self._p.prefilter(_handle(depth, "depth"), _waits(wait_for)))

    def reconstruct(self, u, v, d, visibility, *, count=None, f=None, row=0, wait_for=None):
        n = count if count is not None else _count(d)
        return _event(self._p.reconstruct(n, False, _handle(u, "u"), _handle(v, "v"), _handle(d, "d"), _handle(f, "f"), row,
                                          _handle(visibility, "visibility"), _waits(wait_for)))

    def reconstruct_grid(self, d, visibility, wait_for=None):
        return _event(self._p.reconstruct(self.width * self.height, True, 0, 0, _handle(d, "d"), 0, 0,
                                          _handle(visibility, "visibility"), _waits(wait_for)))

    def lookup_tables(self):
        """(basis, chain, sat): the filtered basis and, for lookup mips or sat, its mip chain or
        summed-area table, as pyopencl Buffers (None where the lookup has none), for a caller's
        kernel built with kernel_prelude() (valid after prefilter()'s event)."""
        return tuple(_buffer(h) for h in self._p.lookup_tables())


class KernelPrelude(NamedTuple):
    """What a caller's kernel needs to reconstruct visibility from a basis filtered with given
    options (docs/embedding.md): `source`, the method's OpenCL C headers in inclusion order (their
    names in `files`), to put before the kernel's own source; `build_options` for the program's
    build; `params`, the bytes of sf_method_params, passed by value (kernel.set_arg(i, params))."""

    files: list
    source: str
    build_options: str
    params: bytes


def kernel_prelude(method="esm", **options):
    """The KernelPrelude for a method and keyword options as filter() takes them. InputError for
    the raw-depth methods (sm, pcf), which have no basis."""
    return KernelPrelude(*_core.kernel_prelude(method, options))


def basis_shape(method, width, height, **options):
    """(planes, bytes per value, bytes) of the basis images of a width x height map: the size of
    the basis buffer enqueue_transform writes (planes of width x height values, plane after plane)."""
    return _core.basis_shape(method, options, int(width), int(height))


def enqueue_transform(queue, width, height, depth, basis, *, method="esm", wait_for=None, **options):
    """The basis transform: depth (width x height float32) -> basis (basis_shape's bytes).
    Returns its Event."""
    return _event(_core.enqueue_transform(_runtime(queue), method, options, int(width), int(height),
                                          _handle(depth, "depth"), _handle(basis, "basis", raw=True),
                                          _waits(wait_for)))


def enqueue_blur(queue, width, height, channels, src, dst, *, tmp=None, wait_for=None, **options):
    """The separable Gaussian prefilter (blur_radius, blur_sigma; storage as the basis holds it)
    of `channels` planes from src into dst. In place (src is dst) it needs tmp, a buffer of the
    same size. Returns the Event of its last command."""
    return _event(_core.enqueue_blur(_runtime(queue), options, int(width), int(height), int(channels),
                                     _handle(src, "src", raw=True), _handle(tmp, "tmp", raw=True),
                                     _handle(dst, "dst", raw=True), _waits(wait_for)))


def enqueue_reconstruct_points(queue, width, height, basis, u, v, d, visibility, *, method="esm", count=None,
                               wait_for=None, **options):
    """Visibility of receivers (u, v, d: float32 of equal length) from a filtered basis, bilinear
    lookup. Returns its Event."""
    n = count if count is not None else _count(d)
    return _event(_core.enqueue_reconstruct_points(_runtime(queue), method, options, int(width), int(height), int(n),
                                                   _handle(basis, "basis", raw=True), _handle(u, "u"), _handle(v, "v"),
                                                   _handle(d, "d"), _handle(visibility, "visibility"),
                                                   _waits(wait_for)))


def enqueue_reconstruct_grid(queue, width, height, basis, d, visibility, *, method="esm", wait_for=None, **options):
    """Visibility of one receiver per map texel (d: width x height float32) from a filtered
    basis. Returns its Event."""
    return _event(_core.enqueue_reconstruct_grid(_runtime(queue), method, options, int(width), int(height),
                                                 _handle(basis, "basis", raw=True), _handle(d, "d"),
                                                 _handle(visibility, "visibility"), _waits(wait_for)))
