#pragma once
// The OpenCL C++ bindings as shadowfilter's headers include them.
//
// The library itself is compiled with CL_HPP_TARGET_OPENCL_VERSION=120,
// CL_HPP_MINIMUM_OPENCL_VERSION=120 and CL_HPP_ENABLE_EXCEPTIONS; none of them is imposed on a
// consumer. Its headers need only what OpenCL 1.2 offers (sub-buffers, markers with wait lists),
// so a consumer may target any version >= 1.2: whatever it defined before this point stands, and
// 1.2 is filled in where it defined no target. No cl::Error leaves the library (errors.hpp), so a
// consumer may compile with or without CL_HPP_ENABLE_EXCEPTIONS; see docs/embedding.md for the
// one rule that follows from linking the static library (opencl.hpp's inline functions).
// The minimum version is filled in only with the target: opencl.hpp 2.x does not compile a
// target >= 2.0 with a minimum below 2.0, and picks the minimum itself for a given target.
#ifndef CL_HPP_TARGET_OPENCL_VERSION
#define CL_HPP_TARGET_OPENCL_VERSION 120
#ifndef CL_HPP_MINIMUM_OPENCL_VERSION
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#endif
#endif
#if CL_HPP_TARGET_OPENCL_VERSION < 120
#error "shadowfilter needs CL_HPP_TARGET_OPENCL_VERSION >= 120"
#endif
#include <CL/opencl.hpp>
