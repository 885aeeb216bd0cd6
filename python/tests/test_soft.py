"""soft(): the `soft` command on arrays. Results equal the command's bit for bit on the bundled
scenes for every technique; every keyword's bad value raises with the command's message."""
import math
import os
import re
import subprocess

import numpy as np
import pytest

import shadowfilter as sf

from cli_files import CLI, DATA, channels, write_depth

needs_cli = pytest.mark.skipif(not CLI, reason="SF_CLI names the shadowfilter command (ctest sets it)")


def header_light(path):
    """The light the command reads from a bundled map's header (strings, as the scene writer
    stores them), as soft()'s keywords."""
    import OpenEXR

    h = OpenEXR.File(path).header()
    x0, x1, _, _ = (float(t) for t in h["ortho_extents"].strip("[]").split(","))
    assert h["light_type"] == "orthographic"
    return dict(light_size=float(h["light_size"]), light_near=float(h["near"]), light_far=float(h["far"]),
                light_extent=x1 - x0)


@needs_cli
@pytest.mark.parametrize("method", ["pcss", "cssm", "ssmm", "ssmm-improved"])
@pytest.mark.parametrize("scene", ["spheres", "fence"])
def test_soft_equals_the_cli(scene, method, tmp_path):
    pytest.importorskip("OpenEXR")
    s = os.path.join(DATA, scene)
    out = tmp_path / "v.exr"
    extra = ["--cssm-order", "6", "--lookup", "mips"] if method == "cssm" and scene == "fence" else []
    subprocess.run([CLI, "soft", "--method", method, "--shadow-map", f"{s}/shadowmap.exr", "--receivers",
                    f"{s}/receivers.exr", "-o", str(out), "-q", *extra], check=True)
    (cli,) = channels(str(out)).values()
    rx = channels(f"{s}/receivers.exr")
    receivers = np.stack([rx[k] for k in ("u", "v", "d", "f", "ndl")], axis=-1)
    options = dict(cssm_order=6, lookup="mips") if extra else {}
    ours = sf.soft(channels(f"{s}/shadowmap.exr")["Z"], receivers, method=method,
                   **header_light(f"{s}/shadowmap.exr"), **options)
    assert ours.shape == cli.shape
    assert (ours < 0.5).mean() > 0.01  # the scene has shadows to compare
    np.testing.assert_array_equal(ours, cli)


def test_lights_from_projections():
    ortho = np.diag([2 / 8.0, 2 / 8.0, -2 / 10.0, 1.0])
    ortho[2, 3] = -(12 + 2) / 10.0  # near 2, far 12
    L = sf.soft_light({"view": np.eye(4).ravel().tolist(), "projection": ortho.ravel().tolist()}, light_size=0.3)
    assert not L.perspective and L.size == 0.3
    assert L.extent == pytest.approx(8.0) and L.near_plane == pytest.approx(2.0) and L.far_plane == pytest.approx(12.0)
    n, f = 1.0, 20.0
    persp = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -(f + n) / (f - n), -2 * f * n / (f - n)], [0, 0, -1, 0]])
    L = sf.soft_light({"view": np.eye(4).tolist(), "projection": persp.tolist()}, light_size=0.5)
    assert L.perspective and L.fov_degrees == pytest.approx(90.0)
    assert L.near_plane == pytest.approx(1.0) and L.far_plane == pytest.approx(20.0)
    with pytest.raises(sf.InputError, match="drop light_extent"):
        sf.soft_light({"view": np.eye(4).tolist(), "projection": persp.tolist()}, light_size=0.5, light_extent=3)
    with pytest.raises(sf.InputError, match="give light_size"):
        sf.soft_light({"view": np.eye(4).tolist(), "projection": persp.tolist()})


# Keyword -> a value the command refuses (its flag is the keyword with '-' for '_').
BAD = {"soft_bias": 1.5, "soft_max_width": 0.5, "cssm_order": 40, "cssm_offset": 2, "cssm_scale": 100,
       "cssm_min_den": 1.5, "cssm_z_offset": 3, "cssm_width_scale": 65, "ssmm_n": 0, "slope_bias": 20,
       "receiver_plane_max_slope": -2, "light_size": -1, "cssm_storage": "unorm8"}


@needs_cli
@pytest.mark.parametrize("keyword", sorted(BAD))
def test_bad_values_raise_with_the_cli_message(keyword, tmp_path):
    pytest.importorskip("OpenEXR")
    depth = np.full((16, 16), 0.5, np.float32)
    rd = np.full((16, 16), 0.4, np.float32)
    write_depth(tmp_path / "map.exr", depth)
    write_depth(tmp_path / "rd.exr", rd)
    method = "ssmm" if keyword == "ssmm_n" else "cssm" if keyword.startswith("cssm") else "pcss"
    flags = {"light_size": 0.2, "light_extent": 8.0, keyword: BAD[keyword]}
    if keyword == "cssm_storage":
        flags["lookup"] = "mips"  # the narrow bases' lookup: unorm8 is then refused for itself
    args = [CLI, "soft", "--method", method, "--shadow-map", str(tmp_path / "map.exr"), "--receiver-depth",
            str(tmp_path / "rd.exr"), "-o", str(tmp_path / "out.exr")]
    for k, v in flags.items():
        args += ["--" + k.replace("_", "-"), str(v)]
    r = subprocess.run(args, capture_output=True, text=True)
    assert r.returncode == 2, r.stderr
    cli = re.sub(r"^shadowfilter: (error: )?", "", r.stderr.strip().splitlines()[0]).replace(" (see --help)", "")
    cli = cli.replace("--" + keyword.replace("_", "-"), keyword)
    with pytest.raises(sf.InputError) as e:
        sf.soft(depth, receiver_depth=rd, method=method, **flags)
    assert str(e.value) == cli


def test_wrong_types_are_refused():
    d = np.full((16, 16), 0.5, np.float32)
    light = dict(light_size=0.2, light_extent=8.0)
    with pytest.raises(sf.InputError, match="cssm_sharpen: must be \\(A, B\\)"):
        sf.soft(d, receiver_depth=d, method="cssm", cssm_sharpen=3, **light)
    with pytest.raises(sf.InputError, match="lookup must be mips or sat"):
        sf.soft(d, receiver_depth=d, method="cssm", lookup="bilinear", **light)
    with pytest.raises(sf.InputError, match="cssm_storage must be a storage name"):
        sf.soft(d, receiver_depth=d, method="cssm", lookup="mips", cssm_storage=16, **light)
    with pytest.raises(sf.InputError, match="cssm_storage: unknown storage 'f64'"):
        sf.soft(d, receiver_depth=d, method="cssm", lookup="mips", cssm_storage="f64", **light)
    with pytest.raises(sf.InputError, match="unknown option 'esm_c'"):
        sf.soft(d, receiver_depth=d, esm_c=3, **light)
    with pytest.raises(sf.InputError, match="unknown soft method 'esm'"):
        sf.soft(d, receiver_depth=d, method="esm", **light)
    with pytest.raises(sf.InputError, match="orthographic light needs"):
        sf.soft(d, receiver_depth=d, light_size=0.2)
    assert math.isclose(float(sf.soft(d, receiver_depth=np.full_like(d, 0.4), **light).min()), 1.0)


def test_cssm_storage_f16_is_float32_within_its_rounding():
    # A floor at 0.8 under a square occluder at 0.3: receivers on the floor cross its penumbra.
    depth = np.full((32, 32), 0.8, np.float32)
    depth[10:22, 10:22] = 0.3
    rd = np.full((32, 32), 0.8, np.float32)
    light = dict(light_size=0.2, light_extent=1.0, method="cssm", lookup="mips")
    f32 = sf.soft(depth, receiver_depth=rd, **light)
    assert ((f32 > 0.02) & (f32 < 0.98)).sum() > 4
    for storage in ("f16", "unorm16"):
        got = sf.soft(depth, receiver_depth=rd, cssm_storage=storage, **light)
        assert np.abs(got - f32).max() <= 2e-3, storage


def test_rectangular_light_sides():
    L = sf.soft_light(light_size=(0.4, 0.1), light_extent=8.0)
    assert (L.size, L.height) == (0.4, 0.1)
    assert sf.soft_light(light_size=0.3, light_extent=8.0).height == 0.3  # L: a square
    for bad in ((0.4,), (0.4, 0.1, 0.2), (0.4, -0.1), ("a", 0.1), (0.4, math.nan), -1):
        with pytest.raises(sf.InputError, match="light_size: must be a finite number >= 0"):
            sf.soft_light(light_size=bad, light_extent=8.0)


@needs_cli
@pytest.mark.parametrize("method", ["pcss", "cssm"])
def test_rectangular_light_equals_the_cli(method, tmp_path):
    pytest.importorskip("OpenEXR")
    s = os.path.join(DATA, "spheres")
    out = tmp_path / "v.exr"
    subprocess.run([CLI, "soft", "--method", method, "--shadow-map", f"{s}/shadowmap.exr", "--receivers",
                    f"{s}/receivers.exr", "--light-size", "0.6,0.1", "-o", str(out), "-q"], check=True)
    (cli,) = channels(str(out)).values()
    rx = channels(f"{s}/receivers.exr")
    receivers = np.stack([rx[k] for k in ("u", "v", "d", "f", "ndl")], axis=-1)
    light = header_light(f"{s}/shadowmap.exr")
    light["light_size"] = (0.6, 0.1)
    ours = sf.soft(channels(f"{s}/shadowmap.exr")["Z"], receivers, method=method, **light)
    np.testing.assert_array_equal(ours, cli)
    square = sf.soft(channels(f"{s}/shadowmap.exr")["Z"], receivers, method=method,
                     **dict(light, light_size=0.6))
    assert np.abs(square - ours).max() > 0.05  # the rectangle is not its long side's square
