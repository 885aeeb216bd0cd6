// Separable Gaussian blur of planar N-channel float images, clamp-to-edge (methods.md sec. 2).
// Knobs: SF_RADIUS (taps -R..R, required), SF_VEC (texels per work-item along a row: 4, 8, 16).
// Weights w[0..R] (normalised, symmetric) come in a __constant buffer.
// NDRange: (ceil(width / SF_VEC), height, channels); any local size works (no local memory).

#if SF_VEC == 16
#define SF_VT float16
#define SF_VLOAD vload16
#define SF_VSTORE vstore16
#elif SF_VEC == 8
#define SF_VT float8
#define SF_VLOAD vload8
#define SF_VSTORE vstore8
#elif SF_VEC == 4
#define SF_VT float4
#define SF_VLOAD vload4
#define SF_VSTORE vstore4
#else
#error "SF_VEC must be 4, 8 or 16"
#endif

// Along x. Interior segments use vector loads at every tap; segments within R of the
// image border take the scalar clamped path.
__kernel void sf_blur_rows(__global const float* restrict src, __global float* restrict dst,
                           const int width, const int height, const int plane_stride,
                           __constant const float* restrict w) {
  const int x0 = get_global_id(0) * SF_VEC;
  const int y = get_global_id(1);
  if (x0 >= width || y >= height) return;
  const size_t row_start = (size_t)get_global_id(2) * plane_stride + (size_t)y * width;
  __global const float* row = src + row_start;
  __global float* out = dst + row_start;

  if (x0 >= SF_RADIUS && x0 + SF_VEC - 1 + SF_RADIUS < width) {
    SF_VT acc = w[0] * SF_VLOAD(0, row + x0);
#pragma unroll
    for (int k = 1; k <= SF_RADIUS; ++k)
      acc += w[k] * (SF_VLOAD(0, row + x0 - k) + SF_VLOAD(0, row + x0 + k));
    SF_VSTORE(acc, 0, out + x0);
    return;
  }
  const int last = width - 1;
  for (int j = 0; j < SF_VEC && x0 + j < width; ++j) {
    const int x = x0 + j;
    float acc = w[0] * row[x];
    for (int k = 1; k <= SF_RADIUS; ++k)
      acc += w[k] * (row[sf_clampi(x - k, 0, last)] + row[sf_clampi(x + k, 0, last)]);
    out[x] = acc;
  }
}

// Along y: each work-item blurs SF_VEC neighbouring columns of one row with vector loads
// from the 2R+1 rows above and below (clamped row indices).
__kernel void sf_blur_cols(__global const float* restrict src, __global float* restrict dst,
                           const int width, const int height, const int plane_stride,
                           __constant const float* restrict w) {
  const int x0 = get_global_id(0) * SF_VEC;
  const int y = get_global_id(1);
  if (x0 >= width || y >= height) return;
  const size_t plane = (size_t)get_global_id(2) * plane_stride;
  __global const float* img = src + plane;
  __global float* out = dst + plane + (size_t)y * width;
  const int last = height - 1;

  if (x0 + SF_VEC <= width) {
    SF_VT acc = w[0] * SF_VLOAD(0, img + (size_t)y * width + x0);
#pragma unroll
    for (int k = 1; k <= SF_RADIUS; ++k) {
      const size_t up = (size_t)sf_clampi(y - k, 0, last) * width + x0;
      const size_t down = (size_t)sf_clampi(y + k, 0, last) * width + x0;
      acc += w[k] * (SF_VLOAD(0, img + up) + SF_VLOAD(0, img + down));
    }
    SF_VSTORE(acc, 0, out + x0);
    return;
  }
  for (int x = x0; x < width; ++x) {
    float acc = w[0] * img[(size_t)y * width + x];
    for (int k = 1; k <= SF_RADIUS; ++k)
      acc += w[k] * (img[(size_t)sf_clampi(y - k, 0, last) * width + x] +
                     img[(size_t)sf_clampi(y + k, 0, last) * width + x]);
    out[x] = acc;
  }
}
