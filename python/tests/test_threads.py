"""The GIL is released while the device works (module.cpp): two threads filtering at once on one
device give what one thread gives."""
import threading

import numpy as np

import shadowfilter as sf


def frame(i):
    depth = np.full((256, 256), 0.7, np.float32)
    depth[40:120, 30 + 8 * i : 110 + 8 * i] = 0.25
    return depth, np.full((256, 256), 0.6, np.float32)


def test_two_threads_at_once_equal_one_after_the_other():
    device = sf.Device()
    frames = [frame(i) for i in range(8)]
    alone = [sf.filter(d, receiver_depth=r, method="evsm4", blur_radius=4, device=device) for d, r in frames]
    results = [None] * len(frames)

    def work(indices):
        for i in indices:
            depth, receiver_depth = frames[i]
            results[i] = sf.filter(depth, receiver_depth=receiver_depth, method="evsm4", blur_radius=4, device=device)

    threads = [threading.Thread(target=work, args=(range(k, 8, 2),)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(alone, results):
        np.testing.assert_array_equal(a, b)
    assert not np.array_equal(alone[0], alone[7])
