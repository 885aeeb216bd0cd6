// The filtered values of N-channel images at receivers, without a method (tests, callers with
// their own reconstruction). Needs common.clh, storage.clh and lookup.clh, with -DSF_CHANNELS=N
// and -DSF_LOOKUP. out: N planes of `count` floats; f may be null (footprint 1). SF_ANISO: f
// holds the receivers' Jacobians, four planes of count floats (lookup.clh).
__kernel void sf_lookup_points(__global const sf_stored* restrict level0,
                               __global const sf_stored* restrict chain,
                               __global const float* restrict sat, const int width,
                               const int height, __global const float* restrict u,
                               __global const float* restrict v, __global const float* restrict f,
                               __global float* restrict out, const int count) {
  const int i = get_global_id(0);
  if (i >= count) return;
  float b[SF_CHANNELS];
#if defined(SF_ANISO)
  const sf_aniso a = sf_aniso_at(f, count, i, SF_ANISO);
  sf_lookup_aniso(level0, chain, sat, width, height, u[i], v[i], &a, b);
#else
  sf_lookup(level0, chain, sat, width, height, u[i], v[i], f ? f[i] : 1.0f, b);
#endif
  for (int c = 0; c < SF_CHANNELS; ++c) out[(size_t)c * count + i] = b[c];
}
