"""pyopencl in place: buffers in, buffers out, events chained, the caller's objects untouched."""
import numpy as np
import pytest

import shadowfilter as sf

cl = pytest.importorskip("pyopencl")
import pyopencl.array as cla  # noqa: E402

import shadowfilter.device as sfd  # noqa: E402

W, H = 96, 64


def scene():
    depth = np.full((H, W), 0.7, np.float32)
    depth[20:44, 30:70] = 0.3
    rng = np.random.default_rng(3)
    u = rng.uniform(0, 1, 5000).astype(np.float32)
    v = rng.uniform(0, 1, 5000).astype(np.float32)
    d = rng.uniform(0.35, 0.65, 5000).astype(np.float32)
    return depth, u, v, d


def context():
    platform = cl.get_platforms()[0]
    return cl.Context([platform.get_devices()[0]])


@pytest.mark.parametrize("order", [0, cl.command_queue_properties.OUT_OF_ORDER_EXEC_MODE_ENABLE])
def test_buffers_in_place_equal_numpy_and_leave_the_inputs_alone(order):
    depth, u, v, d = scene()
    ctx = context()
    try:
        queue = cl.CommandQueue(ctx, properties=order)
    except cl.Error:
        pytest.skip("the device has no out-of-order queues")
    dd = cla.to_device(queue, depth)
    du, dv, drx = (cla.to_device(queue, a) for a in (u, v, d))
    out = cla.empty(queue, d.shape, np.float32)
    refs = [a.base_data.reference_count for a in (dd, du, dv, drx, out)]
    pipe = sfd.Pipeline(queue, W, H, method="vsm", blur_radius=2)
    filtered = pipe.prefilter(dd)
    done = pipe.reconstruct(du, dv, drx, out, wait_for=[filtered])
    assert isinstance(done, cl.Event)
    done.wait()
    receivers = np.stack([u, v, d], axis=-1).reshape(1, -1, 3)
    expected = sf.filter(depth, receivers, method="vsm", blur_radius=2).reshape(-1)
    np.testing.assert_array_equal(out.get(), expected)
    np.testing.assert_array_equal(dd.get(), depth)  # inputs unchanged in content
    np.testing.assert_array_equal(drx.get(), d)
    assert [a.base_data.reference_count for a in (dd, du, dv, drx, out)] == refs  # and in references


def test_events_chain_with_the_callers_own_kernels():
    depth, u, v, d = scene()
    ctx = context()
    queue = cl.CommandQueue(ctx, properties=cl.command_queue_properties.OUT_OF_ORDER_EXEC_MODE_ENABLE)
    prg = cl.Program(ctx, "__kernel void halve(__global float* a) { a[get_global_id(0)] *= 0.5f; }").build()
    dd = cla.to_device(queue, depth * 2)
    halved = prg.halve(queue, (depth.size,), None, dd.data)  # the caller's kernel writes the map
    pipe = sfd.Pipeline(queue, W, H, method="esm")
    grid = cla.to_device(queue, np.full((H, W), 0.5, np.float32))
    out = cla.empty(queue, (H, W), np.float32)
    done = pipe.reconstruct_grid(grid, out, wait_for=[pipe.prefilter(dd, wait_for=[halved])])
    done.wait()
    expected = sf.filter(depth, receiver_depth=np.full((H, W), 0.5, np.float32), method="esm")
    np.testing.assert_array_equal(out.get(), expected)


def test_bad_buffers_are_refused():
    ctx = context()
    queue = cl.CommandQueue(ctx)
    pipe = sfd.Pipeline(queue, W, H)
    small = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 16)
    with pytest.raises(sf.InputError, match="depth holds 16 bytes, 24576 needed"):
        pipe.prefilter(small)
    with pytest.raises(sf.InputError, match="must be float32"):
        pipe.prefilter(cla.zeros(queue, (H, W), np.float64))
    with pytest.raises(sf.InputError, match="blur_radius"):
        sfd.Pipeline(queue, W, H, blur_radius=-1)
