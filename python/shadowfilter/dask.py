"""A sequence of frames filtered on a dask.distributed cluster, one warm device per worker.

    from dask.distributed import Client
    import shadowfilter.dask

    client = Client("scheduler:8786")            # or LocalCluster() on one machine
    futures = shadowfilter.dask.filter_frames(client, frames, method="esm", blur_radius=3)
    images = client.gather(futures)              # one float32 array per frame, in order

A frame is a pair (depth, receivers) or a dict with the keys of shadowfilter.filter (depth,
receivers or receiver_depth). Each value is an array or the path of a .npy file that the worker
reads (on a shared file system the frames then travel as names, not as pickled arrays). With
outputs= (one .npy path per frame) each worker writes its result there, atomically, and the futures
hold the paths. Each worker opens its OpenCL device once (a worker plugin) and keeps its context,
queue and built programs for every frame it runs. docs/scale.md says how to point this at a real
cluster.
"""
from __future__ import annotations

import os
import tempfile
from typing import Any, Iterable, List, Optional, Sequence

import numpy as np
from distributed import WorkerPlugin, get_worker

import shadowfilter

__all__ = ["DevicePlugin", "filter_frames"]


class DevicePlugin(WorkerPlugin):
    """Opens a shadowfilter.Device on every worker as it starts (selector as Device takes it)."""

    name = "shadowfilter-device"

    def __init__(self, selector: str = ""):
        self.selector = selector

    def setup(self, worker):
        worker.shadowfilter_device = shadowfilter.Device(self.selector)

    def teardown(self, worker):
        worker.shadowfilter_device = None


def _worker_device():
    device = getattr(get_worker(), "shadowfilter_device", None)
    if device is None:
        raise shadowfilter.DeviceError("this worker has no shadowfilter device: register DevicePlugin first")
    return device


def _array(value):
    """An array, or the .npy file a path names (read on the worker)."""
    if isinstance(value, (str, bytes)) or hasattr(value, "__fspath__"):
        return np.load(value, mmap_mode="r", allow_pickle=False)
    return value


def _save_atomically(path, image):
    """image as the .npy file `path`: written beside it and renamed, so that a failed or interrupted
    task leaves no partial file."""
    path = os.fspath(path)
    fd, staged = tempfile.mkstemp(prefix=".sf-", suffix=".npy", dir=os.path.dirname(os.path.abspath(path)))
    try:
        with os.fdopen(fd, "wb") as f:
            np.save(f, image, allow_pickle=False)
            f.flush()
            os.fsync(f.fileno())
        os.replace(staged, path)
    except BaseException:
        os.unlink(staged)
        raise
    return path


def _filter_one(frame, method, options, output=None):
    if isinstance(frame, dict):
        kwargs = {k: _array(v) for k, v in frame.items()}
    else:
        depth, receivers = frame
        kwargs = {"depth": _array(depth), "receivers": _array(receivers)}
    depth = kwargs.pop("depth")
    image = shadowfilter.filter(depth, method=method, device=_worker_device(), **kwargs, **options)
    return image if output is None else _save_atomically(output, image)


def filter_frames(client, frames: Iterable[Any], *, method: str = "esm", device: str = "",
                  outputs: Optional[Sequence[Any]] = None, **options) -> List[Any]:
    """Submits one task per frame and returns their futures, in frame order.

    The options are shadowfilter.filter's; device selects each worker's OpenCL device. outputs:
    one .npy path per frame, written by the workers (the futures then hold the paths).
    """
    frames = list(frames)
    if outputs is not None and len(outputs) != len(frames):
        raise shadowfilter.InputError(f"outputs: one path per frame, got {len(outputs)} for {len(frames)} frames")
    if outputs is not None and len({os.path.abspath(os.fspath(p)) for p in outputs}) != len(outputs):
        raise shadowfilter.InputError("outputs: two frames write one file")
    client.register_plugin(DevicePlugin(device))
    return [client.submit(_filter_one, frame, method, options, None if outputs is None else outputs[i], pure=False)
            for i, frame in enumerate(frames)]
