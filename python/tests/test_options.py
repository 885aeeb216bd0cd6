"""Keyword options are generated from the library's declared parameters, and every option's bad
value raises InputError with the CLI's message (the keyword in place of the flag)."""
import math
import re
import subprocess

import numpy as np
import pytest

import shadowfilter as sf

from cli_files import CLI, write_depth

DEPTH = np.full((16, 16), 0.5, np.float32)
RECEIVER_DEPTH = np.full((16, 16), 0.4, np.float32)


def bad_value(option):
    """A value outside the option's declared range (NaN where it declares none)."""
    r = option["range"]
    if option["type"] == "choice":
        return "nosuch"
    if r == "a positive number":
        return 0
    if r.startswith("at least"):
        return -1
    m = re.match(r"in [\[(]?(-?[\d.e+-]+?)(?:\.\.|, )(-?[\d.e+-]+)[\])]?$", r)
    if m:
        return int(m.group(2)) + 1 if option["type"] == "integer" else float(m.group(2)) + 1
    return -1000 if option["type"] == "integer" else math.nan


def test_every_declared_parameter_is_a_keyword():
    keywords = {o["keyword"] for o in sf.options()}
    assert {"esm_c", "blur_radius", "storage", "lookup", "csm_order", "lbr", "bias"} <= keywords
    for o in sf.options():
        assert o["flag"] == "--" + o["keyword"].replace("_", "-")


@pytest.mark.skipif(not CLI, reason="SF_CLI names the shadowfilter command (ctest sets it)")
def test_every_bad_value_raises_with_the_cli_message(tmp_path):
    pytest.importorskip("OpenEXR")
    write_depth(tmp_path / "map.exr", DEPTH)
    write_depth(tmp_path / "rd.exr", RECEIVER_DEPTH)
    checked = 0
    for option in sf.options():
        method = option["methods"][0] if option["methods"] else "esm"
        value = bad_value(option)
        r = subprocess.run([CLI, "filter", "--shadow-map", str(tmp_path / "map.exr"), "--receiver-depth",
                            str(tmp_path / "rd.exr"), "-o", str(tmp_path / "out.exr"), "--method", method,
                            option["flag"], str(value)], capture_output=True, text=True)
        if r.returncode == 0:
            continue  # a value the CLI takes (an unbounded parameter given a finite number)
        assert r.returncode == 2, (option["flag"], r.stderr)
        cli = r.stderr.strip().splitlines()[0]
        cli = re.sub(r"^shadowfilter: (error: )?", "", cli).replace(" (see --help)", "")
        cli = cli.replace(option["flag"], option["keyword"]).replace("'nan'", "nan")
        with pytest.raises(sf.InputError) as e:
            sf.filter(DEPTH, receiver_depth=RECEIVER_DEPTH, method=method, **{option["keyword"]: value})
        assert str(e.value) == cli, option["keyword"]
        checked += 1
    assert checked >= 15


def test_wrong_types_and_unknown_options_are_refused():
    with pytest.raises(sf.InputError, match="unknown option 'esm_k'"):
        sf.filter(DEPTH, receiver_depth=RECEIVER_DEPTH, esm_k=3)
    with pytest.raises(sf.InputError, match="blur_radius: must be an integer, got 2.5"):
        sf.filter(DEPTH, receiver_depth=RECEIVER_DEPTH, blur_radius=2.5)
    with pytest.raises(sf.InputError, match="esm_c: must be a number"):
        sf.filter(DEPTH, receiver_depth=RECEIVER_DEPTH, esm_c="80")
    with pytest.raises(sf.InputError, match="unknown method"):
        sf.filter(DEPTH, receiver_depth=RECEIVER_DEPTH, method="nosuch")
    lit = sf.filter(DEPTH, receiver_depth=RECEIVER_DEPTH, method="esm", esm_c=20, storage="f16", lookup="mips")
    assert lit.min() > 0.99
