// shadowfilter._core on pyopencl objects (shadowfilter/device.py fronts it): the Pipeline and the
// single kernels on a caller's context, queue and buffers, and kernel_prelude for a caller's own
// kernels. Buffers and events cross as retained handles (boundary.hpp); nothing goes through
// the host and the GIL is released while a call enqueues.
#include <nanobind/stl/shared_ptr.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/vector.h>

#include <memory>
#include <string>
#include <vector>

#include "boundary.hpp"
#include "shadowfilter/blur.hpp"
#include "shadowfilter/embed.hpp"
#include "shadowfilter/lookup.hpp"
#include "shadowfilter/method_kernels.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/pipeline.hpp"

using namespace nanobind::literals;

namespace sfpy {
namespace {

// A Pipeline on a caller's context and queue (one Runtime per queue, shared by its pipelines).
struct DevicePipeline {
  std::shared_ptr<sf::Runtime> runtime;
  std::unique_ptr<sf::Pipeline> pipeline;
  int width = 0, height = 0;
};

// A buffer of the library's as a handle pyopencl wraps with a reference of its own
// (MemoryObject.from_int_ptr(p, retain=True)); 0 for none.
uintptr_t handle_of(const cl::Buffer& b) { return reinterpret_cast<uintptr_t>(b()); }

const sf::EventList* wait_of(const sf::EventList& w) { return w.empty() ? nullptr : &w; }

// The basis images of `options` (validated) for a width x height map: planes, bytes per value.
sf::ImageShape basis_shape(const sf::FilterOptions& o, int width, int height) {
  sf::validate_options(o);
  const sf::MethodDesc& m = o.method.desc();
  if (m.raw_depth) throw sf::InputError("method " + m.name + " tests the raw depth: it has no basis to filter");
  sf::ImageShape s;
  s.width = width;
  s.height = height;
  s.channels = m.channels(o);
  s.value_bytes = sf::storage_bytes(o.storage);
  return s;
}

void check_size(int width, int height) {
  if (width <= 0 || height <= 0)
    throw sf::InputError("width and height must be positive, got " + std::to_string(width) + "x" +
                         std::to_string(height));
}

// A single kernel's options and the basis images they make for a width x height map: the sizes
// checked, the options validated (messages with keywords).
struct BasisCall {
  sf::FilterOptions options;
  sf::ImageShape shape;
};

BasisCall basis_call(const std::string& method, const nb::dict& options, int width, int height) {
  check_size(width, height);
  BasisCall c{filter_options_of(method, options), {}};
  c.shape = keyword_errors([&] { return basis_shape(c.options, width, height); });
  return c;
}

}  // namespace

void bind_device(nb::module_& m) {
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
            sf::FilterOptions o = filter_options_of(method, options);
            new (self) DevicePipeline{rt, nullptr, width, height};
            self->pipeline = keyword_errors([&] { return std::make_unique<sf::Pipeline>(rt, o, width, height); });
          },
          "runtime"_a, "method"_a, "options"_a, "width"_a, "height"_a)
      .def(
          "prefilter",
          [](DevicePipeline& p, uintptr_t depth, const std::vector<uintptr_t>& wait) {
            const cl::Buffer d = buffer_of(depth, size_t(p.width) * p.height * sizeof(float), "depth");
            const sf::EventList w = events_of(wait);
            nb::gil_scoped_release released;
            return handed_over(p.pipeline->prefilter(d, wait_of(w)));
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
            return keyword_errors([&] {
              nb::gil_scoped_release released;
              return handed_over(p.pipeline->reconstruct(rx, out, wait_of(w)));
            });
          },
          "count"_a, "grid"_a, "u"_a, "v"_a, "d"_a, "f"_a, "row"_a, "visibility"_a, "wait"_a)
      .def_prop_ro("device_bytes", [](const DevicePipeline& p) { return p.pipeline->device_bytes(); })
      .def(
          "lookup_tables",
          [](const DevicePipeline& p) {
            const sf::LookupBuffers t = p.pipeline->lookup_tables();
            return std::make_tuple(handle_of(p.pipeline->basis()), handle_of(t.chain), handle_of(t.sat));
          },
          "The filtered basis, its mip chain and its SAT as handles (0: none), for a caller's kernel");

  // --- the single kernels (method_kernels.hpp, blur.hpp) in their argument order ---------------
  m.def(
      "basis_shape",
      [](const std::string& method, const nb::dict& options, int width, int height) {
        const sf::ImageShape s = basis_call(method, options, width, height).shape;
        return std::make_tuple(s.channels, s.value_bytes, s.bytes());
      },
      "method"_a, "options"_a, "width"_a, "height"_a);
  m.def(
      "enqueue_transform",
      [](std::shared_ptr<sf::Runtime> rt, const std::string& method, const nb::dict& options, int width, int height,
         uintptr_t depth, uintptr_t basis, const std::vector<uintptr_t>& wait) {
        const BasisCall call = basis_call(method, options, width, height);
        const sf::FilterOptions& o = call.options;
        const sf::ImageShape& s = call.shape;
        const cl::Buffer in = buffer_of(depth, s.plane_texels() * sizeof(float), "depth");
        const cl::Buffer out = buffer_of(basis, s.bytes(), "basis");
        const sf::EventList w = events_of(wait);
        return keyword_errors([&] {
          nb::gil_scoped_release released;
          return handed_over(sf::enqueue_transform(*rt, o.method.desc(), o, width, height, in, out, wait_of(w)));
        });
      },
      "runtime"_a, "method"_a, "options"_a, "width"_a, "height"_a, "depth"_a, "basis"_a, "wait"_a);
  m.def(
      "enqueue_blur",
      [](std::shared_ptr<sf::Runtime> rt, const nb::dict& options, int width, int height, int channels, uintptr_t src,
         uintptr_t tmp, uintptr_t dst, const std::vector<uintptr_t>& wait) {
        check_size(width, height);
        if (channels <= 0) throw sf::InputError("channels must be positive, got " + std::to_string(channels));
        const sf::FilterOptions o = filter_options_of("esm", options);
        sf::ImageShape s;
        s.width = width, s.height = height, s.channels = channels, s.value_bytes = sf::storage_bytes(o.storage);
        const cl::Buffer a = buffer_of(src, s.bytes(), "src"), b = buffer_of(dst, s.bytes(), "dst");
        const cl::Buffer t = tmp ? buffer_of(tmp, s.bytes(), "tmp") : cl::Buffer();
        if (src == dst && !tmp)
          throw sf::InputError("a blur in place (src is dst) needs tmp, a buffer of the same size");
        const sf::EventList w = events_of(wait);
        return keyword_errors([&] {
          nb::gil_scoped_release released;
          return handed_over(sf::enqueue_blur(*rt, o.blur, o.schedule, o.storage, s, a, t, b, nullptr, wait_of(w)));
        });
      },
      "runtime"_a, "options"_a, "width"_a, "height"_a, "channels"_a, "src"_a, "tmp"_a, "dst"_a, "wait"_a);
  m.def(
      "enqueue_reconstruct_points",
      [](std::shared_ptr<sf::Runtime> rt, const std::string& method, const nb::dict& options, int width, int height,
         size_t count, uintptr_t basis, uintptr_t u, uintptr_t v, uintptr_t d, uintptr_t visibility,
         const std::vector<uintptr_t>& wait) {
        const BasisCall call = basis_call(method, options, width, height);
        const sf::FilterOptions& o = call.options;
        const sf::ImageShape& s = call.shape;
        if (o.lookup.kind != sf::Lookup::Bilinear)
          throw sf::InputError(
              "lookup: the single reconstruction reads a basis bilinearly (mips and sat need their "
              "tables: use Pipeline)");
        const size_t bytes = count * sizeof(float);
        const cl::Buffer b = buffer_of(basis, s.bytes(), "basis");
        const cl::Buffer bu = buffer_of(u, bytes, "u"), bv = buffer_of(v, bytes, "v"), bd = buffer_of(d, bytes, "d");
        const cl::Buffer out = buffer_of(visibility, bytes, "visibility");
        const sf::EventList w = events_of(wait);
        return keyword_errors([&] {
          nb::gil_scoped_release released;
          return handed_over(sf::enqueue_reconstruct_points(*rt, o.method.desc(), o, width, height, count, 0, b,
                                                            nullptr, bu, bv, bd, out, wait_of(w)));
        });
      },
      "runtime"_a, "method"_a, "options"_a, "width"_a, "height"_a, "count"_a, "basis"_a, "u"_a, "v"_a, "d"_a,
      "visibility"_a, "wait"_a);
  m.def(
      "enqueue_reconstruct_grid",
      [](std::shared_ptr<sf::Runtime> rt, const std::string& method, const nb::dict& options, int width, int height,
         uintptr_t basis, uintptr_t d, uintptr_t visibility, const std::vector<uintptr_t>& wait) {
        const BasisCall call = basis_call(method, options, width, height);
        const sf::FilterOptions& o = call.options;
        const sf::ImageShape& s = call.shape;
        const size_t bytes = s.plane_texels() * sizeof(float);
        const cl::Buffer b = buffer_of(basis, s.bytes(), "basis");
        const cl::Buffer bd = buffer_of(d, bytes, "d"), out = buffer_of(visibility, bytes, "visibility");
        const sf::EventList w = events_of(wait);
        return keyword_errors([&] {
          nb::gil_scoped_release released;
          return handed_over(
              sf::enqueue_reconstruct_grid(*rt, o.method.desc(), o, width, height, b, bd, out, wait_of(w)));
        });
      },
      "runtime"_a, "method"_a, "options"_a, "width"_a, "height"_a, "basis"_a, "d"_a, "visibility"_a, "wait"_a);

  m.def(
      "kernel_prelude",
      [](const std::string& method, const nb::dict& options) {
        const sf::KernelPrelude p =
            keyword_errors([&] { return sf::kernel_prelude(filter_options_of(method, options)); });
        return std::make_tuple(p.files, p.source, p.build_options,
                               nb::bytes(reinterpret_cast<const char*>(p.params.data()), p.params.size()));
      },
      "method"_a, "options"_a);
}

}  // namespace sfpy
