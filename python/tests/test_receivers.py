"""Receivers from a camera: an analytic ground plane seen by an OpenGL camera and lit by an
orthographic light from above; the package's receivers equal the CLI's bit for bit and the
light-space depth of the plane is the analytic one."""
import json
import subprocess

import numpy as np
import pytest

import shadowfilter as sf

from cli_files import CLI, channels, write_depth

pytest.importorskip("OpenEXR")


def look_at(eye, target, up):
    f = np.subtract(target, eye, dtype=np.float64)
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = r, u, -f
    m[:3, 3] = -m[:3, :3] @ np.asarray(eye, np.float64)
    return m


def perspective(fov_y_deg, aspect, near, far):
    t = 1 / np.tan(np.radians(fov_y_deg) / 2)
    return np.array([[t / aspect, 0, 0, 0], [0, t, 0, 0], [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]])


def orthographic(half, near, far):
    return np.array([[1 / half, 0, 0, 0], [0, 1 / half, 0, 0], [0, 0, -2 / (far - near), -(far + near) / (far - near)],
                     [0, 0, 0, 1]])


W, H = 64, 48
CAMERA = {"view": look_at((0, 3, 5), (0, 0, 0), (0, 1, 0)), "projection": perspective(60, W / H, 0.5, 20)}
LIGHT = {"view": look_at((0, 10, 0), (0, 0, 0), (0, 0, -1)), "projection": orthographic(6, 1, 20)}


def ground_window_depth():
    """OpenGL window depth of the plane y = 0 at every pixel centre (1 where the ray misses it)."""
    inverse = np.linalg.inv(CAMERA["projection"] @ CAMERA["view"])
    x = (np.arange(W) + 0.5) / W * 2 - 1
    y = 1 - (np.arange(H) + 0.5) / H * 2  # row 0 = the top row
    X, Y = np.meshgrid(x, y)
    near = inverse @ np.stack([X, Y, -np.ones_like(X), np.ones_like(X)]).reshape(4, -1)
    far = inverse @ np.stack([X, Y, np.ones_like(X), np.ones_like(X)]).reshape(4, -1)
    near, far = near[:3] / near[3], far[:3] / far[3]
    t = near[1] / (near[1] - far[1])
    hit = (t > 0) & (t < 1)
    p = near + t * (far - near)
    clip = CAMERA["projection"] @ CAMERA["view"] @ np.vstack([p, np.ones(p.shape[1])])
    window = np.where(hit, (clip[2] / clip[3] + 1) / 2, 1.0)
    return window.reshape(H, W).astype(np.float32)


def test_the_package_equals_the_cli_and_the_analytic_depth(tmp_path):
    depth = ground_window_depth()
    counts = {}
    rx = sf.receivers(CAMERA, depth, LIGHT, map_size=(256, 256), counts=counts)
    assert rx.shape == (H, W, 12) and rx.dtype == np.float32
    ground = np.isfinite(rx[..., 2])
    assert ground.sum() > W * H // 2 and counts["background"] == W * H - ground.sum()
    # The light looks straight down from y = 10 with planes 1 and 20: the plane is at d = 9 / 19.
    np.testing.assert_allclose(rx[..., 2][ground], 9 / 19, atol=1e-5)
    np.testing.assert_allclose(rx[..., 4][ground], 1.0, atol=1e-3)  # n.l: the plane faces the light
    # The normal scaled to one texel (12 / 256 world units): straight up, towards the light, so
    # no step across the map and d falls by a texel's width over the depth range of 19.
    np.testing.assert_allclose(rx[..., 5][ground], 0.0, atol=2e-3)
    np.testing.assert_allclose(rx[..., 6][ground], 0.0, atol=2e-3)
    np.testing.assert_allclose(rx[..., 7][ground], -(12 / 256) / 19, rtol=2e-3)
    if not CLI:
        pytest.skip("SF_CLI names the shadowfilter command (ctest sets it)")
    for name, view in (("camera", CAMERA), ("light", LIGHT)):
        (tmp_path / f"{name}.json").write_text(json.dumps({k: v.flatten().tolist() for k, v in view.items()}))
    write_depth(tmp_path / "depth.exr", depth)
    subprocess.run([CLI, "receivers", "--camera", str(tmp_path / "camera.json"), "--camera-depth",
                    str(tmp_path / "depth.exr"), "--light", str(tmp_path / "light.json"), "--map-size", "256x256",
                    "-o", str(tmp_path / "rx.exr"), "-q"], check=True)
    cli = channels(str(tmp_path / "rx.exr"))
    for i, k in enumerate("u v d f ndl nx ny nz dudx dvdx dudy dvdy".split()):
        np.testing.assert_array_equal(rx[..., i], cli[k], err_msg=k)


def test_normal_offset_moves_each_lookup_along_the_normal():
    depth = ground_window_depth()
    rx = sf.receivers(CAMERA, depth, LIGHT, map_size=(256, 256))
    ground = np.isfinite(rx[..., 2]) & (rx[..., 0] >= 0) & (rx[..., 0] <= 1) & (rx[..., 1] >= 0) & (rx[..., 1] <= 1)
    # The plane's map, its right half raised towards the light by 0.003: the flat test (no plane,
    # no bias) shadows the receivers there. Two texels along the normal (straight up) lift them
    # 2 (12 / 256) / 19 = 0.0049 towards the light, above the raised half: lit.
    m = np.full((256, 256), 9 / 19, np.float32)
    m[:, 128:] -= 0.003
    flat = {"method": "sm", "receiver_plane": "off", "bias": 0}
    right = ground & (rx[..., 0] > 130 / 256)
    plain = sf.filter(m, rx, normal_offset=0, **flat)
    assert right.sum() > 100 and (plain[right] == 0).all()
    t = 2.0
    offset = sf.filter(m, rx, normal_offset=t, **flat)
    assert (offset[ground] == 1).all()
    moved = rx.copy()
    moved[..., 0] += t * rx[..., 5] / 256
    moved[..., 1] += t * rx[..., 6] / 256
    moved[..., 2] += t * rx[..., 7]
    np.testing.assert_array_equal(offset, sf.filter(m, moved, normal_offset=0, **flat))
    with pytest.raises(sf.InputError, match="normal_offset"):
        sf.filter(m, rx, method="sm", normal_offset=9)


def test_bad_views_are_refused_with_the_cli_words():
    with pytest.raises(sf.InputError, match="unknown key"):
        sf.receivers({**CAMERA, "fov": 60}, ground_window_depth(), LIGHT, map_size=(8, 8))
    with pytest.raises(sf.InputError, match="clip must be"):
        sf.receivers({**CAMERA, "clip": "metal"}, ground_window_depth(), LIGHT, map_size=(8, 8))
    with pytest.raises(sf.InputError):
        sf.receivers(CAMERA, ground_window_depth() * 3, LIGHT, map_size=(8, 8))  # window depth beyond [0, 1]


def test_the_jacobian_is_the_footprint_and_anisotropic_lookups_follow_it():
    depth = ground_window_depth()
    rx = sf.receivers(CAMERA, depth, LIGHT, map_size=(256, 256))
    ground = np.isfinite(rx[..., 2]) & (rx[..., 0] >= 0) & (rx[..., 0] <= 1) & (rx[..., 1] >= 0) & (rx[..., 1] <= 1)
    jx, jy = np.hypot(rx[..., 8], rx[..., 9]), np.hypot(rx[..., 10], rx[..., 11])
    # f is the longer column; the ground seen from the camera's angle is longer along the view.
    np.testing.assert_allclose(np.maximum(jx, jy)[ground], rx[..., 3][ground], rtol=1e-4)
    ratio = np.maximum(jx, jy)[ground] / np.maximum(np.minimum(jx, jy)[ground], 1e-9)
    assert ratio.max() > 1.5
    # A blocker edge across the ground: the anisotropic lookup differs from the isotropic one,
    # and max_anisotropy=1 is the isotropic lookup of the 8 channels bit for bit.
    m = np.full((256, 256), 9 / 19, np.float32)
    m[100:140, :] = 0.2
    iso = sf.filter(m, rx[..., :8], method="vsm", lookup="mips", blur_radius=1)
    one = sf.filter(m, rx, method="vsm", lookup="mips", blur_radius=1, max_anisotropy=1)
    np.testing.assert_array_equal(one, iso)
    aniso = sf.filter(m, rx, method="vsm", lookup="mips", blur_radius=1, max_anisotropy=8)
    assert np.abs(aniso - iso)[ground].max() > 0.05
    with pytest.raises(sf.InputError, match="max_anisotropy"):
        sf.filter(m, rx, method="vsm", lookup="mips", max_anisotropy=17)
