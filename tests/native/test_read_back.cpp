// The image's read-back off the frame's critical path
// (pipeline/frame/image_read_back.h): frames rendered overlapped, each
// one's pixels landing while the next renders, equal frames rendered one at
// a time; a failed read-back ends only its frame; ReadBack::None brings
// nothing back.
#include <gtest/gtest.h>

#include <cmath>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// A shadowed cube on a floor, or a torus, at different frame sizes, so an
// overlapped frame resizes the image buffers its predecessor's transfer reads.
Scene cube_scene() {
  Scene s = base_scene(96, 72, 4);
  s.meshes.push_back(grid_mesh(4, 6.0f, SubdivScheme::None));
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  s.camera = look_at({2.5f, 2.0f, 4.0f}, {0, 0, 0});
  return s;
}

Scene torus_scene() {
  Scene s = base_scene(80, 64, 4);
  s.meshes.push_back(torus_mesh(12, 8, 0.3f, SubdivScheme::CatmullClark));
  s.camera = look_at({0.0f, 2.0f, 3.0f}, {0, 0, 0});
  return s;
}

void expect_same(const RenderResult& a, const RenderResult& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.rgba, b.rgba);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.normal, b.normal);
}

using ReadBackTest = SharedRendererTest;

TEST_F(ReadBackTest, OverlappedFramesEqualFramesRenderedOneAtATime) {
  const Scene cube = cube_scene(), torus = torus_scene();
  const RenderResult cube_ref = renderer_->render(cube), torus_ref = renderer_->render(torus);
  ASSERT_GT(coverage(cube_ref), 1000.0);
  ASSERT_GT(coverage(torus_ref), 300.0);
  ASSERT_FALSE(cube_ref.depth.empty());
  RenderResult r[2];
  renderer_->render_overlapped(cube, r[0]);
  renderer_->render_overlapped(torus, r[1]);  // r[0] has landed once this starts its own read-back
  expect_same(r[0], cube_ref);
  EXPECT_GT(r[0].stats.timings_ms.readback, 0.0);
  renderer_->render_overlapped(cube, r[0]);
  expect_same(r[1], torus_ref);
  // The same result again: the renderer first lands what is in flight into it.
  renderer_->render_overlapped(cube, r[0]);
  renderer_->finish_frame();
  expect_same(r[0], cube_ref);
  renderer_->finish_frame();  // nothing in flight
  // A frame rendered one at a time after overlapped ones.
  expect_same(renderer_->render(torus), torus_ref);
}

TEST_F(ReadBackTest, AFailedReadBackEndsItsFrameAndTheNextOverlappedFrameIsClean) {
  const Scene cube = cube_scene();
  const RenderResult ref = renderer_->render(cube);
  RenderResult r[2];
  renderer_->render_overlapped(cube, r[0]);
  renderer_->inject_device_fault("read:1:CL_OUT_OF_RESOURCES@readback");
  std::string message;
  try {
    renderer_->render_overlapped(cube, r[1]);
    ADD_FAILURE() << "the planted fault did not fire";
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("(readback)"), std::string::npos) << message;
  // The frame before the failed one had landed before that one's read-back began.
  expect_same(r[0], ref);
  renderer_->render_overlapped(cube, r[1]);
  renderer_->finish_frame();
  expect_same(r[1], ref);
}

TEST_F(ReadBackTest, HalfFloatsAreTheNearestHalvesAndNoneBringsNothingBack) {
  Scene cube = cube_scene();
  const RenderResult ref = renderer_->render(cube);
  cube.settings.read_back = ReadBack::Half;
  const RenderResult half = renderer_->render(cube);
  ASSERT_EQ(half.rgba.size(), ref.rgba.size());
  EXPECT_EQ(half.depth, ref.depth);  // the passes stay floats
  size_t differ = 0;
  for (size_t i = 0; i < ref.rgba.size(); ++i) {
    // Within half a unit in the last place of a half (11 significant bits);
    // tests/python/test_read_back.py checks the rounding itself.
    const float f = ref.rgba[i], h = half.rgba[i];
    EXPECT_LE(std::fabs(h - f), std::ldexp(std::fabs(f), -11) + 1e-7f) << i;
    differ += h != f;
  }
  EXPECT_GT(differ, 0u);  // rounded, not the floats themselves
  cube.settings.read_back = ReadBack::None;
  const RenderResult none = renderer_->render(cube);
  EXPECT_TRUE(none.rgba.empty());
  EXPECT_EQ(none.width, 0);
  EXPECT_EQ(none.stats.width, 96);
  EXPECT_EQ(none.stats.micropolygons, ref.stats.micropolygons);
}

}  // namespace
}  // namespace mp::test
