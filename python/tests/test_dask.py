import numpy as np
import pytest

import shadowfilter as sf

distributed = pytest.importorskip("distributed")
import shadowfilter.dask  # noqa: E402


def frames(count):
    rng = np.random.default_rng(7)
    out = []
    for i in range(count):
        depth = np.full((48, 64), 0.7, np.float32)
        depth[10:30, 5 + i : 25 + i] = rng.uniform(0.2, 0.3)
        receiver_depth = np.full((48, 64), 0.6, np.float32)
        out.append({"depth": depth, "receiver_depth": receiver_depth})
    return out


def test_two_workers_write_what_one_process_writes():
    work = frames(20)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            images = client.gather(shadowfilter.dask.filter_frames(client, work, method="vsm", blur_radius=1))
            served = client.run(lambda dask_worker: dask_worker.shadowfilter_device is not None)
    assert len(served) == 2 and all(served.values())
    for frame, image in zip(work, images):
        alone = sf.filter(frame["depth"], receiver_depth=frame["receiver_depth"], method="vsm", blur_radius=1)
        np.testing.assert_array_equal(image, alone)
    assert not np.array_equal(images[0], images[19])  # the occluder moves: not one image


def test_frames_as_files_in_and_out(tmp_path):
    """Frames named by .npy paths, read on the workers; results written by the workers as .npy
    files, which equal the single process's results."""
    work = frames(6)
    named = []
    for i, frame in enumerate(work):
        entry = {}
        for key, array in frame.items():
            path = tmp_path / f"{key}{i}.npy"
            np.save(path, array)
            entry[key] = str(path)
        named.append(entry)
    outputs = [str(tmp_path / f"v{i}.npy") for i in range(len(work))]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            written = client.gather(shadowfilter.dask.filter_frames(client, named, method="esm", outputs=outputs))
            with pytest.raises(sf.InputError, match="one path per frame"):
                shadowfilter.dask.filter_frames(client, named, outputs=outputs[:2])
    assert written == outputs
    for frame, path in zip(work, outputs):
        alone = sf.filter(frame["depth"], receiver_depth=frame["receiver_depth"], method="esm")
        np.testing.assert_array_equal(np.load(path), alone)
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".sf-")) == []  # nothing staged is left
