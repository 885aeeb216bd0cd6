// Least and largest finite depth of a map (host/src/pipeline/depth_range.cpp finishes the reduction):
// work-item g reduces texels [g per_item, (g + 1) per_item) and writes (min, max) to out[g]
// (INFINITY, -INFINITY when it saw no finite texel).
__kernel void sf_depth_range(__global const float* restrict depth, ulong texels, ulong per_item,
                             __global float2* restrict out) {
  const ulong g = get_global_id(0);
  const ulong begin = g * per_item;
  const ulong end = min(begin + per_item, texels);
  float lo = INFINITY, hi = -INFINITY;
  for (ulong i = begin; i < end; ++i) {
    const float z = depth[i];
    // fmin / fmax would skip NaN but not infinities: both are tested.
    if (isfinite(z)) {
      lo = fmin(lo, z);
      hi = fmax(hi, z);
    }
  }
  out[g] = (float2)(lo, hi);
}
