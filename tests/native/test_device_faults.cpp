// Device faults mid-frame: an OpenCL out-of-memory or device-lost error in
// any phase of a frame ends that render with an mp::Error that names the
// phase and the OpenCL error, and the same Renderer renders the next frame
// exactly as a clean one. The faults are planted by the session's fault
// injector (native/src/cl/device_faults.h), as a driver would raise them.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "cl/device_faults.h"
#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// A subdivided cube over a floor, lit by a sun that casts shadows: every
// phase of a frame (shadow maps, occlusion culling included) runs.
Scene fault_scene(float cube_x = 0.0f) {
  Scene s = base_scene(160, 120, 4);
  s.camera = look_at({2.5f, 2.0f, 4.0f}, {0, 0, 0});
  Mesh cube = cube_mesh(SubdivScheme::CatmullClark);
  cube.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(cube_x, 0.0f, 0.0f));
  s.meshes.push_back(cube);
  Mesh floor = grid_mesh(2, 4.0f, SubdivScheme::None);
  floor.object_to_world = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(0, -1.2f, 0)),
                                      glm::radians(-90.0f), glm::vec3(1, 0, 0));
  s.meshes.push_back(floor);
  return s;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// One planted fault: the plan, the phase the message must name, and what
// the message must say about the error.
struct Fault {
  const char* plan;
  const char* phase;   // failed_activity path the message carries
  const char* code;    // the OpenCL error's name, or what ran out
  const char* advice;  // the hint that follows it
};

const char* const kOutOfMemory = "the device ran out of memory";
const char* const kHostMemory = "the computer ran out of memory";
const char* const kLost = "the next render reopens the device";
const char* const kNever = "launch:2000000000:CL_OUT_OF_RESOURCES";

class DeviceFaultTest : public SharedRendererTest {
 protected:
  static void SetUpTestSuite() {
    SharedRendererTest::SetUpTestSuite();
    if (renderer_) {
      reference_ = renderer_->render(fault_scene());
      other_ = renderer_->render(fault_scene(0.4f));
    }
  }
  static void TearDownTestSuite() {
    reference_ = other_ = RenderResult{};
    SharedRendererTest::TearDownTestSuite();
  }

  // Renders another scene (so the next one is uploaded anew), plants the
  // fault, checks the failed render's message, then renders again cleanly
  // and compares with the reference bit for bit (the suite's repeated
  // renders are bit-identical: RenderTest.SameSceneRendersBitIdenticallyTwice).
  void fails_then_recovers(const Fault& fault) {
    SCOPED_TRACE(fault.plan);
    const Scene scene = fault_scene();
    RenderResult warm = renderer_->render(fault_scene(0.4f));
    ASSERT_EQ(warm.rgba, other_.rgba);
    renderer_->inject_device_fault(fault.plan);
    std::string message;
    try {
      renderer_->render(scene);
      ADD_FAILURE() << "the planted fault did not fire";
      renderer_->inject_device_fault(kNever);  // so it cannot fire in the next case instead
    } catch (const Error& e) {
      message = e.what();
    }
    EXPECT_TRUE(contains(message, std::string("failed (") + fault.phase + ")")) << message;
    EXPECT_TRUE(contains(message, fault.code)) << message;
    EXPECT_TRUE(contains(message, fault.advice)) << message;
    RenderResult again = renderer_->render(scene);
    EXPECT_FALSE(again.stats.cancelled);
    EXPECT_EQ(again.rgba, reference_.rgba) << message;
    EXPECT_EQ(again.depth, reference_.depth);
    EXPECT_EQ(again.normal, reference_.normal);
    // And once more, now with the scene's buffers reused.
    RenderResult third = renderer_->render(scene);
    EXPECT_TRUE(third.stats.scene_reused);
    EXPECT_EQ(third.rgba, reference_.rgba);
  }

  static inline RenderResult reference_, other_;
};

TEST(DeviceFaultPlan, ParsesKindCountCodeAndPhase) {
  FaultPlan p = parse_fault_plan("launch:40:CL_OUT_OF_RESOURCES");
  EXPECT_EQ(p.op, DeviceOp::Launch);
  EXPECT_EQ(p.nth, 40);
  EXPECT_EQ(p.code, CL_OUT_OF_RESOURCES);
  EXPECT_FALSE(p.lost);
  EXPECT_TRUE(p.activity.empty());
  p = parse_fault_plan("read:2:-36@readback");
  EXPECT_EQ(p.op, DeviceOp::Read);
  EXPECT_EQ(p.code, CL_INVALID_COMMAND_QUEUE);
  EXPECT_TRUE(p.lost) << "CL_INVALID_COMMAND_QUEUE is a lost device";
  EXPECT_EQ(p.activity, "readback");
  p = parse_fault_plan("alloc:1:CL_OUT_OF_RESOURCES:lost@dice");
  EXPECT_EQ(p.op, DeviceOp::Alloc);
  EXPECT_TRUE(p.lost);
  EXPECT_EQ(p.activity, "dice");
  p = parse_fault_plan("alloc:3:host@upload");
  EXPECT_TRUE(p.host);
  EXPECT_FALSE(p.lost);
  EXPECT_EQ(p.nth, 3);
  FaultInjector f;
  f.arm(p);
  EXPECT_NO_THROW(f.hit(DeviceOp::Alloc, "clCreateBuffer", "upload"));
  EXPECT_NO_THROW(f.hit(DeviceOp::Alloc, "clCreateBuffer", "upload"));
  EXPECT_THROW(f.hit(DeviceOp::Alloc, "clCreateBuffer", "upload"), std::bad_alloc);
  for (const char* bad : {"", "launch", "launch:1", "jump:1:CL_OUT_OF_RESOURCES", "launch:0:CL_OUT_OF_RESOURCES",
                          "launch:x:CL_OUT_OF_RESOURCES", "launch:1:CL_NOT_AN_ERROR", "launch:1:5",
                          "launch:1:CL_OUT_OF_RESOURCES:gone", "launch:1:CL_OUT_OF_RESOURCES:lost:x"}) {
    EXPECT_THROW(parse_fault_plan(bad), Error) << bad;
  }
}

TEST(DeviceFaultPlan, FiresOnceOnTheNthOperationOfItsKindInItsPhase) {
  FaultInjector f;
  f.arm(parse_fault_plan("write:2:CL_MEM_OBJECT_ALLOCATION_FAILURE@upload"));
  EXPECT_NO_THROW(f.hit(DeviceOp::Write, "clEnqueueWriteBuffer", "dice"));    // another phase
  EXPECT_NO_THROW(f.hit(DeviceOp::Launch, "clEnqueueNDRangeKernel", "upload"));  // another kind
  EXPECT_NO_THROW(f.hit(DeviceOp::Write, "clEnqueueWriteBuffer", "upload"));  // the first
  try {
    f.hit(DeviceOp::Write, "clEnqueueWriteBuffer", "upload");
    ADD_FAILURE() << "the second write did not fail";
  } catch (const cl::Error& e) {
    EXPECT_EQ(e.err(), CL_MEM_OBJECT_ALLOCATION_FAILURE);
    EXPECT_STREQ(e.what(), "clEnqueueWriteBuffer");
  }
  EXPECT_TRUE(f.fired());
  EXPECT_FALSE(f.armed()) << "a spent one-shot plan is disarmed";
  EXPECT_NO_THROW(f.hit(DeviceOp::Write, "clEnqueueWriteBuffer", "upload"));
}

TEST(DeviceFaultPlan, ALostDeviceFailsEveryLaterOperationUntilReopened) {
  FaultInjector f;
  f.arm(parse_fault_plan("finish:1:CL_INVALID_COMMAND_QUEUE"));
  EXPECT_THROW(f.hit(DeviceOp::Finish, "clFinish", ""), cl::Error);
  EXPECT_THROW(f.hit(DeviceOp::Alloc, "clCreateBuffer", "upload"), cl::Error);
  EXPECT_THROW(f.hit(DeviceOp::Read, "clEnqueueReadBuffer", "readback"), cl::Error);
  FaultInjector reopened = f.reopened();
  EXPECT_FALSE(reopened.armed());
  EXPECT_NO_THROW(reopened.hit(DeviceOp::Finish, "clFinish", ""));
}

// Out of device memory, in each phase of the frame and for each kind of
// operation that phase performs.
TEST_F(DeviceFaultTest, OutOfResourcesInEachPhaseEndsTheFrameAndTheNextFrameIsClean) {
  ASSERT_GT(coverage(reference_), 1000.0);
  const Fault faults[] = {
      {"alloc:1:CL_MEM_OBJECT_ALLOCATION_FAILURE@upload", "upload", "CL_MEM_OBJECT_ALLOCATION_FAILURE", kOutOfMemory},
      {"write:3:CL_OUT_OF_RESOURCES@upload", "upload", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"finish:1:CL_OUT_OF_RESOURCES@upload", "upload", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"launch:1:CL_OUT_OF_RESOURCES@shadows", "shadows", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"write:1:CL_MEM_OBJECT_ALLOCATION_FAILURE@shadows", "shadows", "CL_MEM_OBJECT_ALLOCATION_FAILURE",
       kOutOfMemory},
      {"launch:3:CL_OUT_OF_RESOURCES@bound_split", "shadows/bound_split", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"launch:1:CL_OUT_OF_RESOURCES@sample", "sample", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"launch:1:CL_OUT_OF_RESOURCES@occlusion", "occlusion", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"launch:1:CL_OUT_OF_RESOURCES@resolve", "resolve", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"read:1:CL_OUT_OF_RESOURCES@readback", "readback", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"finish:1:CL_OUT_OF_HOST_MEMORY@readback", "readback", "CL_OUT_OF_HOST_MEMORY", kHostMemory},
  };
  for (const Fault& f : faults) fails_then_recovers(f);
}

// The camera's own bound & split and the batches it hands on: dice, shade
// and sample run inside it. (The lights' views dice inside "shadows", so
// these phases count the camera's batches only. How many batches a frame
// takes depends on the device: CPUs take the first roots in small waves
// for occlusion culling, GPUs in one batch here, so the positions below are
// ones every device reaches.)
// Host memory (std::bad_alloc) in each phase: the message names the phase
// and what would help there, never a bare "std::bad_alloc"; the next frame
// is clean.
TEST_F(DeviceFaultTest, OutOfHostMemoryInEachPhaseIsAMessageAndTheNextFrameIsClean) {
  const char* const host = "the computer ran out of host memory";
  const Fault faults[] = {
      {"alloc:1:host@upload", "upload", host, "subdivision levels"},
      {"launch:1:host@shadows", "shadows", host, "shadow memory budget"},
      {"launch:2:host@sample", "bound_split/sample", host, "bound & split memory"},
      {"launch:1:host@resolve", "resolve", host, "lower the resolution"},
      {"read:1:host@readback", "readback", host, "Depth and Normal passes"},
  };
  for (const Fault& f : faults) fails_then_recovers(f);
}

TEST_F(DeviceFaultTest, OutOfResourcesInsideTheCamerasBatchesEndsTheFrame) {
  const Fault faults[] = {
      {"launch:1:CL_OUT_OF_RESOURCES@dice", "bound_split/dice", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"read:1:CL_MEM_OBJECT_ALLOCATION_FAILURE@dice", "bound_split/dice", "CL_MEM_OBJECT_ALLOCATION_FAILURE",
       kOutOfMemory},
      {"launch:1:CL_OUT_OF_RESOURCES@shade", "bound_split/shade", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"launch:2:CL_OUT_OF_RESOURCES@sample", "bound_split/sample", "CL_OUT_OF_RESOURCES", kOutOfMemory},
      {"write:1:CL_OUT_OF_HOST_MEMORY@sample", "sample", "CL_OUT_OF_HOST_MEMORY", kHostMemory},
  };
  for (const Fault& f : faults) fails_then_recovers(f);
}

// A lost device (a GPU reset by its driver or gone from the bus): every
// later call on its context fails, so the renderer must open the device
// anew for the next frame.
TEST_F(DeviceFaultTest, ALostDeviceIsReopenedForTheNextFrame) {
  const Fault faults[] = {
      {"launch:1:CL_INVALID_COMMAND_QUEUE@dice", "bound_split/dice", "CL_INVALID_COMMAND_QUEUE", kLost},
      {"finish:1:CL_DEVICE_NOT_AVAILABLE@readback", "readback", "CL_DEVICE_NOT_AVAILABLE", kLost},
      {"alloc:2:CL_INVALID_CONTEXT@upload", "upload", "CL_INVALID_CONTEXT", kLost},
      {"launch:1:CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST@shadows", "shadows",
       "CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST", kLost},
  };
  for (const Fault& f : faults) fails_then_recovers(f);
}

// NVIDIA's driver reports a kernel that faulted the GPU as
// CL_OUT_OF_RESOURCES and everything after it as failed: the renderer
// cannot tell it from running out of memory until it asks the device again.
TEST_F(DeviceFaultTest, OutOfResourcesThatKilledTheContextIsFoundAndTheDeviceReopened) {
  fails_then_recovers({"launch:1:CL_OUT_OF_RESOURCES:lost@shade", "bound_split/shade", "CL_OUT_OF_RESOURCES",
                       kOutOfMemory});
  fails_then_recovers({"read:1:CL_OUT_OF_RESOURCES:lost@readback", "readback", "CL_OUT_OF_RESOURCES", kOutOfMemory});
}

// Both bound & split methods and a progress callback (which adds finishes
// between chunks) recover the same way.
TEST_F(DeviceFaultTest, BreadthFirstAndProgressiveFramesRecoverToo) {
  Scene breadth = fault_scene();
  breadth.settings.bound_split = BoundSplitMethod::Breadth;
  const RenderResult clean = renderer_->render(breadth);
  renderer_->inject_device_fault("launch:2:CL_OUT_OF_RESOURCES@bound_split");
  EXPECT_THROW(renderer_->render(breadth), Error);
  EXPECT_EQ(renderer_->render(breadth).rgba, clean.rgba);

  int calls = 0;
  ProgressCallback progress = [&](float) { return ++calls > 0; };
  const RenderResult clean_progressive = renderer_->render(fault_scene(), progress);
  EXPECT_EQ(clean_progressive.rgba, reference_.rgba);
  renderer_->inject_device_fault("finish:3:CL_OUT_OF_RESOURCES@sample");
  EXPECT_THROW(renderer_->render(fault_scene(), progress), Error);
  EXPECT_EQ(renderer_->render(fault_scene(), progress).rgba, reference_.rgba);
}

// Setting the stages up again after a failed frame can fail too (their
// constant buffers are allocated then); the frame after that still renders.
TEST_F(DeviceFaultTest, AFaultWhileSettingUpTheStagesEndsTheFrame) {
  renderer_->inject_device_fault("launch:1:CL_OUT_OF_RESOURCES@resolve");
  EXPECT_THROW(renderer_->render(fault_scene()), Error);
  renderer_->inject_device_fault("alloc:1:CL_MEM_OBJECT_ALLOCATION_FAILURE@setup");
  try {
    renderer_->render(fault_scene());
    ADD_FAILURE() << "the planted fault did not fire";
  } catch (const Error& e) {
    EXPECT_TRUE(contains(e.what(), "failed (setup): clCreateBuffer failed: CL_MEM_OBJECT_ALLOCATION_FAILURE"))
        << e.what();
  }
  EXPECT_EQ(renderer_->render(fault_scene()).rgba, reference_.rgba);
}

TEST_F(DeviceFaultTest, AMalformedPlanIsAClearError) {
  try {
    renderer_->inject_device_fault("launch:1:CL_NO_SUCH_ERROR");
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_TRUE(contains(e.what(), "CL_NO_SUCH_ERROR")) << e.what();
  }
  EXPECT_EQ(renderer_->render(fault_scene()).rgba, reference_.rgba);
}

// The CLI as shipped, armed by MICROPOLY_CL_FAULT: a non-zero exit, the
// message on stderr, no crash.
TEST(DeviceFaultCli, AFaultMidFrameExitsWithTheMessage) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("micropoly-faults-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string out = (dir / "out.png").string(), log = (dir / "log.txt").string();
  const std::string command = std::string("MICROPOLY_CL_FAULT='launch:1:CL_OUT_OF_RESOURCES@shade' '") + MICROPOLY_CLI +
                              "' '" + MICROPOLY_TEST_SCENES + "/teapot.rib' -o '" + out +
                              "' --spp 1 > '" + log + "' 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << "the CLI did not exit normally (signal?)";
  EXPECT_NE(WEXITSTATUS(status), 0);
  std::string text;
  if (FILE* f = std::fopen(log.c_str(), "r")) {
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
    std::fclose(f);
  }
  EXPECT_TRUE(contains(text, "(bound_split/shade)")) << text;
  EXPECT_TRUE(contains(text, "CL_OUT_OF_RESOURCES")) << text;
  EXPECT_FALSE(fs::exists(out)) << "no image from a failed frame";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mp::test
