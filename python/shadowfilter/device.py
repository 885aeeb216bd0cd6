"""shadowfilter on pyopencl objects: a Pipeline on the caller's context, queue and buffers (or
pyopencl.array.Array), with wait lists and returned events as pyopencl events. No host round trip
and no copy: the caller's buffers are read and written in place, and the caller orders its own
commands against the returned events, in-order or out-of-order queues alike (docs/python.md)."""
from __future__ import annotations

import pyopencl as cl

from . import _core

__all__ = ["Pipeline"]

_runtimes = {}  # (context, queue) handles -> Runtime: one program cache per queue


def _runtime(queue):
    key = (queue.context.int_ptr, queue.int_ptr)
    if key not in _runtimes:
        _runtimes[key] = (_core.Runtime.on_queue(queue.context.int_ptr, queue.int_ptr), queue)
    return _runtimes[key][0]


def _handle(buf, name):
    if buf is None:
        return 0
    if hasattr(buf, "base_data"):  # pyopencl.array.Array
        if buf.offset:
            raise _core.InputError(f"{name}: an Array with an offset (take buf.base_data.get_sub_region)")
        if buf.dtype.itemsize != 4 or buf.dtype.kind != "f":
            raise _core.InputError(f"{name}: must be float32, got {buf.dtype}")
        buf = buf.base_data
    if not isinstance(buf, cl.MemoryObjectHolder):
        raise _core.InputError(f"{name}: a pyopencl Buffer or Array, got {type(buf).__name__}")
    return buf.int_ptr


def _waits(wait_for):
    return [e.int_ptr for e in (wait_for or [])]


def _event(handle):
    return cl.Event.from_int_ptr(handle, retain=False)


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
        n = count if count is not None else (d.size if hasattr(d, "base_data") else d.size // 4)  # Array: elements
        return _event(self._p.reconstruct(n, False, _handle(u, "u"), _handle(v, "v"), _handle(d, "d"), _handle(f, "f"), row,
                                          _handle(visibility, "visibility"), _waits(wait_for)))

    def reconstruct_grid(self, d, visibility, wait_for=None):
        return _event(self._p.reconstruct(self.width * self.height, True, 0, 0, _handle(d, "d"), 0, 0,
                                          _handle(visibility, "visibility"), _waits(wait_for)))
