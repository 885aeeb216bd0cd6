// Reconstruction: filtered basis + receiver depth -> visibility in [0,1].
// Needs common.clh, storage.clh, lookup.clh and a method header (sf_visibility, sf_method_params) before it.
// Receivers that are background (non-finite d) or outside the light frustum get 1.

// One receiver of sf_reconstruct_points (chain / sat / f as there).
inline void sf_reconstruct_one(__global const sf_stored* restrict basis, int width, int height,
                               __global const float* restrict u, __global const float* restrict v,
                               __global const float* restrict d, __global float* restrict out,
                               const sf_method_params P, __global const sf_stored* restrict chain,
                               __global const float* restrict sat,
                               __global const float* restrict f, int count, int i) {
  const float ui = u[i], vi = v[i], di = d[i];
  if (sf_receiver_outside(ui, vi, di)) {
    out[i] = 1.0f;
    return;
  }
  float b[SF_CHANNELS];
#if defined(SF_ANISO)
  const sf_aniso a = sf_aniso_at(f, count, i, SF_ANISO);
  sf_lookup_aniso(basis, chain, sat, width, height, ui, vi, &a, b);
#else
  sf_lookup(basis, chain, sat, width, height, ui, vi, f ? f[i] : 1.0f, b);
#endif
  out[i] = clamp(sf_visibility(b, clamp(di, 0.0f, 1.0f), P), 0.0f, 1.0f);
}

// Receivers given as (u, v, d) arrays; SF_RX_VEC of them per work-item (lookup.clh: 1, 4, 8 or
// 16), without branches, so that the lookup's coordinate math and the method's visibility run
// as vectors (methods without sf_visibility_vec call sf_visibility lane by lane). The host launches
// ceil(count / SF_RX_VEC) work-items; the last one finishes a partial vector receiver by receiver.
#if !defined(SF_ONE_KERNEL) || defined(SF_ONLY_sf_reconstruct_points)
__kernel void sf_reconstruct_points(__global const sf_stored* restrict basis, const int width,
                                    const int height, const int plane_stride,
                                    __global const float* restrict u, __global const float* restrict v,
                                    __global const float* restrict d, __global float* restrict out,
                                    const int count, const sf_method_params P,
                                    __global const sf_stored* restrict chain,
                                    __global const float* restrict sat,
                                    __global const float* restrict f,
                                    __constant int* restrict level_offsets) {
  // chain / sat / f: the lookup's mip chain or summed-area table and the receivers' footprints
  // (lookup.clh, SF_LOOKUP); null when unused (f null = footprint 1). SF_MIPS_JOINED: basis
  // holds the chain too (chain points into it) and level_offsets[k] is level k's element offset
  // in basis (lookup.clh); null otherwise. SF_ANISO: f holds the receivers' Jacobians instead,
  // four planes of count floats (dudx, dvdx, dudy, dvdy; lookup.clh "Anisotropic footprints").
  const int i0 = get_global_id(0) * SF_RX_VEC;
  if (i0 >= count) return;
#if SF_RX_VEC > 1
  if (count - i0 < SF_RX_VEC) {
    for (int i = i0; i < count; ++i)
      sf_reconstruct_one(basis, width, height, u, v, d, out, P, chain, sat, f, count, i);
    return;
  }
#endif
  const sf_rxf ui = sf_rx_vload(u + i0), vi = sf_rx_vload(v + i0), di = sf_rx_vload(d + i0);
  // Outside receivers look up the map's centre, so that their index math stays in range, and get 1.
  const sf_rxi inside = sf_rx_inside(ui, vi, di);
  const sf_rxf one = (sf_rxf)(1.0f), centre = (sf_rxf)(0.5f);
  // A vector of receivers all outside (background, or served by another layer of a cascade set:
  // layered.hpp) needs no lookup: their visibility is 1 whatever the basis holds.
#if SF_RX_VEC == 1
  if (!inside) {  // a scalar comparison is 1, not -1: any() would test its sign bit
#else
  if (!any(inside)) {
#endif
    sf_rx_vstore(one, out + i0);
    return;
  }
  sf_rxf b[SF_CHANNELS];
#if defined(SF_ANISO)
  sf_rx_lookup_aniso(basis, chain, sat, level_offsets, width, height, select(centre, ui, inside),
                     select(centre, vi, inside), sf_rx_vload(f + i0), sf_rx_vload(f + (size_t)count + i0),
                     sf_rx_vload(f + 2 * (size_t)count + i0), sf_rx_vload(f + 3 * (size_t)count + i0), b);
#else
  sf_rx_lookup(basis, chain, sat, level_offsets, width, height, select(centre, ui, inside),
               select(centre, vi, inside), f ? sf_rx_vload(f + i0) : one, b);
#endif
  const sf_rxf dc = clamp(select(centre, di, inside), 0.0f, 1.0f);
#if defined(sf_visibility_vec)
  const sf_rxf vis = sf_visibility_vec(b, dc, P);
#elif SF_RX_VEC == 1
  const sf_rxf vis = sf_visibility(b, dc, P);
#else
  sf_rxf vis;
  for (int j = 0; j < SF_RX_VEC; ++j) {
    float bj[SF_CHANNELS];
    for (int c = 0; c < SF_CHANNELS; ++c) bj[c] = b[c][j];
    vis[j] = sf_visibility(bj, dc[j], P);
  }
#endif
  sf_rx_vstore(select(one, clamp(vis, 0.0f, 1.0f), inside), out + i0);
}
#endif

// --receiver-depth mode: one receiver per shadow-map texel, at the texel centre.
#if !defined(SF_ONE_KERNEL) || defined(SF_ONLY_sf_reconstruct_grid)
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
#endif
