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
