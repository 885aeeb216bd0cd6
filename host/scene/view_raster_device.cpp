#include "view_raster_device.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "shadowfilter/errors.hpp"

#include "coherent_stack.hpp"
#include "view_raster.hpp"

namespace sf::scene {

namespace {

constexpr size_t kList = 16;                      // raster.cl's SF_RASTER_LIST
constexpr size_t kBatchBytes = size_t(96) << 20;  // a batch's lists and projected vertices

template <class T>
cl::Buffer device_copy(Runtime& rt, const std::vector<T>& v) {
  static const uint32_t zero[4] = {0, 0, 0, 0};
  const size_t bytes = v.size() * sizeof(T);
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes ? bytes : sizeof(zero),
                    const_cast<void*>(bytes ? static_cast<const void*>(v.data()) : zero));
}

size_t round_up(size_t n, size_t group) { return std::max<size_t>(1, (n + group - 1) / group) * group; }

}  // namespace

coherent::DeviceDualDepth render_stack_on_device(Runtime& rt, const SceneGeometry& object,
                                                 const coherent::StackLayout& layout, DeviceRasterStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  coherent::validate(layout);
  if (!object.spheres.empty())
    throw InputError(
        "the device rasteriser takes triangle meshes; this object has analytic spheres (--renderer "
        "embree ray-casts them)");
  if (!rt.info().fp64)
    throw InputError("the device rasteriser computes depths in double precision; '" + rt.info().device_name +
                     "' lacks cl_khr_fp64 (--renderer auto renders on the host)");
  const ViewRasterizer raster(object);
  const int m = layout.resolution;
  const size_t texels = layout.texels(), views = size_t(layout.views());
  const int hits = layout.depth_pair == coherent::DepthPair::FirstThird ? 3 : 2;
  const double radius = layout.radius, diameter = 2.0 * radius, gap = diameter * 1e-7;
  const std::vector<uint32_t> sequence = coherent::enumerate_views(layout);

  std::vector<double> vertices;
  vertices.reserve(3 * raster.vertices().size());
  for (const Vec3& v : raster.vertices()) vertices.insert(vertices.end(), {v.x, v.y, v.z});
  std::vector<uint32_t> triangles;
  triangles.reserve(3 * raster.triangles().size());
  for (const auto& t : raster.triangles()) triangles.insert(triangles.end(), {t[0], t[1], t[2]});
  const size_t nv = raster.vertices().size(), nt = raster.triangles().size();

  // Views a batch: its lists (a uint and a double each, kList a texel), counts and projected
  // vertices within kBatchBytes.
  const size_t per_view = texels * (kList * 12 + 4) + nv * 32 + 76;
  const size_t batch = std::clamp<size_t>(kBatchBytes / per_view, 1, views);

  const cl::Context& ctx = rt.context();
  cl::CommandQueue& q = rt.queue();
  coherent::DeviceDualDepth out;
  out.layout = layout;
  out.device = coherent::device_layout(layout);
  out.z1 = cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<size_t>(1, views * texels) * sizeof(uint16_t));
  out.z2 = cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<size_t>(1, views * texels) * sizeof(uint16_t));
  out.positions = coherent::upload_positions(rt, layout);
  DeviceRasterStats st;
  st.batch_views = batch;

  const cl::Buffer vbuf = device_copy(rt, vertices), tbuf = device_copy(rt, triangles);
  cl::Buffer frames(ctx, CL_MEM_READ_ONLY, batch * 9 * sizeof(double));
  cl::Buffer snapped(ctx, CL_MEM_READ_WRITE, std::max<size_t>(1, batch * nv) * 2 * sizeof(int32_t));
  cl::Buffer exact(ctx, CL_MEM_READ_WRITE, std::max<size_t>(1, batch * nv) * 3 * sizeof(double));
  cl::Buffer counts(ctx, CL_MEM_READ_WRITE, batch * texels * sizeof(uint32_t));
  cl::Buffer list_triangle(ctx, CL_MEM_READ_WRITE, batch * texels * kList * sizeof(uint32_t));
  cl::Buffer list_depth(ctx, CL_MEM_READ_WRITE, batch * texels * kList * sizeof(double));
  cl::Buffer overflow(ctx, CL_MEM_READ_WRITE, batch * sizeof(uint32_t));

  const cl::Program program = rt.program({"coherent/raster.cl"}, "-cl-std=CL1.2");
  cl::Kernel project(program, "sf_raster_project"), cover(program, "sf_raster_cover"),
      resolve(program, "sf_raster_resolve");
  const Vec3 center{layout.center[0], layout.center[1], layout.center[2]};
  constexpr size_t kGroup = 64;
  std::vector<double> frame_values(batch * 9);
  std::vector<uint32_t> flags(batch);
  for (size_t first = 0; first < views; first += batch) {
    const size_t count = std::min(batch, views - first);
    for (size_t b = 0; b < count; ++b) {
      const coherent::ViewFrame f = coherent::view_frame(layout, sequence[first + b]);
      for (int k = 0; k < 3; ++k) {
        frame_values[9 * b + k] = f.dir[k];
        frame_values[9 * b + 3 + k] = f.right[k];
        frame_values[9 * b + 6 + k] = f.up[k];
      }
    }
    q.enqueueWriteBuffer(frames, CL_FALSE, 0, count * 9 * sizeof(double), frame_values.data());
    q.enqueueFillBuffer(counts, cl_uint(0), 0, count * texels * sizeof(uint32_t));
    q.enqueueFillBuffer(overflow, cl_uint(0), 0, count * sizeof(uint32_t));
    int a = 0;
    project.setArg(a++, cl_int(count));
    project.setArg(a++, cl_int(nv));
    project.setArg(a++, vbuf);
    project.setArg(a++, frames);
    project.setArg(a++, center.x);
    project.setArg(a++, center.y);
    project.setArg(a++, center.z);
    project.setArg(a++, double(m) / (2.0 * radius));  // view_raster.cpp's scale, half = radius
    project.setArg(a++, 0.5 * m);
    project.setArg(a++, radius);  // half_depth
    project.setArg(a++, snapped);
    project.setArg(a++, exact);
    q.enqueueNDRangeKernel(project, cl::NullRange, cl::NDRange(round_up(count * nv, kGroup)), cl::NDRange(kGroup));
    a = 0;
    cover.setArg(a++, cl_int(count));
    cover.setArg(a++, cl_int(nt));
    cover.setArg(a++, tbuf);
    cover.setArg(a++, cl_int(nv));
    cover.setArg(a++, cl_int(m));
    cover.setArg(a++, snapped);
    cover.setArg(a++, exact);
    cover.setArg(a++, counts);
    cover.setArg(a++, list_triangle);
    cover.setArg(a++, list_depth);
    q.enqueueNDRangeKernel(cover, cl::NullRange, cl::NDRange(round_up(count * nt, kGroup)), cl::NDRange(kGroup));
    a = 0;
    resolve.setArg(a++, cl_int(count));
    resolve.setArg(a++, cl_int(m));
    resolve.setArg(a++, cl_int(hits));
    resolve.setArg(a++, gap);
    resolve.setArg(a++, diameter);
    resolve.setArg(a++, radius);
    resolve.setArg(a++, cl_int(layout.far_plane == coherent::FarPlane::Sphere ? 1 : 0));
    resolve.setArg(a++, counts);
    resolve.setArg(a++, list_triangle);
    resolve.setArg(a++, list_depth);
    resolve.setArg(a++, cl_uint(first));
    resolve.setArg(a++, out.z1);
    resolve.setArg(a++, out.z2);
    resolve.setArg(a++, overflow);
    q.enqueueNDRangeKernel(resolve, cl::NullRange, cl::NDRange(round_up(count * texels, kGroup)), cl::NDRange(kGroup));
    q.enqueueReadBuffer(overflow, CL_TRUE, 0, count * sizeof(uint32_t), flags.data());
    // A view with a texel of more crossings than a list holds: the host renders it (the same
    // bytes) into its map.
    for (size_t b = 0; b < count; ++b) {
      if (!flags[b]) continue;
      const uint32_t i = uint32_t(first + b);
      const StackPart part = render_stack_part(object, layout, {i, i + 1}, 1);
      q.enqueueWriteBuffer(out.z1, CL_TRUE, size_t(i) * texels * sizeof(uint16_t), texels * sizeof(uint16_t),
                           part.z1.data());
      q.enqueueWriteBuffer(out.z2, CL_TRUE, size_t(i) * texels * sizeof(uint16_t), texels * sizeof(uint16_t),
                           part.z2.data());
      ++st.host_views;
    }
  }
  q.finish();
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = st;
  return out;
}

}  // namespace sf::scene
