// Smooth-shaded polygon meshes (Mesh::corner_normals): a coarse UV sphere
// whose corner normals are the true sphere's normals at its vertices must
// shade with normals close to the true sphere's everywhere, unlike its flat
// faces. Measured through the Normal pass against the analytic normal of the
// sphere under an orthographic camera (pixel (x, y) looks at the point
// (x, y, sqrt(1 - x^2 - y^2)) of the unit sphere).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class SmoothShadingTest : public SharedRendererTest {};

Scene sphere_scene(bool smooth) {
  Scene s = base_scene(96, 96, 4);
  s.camera = look_at({0, 0, 5}, {0, 0, 0});
  s.camera.projection = Camera::Projection::Orthographic;
  s.camera.screen_left = s.camera.screen_bottom = -1.2f;
  s.camera.screen_right = s.camera.screen_top = 1.2f;
  Mesh sphere = uv_sphere_mesh(8, 12);  // 30 degree facets around the equator
  if (smooth)
    for (int v : sphere.face_vertex_indices) sphere.corner_normals.push_back(sphere.points[size_t(v)]);
  s.meshes.push_back(sphere);
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(glm::vec3(-0.3f, -0.4f, -1.0f));
  s.lights.push_back(sun);
  return s;
}

// Angle in degrees between the Normal pass and the true sphere normal, for
// every pixel well inside the silhouette.
std::vector<float> normal_errors(const RenderResult& r) {
  std::vector<float> errors;
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const float px = -1.2f + 2.4f * (x + 0.5f) / r.width, py = 1.2f - 2.4f * (y + 0.5f) / r.height;
      const float rr = px * px + py * py;
      if (rr > 0.8f * 0.8f) continue;
      const size_t i = size_t(y) * size_t(r.width) + size_t(x);
      if (r.rgba[4 * i + 3] < 0.999f) continue;
      const glm::vec3 truth(px, py, std::sqrt(1.0f - rr));
      const glm::vec3 got(r.normal[3 * i], r.normal[3 * i + 1], r.normal[3 * i + 2]);
      errors.push_back(glm::degrees(std::acos(std::clamp(glm::dot(truth, glm::normalize(got)), -1.0f, 1.0f))));
    }
  return errors;
}

float percentile(std::vector<float> v, float q) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * float(v.size())))];
}

TEST_F(SmoothShadingTest, CornerNormalsShadeACoarseSphereAsASphere) {
  const RenderResult flat = renderer_->render(sphere_scene(false));
  const RenderResult smooth = renderer_->render(sphere_scene(true));
  const std::vector<float> e_flat = normal_errors(flat), e_smooth = normal_errors(smooth);
  ASSERT_GT(e_smooth.size(), 2000u);
  // Flat facets of 30 degrees are up to ~15 degrees off; interpolated vertex
  // normals of the same sphere stay within a few degrees.
  EXPECT_GT(percentile(e_flat, 0.9f), 8.0f);
  EXPECT_LT(percentile(e_smooth, 0.5f), 1.5f);
  EXPECT_LT(percentile(e_smooth, 0.99f), 4.0f);
  // The colour follows: fewer distinct steps between neighbouring pixels.
  double jump_flat = 0.0, jump_smooth = 0.0;
  for (size_t i = 4; i < flat.rgba.size(); i += 4) {
    jump_flat = std::max(jump_flat, double(std::fabs(flat.rgba[i] - flat.rgba[i - 4])) * (flat.rgba[i + 3] > 0.999f && flat.rgba[i - 1] > 0.999f));
    jump_smooth = std::max(jump_smooth, double(std::fabs(smooth.rgba[i] - smooth.rgba[i - 4])) * (smooth.rgba[i + 3] > 0.999f && smooth.rgba[i - 1] > 0.999f));
  }
  EXPECT_LT(jump_smooth, 0.5 * jump_flat);
}

TEST_F(SmoothShadingTest, NormalsFacingAwayAtTheSilhouetteAreNotFlipped) {
  // The sphere's pole axis turned to y and its facets turned by 10 degrees
  // about it, so at the +x silhouette a facet that still faces the camera
  // has a vertex whose normal already turns away (100 degrees from the view).
  // Lit from +x, that rim must stay lit: a smooth normal is faced by its
  // facet, as Cycles faces it by the geometric normal, not flipped on its own.
  Scene s = sphere_scene(true);
  s.meshes[0].object_to_world = glm::rotate(glm::rotate(glm::mat4(1.0f), glm::radians(10.0f), glm::vec3(0, 1, 0)),
                                            glm::radians(90.0f), glm::vec3(1, 0, 0));
  Light side;
  side.type = Light::Type::Distant;
  side.direction = glm::vec3(-1.0f, 0.0f, 0.0f);  // lights the +x side only
  s.lights = {side};
  const RenderResult r = renderer_->render(s);
  int rim = 0, dark_rim = 0, away = 0;
  for (int y = 30; y < 66; ++y)
    for (int x = r.width / 2; x < r.width; ++x) {
      const size_t i = size_t(y) * size_t(r.width) + size_t(x);
      if (r.rgba[4 * i + 3] < 0.999f) continue;
      const float px = -1.2f + 2.4f * (x + 0.5f) / r.width;
      if (px < 0.85f) continue;
      ++rim;
      // Matte, 0.8 * Kd 0.5 * cos: at least 0.4 * 0.85 where the sphere's
      // normal is within 32 degrees of the light.
      if (r.rgba[4 * i] < 0.3f) ++dark_rim;
      if (r.normal[3 * i + 2] < 0.0f) ++away;  // the normal turned away from the camera
    }
  ASSERT_GT(rim, 20);
  EXPECT_GT(away, 0) << "the view does not reach normals that face away";
  EXPECT_EQ(dark_rim, 0);
}

TEST(SmoothShadingInput, BadCornerNormalsAreRejectedNamingTheMesh) {
  Scene s = sphere_scene(true);
  s.meshes[0].corner_normals.pop_back();  // one short of the face corners
  try {
    validate_scene(s);
    ADD_FAILURE() << "a short corner-normal list was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sphere"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("corner normals"), std::string::npos) << e.what();
  }
  s = sphere_scene(true);
  s.meshes[0].corner_normals[5].y = std::nanf("");
  EXPECT_THROW(validate_scene(s), Error);
  s.meshes[0].corner_normals.clear();  // none: flat faces
  EXPECT_NO_THROW(validate_scene(s));
}

}  // namespace
}  // namespace mp::test
