// A renderer's own OpenCL pipeline with shadowfilter inside it (docs/embedding.md):
//   1. its own context and queue;
//   2. its own kernel renders a light-space depth map of an analytic scene (a tilted ground, a
//      sphere and a bar above it) and another one the camera's receivers on the ground;
//   3. shadowfilter prefilters that depth buffer (ESM, Gaussian radius 3, mip chain);
//   4. its own shading kernel, which #includes the installed method and lookup headers,
//      reconstructs visibility from the filtered basis and shades the ground;
//   5. every step waits on the events of the steps before it: no host round trip until the
//      results are read back;
//   6. the shading kernel's visibility is checked against shadowfilter's own reconstruction of
//      the same receivers, and the image is written as a PNG.
// Usage: embed_example [OUT.png]    exit 0 when the two agree within kTolerance.
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "shadowfilter/embed.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/pipeline.hpp"

namespace {

constexpr int kMap = 512;                   // shadow map kMap x kMap
constexpr int kWidth = 640, kHeight = 480;  // camera image
constexpr float kTolerance = 1e-5f;         // |own - library| visibility, same math in both

// The renderer's kernels. The five includes are the installed shadowfilter headers; the build
// options (-DSF_STORAGE, -DSF_LOOKUP, the method's) come from sf::kernel_prelude().
const char* kRendererSource = R"CLC(
#include "shadowfilter/cl/shared_types.clh"
#include "shadowfilter/cl/common.clh"
#include "shadowfilter/cl/storage.clh"
#include "shadowfilter/cl/methods/esm.clh"
#include "shadowfilter/cl/lookup.clh"

// Light-space depth in [0, 1] at map coordinates (s, t) of the scene's occluders and ground.
float ground_depth(float s, float t) { return 0.85f - 0.1f * t; }
float scene_depth(float s, float t) {
  float z = ground_depth(s, t);
  const float ds = s - 0.42f, dt = t - 0.5f, r = 0.17f;  // sphere, centre at depth 0.45
  if (ds * ds + dt * dt < r * r) z = fmin(z, 0.45f - sqrt(r * r - ds * ds - dt * dt));
  if (s > 0.70f && s < 0.78f && t > 0.12f && t < 0.88f) z = fmin(z, 0.6f);  // bar at depth 0.6
  return z;
}

__kernel void render_depth(__global float* depth, int W, int H) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= W || y >= H) return;
  depth[y * W + x] = scene_depth((x + 0.5f) / W, (y + 0.5f) / H);
}

// A camera over the ground: rows far away (top) cover more of the map than rows near it, so the
// receivers' footprints f (map texels per pixel) grow with distance.
void camera_ray(float px, float py, int RW, int RH, float* s, float* t) {
  const float y = py / RH;                    // 0 = far, 1 = near
  *t = 0.05f + 0.9f * (1.0f - y) * (1.0f - y);  // far rows compressed
  const float spread = 0.55f + 0.45f * (1.0f - y);
  *s = 0.5f + (px / RW - 0.5f) * 2.0f * spread * 0.5f;
}

__kernel void camera_receivers(__global float* u, __global float* v, __global float* d,
                               __global float* f, int RW, int RH, int W) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= RW || y >= RH) return;
  float s, t, s1, t1;
  camera_ray(x + 0.5f, y + 0.5f, RW, RH, &s, &t);
  camera_ray(x + 1.5f, y + 1.5f, RW, RH, &s1, &t1);
  const int i = y * RW + x;
  u[i] = s;
  v[i] = t;
  d[i] = ground_depth(s, t);
  f[i] = fmax(fabs(s1 - s), fabs(t1 - t)) * W;
}

// Visibility from the filtered basis as shadowfilter's reconstruction computes it, then a
// checkered ground lit by the light.
__kernel void shade(__global const sf_stored* basis, __global const sf_stored* chain,
                    __global const float* sat, int W, int H, __global const float* u,
                    __global const float* v, __global const float* d, __global const float* f,
                    __global float* visibility, __global uchar4* rgba, int count,
                    const sf_method_params P) {
  const int i = get_global_id(0);
  if (i >= count) return;
  float vis = 1.0f;
  if (!sf_receiver_outside(u[i], v[i], d[i])) {
    float b[SF_CHANNELS];
    sf_lookup(basis, chain, sat, W, H, u[i], v[i], f[i], b);
    vis = clamp(sf_visibility(b, clamp(d[i], 0.0f, 1.0f), P), 0.0f, 1.0f);
  }
  visibility[i] = vis;
  const int checker = ((int)(u[i] * 16.0f) + (int)(v[i] * 16.0f)) & 1;
  const float3 albedo = checker ? (float3)(0.85f, 0.80f, 0.70f) : (float3)(0.55f, 0.60f, 0.65f);
  const float3 c = albedo * (0.2f + 0.8f * vis);
  rgba[i] = (uchar4)(convert_uchar_sat_rte(c.x * 255.0f), convert_uchar_sat_rte(c.y * 255.0f),
                     convert_uchar_sat_rte(c.z * 255.0f), 255);
}
)CLC";

cl::Device pick_device() {
  std::vector<cl::Platform> platforms;
  cl::Platform::get(&platforms);
  for (cl_device_type type : {cl_device_type(CL_DEVICE_TYPE_GPU), cl_device_type(CL_DEVICE_TYPE_ALL)})
    for (auto& p : platforms) {
      std::vector<cl::Device> devices;
      try {
        p.getDevices(type, &devices);
      } catch (const cl::Error&) {
        continue;  // no device of this type on this platform
      }
      if (!devices.empty()) return devices.front();
    }
  throw std::runtime_error("no OpenCL device");
}

// Written to a temporary name and renamed, so a failed run leaves no partial file.
void write_png(const std::string& path, const std::vector<cl_uchar4>& rgba) {
  const std::string tmp = path + ".tmp";
  if (!stbi_write_png(tmp.c_str(), kWidth, kHeight, 4, rgba.data(), kWidth * 4))
    throw std::runtime_error("cannot write " + tmp);
  std::filesystem::rename(tmp, path);
}

int run(const std::string& out_path) {
  // 1. The renderer's own context and queue.
  const cl::Device device = pick_device();
  cl::Context context(device);
  cl::CommandQueue queue(context, device);
  std::cout << "device: " << device.getInfo<CL_DEVICE_NAME>() << "\n";

  // shadowfilter on that context and queue.
  auto rt = std::make_shared<sf::Runtime>(context, queue);
  sf::FilterOptions opt;
  opt.method = "esm";
  opt.esm.c = 80;
  opt.blur.radius = 3;
  opt.lookup.kind = sf::Lookup::Mips;
  const sf::BufferPlan plan = sf::Pipeline::plan(*rt, opt, kMap, kMap);
  std::cout << "shadowfilter allocates " << plan.total() << " bytes:";
  for (const auto& b : plan.buffers) std::cout << " " << b.name << " " << b.bytes;
  std::cout << "\n";
  sf::Pipeline pipe(rt, opt, kMap, kMap);

  // The renderer's program: its kernels plus the installed headers (-I the package's dir).
  const sf::KernelPrelude prelude = sf::kernel_prelude(opt);
  cl::Program program(context, kRendererSource);
  const std::string options = std::string("-I ") + SF_KERNEL_INCLUDE_DIR + " " + prelude.build_options;
  try {
    program.build(options.c_str());
  } catch (const cl::Error&) {
    std::cerr << program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device) << "\n";
    throw;
  }

  // 2. Depth map and receivers, by the renderer's kernels, into the renderer's buffers.
  const size_t count = size_t(kWidth) * kHeight;
  cl::Buffer depth(context, CL_MEM_READ_WRITE, size_t(kMap) * kMap * sizeof(float));
  cl::Buffer u(context, CL_MEM_READ_WRITE, count * sizeof(float)), v(context, CL_MEM_READ_WRITE, count * sizeof(float));
  cl::Buffer d(context, CL_MEM_READ_WRITE, count * sizeof(float)), f(context, CL_MEM_READ_WRITE, count * sizeof(float));
  cl::Buffer own_vis(context, CL_MEM_READ_WRITE, count * sizeof(float));
  cl::Buffer lib_vis(context, CL_MEM_READ_WRITE, count * sizeof(float));
  cl::Buffer rgba(context, CL_MEM_READ_WRITE, count * sizeof(cl_uchar4));

  cl::Kernel render(program, "render_depth");
  render.setArg(0, depth);
  render.setArg(1, kMap);
  render.setArg(2, kMap);
  cl::Event rendered;
  queue.enqueueNDRangeKernel(render, cl::NullRange, cl::NDRange(kMap, kMap), cl::NullRange, nullptr, &rendered);

  cl::Kernel camera(program, "camera_receivers");
  camera.setArg(0, u);
  camera.setArg(1, v);
  camera.setArg(2, d);
  camera.setArg(3, f);
  camera.setArg(4, kWidth);
  camera.setArg(5, kHeight);
  camera.setArg(6, kMap);
  cl::Event receivers_ready;
  queue.enqueueNDRangeKernel(camera, cl::NullRange, cl::NDRange(kWidth, kHeight), cl::NullRange, nullptr,
                             &receivers_ready);

  // 3. shadowfilter's prefilter of the renderer's depth buffer, after the render.
  const std::vector<cl::Event> after_render{rendered};
  const cl::Event filtered = pipe.prefilter(depth, &after_render);

  // 4. The renderer's shading kernel on the filtered basis.
  const std::vector<cl::Event> inputs{filtered, receivers_ready};
  const sf::LookupBuffers tables = pipe.lookup_tables();
  cl::Kernel shade(program, "shade");
  shade.setArg(0, pipe.basis());
  shade.setArg(1, tables.chain);  // mips: the chain; bilinear / sat would pass null or the SAT
  if (tables.sat())
    shade.setArg(2, tables.sat);
  else
    shade.setArg(2, sizeof(cl_mem), nullptr);
  shade.setArg(3, kMap);
  shade.setArg(4, kMap);
  shade.setArg(5, u);
  shade.setArg(6, v);
  shade.setArg(7, d);
  shade.setArg(8, f);
  shade.setArg(9, own_vis);
  shade.setArg(10, rgba);
  shade.setArg(11, static_cast<cl_int>(count));
  shade.setArg(12, prelude.params.size(), prelude.params.data());
  cl::Event shaded;
  queue.enqueueNDRangeKernel(shade, cl::NullRange, cl::NDRange(count), cl::NullRange, &inputs, &shaded);

  // 6. shadowfilter's own reconstruction of the same receivers, for the check.
  const sf::DeviceReceivers rx{false, count, u, v, d, f};
  const cl::Event reconstructed = pipe.reconstruct(rx, lib_vis, &inputs);

  // 5. The first host round trip: read the results.
  const std::vector<cl::Event> done{shaded, reconstructed};
  std::vector<float> own(count), lib(count);
  std::vector<cl_uchar4> pixels(count);
  queue.enqueueReadBuffer(own_vis, CL_FALSE, 0, count * sizeof(float), own.data(), &done);
  queue.enqueueReadBuffer(lib_vis, CL_FALSE, 0, count * sizeof(float), lib.data(), &done);
  queue.enqueueReadBuffer(rgba, CL_TRUE, 0, count * sizeof(cl_uchar4), pixels.data(), &done);

  double worst = 0, sum = 0;
  size_t shadowed = 0;
  for (size_t i = 0; i < count; ++i) {
    const double e = std::fabs(double(own[i]) - lib[i]);
    worst = std::max(worst, e);
    sum += e;
    shadowed += lib[i] < 0.5f;
  }
  std::printf(
      "visibility of the shading kernel vs shadowfilter's reconstruct: max |error| %.3g, mean %.3g "
      "(tolerance %.0e) over %zu receivers, %.1f%% shadowed\n",
      worst, sum / count, double(kTolerance), count, 100.0 * shadowed / count);
  write_png(out_path, pixels);
  std::cout << "wrote " << out_path << " (" << kWidth << "x" << kHeight << ")\n";
  if (worst > kTolerance || shadowed == 0 || shadowed == count) {
    std::cerr << "embed_example: the check failed\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "embed.png";
  try {
    return run(out);
  } catch (const sf::InputError& e) {
    std::cerr << "embed_example: " << e.what() << "\n";
    return 2;
  } catch (const sf::DeviceError& e) {
    std::cerr << "embed_example: device error: " << e.what() << "\n";
    return 3;
  } catch (const cl::Error& e) {
    std::cerr << "embed_example: OpenCL error " << e.err() << " in " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "embed_example: " << e.what() << "\n";
    return 1;
  }
}
