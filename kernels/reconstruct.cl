// Reconstruction: filtered basis + receiver depth -> visibility in [0,1].
// Needs common.clh, storage.clh, lookup.clh and a method header (sf_visibility, sf_method_params) before it.
// Receivers that are background (non-finite d) or outside the light frustum get 1.

// Receivers given as (u, v, d) arrays.
__kernel void sf_reconstruct_points(__global const sf_stored* restrict basis, const int width,
                                    const int height, const int plane_stride,
                                    __global const float* restrict u, __global const float* restrict v,
                                    __global const float* restrict d, __global float* restrict out,
                                    const int count, const sf_method_params P,
                                    __global const sf_stored* restrict chain,
                                    __global const float* restrict sat,
                                    __global const float* restrict f) {
  // chain / sat / f: the lookup's mip chain or summed-area table and the receivers' footprints
  // (lookup.clh, SF_LOOKUP); null when unused (f null = footprint 1).
  const int i = get_global_id(0);
  if (i >= count) return;
  const float ui = u[i], vi = v[i], di = d[i];
  if (sf_receiver_outside(ui, vi, di)) {
    out[i] = 1.0f;
    return;
  }
  float b[SF_CHANNELS];
  sf_lookup(basis, chain, sat, width, height, ui, vi, f ? f[i] : 1.0f, b);
  out[i] = clamp(sf_visibility(b, clamp(di, 0.0f, 1.0f), P), 0.0f, 1.0f);
}

// --receiver-depth mode: one receiver per shadow-map texel, at the texel centre.
__kernel void sf_reconstruct_grid(__global const sf_stored* restrict basis, const int width,
                                  const int height, const int plane_stride,
                                  __global const float* restrict d, __global float* restrict out,
                                  const sf_method_params P) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  const size_t i = (size_t)y * width + x;
  const float di = d[i];
  if (!isfinite(di)) {
    out[i] = 1.0f;
    return;
  }
  float b[SF_CHANNELS];
  sf_lookup_texel(basis, width, plane_stride, x, y, b);
  out[i] = clamp(sf_visibility(b, clamp(di, 0.0f, 1.0f), P), 0.0f, 1.0f);
}
