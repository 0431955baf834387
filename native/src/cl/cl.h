// One place that configures the Khronos C++ bindings (RAII handles for every
// OpenCL object, errors as exceptions) for OpenCL 1.2 devices.
#pragma once

#define CL_HPP_TARGET_OPENCL_VERSION 120
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#define CL_HPP_ENABLE_EXCEPTIONS
#include <CL/opencl.hpp>

#include <string>

namespace mp {
// Human-readable name of an OpenCL error code.
const char* cl_error_name(cl_int code);
// Turns a cl::Error into a one-line message (with an out-of-memory hint).
std::string describe_cl_error(const cl::Error& e);
}  // namespace mp
