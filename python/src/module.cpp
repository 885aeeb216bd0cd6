// shadowfilter._core: the core library on numpy arrays (nanobind). The Python package
// (python/shadowfilter) fronts it; the binding only converts arrays, options and errors at the
// boundary (boundary.hpp). This file: filter, options, devices, views and camera receivers;
// soft.cpp: soft shadows; device.cpp: pyopencl objects in place.
#include <nanobind/stl/optional.h>
#include <nanobind/stl/shared_ptr.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "boundary.hpp"
#include "shadowfilter/camera_receivers.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"

using namespace nanobind::literals;
using namespace sfpy;

namespace {

Output2D run_filter(const Device& device, const sf::FilterOptions& options, const Image2D& depth,
                    const sf::Receivers& receivers) {
  sf::FilterResult result = keyword_errors([&] {
    nb::gil_scoped_release released;
    return sf::filter(device.runtime, options, host_image(depth), receivers);
  });
  return to_numpy(std::move(result.visibility.data), result.visibility.width, result.visibility.height);
}

// Frames one after another on one pipeline (sf::FrameFilter): buffers allocated for the first
// frame and reused while the sizes repeat. FrameFilter is not thread-safe; the lock makes a
// second thread wait rather than race (each thread may hold its own instead).
struct FrameFilterHandle {
  std::unique_ptr<sf::FrameFilter> filter;
  std::mutex lock;
};

Output2D run_frame(FrameFilterHandle& f, const Image2D& depth, const sf::Receivers& receivers) {
  sf::FilterResult result = keyword_errors([&] {
    nb::gil_scoped_release released;
    std::lock_guard<std::mutex> held(f.lock);
    return f.filter->run(host_image(depth), receivers);
  });
  return to_numpy(std::move(result.visibility.data), result.visibility.width, result.visibility.height);
}

using Matrix = nb::ndarray<const double, nb::shape<4, 4>, nb::c_contig, nb::device::cpu>;

sf::ClipSpace parse_clip(const std::string& clip) {
  if (clip == "opengl") return sf::ClipSpace::OpenGL;
  if (clip == "d3d") return sf::ClipSpace::D3D;
  if (clip == "vulkan") return sf::ClipSpace::Vulkan;
  throw sf::InputError("clip must be \"opengl\", \"d3d\" or \"vulkan\", got \"" + clip + "\"");
}

sf::CameraDepthKind parse_kind(const std::string& kind) {
  for (sf::CameraDepthKind k : {sf::CameraDepthKind::Window, sf::CameraDepthKind::View, sf::CameraDepthKind::Distance,
                                sf::CameraDepthKind::Position})
    if (kind == sf::camera_depth_kind_name(k)) return k;
  throw sf::InputError("camera_depth_kind must be window, view, distance or position, got \"" + kind + "\"");
}

// A camera or light: row-major 4x4 view and projection (p_clip = projection x view x p_world),
// checked as the CLI checks camera files (projection_depth).
sf::ViewProjection make_view(const Matrix& view, const Matrix& projection, const std::string& clip,
                             std::optional<bool> reversed_z, std::optional<double> far) {
  sf::ViewProjection vp;
  std::memcpy(vp.view.data(), view.data(), 16 * sizeof(double));
  std::memcpy(vp.projection.data(), projection.data(), 16 * sizeof(double));
  vp.clip = parse_clip(clip);
  vp.reversed_z = reversed_z;
  if (far) vp.infinite_far_depth = *far;
  (void)sf::projection_depth(vp);
  return vp;
}

using Output3D = nb::ndarray<nb::numpy, float, nb::ndim<3>>;

std::pair<Output3D, nb::dict> receivers_of_camera(
    const sf::ViewProjection& camera, nb::ndarray<const float, nb::c_contig, nb::device::cpu> depth,
    const std::string& kind, const sf::ViewProjection& light, int map_width, int map_height,
    std::optional<nb::ndarray<const float, nb::c_contig, nb::device::cpu>> normals) {
  sf::CameraDepth cd;
  cd.kind = parse_kind(kind);
  const size_t want_dims = cd.kind == sf::CameraDepthKind::Position ? 3 : 2;
  if (depth.ndim() != want_dims || (want_dims == 3 && depth.shape(2) != 3))
    throw sf::InputError(std::string("camera_depth of kind ") + kind + " must be " +
                         (want_dims == 3 ? "(h, w, 3) world positions" : "(h, w)") + ", got " +
                         std::to_string(depth.ndim()) + " dimensions");
  cd.height = static_cast<int>(depth.shape(0));
  cd.width = static_cast<int>(depth.shape(1));
  cd.values.assign(depth.data(), depth.data() + depth.size());
  sf::CameraReceiverOptions o;
  o.map_width = map_width;
  o.map_height = map_height;
  if (normals) {
    if (normals->ndim() != 3 || normals->shape(0) != depth.shape(0) || normals->shape(1) != depth.shape(1) ||
        normals->shape(2) != 3)
      throw sf::InputError("normals must be (h, w, 3) world-space normals of the camera image's size");
    o.normals.assign(normals->data(), normals->data() + normals->size());
  }
  sf::CameraReceiverCounts counts;
  sf::Receivers r;
  {
    nb::gil_scoped_release released;
    r = sf::camera_receivers(camera, cd, light, o, &counts);
  }
  constexpr size_t kChannels = 12;  // u v d f ndl nx ny nz dudx dvdx dudy dvdy
  auto* out = new std::vector<float>(r.count() * kChannels);
  for (size_t i = 0; i < r.count(); ++i) {
    float* p = out->data() + kChannels * i;
    p[0] = r.u[i], p[1] = r.v[i], p[2] = r.d[i], p[3] = r.f[i], p[4] = r.ndl[i];
    p[5] = r.nx[i], p[6] = r.ny[i], p[7] = r.nz[i];
    p[8] = r.dudx[i], p[9] = r.dvdx[i], p[10] = r.dudy[i], p[11] = r.dvdy[i];
  }
  nb::capsule owner(out, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
  nb::dict c;
  c["background"] = counts.background;
  c["outside"] = counts.outside;
  c["no_normal"] = counts.no_normal;
  return {Output3D(out->data(), {static_cast<size_t>(r.height), static_cast<size_t>(r.width), kChannels}, owner), c};
}

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "shadowfilter's core library (OpenCL) on numpy arrays";

  nb::exception<sf::InputError>(m, "InputError", PyExc_ValueError);
  nb::exception<sf::DeviceError>(m, "DeviceError", PyExc_RuntimeError);

  nb::class_<sf::DeviceInfo>(m, "DeviceInfo")
      .def_ro("platform_name", &sf::DeviceInfo::platform_name)
      .def_ro("device_name", &sf::DeviceInfo::device_name)
      .def_ro("driver_version", &sf::DeviceInfo::driver_version)
      .def_ro("type", &sf::DeviceInfo::type)
      .def_ro("global_mem_bytes", &sf::DeviceInfo::global_mem_bytes)
      .def_ro("compute_units", &sf::DeviceInfo::compute_units)
      .def("__repr__", [](const sf::DeviceInfo& d) { return d.device_name + " (" + d.platform_name + ")"; });
  m.def("devices", &sf::list_devices, "Every OpenCL device on every platform, in platform/device order.");

  m.def("options", [] {
    nb::list out;
    for (const sf::Parameter* p : sf::declared_parameters()) {
      nb::dict d;
      d["keyword"] = keyword_of(p->flag);
      d["flag"] = p->flag;
      d["field"] = p->field;
      d["type"] = p->type == sf::ParameterType::Real      ? "real"
                  : p->type == sf::ParameterType::Integer ? "integer"
                                                          : "choice";
      d["choices"] = p->choices;
      d["default"] = p->default_text;
      d["range"] = p->range ? p->range->text(p->type) : std::string();
      d["help"] = p->help;
      nb::list users;  // the methods that declare it (empty for the knobs every method has)
      for (const auto& m : sf::methods())
        for (const sf::Parameter& q : m.parameters)
          if (q.field == p->field) users.append(m.name);
      d["methods"] = users;
      out.append(d);
    }
    return out;
  });
  m.def("method_names", [] {
    std::vector<std::string> names;
    for (const auto& d : sf::methods()) names.push_back(d.name);
    return names;
  });

  nb::class_<Device>(m, "Device")
      .def(
          "__init__",
          [](Device* self, const std::string& selector) { new (self) Device{sf::Runtime::create(selector)}; },
          "selector"_a = "")
      .def_prop_ro("name", [](const Device& d) { return d.runtime->info().device_name; });

  m.def(
      "filter_points",
      [](const Device& device, const std::string& method, const nb::dict& options, const Image2D& depth,
         const Image3D& receivers) {
        return run_filter(device, filter_options_of(method, options), depth, receivers_of(receivers));
      },
      "device"_a, "method"_a, "options"_a, "depth"_a, "receivers"_a);
  m.def(
      "filter_grid",
      [](const Device& device, const std::string& method, const nb::dict& options, const Image2D& depth,
         const Image2D& receiver_depth) {
        return run_filter(device, filter_options_of(method, options), depth, receiver_grid(receiver_depth));
      },
      "device"_a, "method"_a, "options"_a, "depth"_a, "receiver_depth"_a);

  nb::class_<FrameFilterHandle>(m, "FrameFilter")
      .def(
          "__init__",
          [](FrameFilterHandle* self, const Device& device, const std::string& method, const nb::dict& options) {
            new (self) FrameFilterHandle();
            const sf::FilterOptions o = filter_options_of(method, options);
            self->filter = keyword_errors([&] { return std::make_unique<sf::FrameFilter>(device.runtime, o); });
          },
          "device"_a, "method"_a, "options"_a)
      .def(
          "run_points",
          [](FrameFilterHandle& f, const Image2D& depth, const Image3D& receivers) {
            return run_frame(f, depth, receivers_of(receivers));
          },
          "depth"_a, "receivers"_a)
      .def(
          "run_grid",
          [](FrameFilterHandle& f, const Image2D& depth, const Image2D& receiver_depth) {
            return run_frame(f, depth, receiver_grid(receiver_depth));
          },
          "depth"_a, "receiver_depth"_a)
      .def_prop_ro("allocations", [](const FrameFilterHandle& f) { return f.filter->allocations(); });

  nb::class_<sf::ViewProjection>(m, "View", "A camera or a light: row-major view and projection matrices")
      .def(
          "__init__",
          [](sf::ViewProjection* self, const Matrix& view, const Matrix& projection, const std::string& clip,
             std::optional<bool> reversed_z, std::optional<double> far) {
            new (self) sf::ViewProjection(make_view(view, projection, clip, reversed_z, far));
          },
          "view"_a, "projection"_a, "clip"_a = "opengl", "reversed_z"_a = nb::none(), "far"_a = nb::none())
      .def_prop_ro("clip", [](const sf::ViewProjection& v) { return std::string(sf::clip_space_name(v.clip)); });
  m.def("camera_receivers", &receivers_of_camera, "camera"_a, "camera_depth"_a, "kind"_a, "light"_a, "map_width"_a,
        "map_height"_a, "normals"_a = nb::none());

  bind_soft(m);
  bind_device(m);
}
