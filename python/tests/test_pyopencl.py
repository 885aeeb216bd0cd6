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


@pytest.mark.parametrize("method", ["vsm", "msm", "csm"])
def test_single_kernels_chain_to_the_pipelines_bits(method):
    """transform -> blur (in place, with tmp) -> reconstruct on the caller's buffers equals
    filter() of the same options bit for bit."""
    depth, u, v, d = scene()
    ctx = context()
    queue = cl.CommandQueue(ctx, properties=cl.command_queue_properties.OUT_OF_ORDER_EXEC_MODE_ENABLE)
    planes, value_bytes, nbytes = sfd.basis_shape(method, W, H)
    assert nbytes == planes * value_bytes * W * H
    basis = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, nbytes)
    tmp = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, nbytes)
    dd = cla.to_device(queue, depth)
    du, dv, drx = (cla.to_device(queue, a) for a in (u, v, d))
    out = cla.empty(queue, d.shape, np.float32)
    e = sfd.enqueue_transform(queue, W, H, dd, basis, method=method)
    e = sfd.enqueue_blur(queue, W, H, planes, basis, basis, tmp=tmp, blur_radius=3, wait_for=[e])
    e = sfd.enqueue_reconstruct_points(queue, W, H, basis, du, dv, drx, out, method=method, wait_for=[e])
    e.wait()
    receivers = np.stack([u, v, d], axis=-1).reshape(1, -1, 3)
    expected = sf.filter(depth, receivers, method=method, blur_radius=3).reshape(-1)
    np.testing.assert_array_equal(out.get(), expected)
    grid = cla.to_device(queue, np.full((H, W), 0.5, np.float32))
    gout = cla.empty(queue, (H, W), np.float32)
    sfd.enqueue_reconstruct_grid(queue, W, H, basis, grid, gout, method=method).wait()
    np.testing.assert_array_equal(
        gout.get(), sf.filter(depth, receiver_depth=np.full((H, W), 0.5, np.float32), method=method, blur_radius=3))


CALLER_KERNEL = """
__kernel void caller_shade(__global const sf_stored* basis, __global const sf_stored* chain,
                           __global const float* sat, int width, int height,
                           __global const float* u, __global const float* v,
                           __global const float* d, __global float* out, int count,
                           const sf_method_params P) {
  const int i = get_global_id(0);
  if (i >= count) return;
  if (sf_receiver_outside(u[i], v[i], d[i])) { out[i] = 1.0f; return; }
  float b[SF_CHANNELS];
  sf_lookup(basis, chain, sat, width, height, u[i], v[i], 1.0f, b);
  out[i] = clamp(sf_visibility(b, clamp(d[i], 0.0f, 1.0f), P), 0.0f, 1.0f);
}
"""


@pytest.mark.parametrize("method,lookup", [("esm", "bilinear"), ("vsm", "mips"), ("msm", "sat")])
def test_a_callers_kernel_from_the_prelude_reconstructs_as_the_library(method, lookup):
    depth, u, v, d = scene()
    ctx = context()
    queue = cl.CommandQueue(ctx)
    options = dict(blur_radius=2, lookup=lookup, esm_classify="none") if method == "esm" else \
        dict(blur_radius=2, lookup=lookup)
    pre = sfd.kernel_prelude(method, **options)
    assert pre.files[0] == "shared_types.clh" and len(pre.params) > 0
    prg = cl.Program(ctx, pre.source + CALLER_KERNEL).build(options=pre.build_options)
    pipe = sfd.Pipeline(queue, W, H, method=method, **options)
    dd = cla.to_device(queue, depth)
    du, dv, drx = (cla.to_device(queue, a) for a in (u, v, d))
    ours, theirs = cla.empty(queue, d.shape, np.float32), cla.empty(queue, d.shape, np.float32)
    filtered = pipe.prefilter(dd)
    basis, chain, sat = pipe.lookup_tables()
    assert basis is not None and (chain is not None) == (lookup == "mips") and (sat is not None) == (lookup == "sat")
    shade = prg.caller_shade
    shade.set_args(basis, chain, sat, np.int32(W), np.int32(H), du.data, dv.data, drx.data, ours.data,
                   np.int32(d.size), np.frombuffer(pre.params, np.uint8))
    mine = cl.enqueue_nd_range_kernel(queue, shade, (d.size,), None, wait_for=[filtered])
    pipe.reconstruct(du, dv, drx, theirs, wait_for=[filtered]).wait()
    mine.wait()
    got, want = ours.get(), theirs.get()
    assert np.isfinite(got).all() and (want < 0.5).mean() > 0.05
    np.testing.assert_allclose(got, want, rtol=0, atol=2e-5)  # the same math, scalar against vector code


def test_single_kernels_refuse_what_they_cannot_do():
    ctx = context()
    queue = cl.CommandQueue(ctx)
    small = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 16)
    big = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, W * H * 64)
    with pytest.raises(sf.InputError, match="basis holds 16 bytes"):
        sfd.enqueue_transform(queue, W, H, big, small, method="vsm")
    with pytest.raises(sf.InputError, match="has no basis"):
        sfd.basis_shape("pcf", W, H)
    with pytest.raises(sf.InputError, match="has no basis"):
        sfd.kernel_prelude("sm")
    with pytest.raises(sf.InputError, match="in place .* needs tmp"):
        sfd.enqueue_blur(queue, W, H, 2, big, big, blur_radius=2)
    with pytest.raises(sf.InputError, match="mips and sat need their tables"):
        sfd.enqueue_reconstruct_points(queue, W, H, big, big, big, big, big, count=10, method="vsm", lookup="mips")
    with pytest.raises(sf.InputError, match="csm_order"):
        sfd.basis_shape("csm", W, H, csm_order=99)
