// Point clouds (scene/points.h): spheres for Blender's clouds, discs facing
// the camera for RIB Points, each point one instance of a shared unit shape.
// Coverage against the analytic areas of the discs the points project to.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "renderer_fixture.h"
#include <sstream>

#include "rib/rib_reader.h"
#include "rib/rib_writer.h"
#include "scene/quadrics.h"
#include "scene/points.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A 4 x 3 grid of points 1 apart about the origin, radii 0.1 to 0.32.
PointCloud grid_cloud(PointShape shape) {
  PointCloud c;
  c.name = "grid";
  c.shape = shape;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) {
      c.positions.emplace_back(float(i) - 1.5f, float(j) - 1.0f, 0.0f);
      c.radii.push_back(0.1f + 0.02f * float(4 * j + i));
    }
  return c;
}

double disc_areas(const PointCloud& c) {
  double a = 0.0;
  for (float r : c.radii) a += kPi * r * r;
  return a;
}

// Orthographic, looking down -z at the window [-2.5, 2.5] x [-1.875, 1.875], 160 x 120.
Scene ortho_scene() {
  Scene s = base_scene(160, 120, 16);
  s.camera = look_at(glm::vec3(0.0f, 0.0f, 5.0f), glm::vec3(0.0f), 45.0f);
  s.camera.projection = Camera::Projection::Orthographic;
  s.camera.screen_left = -2.5f, s.camera.screen_right = 2.5f;
  s.camera.screen_bottom = -1.875f, s.camera.screen_top = 1.875f;
  return s;
}

class PointsTest : public SharedRendererTest {};

TEST_F(PointsTest, SpheresCoverTheirDiscs) {
  Scene s = ortho_scene();
  const PointCloud cloud = grid_cloud(PointShape::Sphere);
  EXPECT_EQ(add_point_cloud(s, cloud), 0u);
  ASSERT_EQ(s.prototypes.size(), 1u);
  EXPECT_EQ(s.instances.size(), cloud.positions.size());
  // A second cloud shares the unit sphere (behind the camera, unseen).
  PointCloud more = cloud;
  more.positions = {glm::vec3(0.0f, 0.0f, 40.0f)};
  more.radii = {0.5f};
  add_point_cloud(s, more);
  EXPECT_EQ(s.prototypes.size(), 1u);
  const double px = 160.0 / 5.0;
  const double got = coverage(renderer_->render(s)) / (px * px);
  EXPECT_NEAR(got / disc_areas(cloud), 1.0, 5e-3) << got << " against " << disc_areas(cloud);
}

TEST_F(PointsTest, BadPointsAreSkipped) {
  Scene s = ortho_scene();
  PointCloud c = grid_cloud(PointShape::Sphere);
  c.radii[0] = 0.0f, c.radii[1] = -1.0f, c.radii[2] = NAN, c.positions[3].x = INFINITY;
  EXPECT_EQ(add_point_cloud(s, c), 4u);
  EXPECT_EQ(s.instances.size(), c.positions.size() - 4);
  c.radii.pop_back();
  EXPECT_THROW(add_point_cloud(s, c), Error);
}

TEST_F(PointsTest, RibPointsAreDiscsFacingTheEye) {
  // Perspective, the points at depths 4 to 8 and off the axis: a disc facing
  // the eye covers what a sphere of its radius does (to first order in
  // r / distance), and each is width / 2 across.
  std::string P, width;
  const PointCloud c = grid_cloud(PointShape::Disc);
  for (size_t i = 0; i < c.positions.size(); ++i) {
    const glm::vec3 p = c.positions[i] + glm::vec3(0.0f, 0.0f, 4.0f + float(i % 5));
    P += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + " ";
    width += std::to_string(2.0f * c.radii[i]) + " ";
  }
  const std::string head =
      "Format 160 120 1\nPixelSamples 4 4\nProjection \"perspective\" \"fov\" [60]\nWorldBegin\nSurface \"constant\"\n";
  RibResult discs = read_rib_string(head + "Points \"P\" [" + P + "] \"width\" [" + width + "]\nWorldEnd\n", "p.rib");
  ASSERT_EQ(discs.scene.instances.size(), c.positions.size());
  Scene spheres = discs.scene;
  spheres.prototypes.clear();
  spheres.instances.clear();
  PointCloud sc = c;
  sc.shape = PointShape::Sphere;
  for (size_t i = 0; i < sc.positions.size(); ++i) sc.positions[i].z = 4.0f + float(i % 5);
  add_point_cloud(spheres, sc);
  const double a = coverage(renderer_->render(discs.scene)), b = coverage(renderer_->render(spheres));
  EXPECT_GT(a, 200.0);
  EXPECT_NEAR(a / b, 1.0, 0.02) << a << " against " << b;
  // Turned edge-on (the eye beside the disc's plane) they would all but vanish:
  // with constantwidth, every disc is as wide.
  RibResult constant = read_rib_string(head + "Points \"P\" [" + P + "] \"constantwidth\" [0.2]\nWorldEnd\n", "p.rib");
  for (const Instance& inst : constant.scene.instances)
    EXPECT_NEAR(glm::length(glm::vec3(inst.object_to_world[0])), 0.1f, 1e-6f);
}

TEST(Points, UnitSphereIsWithinItsStatedError) {
  // Quarter-turn arcs: 2.7e-4 of the radius per arc, a sphere two arcs deep.
  const std::vector<glm::vec3> cps = quadric_patches(QuadricKind::Sphere, {1.0, -1.0, 1.0, 360.0}, kPointArcDegrees);
  ASSERT_EQ(cps.size(), 8u * 16u);
  double worst = 0.0;
  for (size_t n = 0; n < 8; ++n)
    for (int a = 0; a <= 16; ++a)
      for (int b = 0; b <= 16; ++b) {
        // De Casteljau along u, then v.
        glm::dvec3 rows[4];
        const double u = a / 16.0, v = b / 16.0;
        auto cubic = [](glm::dvec3 p0, glm::dvec3 p1, glm::dvec3 p2, glm::dvec3 p3, double t) {
          const double s = 1.0 - t;
          return s * s * s * p0 + 3.0 * s * s * t * p1 + 3.0 * s * t * t * p2 + t * t * t * p3;
        };
        for (size_t j = 0; j < 4; ++j) {
          const glm::vec3* p = &cps[16 * n + 4 * j];
          rows[j] = cubic(glm::dvec3(p[0]), glm::dvec3(p[1]), glm::dvec3(p[2]), glm::dvec3(p[3]), u);
        }
        worst = std::max(worst, std::fabs(glm::length(cubic(rows[0], rows[1], rows[2], rows[3], v)) - 1.0));
      }
  EXPECT_LT(worst, 5.4e-4);
  EXPECT_GT(worst, 1e-5);  // quarter-turn arcs are not exact: the bound is what they reach
}

TEST(Points, RibPointsWithoutPositionsOrWithWrongWidthsAreErrors) {
  auto message = [](const std::string& body) {
    try {
      read_rib_string("WorldBegin\n" + body + "\nWorldEnd\n", "p.rib");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("Points \"width\" [1]").find("p.rib:2: Points: missing \"P\""), std::string::npos);
  EXPECT_NE(message("Points \"P\" [0 0 1  1 0 1] \"width\" [0.1]").find("\"width\" has 1 values for 2 points"),
            std::string::npos);
  const RibResult skipped = read_rib_string("WorldBegin\nPoints \"P\" [0 0 1  1 0 1] \"width\" [0.1 -1]\nWorldEnd\n", "p.rib");
  EXPECT_EQ(skipped.scene.instances.size(), 1u);
  EXPECT_EQ(skipped.warnings.size(), 1u);
}

TEST(Points, RibPointsRoundTrip) {
  const std::string rib =
      "WorldBegin\nPoints \"P\" [0 0 4  1 0 5  -1 1 6] \"width\" [0.2 0.3 0.4]\nWorldEnd\n";
  const RibResult first = read_rib_string(rib, "p.rib");
  std::ostringstream written;
  write_rib(first.scene, written);
  const RibResult second = read_rib_string(written.str(), "written.rib");
  ASSERT_EQ(second.scene.instances.size(), 3u);
  ASSERT_EQ(second.scene.prototypes.size(), 1u);
  for (size_t i = 0; i < 3; ++i)
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_NEAR(second.scene.instances[i].object_to_world[c][r], first.scene.instances[i].object_to_world[c][r],
                    1e-5f);
}

}  // namespace
}  // namespace mp::test
