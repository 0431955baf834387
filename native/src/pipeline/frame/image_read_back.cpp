#include "pipeline/frame/image_read_back.h"

#include <algorithm>
#include <cstring>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "cl/kernel_args.h"
#include "io/half_floats.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/pass/micropolygon_stages.h"


namespace mp {
namespace {

double ms_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// `work(first, count)` over [0, n) on a few threads: one core copies a
// 1080p float image out of pinned memory in about 3 ms.
void in_parallel(size_t n, size_t bytes_each, const std::function<void(size_t, size_t)>& work) {
  const size_t min_bytes = size_t(4) << 20;
  const size_t threads =
      std::min<size_t>({std::max(1u, std::thread::hardware_concurrency()), 8, n * bytes_each / min_bytes});
  if (threads <= 1) {
    work(0, n);
    return;
  }
  const size_t chunk = (n / threads + 63) & ~size_t(63);
  std::vector<std::thread> pool;
  for (size_t t = 1; t < threads && t * chunk < n; ++t)
    pool.emplace_back([&, t] { work(t * chunk, std::min(chunk, n - t * chunk)); });
  work(0, std::min(chunk, n));
  for (auto& th : pool) th.join();
}

}  // namespace

ImageReadBack::ImageReadBack(DeviceSession& session)
    : session_(session), to_half_(session.program(), "image_to_half") {
  use_pinned_ = !session.device().getInfo<CL_DEVICE_HOST_UNIFIED_MEMORY>();
}

ImageReadBack::~ImageReadBack() {
  if (worker_.joinable()) worker_.join();
  if (pinned_ptr_) {
    try {
      session_.queue().enqueueUnmapMemObject(pinned_, pinned_ptr_);
      session_.queue().finish();
    } catch (const cl::Error&) {
      // The context goes away with the session; nothing else to release.
    }
  }
}

void ImageReadBack::before_resolve() {
  if (!transferred_()) return;
  const std::vector<cl::Event> transferred{transferred_};
  session_.queue().enqueueBarrierWithWaitList(&transferred);
  transferred_ = cl::Event();
}

void ImageReadBack::start(const ResolveStage& resolve, const FrameSetup& frame, bool passes, ReadBack format,
                          RenderResult& out) {
  finish();
  const FrameParams& f = frame.params;
  const size_t pixels = static_cast<size_t>(f.width) * static_cast<size_t>(f.height);
  out.width = f.width;
  out.height = f.height;
  // Only the passes asked for: Depth with `passes`, Normal with them where
  // the samples kept normals (RenderSettings::normal_pass).
  const bool normals = passes && f.normal_pass;
  const bool half = format == ReadBack::Half;
  out.rgba.resize(pixels * 4);
  out.depth.resize(passes ? pixels : 0);
  out.normal.resize(normals ? pixels * 3 : 0);
  DeviceQueue& q = session_.queue();
  DeviceQueue& t = session_.transfer_queue();
  if (half) {
    session_.reserve(half_, half_bytes_, pixels * 4 * sizeof(uint16_t), "half-float image buffer");
    bind_args(to_half_, resolve.image(), half_, cl_uint(pixels));
    q.enqueueNDRangeKernel(to_half_, cl::NullRange, cl::NDRange((pixels + 63) / 64 * 64), cl::NDRange(64));
  }
  struct Part {
    const cl::Buffer& buffer;
    size_t bytes;      // on the device
    float* host;       // where it lands
    bool halves;       // halves to widen into floats
  };
  const Part parts[] = {
      {half ? half_ : resolve.image(), out.rgba.size() * (half ? sizeof(uint16_t) : sizeof(float)), out.rgba.data(),
       half},
      {resolve.depth(), out.depth.size() * sizeof(float), out.depth.data(), false},
      {resolve.normal(), out.normal.size() * sizeof(float), out.normal.data(), false}};
  // The main queue's work so far (the resolve, the world laid behind, the
  // halves) before the transfers; flushed, so the transfer queue's wait on
  // it can end.
  cl::Event resolved;
  q.enqueueMarkerWithWaitList(nullptr, &resolved);
  q.flush();
  const std::vector<cl::Event> after{resolved};
  const bool staged = use_pinned_ || half;
  size_t total = 0;
  for (const Part& p : parts) total += p.bytes;
  // Grown to the frame, and made again where it holds more than four times
  // what a frame needs (a viewport shrunk, or half floats after floats), so
  // page-locked host memory follows the frames being read.
  if (staged && (pinned_bytes_ < total || total < pinned_bytes_ / 4)) {
    if (pinned_ptr_) q.enqueueUnmapMemObject(pinned_, pinned_ptr_);
    pinned_ptr_ = nullptr;
    pinned_bytes_ = 0;
    pinned_ = cl::Buffer();
    pinned_ = session_.allocate(total, "image readback buffer", CL_MEM_READ_WRITE | CL_MEM_ALLOC_HOST_PTR);
    pinned_ptr_ = q.enqueueMapBuffer(pinned_, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, total);
    pinned_bytes_ = total;
  }
  std::vector<cl::Event> reads;
  size_t at = 0;
  for (const Part& p : parts) {
    if (!p.bytes) continue;
    reads.emplace_back();
    void* to = staged ? static_cast<void*>(static_cast<char*>(pinned_ptr_) + at) : static_cast<void*>(p.host);
    t.enqueueReadBuffer(p.buffer, CL_FALSE, 0, p.bytes, to, &after, &reads.back());
    at += p.bytes;
  }
  t.enqueueMarkerWithWaitList(&reads, &transferred_);
  t.flush();
  out_ = &out;
  started_ = std::chrono::steady_clock::now();
  failed_ = nullptr;
  // The worker: waits for the transfers, then lands the staged parts.
  std::vector<Part> landing;
  for (const Part& p : parts)
    if (p.bytes) landing.push_back(p);
  worker_ = std::thread([this, landing, staged, done = transferred_] {
    try {
      done.wait();
      if (staged) {
        const char* from = static_cast<const char*>(pinned_ptr_);
        for (const Part& p : landing) {
          if (p.halves) {
            const uint16_t* in = reinterpret_cast<const uint16_t*>(from);
            in_parallel(p.bytes / sizeof(uint16_t), sizeof(float),
                        [&](size_t first, size_t n) { halves_to_floats(in + first, p.host + first, n); });
          } else {
            const float* in = reinterpret_cast<const float*>(from);
            in_parallel(p.bytes / sizeof(float), sizeof(float), [&](size_t first, size_t n) {
              std::memcpy(p.host + first, in + first, n * sizeof(float));
            });
          }
          from += p.bytes;
        }
      }
      out_->stats.timings_ms.readback += ms_between(started_, std::chrono::steady_clock::now());
    } catch (...) {
      failed_ = std::current_exception();
    }
  });
}

void ImageReadBack::finish() {
  if (!out_) return;
  const auto waiting = std::chrono::steady_clock::now();
  worker_.join();
  RenderResult& out = *out_;
  out_ = nullptr;
  // Nothing is left on the transfer queue once its marker is done; this
  // also lets a planted fault (device_faults.h) fail the read-back here.
  session_.transfer_queue().finish();
  out.stats.timings_ms.readback_wait += ms_between(waiting, std::chrono::steady_clock::now());
  if (failed_) std::rethrow_exception(std::exchange(failed_, nullptr));
}

}  // namespace mp
