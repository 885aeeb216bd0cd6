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
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <memory>
#include <string>
#include <vector>

#include "shadowfilter/camera_receivers.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/parameters.hpp"
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

// --- keyword options, generated from the declared parameters (parameters.hpp) -----------------
// A flag's keyword: "--esm-c" -> "esm_c". Messages are the CLI's with the keyword for the flag.
std::string keyword_of(const sf::Parameter& p) {
  std::string k = p.flag.substr(p.flag.find_first_not_of('-'));
  std::replace(k.begin(), k.end(), '-', '_');
  return k;
}

bool is_knob(const sf::Parameter& p) {
  for (const sf::Parameter& k : sf::filter_parameters())
    if (k.field == p.field) return true;
  return false;
}

const sf::Parameter& parameter_of(const std::string& keyword) {
  std::string known;
  for (const sf::Parameter* p : sf::declared_parameters()) {
    if (keyword_of(*p) == keyword) return *p;
    known += (known.empty() ? "" : ", ") + keyword_of(*p);
  }
  throw sf::InputError("unknown option '" + keyword + "' (known: method, " + known + ")");
}

std::string text_of(double v) { return sf::parameter_text(v); }

// The library's messages name fields ("FilterOptions::esm.c"); a Python caller reads keywords.
std::string keyword_message(std::string s) {
  std::vector<std::pair<std::string, std::string>> names;
  for (const sf::Parameter* p : sf::declared_parameters()) names.emplace_back(p->field, keyword_of(*p));
  names.emplace_back("FilterOptions::method", "method");
  std::stable_sort(names.begin(), names.end(),
                   [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
  for (const auto& [field, keyword] : names)
    for (size_t at = s.find(field); at != std::string::npos; at = s.find(field, at + keyword.size()))
      s.replace(at, field.size(), keyword);
  return s;
}

// Sets one keyword option as the CLI's flag would: a name for a choice (case-insensitive), a
// finite number otherwise (an integer for integer parameters), a knob's range checked here, a
// method's parameters by the method's validation when the options are used.
void set_option(sf::FilterOptions& o, const std::string& keyword, nb::handle value) {
  const sf::Parameter& p = parameter_of(keyword);
  if (p.type == sf::ParameterType::Choice) {
    if (!nb::isinstance<nb::str>(value))
      throw sf::InputError(keyword + ": must be a name, got " + nb::cast<std::string>(nb::repr(value)));
    const std::string text = nb::cast<std::string>(value);
    if (p.parse) {
      try {
        p.set(o, p.parse(text));
      } catch (const sf::InputError& e) {
        throw sf::InputError(keyword + ": " + e.what());
      }
      return;
    }
    std::vector<std::string> names = p.choices;
    std::sort(names.begin(), names.end());
    std::string listed, lower = text;
    for (size_t i = 0; i < names.size(); ++i)
      listed += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + names[i];
    for (char& ch : lower) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    for (size_t i = 0; i < p.choices.size(); ++i)
      if (p.choices[i] == lower) return p.set(o, double(i));
    throw sf::InputError(keyword + ": must be " + listed + ", got '" + text + "'");
  }
  if (nb::isinstance<nb::bool_>(value) || !(nb::isinstance<nb::int_>(value) || nb::isinstance<nb::float_>(value)))
    throw sf::InputError(keyword + ": must be a number, got " + nb::cast<std::string>(nb::repr(value)));
  const double v = nb::cast<double>(value);
  if (!std::isfinite(v)) throw sf::InputError(keyword + ": must be a finite number, got " + text_of(v));
  if (p.type == sf::ParameterType::Integer && (v != std::floor(v) || std::abs(v) > 2147483647.0))
    throw sf::InputError(keyword + ": must be an integer, got " + text_of(v));
  if (is_knob(p) && p.range && !p.range->contains(v) && !(p.unset == sf::ParameterUnset::Negative && v < 0))
    throw sf::InputError(keyword + ": must be " + p.range->text(p.type) + ", got " + text_of(v));
  p.set(o, v);
}

sf::FilterOptions options_of(const std::string& method, const nb::dict& options) {
  sf::FilterOptions o;
  o.method = sf::method(method);
  for (auto [key, value] : options) set_option(o, nb::cast<std::string>(key), value);
  return o;
}

// One warm device: a Runtime with its context, queue and program cache, shared by every call
// that names it.
struct Device {
  std::shared_ptr<sf::Runtime> runtime;
};

Output2D run_filter(const Device& device, const sf::FilterOptions& options, const Image2D& depth,
                    const sf::Receivers& receivers) {
  sf::FilterResult result;
  try {
    nb::gil_scoped_release released;
    result = sf::filter(device.runtime, options, host_image(depth), receivers);
  } catch (const sf::InputError& e) {
    throw sf::InputError(keyword_message(e.what()));
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

// --- pyopencl in place ---------------------------------------------------------------------------
// pyopencl objects arrive as their handles (int_ptr): cl:: wrappers that retain them for the call
// and release them after, so the caller's objects keep their identity, content and reference
// counts. Events go back as a handle with one reference that pyopencl takes over
// (Event.from_int_ptr(p, retain=False)).
template <class T, class H>
T retained(uintptr_t handle) {
  return T(reinterpret_cast<H>(handle), /*retainObject=*/true);
}

cl::Buffer buffer_of(uintptr_t handle, size_t bytes, const char* name) {
  if (handle == 0) throw sf::InputError(std::string(name) + " is not a buffer");
  cl::Buffer b = retained<cl::Buffer, cl_mem>(handle);
  const size_t size = b.getInfo<CL_MEM_SIZE>();
  if (size < bytes)
    throw sf::InputError(std::string(name) + " holds " + std::to_string(size) + " bytes, " + std::to_string(bytes) +
                         " needed");
  return b;
}

sf::EventList events_of(const std::vector<uintptr_t>& handles) {
  sf::EventList list;
  for (uintptr_t h : handles) list.push_back(retained<cl::Event, cl_event>(h));
  return list;
}

uintptr_t handed_over(const cl::Event& e) {
  cl_event raw = e();
  if (raw) clRetainEvent(raw);
  return reinterpret_cast<uintptr_t>(raw);
}

// A Pipeline on a caller's context and queue (one Runtime per queue, shared by its pipelines).
struct DevicePipeline {
  std::shared_ptr<sf::Runtime> runtime;
  std::unique_ptr<sf::Pipeline> pipeline;
  int width = 0, height = 0;
};

std::shared_ptr<sf::Runtime> runtime_of_queue(uintptr_t context, uintptr_t queue) {
  return std::make_shared<sf::Runtime>(retained<cl::Context, cl_context>(context),
                                       retained<cl::CommandQueue, cl_command_queue>(queue));
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
      d["keyword"] = keyword_of(*p);
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
        return run_filter(device, options_of(method, options), depth, receivers_of(receivers));
      },
      "device"_a, "method"_a, "options"_a, "depth"_a, "receivers"_a);
  m.def(
      "filter_grid",
      [](const Device& device, const std::string& method, const nb::dict& options, const Image2D& depth,
         const Image2D& receiver_depth) {
        return run_filter(device, options_of(method, options), depth, receiver_grid(receiver_depth));
      },
      "device"_a, "method"_a, "options"_a, "depth"_a, "receiver_depth"_a);

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

  nb::class_<sf::Runtime>(m, "Runtime", "A caller's OpenCL context and queue, with their program cache")
      .def_static(
          "on_queue",
          [](uintptr_t context, uintptr_t queue) -> std::shared_ptr<sf::Runtime> {
            return runtime_of_queue(context, queue);
          },
          "context"_a, "queue"_a);
  nb::class_<DevicePipeline>(m, "DevicePipeline")
      .def(
          "__init__",
          [](DevicePipeline* self, std::shared_ptr<sf::Runtime> rt, const std::string& method, const nb::dict& options,
             int width, int height) {
            sf::FilterOptions o = options_of(method, options);
            new (self) DevicePipeline{rt, nullptr, width, height};
            try {
              self->pipeline = std::make_unique<sf::Pipeline>(rt, o, width, height);
            } catch (const sf::InputError& e) {
              throw sf::InputError(keyword_message(e.what()));
            }
          },
          "runtime"_a, "method"_a, "options"_a, "width"_a, "height"_a)
      .def(
          "prefilter",
          [](DevicePipeline& p, uintptr_t depth, const std::vector<uintptr_t>& wait) {
            const cl::Buffer d = buffer_of(depth, size_t(p.width) * p.height * sizeof(float), "depth");
            const sf::EventList w = events_of(wait);
            cl::Event e;
            {
              nb::gil_scoped_release released;
              e = p.pipeline->prefilter(d, w.empty() ? nullptr : &w);
            }
            return handed_over(e);
          },
          "depth"_a, "wait"_a)
      .def(
          "reconstruct",
          [](DevicePipeline& p, size_t count, bool grid, uintptr_t u, uintptr_t v, uintptr_t d, uintptr_t f, int row,
             uintptr_t visibility, const std::vector<uintptr_t>& wait) {
            const size_t bytes = count * sizeof(float);
            sf::DeviceReceivers rx;
            rx.grid = grid;
            rx.count = count;
            rx.row = row;
            if (grid && count != size_t(p.width) * p.height)
              throw sf::InputError("grid receivers are one per map texel: " +
                                   std::to_string(size_t(p.width) * p.height) + ", got " + std::to_string(count));
            if (!grid) {
              rx.u = buffer_of(u, bytes, "u");
              rx.v = buffer_of(v, bytes, "v");
              if (f) rx.f = buffer_of(f, bytes, "f");
            }
            rx.d = buffer_of(d, bytes, "d");
            const cl::Buffer out = buffer_of(visibility, bytes, "visibility");
            const sf::EventList w = events_of(wait);
            cl::Event e;
            try {
              nb::gil_scoped_release released;
              e = p.pipeline->reconstruct(rx, out, w.empty() ? nullptr : &w);
            } catch (const sf::InputError& err) {
              throw sf::InputError(keyword_message(err.what()));
            }
            return handed_over(e);
          },
          "count"_a, "grid"_a, "u"_a, "v"_a, "d"_a, "f"_a, "row"_a, "visibility"_a, "wait"_a)
      .def_prop_ro("device_bytes", [](const DevicePipeline& p) { return p.pipeline->device_bytes(); });
}
