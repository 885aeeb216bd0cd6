// Separable Gaussian blur of planar N-channel images in any storage format (storage.clh:
// SF_STORAGE f32 / f16 / unorm16 / unorm8), clamp-to-edge (methods.md sec. 2), both passes fused
// in one kernel. A work-item owns a strip of SF_STRIP vectors (SF_VEC texels each) across SF_ROWS
// output rows: it blurs each input row it needs along x (rows clamped to the image) into a ring
// of float row vectors in private memory, and every output row is the weighted sum down 2R+1
// consecutive ring rows. The intermediate image never leaves the cache. Values are decoded to
// float once on load and rounded to the storage format once on store (one rounding per blur).
//
// Compile-time knobs (none changes a result: every texel is computed by the same fma sequence
// whatever the schedule and whichever path computes it):
//   SF_STORAGE  the storage format of src and dst (storage.clh, included before this file)
//   SF_RADIUS   taps -R..R (>= 1)
//   SF_WEIGHTS  w[0..R], the normalised symmetric weights, comma-separated float literals
//   SF_VEC      texels per vector: 4, 8 or 16
//   SF_STRIP    vectors per work-item along a row
//   SF_ROWS     output rows per work-item
//   SF_VROWS    output rows per step: the rows of a step share their ring loads
//   SF_STREAM   defined when every row starts on a vector boundary (width % SF_VEC == 0):
//               results are then written with aligned streaming (non-temporal) stores
// NDRange: (ceil(width / (SF_STRIP * SF_VEC)), ceil(height / SF_ROWS), channels), local size
// (1, 1, 1): PoCL replicates private arrays per work-item of a group, and one ring is enough.
// sf_blur_copy is the copy back of an in-place blur, with the same streaming stores.
//
// SF_BLUR_MAX (float32 only) makes the same kernels a separable max filter: every output is the
// max over the clamped (2R+1)^2 window (the z-max dilation of esm_classify.cl) instead of the
// weighted sum (max, not fmax: depths are finite, no NaN to order). SF_TAP0 and SF_TAPS are the
// two steps of either; both families pass them the weights as sf_w[k], which a max filter never
// expands, so SF_WEIGHTS and sf_w exist for the blur only.
#ifdef SF_BLUR_MAX
#define SF_TAP0(w, x) (x)
#define SF_TAPS(w, a, b, acc) max(acc, max(a, b))
#else
__constant float sf_w[SF_RADIUS + 1] = {SF_WEIGHTS};
#define SF_TAP0(w, x) ((w) * (x))
#define SF_TAPS(w, a, b, acc) fma(w, (a) + (b), acc)
#endif

// Gpu family (SF_BLUR_GPU; docs/gpu.md, "Launch shapes"): sf_blur_tiles, a work-group of
// SF_BGX x SF_BGY work-items, one per column of its tile, each computing SF_BROWS output rows of
// that column. The tile is SF_BGX columns x SF_BGY SF_BROWS rows; its row pass blurs along x
// the tile's rows plus the 2R halo rows (clamped to the image) into local memory, lanes on
// adjacent columns (coalesced loads), and after one barrier the column pass sums down 2R + 1
// of them. Every texel is the same fma sequence as in sf_blur (the Cpu family), on the same
// decoded values, rounded once on store: the two families give the same codes. Columns past the
// image (partial groups) are blurred on the clamped column and never stored; every item reaches
// the barrier. NDRange (ceil(W / SF_BGX) SF_BGX, ceil(H / (SF_BGY SF_BROWS)) SF_BGY, channels).
// Plain scalar loads and stores through storage.clh: no vector pointer of any alignment.
#ifdef SF_BLUR_GPU

#define SF_TILE_ROWS (SF_BGY * SF_BROWS)
#define SF_TILE_SPAN (SF_TILE_ROWS + 2 * SF_RADIUS)

__kernel __attribute__((reqd_work_group_size(SF_BGX, SF_BGY, 1))) void sf_blur_tiles(
    __global const sf_stored* restrict src, __global sf_stored* restrict dst, const int width,
    const int height, const int plane_stride) {
  __local float tile[SF_TILE_SPAN * SF_BGX];
  const int lx = get_local_id(0), ly = get_local_id(1);
  const int x = get_group_id(0) * SF_BGX + lx;
  const int y0 = get_group_id(1) * SF_TILE_ROWS;
  const size_t plane = (size_t)get_global_id(2) * plane_stride;
  __global const sf_stored* img = src + plane;
  const int xc = min(x, width - 1);
  // Tile row r holds image row y0 - R + r (clamped); the last tile needs the rows down to H - 1 + R.
  const int span = min(SF_TILE_SPAN, height - y0 + 2 * SF_RADIUS);
  for (int r = ly; r < span; r += SF_BGY) {
    __global const sf_stored* row = img + (size_t)sf_clampi(y0 - SF_RADIUS + r, 0, height - 1) * width;
    float acc = SF_TAP0(sf_w[0], sf_load(row, xc));
    for (int k = 1; k <= SF_RADIUS; ++k)
      acc = SF_TAPS(sf_w[k], sf_load(row, max(xc - k, 0)), sf_load(row, min(xc + k, width - 1)), acc);
    tile[r * SF_BGX + lx] = acc;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (x >= width) return;
  __global sf_stored* out = dst + plane;
  for (int i = 0; i < SF_BROWS; ++i) {
    const int j = ly + i * SF_BGY, y = y0 + j;
    if (y >= height) break;
    __local const float* col = tile + (j + SF_RADIUS) * SF_BGX + lx;
    float acc = SF_TAP0(sf_w[0], col[0]);
    for (int k = 1; k <= SF_RADIUS; ++k) acc = SF_TAPS(sf_w[k], col[-k * SF_BGX], col[k * SF_BGX], acc);
    sf_store(out, (size_t)y * width + x, acc);
  }
}

#else  // the Cpu family

#if SF_VEC == 16
typedef float16 sf_vec;
typedef uint16 sf_uvec;
typedef ushort16 sf_hvec;
typedef uchar16 sf_bvec;
#define SF_CONVERT(T, x) convert_##T##16(x)
#define SF_AS(T, x) as_##T##16(x)
#elif SF_VEC == 8
typedef float8 sf_vec;
typedef uint8 sf_uvec;
typedef ushort8 sf_hvec;
typedef uchar8 sf_bvec;
#define SF_CONVERT(T, x) convert_##T##8(x)
#define SF_AS(T, x) as_##T##8(x)
#elif SF_VEC == 4
typedef float4 sf_vec;
typedef uint4 sf_uvec;
typedef ushort4 sf_hvec;
typedef uchar4 sf_bvec;
#define SF_CONVERT(T, x) convert_##T##4(x)
#define SF_AS(T, x) as_##T##4(x)
#else
#error "SF_VEC must be 4, 8 or 16"
#endif

// Narrow formats: interior vectors decode their taps straight from the row (1: unorm, a
// conversion and a product per tap) or the strip's span is decoded once into a private row
// first (0: f16, whose decode is ~15 integer operations). Both give the same values.
#ifndef SF_BLUR_DECODE_TAPS
#define SF_BLUR_DECODE_TAPS (SF_STORAGE >= 2)
#endif

// Every helper must inline: a call per vector costs more than the vector's arithmetic.
#define SF_INLINE inline __attribute__((always_inline))

// The vector type aligned to one float: loads and stores through it compile to single unaligned
// vector moves (PoCL's vloadN is split into 64-bit pieces).
typedef sf_vec __attribute__((aligned(4))) sf_vec_u;

// One vector of stored values (sf_raw, aligned to one value) and its conversion to and from
// float. The conversions are plain vector arithmetic equal to sf_load / sf_store (PoCL's
// vload_half / vstore_half are scalar calls per texel).
#if SF_STORAGE == 0
typedef float sf_elem;
typedef sf_vec sf_raw_a;
typedef sf_vec __attribute__((aligned(4))) sf_raw;
SF_INLINE sf_vec sf_decode(sf_raw r) { return r; }
SF_INLINE sf_raw sf_encode(sf_vec v) { return v; }
#elif SF_STORAGE == 1
typedef ushort sf_elem;
typedef sf_hvec sf_raw_a;
typedef sf_hvec __attribute__((aligned(2))) sf_raw;
// Half bits to float: normal halves rebias the exponent (+112 << 23), subnormals are
// mantissa * 2^-24 (exact, normal in float), infinity / NaN keep an all-ones exponent.
SF_INLINE sf_vec sf_decode(sf_raw r) {
  const sf_uvec h = SF_CONVERT(uint, r), mag = h & 0x7fffu;
  const sf_uvec sign = (h & 0x8000u) << 16;
  // Compares and conversions on int (the values fit): unsigned ones are emulated without AVX2.
  const sf_uvec normal =
      SF_AS(int, mag) >= 0x7c00 ? (mag << 13) | 0x7f800000u : (mag << 13) + 0x38000000u;
  const sf_vec sub = SF_CONVERT(float, SF_AS(int, mag)) * 5.9604644775390625e-8f;
  return SF_AS(float, sign | (SF_AS(int, mag) < 0x400 ? SF_AS(uint, sub) : normal));
}
// sf_half_bits (storage.clh) across the lanes: round to nearest even.
SF_INLINE sf_raw sf_encode(sf_vec f) {
  const sf_uvec x = SF_AS(uint, f), sign = (x >> 16) & 0x8000u, ax = x & 0x7fffffffu;
  const sf_uvec sub = SF_AS(uint, SF_CONVERT(int, rint(SF_AS(float, ax) * 16777216.0f)));
  const sf_uvec r = ax - 0x38000000u;
  const sf_uvec nrm = (r + 0x0fffu + ((r >> 13) & 1u)) >> 13;
  const sf_uvec bits = SF_AS(int, ax) >= 0x477ff000 ? (sf_uvec)0x7c00u
                       : SF_AS(int, ax) < 0x38800000 ? sub
                                                     : nrm;
  return SF_CONVERT(ushort, sign | bits);
}
#elif SF_STORAGE == 2
typedef ushort sf_elem;
typedef sf_hvec sf_raw_a;
typedef sf_hvec __attribute__((aligned(2))) sf_raw;
SF_INLINE sf_vec sf_decode(sf_raw r) { return SF_CONVERT(float, r) * (1.0f / 65535.0f); }
SF_INLINE sf_raw sf_encode(sf_vec v) {
  return SF_CONVERT(ushort, SF_CONVERT(int, rint(clamp(v, 0.0f, 1.0f) * 65535.0f)));
}
#else
typedef uchar sf_elem;
typedef sf_bvec sf_raw_a;
typedef sf_bvec __attribute__((aligned(1))) sf_raw;
SF_INLINE sf_vec sf_decode(sf_raw r) { return SF_CONVERT(float, r) * (1.0f / 255.0f); }
SF_INLINE sf_raw sf_encode(sf_vec v) {
  return SF_CONVERT(uchar, SF_CONVERT(int, rint(clamp(v, 0.0f, 1.0f) * 255.0f)));
}
#endif

// Ring rows of one step: the 2R+1 taps of its first output row plus one per further row.
#define SF_SPAN (2 * SF_RADIUS + SF_VROWS)

// Blur along x of the SF_VEC texels at p[0..SF_VEC-1], reading p[-R .. SF_VEC-1+R]: the same
// function for global rows (interior vectors) and private padded copies (edge vectors).
#define SF_DEFINE_HBLUR(NAME, SPACE)                                                          \
  SF_INLINE sf_vec NAME(SPACE const float* p) {                                               \
    sf_vec acc = SF_TAP0(sf_w[0], *(SPACE const sf_vec_u*)p);                                 \
    _Pragma("unroll") for (int k = 1; k <= SF_RADIUS; ++k) acc =                              \
        SF_TAPS((sf_vec)sf_w[k], *(SPACE const sf_vec_u*)(p - k), *(SPACE const sf_vec_u*)(p + k), acc); \
    return acc;                                                                               \
  }
SF_DEFINE_HBLUR(sf_hblur_global, __global)
SF_DEFINE_HBLUR(sf_hblur_private, __private)

// The same for stored values read straight from a global row, decoding each tap's vector.
SF_INLINE sf_vec sf_hblur_stored(__global const sf_stored* p) {
  sf_vec acc = SF_TAP0(sf_w[0], sf_decode(*(__global const sf_raw*)p));
#pragma unroll
  for (int k = 1; k <= SF_RADIUS; ++k)
    acc = SF_TAPS((sf_vec)sf_w[k], sf_decode(*(__global const sf_raw*)(p - k)),
                  sf_decode(*(__global const sf_raw*)(p + k)), acc);
  return acc;
}

// A work-item's strip: `vecs` vectors from x0. Vectors [left, right) are interior (their taps
// lie inside the row); those before `left` and from `right` on read past a border.
typedef struct {
  int x0, vecs, left, right;
} sf_strip;

SF_INLINE sf_strip sf_make_strip(int x0, int width) {
  sf_strip s;
  s.x0 = x0;
  s.vecs = min(SF_STRIP, (width - x0 + SF_VEC - 1) / SF_VEC);
  // Vector v is interior when x0 + v VEC >= R and x0 + v VEC + VEC + R <= width.
  s.left = clamp((SF_RADIUS - x0 + SF_VEC - 1) / SF_VEC, 0, s.vecs);
  const int last_fit = width - SF_RADIUS - SF_VEC - x0;
  s.right = clamp(last_fit < 0 ? 0 : last_fit / SF_VEC + 1, s.left, s.vecs);
  return s;
}

// Each ring row is stored twice, so that every window is contiguous in the ring.
SF_INLINE void sf_ring_put(sf_vec* slot, int v, sf_vec h) {
  slot[v] = h;
  slot[v + SF_SPAN * SF_STRIP] = h;
}

// Vectors v0 .. v0 + n - 1 of the strip from a private float copy of their span, clamped to the
// row and decoded once per texel (vector loads for the inside part), blurred like interior
// vectors. Float32 takes this path only where the span reads past a border.
SF_INLINE void sf_hblur_padded(__global const sf_stored* row, const sf_strip* s, int v0, int n,
                               int width, sf_vec* slot) {
  if (n <= 0) return;
  float pad[SF_STRIP * SF_VEC + 2 * SF_RADIUS];
  const int lo = s->x0 + v0 * SF_VEC - SF_RADIUS, len = n * SF_VEC + 2 * SF_RADIUS;
  const int a = max(lo, 0), b = min(lo + len, width);  // the part inside the row
  const float first = sf_load(row, 0), last = sf_load(row, width - 1);
  for (int j = 0; j < a - lo; ++j) pad[j] = first;
  int j = a;
  for (; j + SF_VEC <= b; j += SF_VEC)
    *(sf_vec_u*)(pad + (j - lo)) = sf_decode(*(__global const sf_raw*)(row + j));
  for (; j < b; ++j) pad[j - lo] = sf_load(row, j);
  for (j = b - lo; j < len; ++j) pad[j] = last;
  for (int v = 0; v < n; ++v)
    sf_ring_put(slot, v0 + v, sf_hblur_private(pad + SF_RADIUS + v * SF_VEC));
}

// Blurs the strip of one input row along x into a ring slot. Float32 (and unorm, decoding each
// tap) reads interior vectors' taps straight from the row; f16 decodes the strip's span once
// instead of 2R + 1 times per texel.
SF_INLINE void sf_hblur_strip(__global const sf_stored* row, const sf_strip* s, int width,
                              sf_vec* slot) {
#if SF_STORAGE == 0
  sf_hblur_padded(row, s, 0, s->left, width, slot);
  for (int v = s->left; v < s->right; ++v)
    sf_ring_put(slot, v, sf_hblur_global(row + s->x0 + v * SF_VEC));
  sf_hblur_padded(row, s, s->right, s->vecs - s->right, width, slot);
#elif SF_BLUR_DECODE_TAPS
  sf_hblur_padded(row, s, 0, s->left, width, slot);
  for (int v = s->left; v < s->right; ++v)
    sf_ring_put(slot, v, sf_hblur_stored(row + s->x0 + v * SF_VEC));
  sf_hblur_padded(row, s, s->right, s->vecs - s->right, width, slot);
#else
  sf_hblur_padded(row, s, 0, s->vecs, width, slot);
#endif
}

// Input row i of the work-item starting at output row y0 into its ring slot.
SF_INLINE void sf_hblur_input(__global const sf_stored* img, int y0, int i, const sf_strip* s,
                              int width, int height, sf_vec* ring) {
  const int y = sf_clampi(y0 - SF_RADIUS + i, 0, height - 1);
  sf_hblur_strip(img + (size_t)y * width, s, width, ring + i % SF_SPAN * SF_STRIP);
}

// One vector of stored values at p (aligned to the vector under SF_STREAM).
SF_INLINE void sf_put_raw(__global sf_stored* p, sf_raw r) {
#if defined(SF_STREAM) && defined(__clang__)
  __builtin_nontemporal_store((sf_raw_a)r, (__global sf_raw_a*)p);
#else
  *(__global sf_raw*)p = r;
#endif
}

// One vector of an output row, rounded to the storage format.
SF_INLINE void sf_put_vec(__global sf_stored* out, int x, int width, sf_vec v) {
  if (x + SF_VEC <= width) {
    sf_put_raw(out + x, sf_encode(v));
    return;
  }
  float lanes[SF_VEC];  // the last vector of a row: only its lanes inside the row
  *(sf_vec_u*)lanes = v;
  for (int j = 0; x + j < width; ++j) sf_store(out, x + j, lanes[j]);
}

// Sums down the window win[m * SF_STRIP] (m = 0 .. SF_SPAN-1) for the SF_VROWS output rows of
// one step, vector v of the strip: row r takes taps m = r .. r + 2R. The rows' loads overlap,
// and the compiler loads each ring row once for all of them.
SF_INLINE void sf_vblur_step(const sf_vec* win, int v, sf_vec* acc) {
#pragma unroll
  for (int r = 0; r < SF_VROWS; ++r) acc[r] = SF_TAP0(sf_w[0], win[(r + SF_RADIUS) * SF_STRIP + v]);
#pragma unroll
  for (int k = 1; k <= SF_RADIUS; ++k) {
#pragma unroll
    for (int r = 0; r < SF_VROWS; ++r)
      acc[r] = SF_TAPS((sf_vec)sf_w[k], win[(r + SF_RADIUS - k) * SF_STRIP + v],
                       win[(r + SF_RADIUS + k) * SF_STRIP + v], acc[r]);
  }
}

// Writes output rows y .. y + rows - 1 (rows <= SF_VROWS) of the strip from window `win`.
SF_INLINE void sf_vblur_strip(const sf_vec* win, int x0, int vecs, int width, int rows,
                              __global sf_stored* out) {
  for (int v = 0; v < vecs; ++v) {
    sf_vec acc[SF_VROWS];
    sf_vblur_step(win, v, acc);
    for (int r = 0; r < rows; ++r)
      sf_put_vec(out + (size_t)r * width, x0 + v * SF_VEC, width, acc[r]);
  }
}

__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_blur(
    __global const sf_stored* restrict src, __global sf_stored* restrict dst, const int width,
    const int height, const int plane_stride) {
  const int x0 = get_global_id(0) * (SF_STRIP * SF_VEC);
  const int y0 = get_global_id(1) * SF_ROWS;
  if (x0 >= width || y0 >= height) return;
  const size_t plane = (size_t)get_global_id(2) * plane_stride;
  __global const sf_stored* img = src + plane;
  __global sf_stored* out = dst + plane;
  const sf_strip s = sf_make_strip(x0, width);
  const int rows_out = min(SF_ROWS, height - y0);

  // Input row i (image row y0 - R + i, clamped) lives in ring slot i % SF_SPAN and its copy.
  sf_vec ring[2 * SF_SPAN * SF_STRIP];
  for (int i = 0; i < 2 * SF_RADIUS; ++i) sf_hblur_input(img, y0, i, &s, width, height, ring);
  for (int y = 0; y < rows_out; y += SF_VROWS) {  // output rows y0 + y ...
    for (int r = 0; r < SF_VROWS; ++r)
      sf_hblur_input(img, y0, y + 2 * SF_RADIUS + r, &s, width, height, ring);
    sf_vblur_strip(ring + y % SF_SPAN * SF_STRIP, x0, s.vecs, width, min(SF_VROWS, rows_out - y),
                   out + (size_t)(y0 + y) * width);
  }
#ifdef SF_STREAM
  write_mem_fence(CLK_GLOBAL_MEM_FENCE);  // streaming stores are weakly ordered
#endif
}

// dst[i] = src[i] for i < count stored values, SF_COPY_CHUNK per work-item (the in-place blur's
// copy back from tmp: vector loads and the same stores as the blur, about 2x
// clEnqueueCopyBuffer on PoCL). NDRange: ceil(count / SF_COPY_CHUNK), local size 1.
#define SF_COPY_CHUNK 4096
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_blur_copy(
    __global const sf_stored* restrict src, __global sf_stored* restrict dst, const int count) {
  const int i0 = get_global_id(0) * SF_COPY_CHUNK;
  const int end = min(i0 + SF_COPY_CHUNK, count);
  int i = i0;
  for (; i + SF_VEC <= end; i += SF_VEC) sf_put_raw(dst + i, *(__global const sf_raw*)(src + i));
  __global const sf_elem* s = (__global const sf_elem*)src;
  __global sf_elem* d = (__global sf_elem*)dst;
  for (; i < end; ++i) d[i] = s[i];
#ifdef SF_STREAM
  write_mem_fence(CLK_GLOBAL_MEM_FENCE);
#endif
}

#endif  // SF_BLUR_GPU
