// Coherent shadow map compression on the device (methods.md sec. 5; Ritschel 2007 eq. (1)): per
// texel the greedy piecewise-constant fit of sf::ref::coherent::compress, byte for byte. A
// work-item walks the stack's N maps in sequence order for SF_COHERENT_LANES neighbouring texels;
// z1 and z2 are ushort [i * texels + t]. Lanes: 1 on GPUs (neighbouring work-items read
// neighbouring words of every map, coalesced); 256 on CPUs, where a work-item runs alone and one
// texel per item would read one word per cache line of every map: 256 texels read 512
// contiguous bytes of each map, a stream the prefetcher follows.
// Three passes: count (segments per texel into offsets[t]), an exclusive scan of the counts in
// place (offsets[texels] = the total), write (the segments at offsets[t]).
// Every kernel guards its index: any global size (rounded up to whole work-groups) is correct.
#ifndef SF_COHERENT_LANES
#define SF_COHERENT_LANES 1
#endif

// z2 with kNoSurface (65535) read as +infinity (65536), as the reference does.
inline uint sf_coherent_upper(ushort z2) { return z2 == (ushort)65535 ? 65536u : (uint)z2; }

// The greedy walk of lanes 0 .. LN - 1 (texels t0 + l): extends each lane's run while
// max z1 < min z2 stays true, and emits a segment (z_avg = floor((max z1 + min z2) / 2), i_last)
// when the next map breaks it. Each map is read once: the map that breaks a run starts the next
// one (the reference reads it again). The update is branch-free so that the lanes vectorise;
// EMIT(cut, z_avg, i_last, l) stores lane l's k[l]-th segment where cut is 1. k[l] ends as the
// count.
#define SF_COHERENT_WALK(LN, EMIT)                                                     \
  uint lo[SF_COHERENT_LANES], hi[SF_COHERENT_LANES], k[SF_COHERENT_LANES];                       \
  for (uint l = 0; l < (LN); ++l) {                                               \
    lo[l] = z1[t0 + l];                                                           \
    hi[l] = sf_coherent_upper(z2[t0 + l]);                                             \
    k[l] = 0;                                                                     \
  }                                                                               \
  for (uint i = 1; i < n; ++i) {                                                  \
    const ulong at = (ulong)i * texels + t0;                                      \
    for (uint l = 0; l < (LN); ++l) {                                             \
      const uint a = z1[at + l], b = sf_coherent_upper(z2[at + l]);                   \
      const uint l2 = max(lo[l], a), h2 = min(hi[l], b);                          \
      const uint cut = l2 >= h2 ? 1u : 0u;                                        \
      EMIT(cut, (lo[l] + hi[l]) >> 1, i - 1, l)                                  \
      k[l] += cut;                                                                \
      lo[l] = cut ? a : l2;                                                       \
      hi[l] = cut ? b : h2;                                                       \
    }                                                                             \
  }                                                                               \
  for (uint l = 0; l < (LN); ++l) {                                               \
    EMIT(1u, (lo[l] + hi[l]) >> 1, n - 1, l)                                      \
    k[l] += 1;                                                                    \
  }

#define SF_COHERENT_EMIT_NONE(cut, z, i, l)

// Pass 1: counts[t] = segments of texel t (counts is the offsets buffer, texels + 1 words).
// Whole items take the constant lane count (vectorised), the last partial one the rest.
__kernel void sf_coherent_count(__global const ushort* restrict z1, __global const ushort* restrict z2, uint texels,
                           uint n, __global uint* restrict counts) {
  const uint t0 = get_global_id(0) * SF_COHERENT_LANES;
  if (t0 >= texels) return;
  const uint lanes = min((uint)SF_COHERENT_LANES, texels - t0);
  if (lanes == SF_COHERENT_LANES) {
    SF_COHERENT_WALK(SF_COHERENT_LANES, SF_COHERENT_EMIT_NONE)
    for (uint l = 0; l < SF_COHERENT_LANES; ++l) counts[t0 + l] = k[l];
  } else {
    SF_COHERENT_WALK(lanes, SF_COHERENT_EMIT_NONE)
    for (uint l = 0; l < lanes; ++l) counts[t0 + l] = k[l];
  }
}

// Pass 2a: each work-item scans a block of `block` counts in place (exclusive, from 0) and
// stores the block's total in sums[b] (ulong: a stack's total may pass 2^32, which the host
// refuses after pass 2b rather than wrap).
__kernel void sf_coherent_scan_blocks(__global uint* restrict offsets, uint texels, uint block,
                                 __global ulong* restrict sums, uint blocks) {
  const uint b = get_global_id(0);
  if (b >= blocks) return;
  const uint first = b * block, last = min(first + block, texels);
  ulong s = 0;
  for (uint t = first; t < last; ++t) {
    const uint c = offsets[t];
    offsets[t] = (uint)s;
    s += c;
  }
  sums[b] = s;
}

// Pass 2b: one work-item scans the block totals (exclusive) and writes the grand total to
// sums[blocks] and, cut to 32 bits, to offsets[texels].
__kernel void sf_coherent_scan_totals(__global ulong* restrict sums, uint blocks, __global uint* restrict offsets,
                                 uint texels) {
  if (get_global_id(0) != 0) return;
  ulong s = 0;
  for (uint b = 0; b < blocks; ++b) {
    const ulong c = sums[b];
    sums[b] = s;
    s += c;
  }
  sums[blocks] = s;
  offsets[texels] = (uint)s;
}

// Pass 2c: every count of block b gets the blocks before it.
__kernel void sf_coherent_scan_add(__global uint* restrict offsets, uint texels, uint block,
                              __global const ulong* restrict sums) {
  const uint t = get_global_id(0);
  if (t >= texels) return;
  offsets[t] += (uint)sums[t / block];
}

// Pass 3: the segments of texel t at offsets[t] .. (last and depth); writes past `capacity`
// segments are dropped (a caller's short buffer loses segments, never memory).
#define SF_COHERENT_EMIT_STORE(cut, z, i, l) \
  if (cut) {                                 \
    const uint o = base[l] + k[l];           \
    if (o < capacity) {                      \
      last[o] = (i);                         \
      depth[o] = (ushort)(z);                \
    }                                        \
  }

__kernel void sf_coherent_write(__global const ushort* restrict z1, __global const ushort* restrict z2, uint texels,
                           uint n, __global const uint* restrict offsets, __global uint* restrict last,
                           __global ushort* restrict depth, uint capacity) {
  const uint t0 = get_global_id(0) * SF_COHERENT_LANES;
  if (t0 >= texels) return;
  const uint lanes = min((uint)SF_COHERENT_LANES, texels - t0);
  uint base[SF_COHERENT_LANES];
  for (uint l = 0; l < lanes; ++l) base[l] = offsets[t0 + l];
  if (lanes == SF_COHERENT_LANES) {
    SF_COHERENT_WALK(SF_COHERENT_LANES, SF_COHERENT_EMIT_STORE)
  } else {
    SF_COHERENT_WALK(lanes, SF_COHERENT_EMIT_STORE)
  }
}
