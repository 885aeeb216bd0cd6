// shadowfilter._core: the core library on numpy arrays (nanobind). The Python package
// (python/shadowfilter) fronts it; this file only converts arrays and errors at the boundary.
// Rules: arrays are float32 C-contiguous after the Python side's exact conversion (never a
// silent narrowing); every call releases the GIL while the device works; InputError and
// DeviceError become shadowfilter.InputError (a ValueError) and shadowfilter.DeviceError.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/shared_ptr.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "shadowfilter/camera_receivers.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/runtime.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using Image2D = nb::ndarray<const float, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Image3D = nb::ndarray<const float, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using Output2D = nb::ndarray<nb::numpy, float, nb::ndim<2>>;

sf::HostImage host_image(const Image2D& a) {
  sf::HostImage img(static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), 1);
  std::memcpy(img.data.data(), a.data(), img.data.size() * sizeof(float));
  return img;
}

// A (H, W, C) receiver image: u, v, d and optionally f (footprint) and ndl, as the CLI's
// receiver files hold them.
sf::Receivers receivers_of(const Image3D& a) {
  const size_t h = a.shape(0), w = a.shape(1), c = a.shape(2);
  if (c < 3 || c > 5)
    throw sf::InputError("receivers must have 3 to 5 channels (u, v, d[, f[, ndl]]), got " + std::to_string(c));
  sf::Receivers r;
  r.width = static_cast<int>(w);
  r.height = static_cast<int>(h);
  r.has_footprint = c >= 4;
  r.has_ndl = c >= 5;
  const size_t n = w * h;
  r.u.resize(n);
  r.v.resize(n);
  r.d.resize(n);
  r.f.assign(n, 1.0f);
  if (r.has_ndl) r.ndl.resize(n);
  const float* p = a.data();
  for (size_t i = 0; i < n; ++i, p += c) {
    r.u[i] = p[0];
    r.v[i] = p[1];
    r.d[i] = p[2];
    if (c >= 4) r.f[i] = p[3];
    if (c >= 5) r.ndl[i] = p[4];
  }
  return r;
}

sf::Receivers receiver_grid(const Image2D& a) {
  sf::Receivers r;
  r.width = static_cast<int>(a.shape(1));
  r.height = static_cast<int>(a.shape(0));
  r.grid = true;
  r.d.assign(a.data(), a.data() + r.count());
  return r;
}

Output2D to_numpy(std::vector<float> values, int width, int height) {
  auto* owned = new std::vector<float>(std::move(values));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
  return Output2D(owned->data(), {static_cast<size_t>(height), static_cast<size_t>(width)}, owner);
}

// One warm device: a Runtime with its context, queue and program cache, shared by every call
// that names it.
struct Device {
  std::shared_ptr<sf::Runtime> runtime;
};

Output2D run_filter(const Device& device, const sf::FilterOptions& options, const Image2D& depth,
                    const sf::Receivers& receivers) {
  sf::FilterResult result;
  {
    nb::gil_scoped_release released;
    result = sf::filter(device.runtime, options, host_image(depth), receivers);
  }
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
  auto* out = new std::vector<float>(r.count() * 5);
  for (size_t i = 0; i < r.count(); ++i) {
    float* p = out->data() + 5 * i;
    p[0] = r.u[i], p[1] = r.v[i], p[2] = r.d[i], p[3] = r.f[i], p[4] = r.ndl[i];
  }
  nb::capsule owner(out, [](void* p) noexcept { delete static_cast<std::vector<float>*>(p); });
  nb::dict c;
  c["background"] = counts.background;
  c["outside"] = counts.outside;
  c["no_normal"] = counts.no_normal;
  return {Output3D(out->data(), {static_cast<size_t>(r.height), static_cast<size_t>(r.width), 5}, owner), c};
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

  nb::class_<sf::FilterOptions>(m, "FilterOptions")
      .def(nb::init<>())
      .def_rw("method", &sf::FilterOptions::method)
      .def_prop_rw(
          "blur_radius", [](const sf::FilterOptions& o) { return o.blur.radius; },
          [](sf::FilterOptions& o, int r) { o.blur.radius = r; });

  m.def(
      "filter_points",
      [](const Device& device, const sf::FilterOptions& options, const Image2D& depth, const Image3D& receivers) {
        return run_filter(device, options, depth, receivers_of(receivers));
      },
      "device"_a, "options"_a, "depth"_a, "receivers"_a);
  m.def(
      "filter_grid",
      [](const Device& device, const sf::FilterOptions& options, const Image2D& depth, const Image2D& receiver_depth) {
        return run_filter(device, options, depth, receiver_grid(receiver_depth));
      },
      "device"_a, "options"_a, "depth"_a, "receiver_depth"_a);

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
}
