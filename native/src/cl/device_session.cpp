#include "cl/device_session.h"

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <iterator>
#include <mutex>

#include "cl/program_cache.h"
#include "micropoly/error.h"

namespace mp {
namespace {

struct FoundDevice {
  DeviceInfo info;
  cl::Device device;
};

std::vector<FoundDevice> enumerate() {
  // The ICD loader and drivers load their platforms on the first call; two
  // threads making that call together can see no platforms at all (the
  // add-on lists devices on a background thread while a render may start).
  // One lock for the process serialises discovery; it guards no data.
  static std::mutex discovery;
  std::lock_guard<std::mutex> lock(discovery);
  std::vector<FoundDevice> out;
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return out;  // no ICD loader platforms at all
  }
  for (auto& platform : platforms) {
    std::vector<cl::Device> devices;
    try {
      platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;
    }
    for (auto& d : devices) {
      FoundDevice f;
      f.device = d;
      f.info.index = static_cast<int>(out.size());
      f.info.name = d.getInfo<CL_DEVICE_NAME>();
      f.info.platform = platform.getInfo<CL_PLATFORM_NAME>();
      f.info.version = d.getInfo<CL_DEVICE_VERSION>();
      auto type = d.getInfo<CL_DEVICE_TYPE>();
      f.info.type = (type & CL_DEVICE_TYPE_GPU) ? "gpu" : (type & CL_DEVICE_TYPE_CPU) ? "cpu" : "other";
      out.push_back(f);
    }
  }
  return out;
}

FoundDevice choose(const std::string& requested) {
  std::string selector = requested;
  if (selector.empty())
    if (const char* env = std::getenv("MICROPOLY_DEVICE"); env && *env) selector = env;
  auto devices = enumerate();
  if (devices.empty())
    throw Error("no OpenCL device found: install an OpenCL driver (e.g. Debian's pocl-opencl-icd for the CPU)");
  auto first_of = [&](const std::string& type) -> const FoundDevice* {
    for (auto& d : devices)
      if (d.info.type == type) return &d;
    return nullptr;
  };
  if (selector.empty()) {
    if (auto* gpu = first_of("gpu")) return *gpu;
    if (auto* cpu = first_of("cpu")) return *cpu;
    return devices.front();
  }
  if (selector == "gpu" || selector == "cpu") {
    if (auto* d = first_of(selector)) return *d;
    throw Error("no OpenCL " + selector + " device found (" + std::to_string(devices.size()) +
                " device(s) present; see --list-devices)");
  }
  char* end = nullptr;
  long index = std::strtol(selector.c_str(), &end, 10);
  if (end && *end == '\0' && !selector.empty()) {
    if (index >= 0 && index < static_cast<long>(devices.size())) return devices[static_cast<size_t>(index)];
    throw Error("OpenCL device index " + selector + " out of range (" + std::to_string(devices.size()) +
                " device(s) present)");
  }
  throw Error("unknown device '" + selector + "': use cpu, gpu or a device index");
}

}  // namespace

bool compiles_tile_sampler(const std::string& platform_version) {
  // PoCL names its LLVM in the platform version: "OpenCL 3.0 PoCL 3.0-rc2
  // Linux, Release, RELOC, LLVM 14.0.6, ...".
  if (platform_version.find("PoCL") == std::string::npos) return true;
  const size_t at = platform_version.find("LLVM ");
  if (at == std::string::npos) return true;
  return std::atoi(platform_version.c_str() + at + 5) >= 15;
}

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (auto& d : enumerate()) out.push_back(d.info);
  return out;
}

DeviceSession::DeviceSession(const std::string& selector) {
  if (const char* plan = std::getenv("MICROPOLY_CL_FAULT"); plan && *plan) faults_.arm(parse_fault_plan(plan));
  open(selector);
}

DeviceSession::DeviceSession(const std::string& selector, const FaultInjector& faults) : faults_(faults) {
  open(selector);
}

void DeviceSession::open(const std::string& selector) {
  FoundDevice found = choose(selector);
  info_ = found.info;
  device_ = found.device;
  try {
    auto ext = device_.getInfo<CL_DEVICE_EXTENSIONS>();
    if (ext.find("cl_khr_int64_extended_atomics") == std::string::npos)
      throw Error("OpenCL device '" + info_.name + "' lacks cl_khr_int64_extended_atomics, which the rasteriser needs");
    context_ = cl::Context(device_);
    queue_ = DeviceQueue(cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE), faults_, activities_,
                         queue_counts_);
    transfer_queue_ = DeviceQueue(cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE), faults_,
                                  activities_, queue_counts_);
    max_alloc_ = device_.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
    tile_sampler_ = compiles_tile_sampler(cl::Platform(device_.getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_VERSION>());
    // Occlusion culling's planes (kernels/geometry/mp_bound.h) where the
    // roots are taken in waves: on CPU devices.
    std::string options = "-cl-std=CL1.2";
    if (!tile_sampler_) options += " -DMP_NO_TILE_SAMPLER";
    if (info_.type == "cpu") options += " -DMP_OCCLUSION_PLANES";
    auto built = build_program_cached(context_, device_, assemble_program_source(), options);
    program_ = built.program;
    build_ms_ = built.build_ms;
    cache_hit_ = built.from_cache;
  } catch (const cl::Error& e) {
    throw Error("OpenCL device '" + info_.name + "': " + describe_cl_error(e));
  }
}

cl::Buffer DeviceSession::allocate(size_t bytes, const char* what, cl_mem_flags flags) {
  if (bytes > max_alloc_)
    throw Error(std::string("the ") + what + " needs " + std::to_string(bytes >> 20) + " MiB in one buffer but the device '" +
                info_.name + "' allows " + std::to_string(max_alloc_ >> 20) +
                " MiB: lower the resolution or the samples per pixel");
  if (faults_.armed()) faults_.hit(DeviceOp::Alloc, "clCreateBuffer", activities_.empty() ? "" : activities_.back());
  return cl::Buffer(context_, flags, std::max<size_t>(bytes, 16));
}

void DeviceSession::reserve(cl::Buffer& buffer, size_t& capacity, size_t bytes, const char* what) {
  if (bytes <= capacity && capacity > 0) return;
  // Released first, and the capacity forgotten until the new one exists:
  // a failed allocation must not leave a capacity that an empty buffer
  // seems to have.
  buffer = cl::Buffer();
  capacity = 0;
  buffer = allocate(bytes, what);
  capacity = std::max<size_t>(bytes, 16);
}

DeviceSession::Activity::Activity(DeviceSession& session, const char* name)
    : session_(session), uncaught_(std::uncaught_exceptions()) {
  session.activities_.push_back(name);
}

DeviceSession::Activity::~Activity() {
  // Innermost first: the first phase an exception leaves is where it arose.
  if (std::uncaught_exceptions() > uncaught_ && session_.failed_activity_.empty()) {
    for (const char* name : session_.activities_) {
      if (!session_.failed_activity_.empty()) session_.failed_activity_ += '/';
      session_.failed_activity_ += name;
    }
  }
  session_.activities_.pop_back();
}

bool DeviceSession::responds() {
  try {
    const cl_uint sent[4] = {0x9e3779b9u, 1u, 2u, 3u};
    cl_uint back[4] = {};
    cl::Buffer probe = allocate(sizeof sent, "device probe");
    queue_.enqueueWriteBuffer(probe, CL_TRUE, 0, sizeof sent, sent);
    queue_.enqueueReadBuffer(probe, CL_TRUE, 0, sizeof back, back);
    queue_.finish();
    return std::equal(std::begin(sent), std::end(sent), std::begin(back));
  } catch (const cl::Error&) {
    return false;
  }
}

}  // namespace mp
