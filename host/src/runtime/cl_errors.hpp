#pragma once
// The library's boundary for OpenCL errors: every public entry point that calls OpenCL ends in
//   } catch (const cl::Error& e) { detail::throw_device_error("enqueue_blur", e); }
// (a function-try-block), so no cl::Error reaches a caller, whose code may be compiled without
// CL_HPP_ENABLE_EXCEPTIONS (opencl.hpp); it gets sf::DeviceError naming the entry point, the
// OpenCL call and the error code.
#include "shadowfilter/errors.hpp"
#include "shadowfilter/opencl.hpp"

namespace sf::detail {

// "CL_OUT_OF_RESOURCES" for -5, "OpenCL error N" for codes it does not know.
std::string cl_error_name(cl_int code);

[[noreturn]] void throw_device_error(const char* entry_point, const cl::Error& e);

}  // namespace sf::detail
