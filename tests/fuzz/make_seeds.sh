#!/usr/bin/env bash
# Writes the seed corpora of the fuzz harnesses (tests/fuzz/corpus/<harness>/): small valid inputs
# of every format each parser reads, made with the built CLI (BUILD/shadowfilter), oiiotool and
# printf. The committed corpus came from this script; libFuzzer grows its own copy of it
# (make fuzz copies the corpus to a scratch directory first).
# Usage: tests/fuzz/make_seeds.sh [BUILD]   (default: build)
set -euo pipefail
cd "$(dirname "$0")"
cli="$(cd ../.. && pwd)/${1:-build}/shadowfilter"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
c=corpus
rm -rf "$c" && mkdir -p "$c"/{image,cascade,csm,frame_list,light_list,mesh,view_file}

# Images: every format and layout the readers take, 8x8 (a few smaller).
ramp="--pattern fill:top=0.2:bottom=0.9"
oiiotool $ramp 8x8 1 -d half --compression zip -o "$c/image/depth_half_zip.exr"
oiiotool $ramp 8x8 1 -d float --compression none -o "$c/image/depth_float_none.exr"
oiiotool $ramp 8x8 1 -d half --compression rle -o "$c/image/depth_half_rle.exr"
oiiotool $ramp 8x8 1 -d float --compression piz --tile 4 4 -o "$c/image/depth_tiled_piz.exr"
oiiotool $ramp 8x8 4 -d float --chnames u,v,d,f -o "$c/image/receivers_uvdf.exr"
oiiotool $ramp 4x4 5 -d half --chnames u,v,d,f,ndl -o "$c/image/receivers_uvdf_ndl.exr"
oiiotool $ramp 4x4 3 -d float -o "$c/image/receivers_rgb.exr"
oiiotool $ramp 8x8 1 -d uint16 -o "$c/image/depth16.png"
oiiotool $ramp 8x8 1 -d uint8 -o "$c/image/depth8.png"
oiiotool $ramp 16x4 3 -o "$c/image/grey_rle.hdr"
oiiotool $ramp 4x4 3 -o "$c/image/grey_flat.hdr"
oiiotool $ramp 8x8 1 -d float --compression zip -o "$c/image/depth_zip.tif"
oiiotool $ramp 8x8 1 -d float --compression none -o "$c/image/depth_none.tif"
oiiotool $ramp 8x8 1 -d uint8 -o "$c/image/depth.pgm"
printf 'P2\n3 2\n255\n0 64 128\n192 255 7\n' > "$c/image/text.pgm"
python3 - "$c/image" <<'PY'
import struct, sys
d = sys.argv[1]
# PFM: "Pf" (grey) or "PF" (RGB), size, a negative scale (little-endian), rows bottom-up.
open(d + "/depth.pfm", "wb").write(b"Pf\n8 8\n-1.0\n" + struct.pack("<64f", *[i / 64 for i in range(64)]))
open(d + "/rgb.pfm", "wb").write(b"PF\n4 4\n-1.0\n" + struct.pack("<48f", *[i / 48 for i in range(48)]))
PY

# Layer and view files as `scene --layout` writes them (a one-layer set says "0 1").
"$cli" scene spheres -o "$work/single" --size 8 --receivers 8x6 --samples 1 --layout single -q >/dev/null
"$cli" scene spheres -o "$work/pssm" --size 8 --receivers 8x6 --samples 1 --layout pssm --cascades 2 -q >/dev/null
cp "$work/single/cascade_0.exr" "$c/cascade/single_layer.exr"
cp "$work/pssm/cascade_1.exr" "$c/cascade/pssm_layer_1_of_2.exr"
cp "$work/single/view.exr" "$c/cascade/view.exr"

# Coherent shadow maps: a Hilbert box and a scan-line sphere, the smallest grids.
"$cli" coherent build box -o "$c/csm/box.csm" --views 2x2 --res 4 -q
"$cli" coherent build sphere -o "$c/csm/sphere.csm" --views 2x3 --res 2 --ordering scanline -q
# A local light's cube maps (version 3): a rectangle, and a mesh light of three points.
"$cli" coherent build box -o "$c/csm/box_local.csm" --local-light -1 1 -1 2 0 0 0 0 2 --light-samples 2x2 --res 2 -q
printf 'v -1 1 -1\nv 1 1 -1\nv 1 1 1\nf 1 2 3\n' > "$work/lamp.obj"
"$cli" coherent build box -o "$c/csm/box_lamp.csm" --local-light-mesh "$work/lamp.obj" --light-samples 3x1 --res 2 -q

# Frame lists.
printf 'map0.exr rx.exr out/f0.exr\nmap1.exr depth=rd.exr out/f1.exr  # planar\n' > "$c/frame_list/two_frames.txt"
printf '# quoted paths\n"my map.exr" "my rx.exr" "out dir/f.exr"\r\n\n/abs/m.exr ../rx.exr o.exr\n' > "$c/frame_list/quoted.txt"
printf 'a.exr rx.exr a.exr\n' > "$c/frame_list/output_is_input.txt"
printf 'map.exr camera=cam.json camera-depth=cam_depth.exr light=sun.json out/f0.exr\nmap.exr rx.exr light=sun.json out/f1.exr\n' \
  > "$c/frame_list/camera_and_light.txt"

# Light lists.
printf '# two lights\n\na.exr rx.exr\n  b.exr rx.exr weight=3   # the second\n' > "$c/light_list/two_lights.txt"
printf 'a.exr rx.exr size=0.6 weight=0.25\n' > "$c/light_list/sized.txt"

# Camera and light files (docs/inputs.md): rows of 4 or 16 numbers, each clip convention, a
# reversed infinite projection with its far distance.
printf '{"view": [[1,0,0,0],[0,1,0,0],[0,0,1,-5],[0,0,0,1]],\n "projection": [[1.5,0,0,0],[0,2,0,0],[0,0,-1.2,-2.2],[0,0,-1,0]],\n "clip": "opengl", "width": 640, "height": 480}\n' > "$c/view_file/camera_opengl_rows.json"
printf '{"view": [1,0,0,0, 0,0,1,0, 0,-1,0,8, 0,0,0,1], "projection": [0.1,0,0,0, 0,0.1,0,0, 0,0,-0.1,-1, 0,0,0,1]}\n' > "$c/view_file/light_ortho_flat.json"
printf '{"view": [1,0,0,0, 0,1,0,0, 0,0,1,-3, 0,0,0,1], "projection": [1,0,0,0, 0,1,0,0, 0,0,0,0.5, 0,0,-1,0], "clip": "d3d", "reversed_z": true, "far": 16, "width": 128, "height": 128}\n' > "$c/view_file/light_d3d_reversed_infinite.json"
printf '{"view": [1,0,0,0, 0,1,0,0, 0,0,1,-3, 0,0,0,1], "projection": [1,0,0,0, 0,1,0,0, 0,0,-1.0101010101,-1.0101010101, 0,0,-1,0], "clip": "vulkan", "reversed_z": false}\n' > "$c/view_file/camera_vulkan.json"

# Meshes: a tetrahedron in each format assimp reads for `scene` and `coherent build`.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n' > "$c/mesh/tetra.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n' > "$c/mesh/quad.obj"
printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n' > "$c/mesh/tetra.off"
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n%s' \
  'element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n' \
  | sed 's/\\n/\n/g' > "$c/mesh/tetra_ascii.ply"
python3 - "$c/mesh" <<'PY'
import struct, sys
d = sys.argv[1]
v = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
f = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
head = ("ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n").encode()
body = b"".join(struct.pack("<3f", *p) for p in v) + b"".join(struct.pack("<B3i", 3, *t) for t in f)
open(d + "/tetra_binary.ply", "wb").write(head + body)
stl = b"\0" * 80 + struct.pack("<I", len(f))
for t in f:
    stl += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *v[i]) for i in t) + b"\0\0"
open(d + "/tetra_binary.stl", "wb").write(stl)
text = "solid tetra\n"
for t in f:
    text += " facet normal 0 0 1\n  outer loop\n" + "".join("   vertex %g %g %g\n" % v[i] for i in t)
    text += "  endloop\n endfacet\n"
open(d + "/tetra_ascii.stl", "w").write(text + "endsolid tetra\n")
PY
du -sh "$c"/* | sed 's/^/make_seeds: /'
