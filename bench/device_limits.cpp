// The limits a frame's time is measured against on one OpenCL device: what a
// host round trip costs, how fast launches can follow one another, and the
// bandwidth of read-back and of the device's own memory
// (docs/performance.md, "Host waits and kernel launches").
//
//   device_limits [--device cpu|gpu|NAME] [--json FILE]
//
// Each figure is the median of repeated trials after a warm-up:
//   round_trip_us       one empty kernel (one work-item) enqueued, then clFinish
//   read_round_trip_us  a blocking read of 4 bytes after an empty kernel
//   launch_us           one of 1000 empty kernels enqueued back to back, one
//                       clFinish at the end (what a launch costs when the
//                       host never waits)
//   enqueue_us          of that, the host's own time in clEnqueueNDRangeKernel
//   launch_20_buffers_us, enqueue_20_buffers_us  the same two for a kernel
//                       of 20 buffer arguments
//   read_pinned_gbs     32 MiB read into host memory the driver pinned
//                       (CL_MEM_ALLOC_HOST_PTR, mapped)
//   read_pageable_gbs   32 MiB read into ordinary host memory
//   copy_gbs            256 MiB copied device to device (read + write bytes)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "cl/device_session.h"

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <typename F>
double median_us(int trials, F&& f) {
  std::vector<double> t;
  for (int i = 0; i < trials + 3; ++i) {
    const auto start = Clock::now();
    f();
    const double us = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
    if (i >= 3) t.push_back(us);  // the first trials warm the driver up
  }
  return median(t);
}

}  // namespace

int main(int argc, char** argv) {
  std::string device, json;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--device")) device = argv[i + 1];
    if (!std::strcmp(argv[i], "--json")) json = argv[i + 1];
  }
  try {
    mp::DeviceSession session(device);
    mp::DeviceQueue& q = session.queue();
    cl::Program program(session.context(), "__kernel void nothing(__global uint* x) { if (x[0] == 7u) x[0] = 8u; }");
    program.build({session.device()});
    cl::Kernel nothing(program, "nothing");
    cl::Buffer word = session.allocate(16, "device_limits word");
    nothing.setArg(0, word);
    auto launch = [&] { q.enqueueNDRangeKernel(nothing, cl::NullRange, cl::NDRange(1), cl::NullRange); };


    const double round_trip = median_us(200, [&] {
      launch();
      q.finish();
    });
    cl_uint back = 0;
    const double read_round_trip = median_us(200, [&] {
      launch();
      q.enqueueReadBuffer(word, CL_TRUE, 0, sizeof back, &back);
    });
    // 1,000 launches of `kernel` back to back, one clFinish at the end:
    // microseconds per launch in all, and of the host's enqueue alone.
    auto launches_us = [&](const cl::Kernel& kernel, double& enqueue_us) {
      const int kLaunches = 1000;
      std::vector<double> enqueue;
      const double all = median_us(5, [&] {
        const auto start = Clock::now();
        for (int i = 0; i < kLaunches; ++i)
          q.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(1), cl::NullRange);
        enqueue.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
        q.finish();
      });
      enqueue.erase(enqueue.begin(), enqueue.begin() + 3);  // median_us's warm-up trials
      enqueue_us = median(enqueue) / kLaunches;
      return all / kLaunches;
    };
    double enqueue_us = 0, wide_enqueue_us = 0;
    const double launch_us = launches_us(nothing, enqueue_us);
    // The same with 20 buffer arguments (the scene's kernel data is about
    // that many buffers, bound to every kernel that reads the scene).
    std::string wide_source = "__kernel void wide(";
    for (int a = 0; a < 20; ++a) wide_source += (a ? ", " : "") + std::string("__global uint* b") + std::to_string(a);
    wide_source += ") { if (b0[0] == 7u) b19[0] = 8u; }";
    cl::Program wide_program(session.context(), wide_source);
    wide_program.build({session.device()});
    cl::Kernel wide(wide_program, "wide");
    for (cl_uint a = 0; a < 20; ++a) wide.setArg(a, word);
    const double launch_wide_us = launches_us(wide, wide_enqueue_us);

    const size_t read_bytes = size_t(32) << 20;
    cl::Buffer image = session.allocate(read_bytes, "device_limits image");
    q.enqueueFillBuffer(image, cl_uint(0), 0, read_bytes);
    cl::Buffer pinned = session.allocate(read_bytes, "device_limits pinned", CL_MEM_READ_WRITE | CL_MEM_ALLOC_HOST_PTR);
    void* pinned_ptr = q.enqueueMapBuffer(pinned, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, read_bytes);
    std::vector<unsigned char> pageable(read_bytes, 1);
    const double pinned_us = median_us(20, [&] { q.enqueueReadBuffer(image, CL_TRUE, 0, read_bytes, pinned_ptr); });
    const double pageable_us =
        median_us(20, [&] { q.enqueueReadBuffer(image, CL_TRUE, 0, read_bytes, pageable.data()); });
    q.enqueueUnmapMemObject(pinned, pinned_ptr);

    const size_t copy_bytes = size_t(256) << 20;
    cl::Buffer from = session.allocate(copy_bytes, "device_limits copy source");
    cl::Buffer to = session.allocate(copy_bytes, "device_limits copy target");
    q.enqueueFillBuffer(from, cl_uint(0), 0, copy_bytes);
    const double copy_us = median_us(10, [&] {
      q.enqueueCopyBuffer(from, to, 0, 0, copy_bytes);
      q.finish();
    });
    q.finish();

    auto gbs = [](size_t bytes, double us) { return double(bytes) / (us * 1e3); };
    char text[1024];
    std::snprintf(text, sizeof text,
                  "{\"device\": \"%s\", \"round_trip_us\": %.2f, \"read_round_trip_us\": %.2f, \"launch_us\": %.3f, "
                  "\"enqueue_us\": %.3f, \"launch_20_buffers_us\": %.3f, \"enqueue_20_buffers_us\": %.3f, "
                  "\"read_pinned_gbs\": %.2f, \"read_pageable_gbs\": %.2f, \"copy_gbs\": %.1f}\n",
                  session.info().name.c_str(), round_trip, read_round_trip, launch_us, enqueue_us, launch_wide_us, wide_enqueue_us,
                  gbs(read_bytes, pinned_us), gbs(read_bytes, pageable_us), gbs(2 * copy_bytes, copy_us));
    std::fputs(text, stdout);
    if (!json.empty()) std::ofstream(json) << text;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "device_limits: %s\n", e.what());
    return 1;
  }
  return 0;
}
