// The counts of the host's waits on the device and of kernel launches
// (native/src/cl/queue_counts.h): what the device queue counts, by phase,
// and what a frame reports.
#include <gtest/gtest.h>

#include <numeric>

#include "cl/device_session.h"
#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

TEST(QueueCounts, CountsByPhasePathMostFirst) {
  PhaseCounts w;
  const char* outer = "shadows";
  const char* inner = "dice";
  w.note({outer, inner});
  w.note({outer});
  w.note({outer, inner});
  w.note({});
  EXPECT_EQ(w.total(), 4u);
  const auto phases = w.by_phase();
  ASSERT_EQ(phases.size(), 3u);
  EXPECT_EQ(phases[0], (std::pair<std::string, size_t>{"shadows/dice", 2}));
  EXPECT_EQ(w.by_phase().back().second, 1u);
  w.reset();
  EXPECT_EQ(w.total(), 0u);
  EXPECT_TRUE(w.by_phase().empty());
}

TEST(QueueCounts, TheQueueCountsLaunchesAndWhatHoldsTheHostAndNothingElse) {
  DeviceSession session("");
  QueueCounts& counts = session.queue_counts();
  counts.reset();
  cl::Program program(session.context(), "__kernel void nothing(__global uint* x) { if (x[0] == 7u) x[0] = 8u; }");
  program.build({session.device()});
  cl::Kernel nothing(program, "nothing");
  cl::Buffer buffer = session.allocate(64, "test buffer");
  cl_uint sent[4] = {1u, 2u, 3u, 4u}, back[4] = {};
  {
    DeviceSession::Activity outer(session, "upload");
    DeviceSession::Activity inner(session, "probe");
    nothing.setArg(0, buffer);
    session.queue().enqueueNDRangeKernel(nothing, cl::NullRange, cl::NDRange(1), cl::NullRange);  // a launch
    session.queue().enqueueWriteBuffer(buffer, CL_FALSE, 0, sizeof sent, sent);  // not a wait
    cl::Event read;
    session.queue().enqueueReadBuffer(buffer, CL_FALSE, 0, sizeof back, back, nullptr, &read);  // not a wait
    session.queue().wait(read);                                                                  // a wait
    session.queue().enqueueReadBuffer(buffer, CL_TRUE, 0, sizeof back, back);                   // a wait
  }
  session.queue().finish();  // a wait outside any phase
  EXPECT_EQ(back[3], 4u);
  EXPECT_EQ(counts.waits.total(), 3u);
  const auto phases = counts.waits.by_phase();
  ASSERT_EQ(phases.size(), 2u);
  EXPECT_EQ(phases[0], (std::pair<std::string, size_t>{"upload/probe", 2}));
  EXPECT_EQ(phases[1], (std::pair<std::string, size_t>{"(no phase)", 1}));
  ASSERT_EQ(counts.launches.by_phase().size(), 1u);
  EXPECT_EQ(counts.launches.by_phase()[0], (std::pair<std::string, size_t>{"upload/probe", 1}));
}

using FrameQueueCounts = SharedRendererTest;

TEST_F(FrameQueueCounts, AFrameReportsItsWaitsAndLaunchesByPhaseAndStartsFromNone) {
  Scene s = base_scene(160, 120, 4);
  s.camera = look_at({2.5f, 2.0f, 4.0f}, {0, 0, 0});
  s.meshes.push_back(grid_mesh(6, 4.0f, SubdivScheme::CatmullClark));
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  s.settings.shadows = true;
  // Auto would choose by measured kernel times, and with it how many passes
  // (and waits) a frame takes.
  s.settings.visibility_first = VisibilityFirst::Off;
  RenderResult first, second;
  renderer_->render(s, first);
  renderer_->render(s, second);
  for (const RenderResult* r : {&first, &second}) {
    const RenderStats& st = r->stats;
    // At least the read-back of the image holds the host.
    EXPECT_GE(st.host_waits, 1u);
    size_t sum = 0;
    bool readback = false;
    for (const auto& [phase, count] : st.host_waits_by_phase) {
      sum += count;
      readback = readback || phase == "readback";
    }
    EXPECT_EQ(sum, st.host_waits);
    EXPECT_TRUE(readback);
    EXPECT_NE(st.to_json().find("\"host_waits\": " + std::to_string(st.host_waits)), std::string::npos);
    // Every stage launches: at least bound & split, dicing, shading,
    // sampling and the resolve, each in its phase.
    size_t launched = 0;
    for (const auto& [phase, count] : st.kernel_launches_by_phase) launched += count;
    EXPECT_EQ(launched, st.kernel_launches);
    EXPECT_GE(st.kernel_launches_by_phase.size(), 3u);
    EXPECT_GE(st.kernel_launches, st.bound_split_launches + 4u);
  }
  // Each frame counts its own: the second's are not added to the first's.
  EXPECT_LE(second.stats.host_waits, first.stats.host_waits);
  EXPECT_LE(second.stats.kernel_launches, first.stats.kernel_launches);
}

}  // namespace
}  // namespace mp::test
