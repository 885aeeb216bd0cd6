#pragma once
// The binding's boundary, shared by its files: numpy arrays in and out, keyword options and the
// messages that name them, the warm Device, and pyopencl objects as retained handles.
// Rules: arrays are float32 C-contiguous after the Python side's exact conversion (never a
// silent narrowing); every call releases the GIL while the device works; the library's messages
// name fields ("FilterOptions::esm.c"), a Python caller reads keywords ("esm_c").
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/host_image.hpp"
#include "shadowfilter/options.hpp"
#include "shadowfilter/parameters.hpp"
#include "shadowfilter/runtime.hpp"

namespace sfpy {

namespace nb = nanobind;

using Image2D = nb::ndarray<const float, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Image3D = nb::ndarray<const float, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using Output2D = nb::ndarray<nb::numpy, float, nb::ndim<2>>;

sf::HostImage host_image(const Image2D& a);
// A (H, W, C) receiver image: u, v, d and optionally f (footprint) and ndl, as the CLI's receiver
// files hold them.
sf::Receivers receivers_of(const Image3D& a);
// One receiver per map texel at depth a[y, x].
sf::Receivers receiver_grid(const Image2D& a);
Output2D to_numpy(std::vector<float> values, int width, int height);

// A flag's keyword: "--esm-c" -> "esm_c", "--cssm-sharpen A" -> "cssm_sharpen A".
std::string keyword_of(const std::string& flag);
// The library's message with every field it names (FilterOptions', SoftOptions') as its keyword.
std::string keyword_message(const std::string& library_message);

// Runs f(); an InputError leaves with the keywords in its message.
template <class F>
auto keyword_errors(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const sf::InputError& e) {
    throw sf::InputError(keyword_message(e.what()));
  }
}

// A keyword's number as the CLI's flag takes it: finite, an integer where `integer`; anything
// else (a bool, a string) is refused with "<keyword>: must be ...".
double number_of(const std::string& keyword, nb::handle value, bool integer);

// Sets one FilterOptions keyword as the CLI's flag does (parameters.hpp: parse_choice,
// check_given_value); a method's parameters are checked by the method's validation when the
// options are used. Throws InputError for unknown keywords, naming the known ones.
void set_filter_option(sf::FilterOptions& o, const std::string& keyword, nb::handle value);
void set_filter_option(sf::FilterOptions& o, const sf::Parameter& p, const std::string& keyword, nb::handle value);
sf::FilterOptions filter_options_of(const std::string& method, const nb::dict& options);

// One warm device: a Runtime with its context, queue and program cache, shared by every call
// that names it.
struct Device {
  std::shared_ptr<sf::Runtime> runtime;
};

// --- pyopencl objects --------------------------------------------------------------------------
// They arrive as their handles (int_ptr): cl:: wrappers that retain them for the call and release
// them after, so the caller's objects keep their identity, content and reference counts. Events
// go back as a handle with one reference that pyopencl takes over (Event.from_int_ptr(p,
// retain=False)).
cl::Buffer buffer_of(uintptr_t handle, size_t bytes, const char* name);
sf::EventList events_of(const std::vector<uintptr_t>& handles);
uintptr_t handed_over(const cl::Event& e);
std::shared_ptr<sf::Runtime> runtime_of_queue(uintptr_t context, uintptr_t queue);

void bind_soft(nb::module_& m);
void bind_device(nb::module_& m);

}  // namespace sfpy
