"""What the tests that compare the package with the `shadowfilter` command share: the command
(SF_CLI, which ctest sets), the bundled data, and EXR files read and written as the command does."""
import os

import numpy as np

CLI = os.environ.get("SF_CLI", "")
DATA = os.path.join(os.environ.get("SF_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")), "data")


def channels(path):
    """An EXR's channels by name, as float32 arrays."""
    import OpenEXR

    return {k: v.pixels.astype(np.float32) for k, v in OpenEXR.File(path).channels().items()}


def write_depth(path, depth):
    """A one-channel (Z) zip-compressed scan-line EXR, as the command reads depth maps."""
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"Z": depth}).write(str(path))
