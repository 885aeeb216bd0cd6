import numpy as np
import pytest

import shadowfilter as sf


def test_methods_lists_the_registry():
    assert {"esm", "vsm", "msm", "pcf"} <= set(sf.methods())


def test_a_flat_receiver_in_front_of_the_map_is_lit_and_one_behind_it_is_shadowed():
    depth = np.full((64, 64), 0.5, dtype=np.float32)
    lit = sf.filter(depth, receiver_depth=np.full((64, 64), 0.4, np.float32), method="pcf")
    dark = sf.filter(depth, receiver_depth=np.full((64, 64), 0.6, np.float32), method="pcf")
    assert lit.shape == (64, 64) and lit.dtype == np.float32
    assert lit.min() == pytest.approx(1.0)
    assert dark.max() == pytest.approx(0.0)


def test_an_inexact_conversion_is_refused():
    depth = np.full((8, 8), 0.1, dtype=np.float64)  # 0.1 is not a float32
    with pytest.raises(sf.InputError, match="float32 does not hold exactly"):
        sf.filter(depth, receiver_depth=np.zeros((8, 8), np.float32))
    assert issubclass(sf.InputError, ValueError)


def test_the_python_benchmark_runs(tmp_path):
    """bench/python_layers.py --smoke: every part of the Python figures once at small sizes, so
    that the benchmark does not break unseen (its figures mean nothing here)."""
    import json
    import os
    import subprocess
    import sys

    pytest.importorskip("pyopencl")
    pytest.importorskip("distributed")
    source = os.environ.get("SF_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
    out = tmp_path / "figures.json"
    subprocess.run([sys.executable, os.path.join(source, "bench", "python_layers.py"), "--smoke", "--json", str(out)],
                   check=True, capture_output=True, env=dict(os.environ))
    figures = json.loads(out.read_text())
    assert figures["pyopencl"]["in_place_ms"] > 0 and figures["dask"][0]["cluster_files_fps"] > 0


def test_the_stubs_declare_every_public_name():
    """Each module's __all__ is declared in its .pyi, so that type checkers see the whole API."""
    import ast
    import importlib
    import os

    pytest.importorskip("pyopencl")
    pytest.importorskip("distributed")
    for name in ("shadowfilter", "shadowfilter.device", "shadowfilter.dask"):
        module = importlib.import_module(name)
        stub = os.path.splitext(module.__file__)[0] + ".pyi"
        tree = ast.parse(open(stub).read())
        declared = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
        declared |= {t.id for n in tree.body if isinstance(n, (ast.Assign, ast.AnnAssign))
                     for t in (n.targets if isinstance(n, ast.Assign) else [n.target]) if isinstance(t, ast.Name)}
        assert set(module.__all__) <= declared, (name, set(module.__all__) - declared)


def test_a_frame_filter_gives_filters_bits_on_a_sequence_and_reuses_its_buffers():
    rng = np.random.default_rng(5)
    frames = []
    for i, n in enumerate((48, 48, 48, 64)):  # the last frame changes size: one more allocation
        depth = rng.uniform(0.2, 0.9, (n, n)).astype(np.float32)
        frames.append({"depth": depth, "receiver_depth": np.full((n, n), 0.55, np.float32)})
    rx = np.stack([rng.uniform(0, 1, (8, 8)), rng.uniform(0, 1, (8, 8)), rng.uniform(0.3, 0.8, (8, 8))], axis=-1).astype(np.float32)
    batch = sf.FrameFilter(method="vsm", blur_radius=2)
    for f in frames:
        np.testing.assert_array_equal(batch(f["depth"], receiver_depth=f["receiver_depth"]),
                                      sf.filter(f["depth"], receiver_depth=f["receiver_depth"], method="vsm",
                                                blur_radius=2))
    assert batch.allocations == 2
    images = list(sf.filter_frames([(f["depth"], rx) for f in frames], method="esm"))
    for f, image in zip(frames, images):
        np.testing.assert_array_equal(image, sf.filter(f["depth"], rx, method="esm"))
    with pytest.raises(sf.InputError, match="blur_radius"):
        sf.FrameFilter(blur_radius=-3)
