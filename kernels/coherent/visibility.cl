// Coherent shadow map queries of unstructured points (methods.md sec. 5; Ritschel 2007 sec. 3.2 and
// 4.5), after coherent/query.clh: one work-item per query, point p = points[i].xyz (w ignored) and
// the second float4 either a direction d (toward 0: distant light) or a light sample's position
// l (toward 1: semi-local light, d = l - p). `toward` is an argument, not a build option: the
// branch is uniform, and one program (three kernels) serves every query.
// Every kernel guards its index: any global size (rounded up to whole work-groups) is correct.

inline float3 sf_coherent_query_dir(float4 p, float4 s, int toward) { return toward ? s.xyz - p.xyz : s.xyz; }

// Nearest view, nearest texel: 0 or 1.
__kernel void sf_coherent_visibility_points(const sf_coherent_layout L, __global const uint* restrict offsets,
                                       __global const uint* restrict last, __global const ushort* restrict depth, __global const uint* restrict positions,
                                       __global const float4* restrict points, __global const float4* restrict second,
                                       __global float* restrict out, uint count, int toward) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float4 p = points[i];
  out[i] = sf_coherent_visibility(L, offsets, last, depth, positions, p.xyz, sf_coherent_query_dir(p, second[i], toward));
}

// Generalized PCF over 2x2 views x 2x2 texels: in [0, 1].
__kernel void sf_coherent_visibility_points_pcf(const sf_coherent_layout L, __global const uint* restrict offsets,
                                           __global const uint* restrict last, __global const ushort* restrict depth,
                                           __global const uint* restrict positions,
                                           __global const float4* restrict points,
                                           __global const float4* restrict second, __global float* restrict out,
                                           uint count, int toward) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float4 p = points[i];
  out[i] = sf_coherent_visibility_filtered(L, offsets, last, depth, positions, p.xyz, sf_coherent_query_dir(p, second[i], toward));
}

// The uncompressed dual-depth test with the same view and texel (sf::ref::coherent::stack_test):
// +1 lit (q <= z1, or outside the map), 0 blocked (q >= z2, z2 = 65535 read as +infinity), -1
// between the surfaces. z1, z2: ushort [i * texels + t], i the view's position in the sequence.
__kernel void sf_coherent_stack_points(const sf_coherent_layout L, __global const ushort* restrict z1,
                                  __global const ushort* restrict z2, __global const uint* restrict positions,
                                  __global const float4* restrict points, __global const float4* restrict second,
                                  __global float* restrict out, uint count, int toward) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float4 p = points[i];
  const float3 d = sf_coherent_query_dir(p, second[i], toward);
  const int g = sf_coherent_view_of(L, d);
  uint q;
  const float2 uv = sf_coherent_map_coords(L, g, p.xyz, &q);
  const int x = (int)floor(uv.x), y = (int)floor(uv.y);
  float r = 1.0f;
  if (x >= 0 && y >= 0 && x < L.resolution && y < L.resolution) {
    const ulong at = (ulong)positions[g] * (ulong)L.resolution * (ulong)L.resolution + (ulong)(y * L.resolution + x);
    const uint a = z1[at], b = z2[at] == (ushort)65535 ? 65536u : (uint)z2[at];
    r = q <= a ? 1.0f : (q >= b ? 0.0f : -1.0f);
  }
  out[i] = r;
}
