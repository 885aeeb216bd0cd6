#!/usr/bin/env python3
"""Frames of a built-in scene under a turning light, for `shadowfilter evaluate --frames`.

Writes OUT/f0 .. OUT/f{N-1}, each a whole scene directory (`shadowfilter scene`): frame 0 under
the scene's own light, frame k under that light's direction turned k * STEP degrees about the
world's up axis (y), its elevation kept, as a sun over a day. The camera is the scene's default
in every frame, so a receiver is one world point in all of them.

Usage: scripts/light_frames.py BUILD_DIR SCENE OUT [--frames 4] [--step 0.5] [--size 512]
           [--receivers 320x240] [--samples 16]
then:  BUILD_DIR/shadowfilter evaluate OUT/f0 OUT/f1 ... --frames -o RESULTS
(docs/results.md "Flicker under a moving light"). Needs oiiotool (openimageio-tools) to read
frame 0's light direction from its header.
"""
import argparse
import math
import re
import subprocess
import sys


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("build")
    p.add_argument("scene")
    p.add_argument("out")
    p.add_argument("--frames", type=int, default=4)
    p.add_argument("--step", type=float, default=0.5, help="degrees the light turns per frame")
    p.add_argument("--size", default="512")
    p.add_argument("--receivers", default="320x240")
    p.add_argument("--samples", default="16")
    a = p.parse_args()
    if a.frames < 2:
        sys.exit("light_frames.py: --frames must be at least 2")
    tool = a.build + "/shadowfilter"
    common = ["--size", a.size, "--receivers", a.receivers, "--samples", a.samples, "-q"]
    first = f"{a.out}/f0"
    subprocess.run([tool, "scene", a.scene, "-o", first] + common, check=True)
    info = subprocess.run(["oiiotool", "--info", "-v", first + "/shadowmap.exr"], capture_output=True, text=True,
                          check=True).stdout
    m = re.search(r'light_direction: "\[([^\]]*)\]"', info)
    if not m:
        sys.exit(f"light_frames.py: {first}/shadowmap.exr names no light_direction (a perspective light?)")
    x, y, z = (float(t) for t in m.group(1).split(","))
    for k in range(1, a.frames):
        t = math.radians(a.step * k)
        d = f"{x * math.cos(t) + z * math.sin(t):.9f},{y:.9f},{-x * math.sin(t) + z * math.cos(t):.9f}"
        subprocess.run([tool, "scene", a.scene, "-o", f"{a.out}/f{k}", "--light-dir", d] + common, check=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
