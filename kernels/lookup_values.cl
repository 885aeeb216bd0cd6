// The filtered values of N-channel images at receivers, without a method (tests, callers with
// their own reconstruction). Needs common.clh, storage.clh and lookup.clh, with -DSF_CHANNELS=N
// and -DSF_LOOKUP. out: N planes of `count` floats; f may be null (footprint 1).
__kernel void sf_lookup_points(__global const sf_stored* restrict level0,
                               __global const sf_stored* restrict chain,
                               __global const float* restrict sat, const int width,
                               const int height, __global const float* restrict u,
                               __global const float* restrict v, __global const float* restrict f,
                               __global float* restrict out, const int count) {
  const int i = get_global_id(0);
  if (i >= count) return;
  float b[SF_CHANNELS];
  sf_lookup(level0, chain, sat, width, height, u[i], v[i], f ? f[i] : 1.0f, b);
  for (int c = 0; c < SF_CHANNELS; ++c) out[(size_t)c * count + i] = b[c];
}
