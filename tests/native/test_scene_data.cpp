// The scene's device data named once (kernels/core/mp_scene_data.h): every
// kernel that reads the scene takes the whole list first, in its order, and
// a SceneKernel binds it again exactly when the buffers it holds are no
// longer the scene's.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cl/device_session.h"
#include "cl/program_cache.h"
#include "pipeline/device_scene/scene_kernel.h"

namespace mp {
namespace {

std::vector<std::string> scene_data_names() {
  std::vector<std::string> names;
#define MP_NAME_OF_ENTRY(type, name) names.push_back(#name);
  MP_SCENE_DATA(MP_NAME_OF_ENTRY, MP_NAME_OF_ENTRY)
#undef MP_NAME_OF_ENTRY
  return names;
}

// A kernel's argument names, from the program the session built (PoCL keeps
// them; a driver that keeps none without -cl-kernel-arg-info builds the
// source again with it).
std::vector<std::vector<std::string>> kernel_arguments(cl::Program program, std::vector<std::string>& kernels) {
  std::vector<cl::Kernel> all;
  program.createKernels(&all);
  std::vector<std::vector<std::string>> args;
  for (cl::Kernel& k : all) {
    kernels.push_back(k.getInfo<CL_KERNEL_FUNCTION_NAME>());
    // Some drivers end the name with a NUL inside the string.
    kernels.back() = kernels.back().c_str();
    std::vector<std::string> names;
    const cl_uint n = k.getInfo<CL_KERNEL_NUM_ARGS>();
    for (cl_uint i = 0; i < n; ++i) names.push_back(k.getArgInfo<CL_KERNEL_ARG_NAME>(i).c_str());
    args.push_back(names);
  }
  return args;
}

TEST(SceneData, EveryKernelThatReadsTheSceneTakesTheWholeListFirst) {
  DeviceSession session("");
  const std::vector<std::string> list = scene_data_names();
  ASSERT_EQ(list.size(), size_t(kSceneDataArgs));
  std::vector<std::string> kernels;
  std::vector<std::vector<std::string>> args;
  try {
    args = kernel_arguments(session.program(), kernels);
  } catch (const cl::Error& e) {
    ASSERT_EQ(e.err(), CL_KERNEL_ARG_INFO_NOT_AVAILABLE) << e.what();
    kernels.clear();
    const std::string options = session.tile_sampler() ? "" : " -DMP_NO_TILE_SAMPLER";
    BuiltProgram built = build_program_cached(session.context(), session.device(), assemble_program_source(),
                                              "-cl-std=CL1.2 -cl-kernel-arg-info" + options);
    args = kernel_arguments(built.program, kernels);
  }
  int readers = 0;
  for (size_t k = 0; k < kernels.size(); ++k) {
    std::string reads;
    for (const std::string& name : args[k])
      for (const std::string& entry : list)
        if (name == entry) reads = name;
    if (reads.empty()) continue;
    ++readers;
    if (args[k].size() < list.size()) {
      ADD_FAILURE() << kernels[k] << " takes the scene's " << reads << " outside the list";
      continue;
    }
    for (size_t i = 0; i < list.size(); ++i)
      EXPECT_EQ(args[k][i], list[i]) << kernels[k] << " argument " << i;
  }
  // The pass's kernels: bound & split, dice, shade, sample, the markings.
  EXPECT_GE(readers, 12);
}

// bs_init_queue reads root_count from the list: without instances, root r
// of two views is patch r % root_count in view r / root_count.
std::vector<SubPatch> roots(DeviceSession& session, SceneKernel& kernel, const SceneBuffers& scene, cl_uint n) {
  cl::Buffer queue = session.allocate(n * sizeof(SubPatch), "roots");
  cl::Kernel& k = kernel.bind(scene, queue, n, cl_uint(2), cl::Buffer());
  session.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n), cl::NullRange);
  std::vector<SubPatch> out(n);
  session.queue().enqueueReadBuffer(queue, CL_TRUE, 0, n * sizeof(SubPatch), out.data());
  return out;
}

TEST(SceneData, AKernelBindsTheSceneAgainOnlyWhenItsBuffersChange) {
  DeviceSession session("");
  SceneKernel init(session.program(), "bs_init_queue");
  SceneBuffers a;
  a.patch_count = a.root_count = 3;  // no instances: a root per patch
  a.version = session.next_data_version();
  std::vector<SubPatch> r = roots(session, init, a, 6);
  EXPECT_EQ(r[3].patch, 0u);
  EXPECT_EQ(r[3].info >> 24, 1u);  // view 1 starts at root_count

  // Another upload: bound again.
  SceneBuffers b;
  b.patch_count = b.root_count = 2;
  b.version = session.next_data_version();
  r = roots(session, init, b, 6);
  EXPECT_EQ(r[2].patch, 0u);
  EXPECT_EQ(r[2].info >> 24, 1u);

  // The same upload: what the kernel holds stays (a change that does not
  // take a new version is not seen, which is why every replacement takes one).
  b.patch_count = b.root_count = 5;
  r = roots(session, init, b, 6);
  EXPECT_EQ(r[2].info >> 24, 1u);

  // A replaced buffer takes a new version (upload_lights, set_world_glossy).
  b.version = session.next_data_version();
  r = roots(session, init, b, 6);
  EXPECT_EQ(r[2].patch, 2u);
  EXPECT_EQ(r[2].info >> 24, 0u);
  EXPECT_EQ(r[5].info >> 24, 1u);
}

}  // namespace
}  // namespace mp
