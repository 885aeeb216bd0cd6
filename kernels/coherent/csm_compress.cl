// Coherent shadow map compression on the device (methods.md sec. 5; seed 002 eq. (1)): per
// texel the greedy piecewise-constant fit of sf::ref::coherent::compress, byte for byte. One
// work-item per texel walks the stack's N maps in sequence order; z1 and z2 are ushort
// [i * texels + t], so neighbouring work-items read neighbouring words of every map.
// Three passes: count (segments per texel into offsets[t]), an exclusive scan of the counts in
// place (offsets[texels] = the total), write (the segments at offsets[t]).
// Every kernel guards its index: any global size (rounded up to whole work-groups) is correct.

// z2 with kNoSurface (65535) read as +infinity (65536), as the reference does.
inline uint sf_csm_upper(ushort z2) { return z2 == (ushort)65535 ? 65536u : (uint)z2; }

// The greedy walk: extends the current run while max z1 < min z2 stays true, and emits a
// segment (z_avg = floor((max z1 + min z2) / 2), i_last) when the next map breaks it. Each map is
// read once: the map that breaks a run starts the next one (the reference reads it again).
// EMIT(packed, k) is called for the k-th segment; the walk returns the count.
#define SF_CSM_WALK(EMIT)                                                         \
  {                                                                               \
    uint lo = z1[t], hi = sf_csm_upper(z2[t]), k = 0;                            \
    for (uint i = 1; i < n; ++i) {                                                \
      const ulong at = (ulong)i * texels + t;                                     \
      const uint a = z1[at], b = sf_csm_upper(z2[at]);                           \
      const uint l2 = max(lo, a), h2 = min(hi, b);                                \
      if (l2 >= h2) {                                                             \
        EMIT((((lo + hi) >> 1) << 16) | (i - 1), k);                              \
        ++k;                                                                      \
        lo = a;                                                                   \
        hi = b;                                                                   \
      } else {                                                                    \
        lo = l2;                                                                  \
        hi = h2;                                                                  \
      }                                                                           \
    }                                                                             \
    EMIT((((lo + hi) >> 1) << 16) | (n - 1), k);                                  \
    ++k;                                                                          \
    count = k;                                                                    \
  }

#define SF_CSM_EMIT_NONE(s, k)

// Pass 1: counts[t] = segments of texel t (counts is the offsets buffer, texels + 1 words).
__kernel void sf_csm_count(__global const ushort* restrict z1, __global const ushort* restrict z2, uint texels,
                           uint n, __global uint* restrict counts) {
  const uint t = get_global_id(0);
  if (t >= texels) return;
  uint count;
  SF_CSM_WALK(SF_CSM_EMIT_NONE)
  counts[t] = count;
}

// Pass 2a: each work-item scans a block of `block` counts in place (exclusive, from 0) and
// stores the block's total in sums[b] (ulong: a stack's total may pass 2^32, which the host
// refuses after pass 2b rather than wrap).
__kernel void sf_csm_scan_blocks(__global uint* restrict offsets, uint texels, uint block,
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
__kernel void sf_csm_scan_totals(__global ulong* restrict sums, uint blocks, __global uint* restrict offsets,
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
__kernel void sf_csm_scan_add(__global uint* restrict offsets, uint texels, uint block,
                              __global const ulong* restrict sums) {
  const uint t = get_global_id(0);
  if (t >= texels) return;
  offsets[t] += (uint)sums[t / block];
}

// Pass 3: the segments of texel t at offsets[t] ..; writes past `capacity` words are dropped
// (a caller's short buffer loses segments, never memory).
#define SF_CSM_EMIT_STORE(s, k)                           \
  {                                                       \
    const uint o = base + (k);                            \
    if (o < capacity) segments[o] = (s);                  \
  }

__kernel void sf_csm_write(__global const ushort* restrict z1, __global const ushort* restrict z2, uint texels,
                           uint n, __global const uint* restrict offsets, __global uint* restrict segments,
                           uint capacity) {
  const uint t = get_global_id(0);
  if (t >= texels) return;
  const uint base = offsets[t];
  uint count;
  SF_CSM_WALK(SF_CSM_EMIT_STORE)
  (void)count;
}
