// Basis transform: depth z (W*H floats) -> SF_CHANNELS planes of basis values.
// Needs a method header (sf_basis, sf_method_params, SF_CHANNELS) before it.

__kernel void sf_transform(__global const float* restrict depth, __global float* restrict basis,
                           const int texels, const int plane_stride, const sf_method_params P) {
  const int i = get_global_id(0);
  if (i >= texels) return;
  float b[SF_CHANNELS];
  sf_basis(depth[i], P, b);
  for (int c = 0; c < SF_CHANNELS; ++c) basis[c * plane_stride + i] = b[c];
}
