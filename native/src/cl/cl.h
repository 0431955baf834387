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
// Whether an error code says the device or its context is gone: what
// drivers return on the calls after a GPU hang, a watchdog reset or a GPU
// lost from the bus (NVIDIA: CL_INVALID_COMMAND_QUEUE after the failing
// call's CL_OUT_OF_RESOURCES). Such a session cannot be used again.
bool cl_error_means_device_lost(cl_int code);
// Whether an error code is one of the out-of-memory family. NVIDIA's and
// Intel's drivers also return CL_OUT_OF_RESOURCES for a kernel that faulted
// or hung the GPU, so after one the session has to be tested before reuse.
bool cl_error_means_out_of_memory(cl_int code);
}  // namespace mp
