// What a kernel build error names besides the device: for a CPU device, the
// processor and what its OpenCL compiler built for (PoCL picks a target from
// the CPU's features, docs/install.md), so a report from a machine the
// compiler does not know says which machine and what was tried.
#pragma once

#include <string>

#include "cl/cl.h"

namespace mp {

// "model name" of the first processor in /proc/cpuinfo's text, or "".
std::string cpu_model_name(const std::string& cpuinfo);

// The target a PoCL CPU device compiles for, from its CL_DEVICE_VERSION
// ("OpenCL 3.0 PoCL HSTR: pthread-x86_64-pc-linux-gnu-haswell" -> "haswell"),
// or "".
std::string pocl_target(const std::string& device_version);

// "CPU 'AMD EPYC 9654', PoCL 3.1+debian (LLVM 15.0.6) compiling for
// skylake-avx512" for a CPU device; the driver version for other devices.
std::string build_context(const cl::Device& device);

}  // namespace mp
