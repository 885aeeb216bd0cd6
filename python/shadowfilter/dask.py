"""A sequence of frames filtered on a dask.distributed cluster, one warm device per worker.

    from dask.distributed import Client
    import shadowfilter.dask

    client = Client("scheduler:8786")            # or LocalCluster() on one machine
    futures = shadowfilter.dask.filter_frames(client, frames, method="esm", blur_radius=3)
    images = client.gather(futures)              # one float32 array per frame, in order

A frame is a pair (depth, receivers) or a dict with the keys of shadowfilter.filter (depth,
receivers or receiver_depth). Each worker opens its OpenCL device once (a worker plugin) and keeps
its context, queue and built programs for every frame it runs. docs/scale.md says how to point
this at a real cluster.
"""
from __future__ import annotations

from typing import Any, Iterable, List

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


def _filter_one(frame, method, options):
    if isinstance(frame, dict):
        kwargs = dict(frame)
    else:
        depth, receivers = frame
        kwargs = {"depth": depth, "receivers": receivers}
    depth = kwargs.pop("depth")
    return shadowfilter.filter(depth, method=method, device=_worker_device(), **kwargs, **options)


def filter_frames(client, frames: Iterable[Any], *, method: str = "esm", device: str = "", **options) -> List[Any]:
    """Submits one task per frame and returns their futures, in frame order.

    The options are shadowfilter.filter's; device selects each worker's OpenCL device.
    """
    client.register_plugin(DevicePlugin(device))
    return [client.submit(_filter_one, frame, method, options, pure=False) for frame in frames]
