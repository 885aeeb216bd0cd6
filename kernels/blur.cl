// Separable Gaussian blur of planar N-channel float images, clamp-to-edge (methods.md sec. 2),
// both passes fused in one kernel. A work-item owns a strip of SF_STRIP vectors (SF_VEC texels
// each) across SF_ROWS output rows: it blurs each input row it needs along x (rows clamped to
// the image) into a ring of row vectors in private memory, and every output row is the weighted
// sum down 2R+1 consecutive ring rows. The intermediate image never leaves the cache.
//
// Compile-time knobs (none changes a result: every texel is computed by the same fma sequence
// whatever the schedule and whichever path computes it):
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

#if SF_VEC == 16
typedef float16 sf_vec;
#elif SF_VEC == 8
typedef float8 sf_vec;
#elif SF_VEC == 4
typedef float4 sf_vec;
#else
#error "SF_VEC must be 4, 8 or 16"
#endif

// The vector type aligned to one float: loads and stores through it compile to single unaligned
// vector moves (PoCL's vloadN is split into 64-bit pieces).
typedef sf_vec __attribute__((aligned(4))) sf_vec_u;

__constant float sf_w[SF_RADIUS + 1] = {SF_WEIGHTS};

// Every helper must inline: a call per vector costs more than the vector's arithmetic.
#define SF_INLINE inline __attribute__((always_inline))

// Ring rows of one step: the 2R+1 taps of its first output row plus one per further row.
#define SF_SPAN (2 * SF_RADIUS + SF_VROWS)

// Blur along x of the SF_VEC texels at p[0..SF_VEC-1], reading p[-R .. SF_VEC-1+R]: the same
// function for global rows (interior vectors) and private padded copies (edge vectors).
#define SF_DEFINE_HBLUR(NAME, SPACE)                                                          \
  SF_INLINE sf_vec NAME(SPACE const float* p) {                                               \
    sf_vec acc = sf_w[0] * *(SPACE const sf_vec_u*)p;                                         \
    _Pragma("unroll") for (int k = 1; k <= SF_RADIUS; ++k) {                                  \
      const sf_vec pair = *(SPACE const sf_vec_u*)(p - k) + *(SPACE const sf_vec_u*)(p + k); \
      acc = fma((sf_vec)sf_w[k], pair, acc);                                                  \
    }                                                                                         \
    return acc;                                                                               \
  }
SF_DEFINE_HBLUR(sf_hblur_global, __global)
SF_DEFINE_HBLUR(sf_hblur_private, __private)

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

// Vectors v0 .. v0 + n - 1 of the strip where they read past a border: their span, clamped to
// the row, is copied into a private row (vector moves for the inside part), then blurred
// like interior vectors.
SF_INLINE void sf_hblur_padded(__global const float* row, const sf_strip* s, int v0, int n,
                               int width, sf_vec* slot) {
  if (n <= 0) return;
  float pad[SF_STRIP * SF_VEC + 2 * SF_RADIUS];
  const int lo = s->x0 + v0 * SF_VEC - SF_RADIUS, len = n * SF_VEC + 2 * SF_RADIUS;
  const int a = max(lo, 0), b = min(lo + len, width);  // the part inside the row
  for (int j = 0; j < a - lo; ++j) pad[j] = row[0];
  int j = a;
  for (; j + SF_VEC <= b; j += SF_VEC)
    *(sf_vec_u*)(pad + j - lo) = *(__global const sf_vec_u*)(row + j);
  for (; j < b; ++j) pad[j - lo] = row[j];
  for (j = b - lo; j < len; ++j) pad[j] = row[width - 1];
  for (int v = 0; v < n; ++v)
    sf_ring_put(slot, v0 + v, sf_hblur_private(pad + SF_RADIUS + v * SF_VEC));
}

// Blurs the strip of one input row along x into a ring slot.
SF_INLINE void sf_hblur_strip(__global const float* row, const sf_strip* s, int width,
                              sf_vec* slot) {
  sf_hblur_padded(row, s, 0, s->left, width, slot);
  for (int v = s->left; v < s->right; ++v)
    sf_ring_put(slot, v, sf_hblur_global(row + s->x0 + v * SF_VEC));
  sf_hblur_padded(row, s, s->right, s->vecs - s->right, width, slot);
}

// Input row i of the work-item starting at output row y0 into its ring slot.
SF_INLINE void sf_hblur_input(__global const float* img, int y0, int i, const sf_strip* s,
                              int width, int height, sf_vec* ring) {
  const int y = sf_clampi(y0 - SF_RADIUS + i, 0, height - 1);
  sf_hblur_strip(img + (size_t)y * width, s, width, ring + i % SF_SPAN * SF_STRIP);
}

// One vector of an output row.
SF_INLINE void sf_put_vec(__global float* out, int x, int width, sf_vec v) {
  if (x + SF_VEC <= width) {
#if defined(SF_STREAM) && defined(__clang__)
    __builtin_nontemporal_store(v, (__global sf_vec*)(out + x));  // aligned under SF_STREAM
#else
    *(__global sf_vec_u*)(out + x) = v;
#endif
    return;
  }
  float lanes[SF_VEC];  // the last vector of a row: only its lanes inside the row
  *(sf_vec_u*)lanes = v;
  for (int j = 0; x + j < width; ++j) out[x + j] = lanes[j];
}

// Sums down the window win[m * SF_STRIP] (m = 0 .. SF_SPAN-1) for the SF_VROWS output rows of
// one step, vector v of the strip: row r takes taps m = r .. r + 2R. The rows' loads overlap,
// and the compiler loads each ring row once for all of them.
SF_INLINE void sf_vblur_step(const sf_vec* win, int v, sf_vec* acc) {
#pragma unroll
  for (int r = 0; r < SF_VROWS; ++r) acc[r] = sf_w[0] * win[(r + SF_RADIUS) * SF_STRIP + v];
#pragma unroll
  for (int k = 1; k <= SF_RADIUS; ++k) {
#pragma unroll
    for (int r = 0; r < SF_VROWS; ++r) {
      const sf_vec pair =
          win[(r + SF_RADIUS - k) * SF_STRIP + v] + win[(r + SF_RADIUS + k) * SF_STRIP + v];
      acc[r] = fma((sf_vec)sf_w[k], pair, acc[r]);
    }
  }
}

// Writes output rows y .. y + rows - 1 (rows <= SF_VROWS) of the strip from window `win`.
SF_INLINE void sf_vblur_strip(const sf_vec* win, int x0, int vecs, int width, int rows,
                              __global float* out) {
  for (int v = 0; v < vecs; ++v) {
    sf_vec acc[SF_VROWS];
    sf_vblur_step(win, v, acc);
    for (int r = 0; r < rows; ++r)
      sf_put_vec(out + (size_t)r * width, x0 + v * SF_VEC, width, acc[r]);
  }
}

__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_blur(
    __global const float* restrict src, __global float* restrict dst, const int width,
    const int height, const int plane_stride) {
  const int x0 = get_global_id(0) * (SF_STRIP * SF_VEC);
  const int y0 = get_global_id(1) * SF_ROWS;
  if (x0 >= width || y0 >= height) return;
  const size_t plane = (size_t)get_global_id(2) * plane_stride;
  __global const float* img = src + plane;
  __global float* out = dst + plane;
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

// dst[i] = src[i] for i < count, SF_COPY_CHUNK floats per work-item (the in-place blur's copy
// back from tmp: vector loads and the same stores as the blur, about 2x clEnqueueCopyBuffer on
// PoCL). NDRange: ceil(count / SF_COPY_CHUNK), local size 1.
#define SF_COPY_CHUNK 4096
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void sf_blur_copy(
    __global const float* restrict src, __global float* restrict dst, const int count) {
  const int i0 = get_global_id(0) * SF_COPY_CHUNK;
  const int end = min(i0 + SF_COPY_CHUNK, count);
  int i = i0;
  for (; i + SF_VEC <= end; i += SF_VEC)
    sf_put_vec(dst, i, end, *(__global const sf_vec_u*)(src + i));
  for (; i < end; ++i) dst[i] = src[i];
#ifdef SF_STREAM
  write_mem_fence(CLK_GLOBAL_MEM_FENCE);
#endif
}
