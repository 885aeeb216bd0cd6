// Layered filtering (layered.hpp) against one map of the same texel count: one S x S map (the
// `single` layout) against four layers of (S/2)^2 (a PSSM of the same camera), each a whole
// frame through LayeredPipeline: transform, blur, mips, the projection, every layer's
// reconstruction and the blend, at 1920x1080 receivers of a camera looking over a ground plane
// (smoke mode: sizes() and screen()).
// ESM, R = 3, trilinear mips (the README's main configuration). The two frames run one after
// the other in every iteration, so their ratio compares runs under the same load. Manual time:
// the four-layer frame; counters: both frames' device ms and four / single.
#include <cmath>

#include "bench_common.hpp"
#include "shadowfilter/layered.hpp"

namespace sf::bench {
namespace {

CameraFrustum bench_camera() {
  CameraFrustum cam;
  cam.position = {0, 4, 9};
  const double n = std::sqrt(16.0 + 81.0);
  cam.forward = {0, -4 / n, -9 / n};
  cam.up = {0, 9 / n, -4 / n};
  cam.vertical_fov_degrees = 50;
  cam.aspect = double(screen().width) / screen().height;
  cam.near_depth = 1;
  cam.far_depth = 60;
  return cam;
}

// The ground plane y = 0 seen by the camera: positions, view depths and the pixel's offsets;
// background (NaN) above the horizon or past the far plane.
ViewReceivers ground_view(const CameraFrustum& cam) {
  const int w = screen().width, h = screen().height;
  ViewReceivers v;
  v.width = w;
  v.height = h;
  std::vector<float>* all[] = {&v.x, &v.y, &v.z, &v.depth, &v.dxx, &v.dxy, &v.dxz, &v.dyx, &v.dyy, &v.dyz};
  for (auto* a : all) a->assign(v.count(), NAN);
  const Point3 right{1, 0, 0};  // forward x up for this camera
  const double tan_half = std::tan(0.5 * cam.vertical_fov_degrees * M_PI / 180.0);
  const auto hit = [&](double sx, double sy, Point3& p) {
    const double nx = (2.0 * sx / w - 1.0) * tan_half * cam.aspect, ny = (1.0 - 2.0 * sy / h) * tan_half;
    const Point3 d{cam.forward[0] + nx * right[0] + ny * cam.up[0], cam.forward[1] + nx * right[1] + ny * cam.up[1],
                   cam.forward[2] + nx * right[2] + ny * cam.up[2]};
    if (!(d[1] < 0)) return -1.0;
    const double t = -cam.position[1] / d[1];
    for (int a = 0; a < 3; ++a) p[a] = cam.position[a] + t * d[a];
    return t;  // the view depth: forward . d = 1
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Point3 p{}, x0{}, x1{}, y0{}, y1{};
      const double t = hit(x + 0.5, y + 0.5, p);
      if (!(t > 0 && t <= cam.far_depth)) continue;
      hit(x, y + 0.5, x0), hit(x + 1, y + 0.5, x1), hit(x + 0.5, y, y0), hit(x + 0.5, y + 1, y1);
      const size_t i = size_t(y) * w + x;
      v.x[i] = float(p[0]), v.y[i] = float(p[1]), v.z[i] = float(p[2]), v.depth[i] = float(t);
      v.dxx[i] = float(x1[0] - x0[0]), v.dxy[i] = float(x1[1] - x0[1]), v.dxz[i] = float(x1[2] - x0[2]);
      v.dyx[i] = float(y1[0] - y0[0]), v.dyy[i] = float(y1[1] - y0[1]), v.dyz[i] = float(y1[2] - y0[2]);
    }
  return v;
}

struct Frame {
  std::unique_ptr<LayeredPipeline> pipe;
  std::vector<cl::Buffer> depth;
};

Frame make_frame(const FilterOptions& opt, LayoutKind kind, int cascades, int size, const CameraFrustum& cam) {
  LayoutOptions lo;
  lo.kind = kind;
  lo.cascades = cascades;
  lo.map_size = size;
  const WorldBox ground{{-200, -0.01, -200}, {200, 0, 200}}, blocker{{-2, 1, -2}, {2, 3, 2}};
  Frame f;
  f.pipe =
      std::make_unique<LayeredPipeline>(runtime_ptr(), opt, fit_layout(lo, cam, {0.35, -1.0, 0.25}, {ground, blocker}));
  for (int k = 0; k < f.pipe->layer_count(); ++k)
    f.depth.push_back(to_device(random_floats(size_t(size) * size, 20 + k, 0.2f, 1.0f)));
  return f;
}

double run_frame(Frame& f, const DeviceReceivers& rx, const cl::Buffer& vis) {
  EventList filtered{f.pipe->prefilter(f.depth)};
  f.pipe->reconstruct(rx, vis, &filtered).wait();
  return f.pipe->times().total();
}

void BM_LayeredFrame(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0));
  FilterOptions opt;
  opt.blur.radius = 3;
  opt.lookup.kind = Lookup::Mips;
  opt.esm_classify.mode = EsmClassify::None;  // as esm_pipeline (bench_pipeline.cpp)
  const CameraFrustum cam = bench_camera();
  const ViewReceivers view = ground_view(cam);
  const DeviceReceivers rx = upload_view_receivers(runtime(), view);
  cl::Buffer vis = device_buffer(view.count() * sizeof(float));
  Frame single = make_frame(opt, LayoutKind::Single, 1, size, cam);
  Frame four = make_frame(opt, LayoutKind::Pssm, 4, size / 2, cam);
  double single_s = 0, four_s = 0, project_s = 0, blend_s = 0, reconstruct_s = 0, prefilter_s = 0;
  int runs = 0;
  const double s = time_runs(
      state,
      [&] {
        single_s += run_frame(single, rx, vis);
        const double t = run_frame(four, rx, vis);
        const StageTimes lt = four.pipe->times();
        project_s += lt.project, blend_s += lt.blend, reconstruct_s += lt.reconstruct + lt.classify;
        prefilter_s += lt.transform + lt.blur + lt.pyramid + lt.zmax;
        four_s += t;
        ++runs;
        return t;
      },
      2, [&] { single_s = four_s = project_s = blend_s = reconstruct_s = prefilter_s = 0, runs = 0; });
  state.counters["single_ms"] = 1e3 * single_s / runs;
  state.counters["four_ms"] = 1e3 * four_s / runs;
  state.counters["ratio"] = four_s / single_s;
  state.counters["project_ms"] = 1e3 * project_s / runs;
  state.counters["blend_ms"] = 1e3 * blend_s / runs;
  state.counters["four_prefilter_ms"] = 1e3 * prefilter_s / runs;
  state.counters["four_reconstruct_ms"] = 1e3 * reconstruct_s / runs;
  if (s > 0) state.counters["fps"] = 1.0 / s;
}

}  // namespace

void register_layered() {
  configure(benchmark::RegisterBenchmark(("layered/four_vs_single_" + screen().name()).c_str(), BM_LayeredFrame))
      ->ArgNames({"size"})
      ->ArgsProduct({sizes({2048, 4096})});
}

}  // namespace sf::bench
