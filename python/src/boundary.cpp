// The binding's boundary (boundary.hpp): arrays, keyword options and their messages, pyopencl
// handles.
#include "boundary.hpp"

#include <nanobind/stl/string.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "shadowfilter/footprint.hpp"
#include "shadowfilter/methods.hpp"
#include "shadowfilter/soft.hpp"

namespace sfpy {

sf::HostImage host_image(const Image2D& a) {
  sf::HostImage img(static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), 1);
  std::memcpy(img.data.data(), a.data(), img.data.size() * sizeof(float));
  return img;
}

sf::Receivers receivers_of(const Image3D& a) {
  const size_t h = a.shape(0), w = a.shape(1), c = a.shape(2);
  if (c < 3 || (c > 5 && c != 8 && c != 12))
    throw sf::InputError(
        "receivers must have 3, 4, 5, 8 or 12 channels (u, v, d[, f[, ndl[, nx, ny, nz[, dudx, dvdx, dudy, dvdy]]]]), "
        "got " +
        std::to_string(c));
  sf::Receivers r;
  r.width = static_cast<int>(w);
  r.height = static_cast<int>(h);
  r.has_footprint = c >= 4;
  r.has_ndl = c >= 5;
  r.has_normal = c >= 8;
  r.has_jacobian = c == 12;
  const size_t n = w * h;
  r.u.resize(n);
  r.v.resize(n);
  r.d.resize(n);
  r.f.assign(n, 1.0f);
  if (r.has_ndl) r.ndl.resize(n);
  if (r.has_normal) {
    r.nx.resize(n);
    r.ny.resize(n);
    r.nz.resize(n);
  }
  if (r.has_jacobian) {
    r.dudx.resize(n);
    r.dvdx.resize(n);
    r.dudy.resize(n);
    r.dvdy.resize(n);
  }
  const float* p = a.data();
  for (size_t i = 0; i < n; ++i, p += c) {
    r.u[i] = p[0];
    r.v[i] = p[1];
    r.d[i] = p[2];
    if (c >= 4) r.f[i] = p[3];
    if (c >= 5) r.ndl[i] = p[4];
    if (c >= 8) r.nx[i] = p[5], r.ny[i] = p[6], r.nz[i] = p[7];
    if (c == 12) r.dudx[i] = p[8], r.dvdx[i] = p[9], r.dudy[i] = p[10], r.dvdy[i] = p[11];
  }
  sf::isotropic_where_unknown(r);  // a non-finite Jacobian is unknown (footprint.hpp)
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

std::string keyword_of(const std::string& flag) {
  std::string k = flag.substr(flag.find_first_not_of('-'));
  const size_t space = k.find(' ');
  std::replace(k.begin(), space == std::string::npos ? k.end() : k.begin() + long(space), '-', '_');
  return k;
}

std::string keyword_message(const std::string& library_message) {
  std::vector<std::pair<std::string, std::string>> names = sf::option_flags();
  names.insert(names.end(), sf::soft_option_flags().begin(), sf::soft_option_flags().end());
  for (auto& [field, name] : names) name = keyword_of(name);
  return sf::rename_fields(library_message, std::move(names));
}

double number_of(const std::string& keyword, nb::handle value, bool integer) {
  if (nb::isinstance<nb::bool_>(value) || !(nb::isinstance<nb::int_>(value) || nb::isinstance<nb::float_>(value)))
    throw sf::InputError(keyword + ": must be a number, got " + nb::cast<std::string>(nb::repr(value)));
  const double v = nb::cast<double>(value);
  if (!std::isfinite(v)) throw sf::InputError(keyword + ": must be a finite number, got " + sf::parameter_text(v));
  if (integer && (v != std::floor(v) || std::abs(v) > 2147483647.0))
    throw sf::InputError(keyword + ": must be an integer, got " + sf::parameter_text(v));
  return v;
}

void set_filter_option(sf::FilterOptions& o, const sf::Parameter& p, const std::string& keyword, nb::handle value) {
  double v = 0.0;
  try {
    if (p.type == sf::ParameterType::Choice) {
      if (!nb::isinstance<nb::str>(value))
        throw sf::InputError("must be a name, got " + nb::cast<std::string>(nb::repr(value)));
      v = sf::parse_choice(p, nb::cast<std::string>(value));
    } else {
      v = number_of(keyword, value, p.type == sf::ParameterType::Integer);
      sf::check_given_value(p, v);
    }
  } catch (const sf::InputError& e) {
    const std::string what = e.what();
    throw sf::InputError(what.rfind(keyword + ":", 0) == 0 ? what : keyword + ": " + what);
  }
  p.set(o, v);
}

void set_filter_option(sf::FilterOptions& o, const std::string& keyword, nb::handle value) {
  std::string known;
  for (const sf::Parameter* p : sf::declared_parameters()) {
    if (keyword_of(p->flag) == keyword) return set_filter_option(o, *p, keyword, value);
    known += (known.empty() ? "" : ", ") + keyword_of(p->flag);
  }
  throw sf::InputError("unknown option '" + keyword + "' (known: method, " + known + ")");
}

sf::FilterOptions filter_options_of(const std::string& method, const nb::dict& options) {
  sf::FilterOptions o;
  o.method = sf::method(method);
  for (auto [key, value] : options) set_filter_option(o, nb::cast<std::string>(key), value);
  return o;
}

cl::Buffer buffer_of(uintptr_t handle, size_t bytes, const char* name) {
  if (handle == 0) throw sf::InputError(std::string(name) + " is not a buffer");
  cl::Buffer b(reinterpret_cast<cl_mem>(handle), /*retainObject=*/true);
  const size_t size = b.getInfo<CL_MEM_SIZE>();
  if (size < bytes)
    throw sf::InputError(std::string(name) + " holds " + std::to_string(size) + " bytes, " + std::to_string(bytes) +
                         " needed");
  return b;
}

sf::EventList events_of(const std::vector<uintptr_t>& handles) {
  sf::EventList list;
  for (uintptr_t h : handles) list.push_back(cl::Event(reinterpret_cast<cl_event>(h), /*retainObject=*/true));
  return list;
}

uintptr_t handed_over(const cl::Event& e) {
  cl_event raw = e();
  if (raw) clRetainEvent(raw);
  return reinterpret_cast<uintptr_t>(raw);
}

std::shared_ptr<sf::Runtime> runtime_of_queue(uintptr_t context, uintptr_t queue) {
  return std::make_shared<sf::Runtime>(cl::Context(reinterpret_cast<cl_context>(context), true),
                                       cl::CommandQueue(reinterpret_cast<cl_command_queue>(queue), true));
}

}  // namespace sfpy
