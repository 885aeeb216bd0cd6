"""Python's results equal the CLI's bit for bit on the bundled scenes, for every method."""
import os
import subprocess

import numpy as np
import pytest

import shadowfilter as sf

from cli_files import CLI, DATA, channels

pytest.importorskip("OpenEXR")
pytestmark = pytest.mark.skipif(not CLI, reason="SF_CLI names the shadowfilter command (ctest sets it)")


def receivers_of(path):
    c = channels(path)
    return np.stack([c[k] for k in ("u", "v", "d", "f", "ndl")], axis=-1)


@pytest.mark.parametrize("method", sf.methods())
def test_python_equals_the_cli_on_spheres(method, tmp_path):
    scene = os.path.join(DATA, "spheres")
    out = tmp_path / "v.exr"
    subprocess.run([CLI, "filter", "--shadow-map", f"{scene}/shadowmap.exr", "--receivers", f"{scene}/receivers.exr",
                    "-o", str(out), "--method", method, "--blur-radius", "2", "-q"], check=True)
    cli = channels(str(out))
    (cli_v,) = cli.values()
    ours = sf.filter(channels(f"{scene}/shadowmap.exr")["Z"], receivers_of(f"{scene}/receivers.exr"), method=method,
                     blur_radius=2)
    assert ours.shape == cli_v.shape
    np.testing.assert_array_equal(ours, cli_v)
