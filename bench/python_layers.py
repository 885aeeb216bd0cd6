#!/usr/bin/env python3
"""The Python layers' figures (docs/python.md "Figures"): a benchmark, not a test.

1. numpy-call overhead: shadowfilter.filter on one 512x512 frame (vsm, blur R = 2, one receiver per
   texel), and shadowfilter.FrameFilter running it as a frame of a sequence, against the C++
   API's sf::filter on the same frame (sf_bench's host_filter/grid_vsm), A/B interleaved: rounds
   alternate them, and the medians are compared.
2. Dask: frames per second of shadowfilter.dask on a LocalCluster of 2 single-threaded worker
   processes against one process filtering the same frames in turn, on the same cores, for 20
   frames of 512x512 and of 2048x2048: frames as arrays sent from the client, and as .npy files
   that the workers read and write.
3. pyopencl in place: shadowfilter.device.Pipeline on device buffers (the map already on the
   device, the visibility left there) against shadowfilter.filter's numpy round trip, at
   2048x2048 with one receiver per texel.

    python3 bench/python_layers.py --sf-bench build/sf_bench [--json out.json]
    python3 bench/python_layers.py --smoke      # every part once at small sizes (the tests run it)

Needs the package on the path (PYTHONPATH=build/python, or installed), numpy, and for parts 2 and
3 dask[distributed] and pyopencl. Without --sf-bench part 1 reports the Python side alone.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

import numpy as np

import shadowfilter as sf


def median_seconds(run, repeats, warmups=2):
    for _ in range(warmups):
        run()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def frame(n, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.2, 0.9, (n, n)).astype(np.float32), rng.uniform(0.2, 0.9, (n, n)).astype(np.float32)


def cpp_host_filter_seconds(sf_bench):
    """sf_bench's median of sf::filter on the 512x512 frame (host wall time)."""
    out = subprocess.run([sf_bench, "--benchmark_filter=host_filter/grid_vsm", "--benchmark_format=json"],
                         check=True, capture_output=True, text=True, env={"SF_BENCH_REPETITIONS": "5",
                                                                          "PATH": "/usr/bin:/bin"}).stdout
    runs = [b for b in json.loads(out)["benchmarks"] if b.get("aggregate_name") == "median"]
    return runs[0]["real_time"] * {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[runs[0]["time_unit"]]


def part_numpy_overhead(n, rounds, repeats, sf_bench):
    depth, rd = frame(n, 9)
    device = sf.Device("")
    batch = sf.FrameFilter(method="vsm", blur_radius=2, device=device)
    py, frames, cpp = [], [], []
    for _ in range(rounds):  # A/B interleaved: the machine is shared and noisy
        py.append(median_seconds(lambda: sf.filter(depth, receiver_depth=rd, method="vsm", blur_radius=2,
                                                   device=device), repeats))
        frames.append(median_seconds(lambda: batch(depth, receiver_depth=rd), repeats))
        if sf_bench:
            cpp.append(cpp_host_filter_seconds(sf_bench))
    r = {"size": n, "python_ms": 1e3 * statistics.median(py), "frame_filter_ms": 1e3 * statistics.median(frames)}
    if cpp:
        r["cpp_ms"] = 1e3 * statistics.median(cpp)
        r["overhead_ms"] = r["python_ms"] - r["cpp_ms"]
        r["ratio"] = r["python_ms"] / r["cpp_ms"]
        r["frame_filter_ratio"] = r["frame_filter_ms"] / r["cpp_ms"]
    return r


def part_dask(n, count, rounds):
    """Frames as arrays sent from the client (results gathered), and as .npy files read and written
    by the workers (what a shared file system gives a real cluster); one process does the same."""
    import tempfile

    import distributed

    import shadowfilter.dask

    frames = [dict(zip(("depth", "receiver_depth"), frame(n, 100 + i))) for i in range(count)]
    device = sf.Device("")
    options = dict(method="vsm", blur_radius=2)
    with tempfile.TemporaryDirectory() as tmp:
        named, outputs = [], []
        for i, f in enumerate(frames):
            named.append({k: f"{tmp}/{k}{i}.npy" for k in f})
            for k, v in f.items():
                np.save(named[-1][k], v)
            outputs.append(f"{tmp}/v{i}.npy")

        def one_arrays():
            return [sf.filter(f["depth"], receiver_depth=f["receiver_depth"], device=device, **options) for f in frames]

        def one_files():
            for f, out in zip(named, outputs):
                np.save(out, sf.filter(np.load(f["depth"]), receiver_depth=np.load(f["receiver_depth"]), device=device,
                                       **options))

        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
            with distributed.Client(c) as client:
                def two_arrays():
                    return client.gather(shadowfilter.dask.filter_frames(client, frames, **options))

                def two_files():
                    return client.gather(shadowfilter.dask.filter_frames(client, named, outputs=outputs, **options))

                two_files()  # the workers open their devices and build their programs
                t = {"one_arrays": [], "cluster_arrays": [], "one_files": [], "cluster_files": []}
                for _ in range(rounds):  # A/B interleaved
                    for name, run in (("one_arrays", one_arrays), ("cluster_arrays", two_arrays),
                                      ("one_files", one_files), ("cluster_files", two_files)):
                        t[name].append(median_seconds(run, 1, warmups=0))
    fps = {k: count / statistics.median(v) for k, v in t.items()}
    return {"size": n, "frames": count, **{k + "_fps": v for k, v in fps.items()},
            "ratio_arrays": fps["cluster_arrays"] / fps["one_arrays"],
            "ratio_files": fps["cluster_files"] / fps["one_files"]}


def part_pyopencl(n, rounds, repeats):
    import pyopencl as cl
    import pyopencl.array as cla

    import shadowfilter.device as sfd

    depth, rd = frame(n, 11)
    ctx = cl.Context([cl.get_platforms()[0].get_devices()[0]])
    queue = cl.CommandQueue(ctx)
    dd, drd = cla.to_device(queue, depth), cla.to_device(queue, rd)
    out = cla.empty(queue, (n, n), np.float32)
    pipe = sfd.Pipeline(queue, n, n, method="vsm", blur_radius=2)
    device = sf.Device("")
    in_place = lambda: pipe.reconstruct_grid(drd, out, wait_for=[pipe.prefilter(dd)]).wait()
    round_trip = lambda: sf.filter(depth, receiver_depth=rd, method="vsm", blur_radius=2, device=device)
    a, b = [], []
    for _ in range(rounds):
        a.append(median_seconds(in_place, repeats))
        b.append(median_seconds(round_trip, repeats))
    np.testing.assert_array_equal(out.get(), round_trip())  # the same bits either way
    t_in, t_rt = statistics.median(a), statistics.median(b)
    return {"size": n, "in_place_ms": 1e3 * t_in, "numpy_round_trip_ms": 1e3 * t_rt, "ratio": t_rt / t_in}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sf-bench", help="the sf_bench binary (the C++ side of part 1)")
    ap.add_argument("--smoke", action="store_true", help="every part once at small sizes")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    if a.smoke:
        sizes = dict(numpy=64, dask=[32], frames=4, pyopencl=128, rounds=1, repeats=1)
    else:
        sizes = dict(numpy=512, dask=[512, 2048], frames=20, pyopencl=2048, rounds=5, repeats=5)
    device = sf.devices()[0]
    figures = {"device": repr(device)}
    t0 = time.perf_counter()
    figures["numpy_overhead"] = part_numpy_overhead(sizes["numpy"], sizes["rounds"], sizes["repeats"],
                                                    None if a.smoke else a.sf_bench)
    figures["dask"] = [part_dask(n, sizes["frames"], min(sizes["rounds"], 3)) for n in sizes["dask"]]
    figures["pyopencl"] = part_pyopencl(sizes["pyopencl"], sizes["rounds"], sizes["repeats"])
    figures["seconds"] = time.perf_counter() - t0
    print(json.dumps(figures, indent=2))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(figures, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
