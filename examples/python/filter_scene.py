"""Filters a bundled scene with shadowfilter and plots the light's depth map, the filtered
visibility and its error against the ray-traced reference (docs/python.md).

    python examples/python/filter_scene.py [SCENE_DIR] [-o FIGURE.png] [--method esm]

Needs numpy, matplotlib and openexr (pip install shadowfilter[examples]).
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import OpenEXR  # noqa: E402

import shadowfilter as sf  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def channels(path):
    """Every channel of an EXR file as float32 (half channels convert exactly)."""
    return {k: v.pixels.astype(np.float32) for k, v in OpenEXR.File(path).channels().items()}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene", nargs="?", default=os.path.join(HERE, "..", "..", "data", "spheres"))
    p.add_argument("-o", "--output", default="filter_scene.png")
    p.add_argument("--method", default="esm")
    p.add_argument("--blur-radius", type=int, default=3)
    a = p.parse_args()

    depth = channels(os.path.join(a.scene, "shadowmap.exr"))["Z"]
    rx = channels(os.path.join(a.scene, "receivers.exr"))
    receivers = np.stack([rx[k] for k in ("u", "v", "d", "f", "ndl")], axis=-1)  # (h, w, 5)
    reference = channels(os.path.join(a.scene, "reference_hard.exr"))["Y"]  # ray traced, hard shadows

    visibility = sf.filter(depth, receivers, method=a.method, blur_radius=a.blur_radius)
    error = visibility - reference
    seen = np.isfinite(rx["d"])  # the background has no receiver
    rmse = float(np.sqrt(np.mean(error[seen] ** 2)))

    grey = plt.get_cmap("gray").copy()
    grey.set_bad("lightsteelblue")  # background: no receiver
    diverging = plt.get_cmap("RdBu_r").copy()
    diverging.set_bad("lightsteelblue")
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4), constrained_layout=True)
    im = axes[0].imshow(depth, cmap="viridis")
    axes[0].set_title("light's depth map d (linear, 0 = near)")
    fig.colorbar(im, ax=axes[0], shrink=0.8)
    im = axes[1].imshow(np.where(seen, visibility, np.nan), cmap=grey, vmin=0, vmax=1)
    axes[1].set_title(f"{a.method}, blur radius {a.blur_radius}: visibility")
    fig.colorbar(im, ax=axes[1], shrink=0.8)
    im = axes[2].imshow(np.where(seen, error, np.nan), cmap=diverging, vmin=-0.5, vmax=0.5)
    axes[2].set_title(f"minus the ray-traced reference (RMSE {rmse:.3f})")
    fig.colorbar(im, ax=axes[2], shrink=0.8)
    for ax in axes:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.savefig(a.output, dpi=80)
    print(f"{a.output}: {a.method} on {os.path.basename(os.path.normpath(a.scene))}, RMSE {rmse:.4f} against the reference")


if __name__ == "__main__":
    main()
