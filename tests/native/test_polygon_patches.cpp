// Flat polygons and Bezier patch sets as device patches: planar faces are
// reproduced exactly (position on the plane, area, front-facing normals).
#include <cstring>  // mp_compat.h uses std::memcpy

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/error.h"
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "geometry/mp_patch_eval.h"
#include "subdiv/patch_buffer.h"

namespace {

// A polygon in a tilted plane through `origin`, given by 2D coordinates
// (counter-clockwise) in the plane's (e1, e2) frame; front = e1 x e2.
struct PlanarPolygon {
  glm::dvec3 origin{0.3, -1.2, 2.0};
  glm::dvec3 e1 = glm::normalize(glm::dvec3(1.0, 0.4, -0.3));
  glm::dvec3 e2;
  glm::dvec3 normal;
  std::vector<glm::dvec2> corners;

  explicit PlanarPolygon(std::vector<glm::dvec2> c) : corners(std::move(c)) {
    glm::dvec3 helper(0.2, 1.0, 0.5);
    e2 = glm::normalize(helper - glm::dot(helper, e1) * e1);
    normal = glm::cross(e1, e2);
  }
  double area() const {  // shoelace
    double a = 0.0;
    for (size_t k = 0; k < corners.size(); ++k) {
      const glm::dvec2& p = corners[k];
      const glm::dvec2& q = corners[(k + 1) % corners.size()];
      a += p.x * q.y - q.x * p.y;
    }
    return 0.5 * a;
  }
  mp::Mesh mesh() const {
    mp::Mesh m;
    m.name = "polygon";
    for (const glm::dvec2& c : corners) m.points.emplace_back(origin + c.x * e1 + c.y * e2);
    m.face_vertex_counts = {int(corners.size())};
    for (size_t k = 0; k < corners.size(); ++k) m.face_vertex_indices.push_back(int(k));
    return m;
  }
};

// Midpoint rule on an n x n grid; exact for planar bilinear patches, whose
// |dP/du x dP/dv| is affine in (u, v).
double patch_area(const glm::vec4* cp, uint type, int n = 8) {
  double area = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      float3 P, du, dv;
      mp_eval_patch(cp, type, (i + 0.5f) / n, (j + 0.5f) / n, &P, &du, &dv);
      area += glm::length(glm::dvec3(cross(du, dv)));
    }
  return area / (n * n);
}

void expect_reproduces(const PlanarPolygon& poly, size_t expected_patches) {
  const mp::Mesh mesh = poly.mesh();
  mp::PatchBuffer buf;
  mp::append_polygon_patches(mesh, glm::mat4(1.0f), buf);
  ASSERT_EQ(buf.size(), expected_patches);
  ASSERT_EQ(buf.points.size(), expected_patches * MP_PATCH_POINTS);
  const double size = 4.0;
  double total_area = 0.0;
  for (size_t p = 0; p < buf.size(); ++p) {
    const glm::vec4* cp = &buf.points[p * MP_PATCH_POINTS];
    EXPECT_EQ(buf.info[p], glm::uvec4(MP_PATCH_BEZIER, 0u, MP_PATCH_DOUBLE_SIDED, 0u));
    for (int k = 0; k < 4; ++k) EXPECT_EQ(cp[mp_partner_index(k)], cp[mp_interior_index(k)]);
    for (int j = 0; j <= 6; ++j)
      for (int i = 0; i <= 6; ++i) {
        float3 P, du, dv;
        mp_eval_patch(cp, MP_PATCH_BEZIER, i / 6.0f, j / 6.0f, &P, &du, &dv);
        EXPECT_NEAR(glm::dot(glm::dvec3(P) - poly.origin, poly.normal), 0.0, 1e-6 * size);
        glm::dvec3 n = glm::dvec3(cross(du, dv));
        ASSERT_GT(glm::length(n), 0.0);
        EXPECT_GT(glm::dot(glm::normalize(n), poly.normal), 0.999) << "patch " << p;
      }
    total_area += patch_area(cp, MP_PATCH_BEZIER);
  }
  EXPECT_NEAR(total_area, poly.area(), 1e-5 * poly.area());
}

TEST(PolygonPatches, QuadIsOneExactBilinearPatch) {
  PlanarPolygon quad({{0.0, 0.0}, {2.0, 0.2}, {1.7, 1.5}, {-0.2, 1.1}});
  expect_reproduces(quad, 1);

  // u runs v0 -> v1 and v runs v0 -> v3; corners are the face's vertices.
  const mp::Mesh mesh = quad.mesh();
  mp::PatchBuffer buf;
  mp::append_polygon_patches(mesh, glm::mat4(1.0f), buf);
  const glm::vec4* cp = buf.points.data();
  const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int k = 0; k < 4; ++k) {
    float3 P, du, dv;
    mp_eval_patch(cp, MP_PATCH_BEZIER, uv[k][0], uv[k][1], &P, &du, &dv);
    EXPECT_LT(glm::length(P - mesh.points[k]), 1e-6f) << "corner " << k;
  }
  // Bilinear: the midpoint of an edge is the mean of its corners.
  float3 P, du, dv;
  mp_eval_patch(cp, MP_PATCH_BEZIER, 0.5f, 0.0f, &P, &du, &dv);
  EXPECT_LT(glm::length(P - 0.5f * (mesh.points[0] + mesh.points[1])), 1e-6f);
  EXPECT_LT(glm::length(du - (mesh.points[1] - mesh.points[0])), 1e-5f);
}

TEST(PolygonPatches, TriangleIsThreeQuadsAroundTheCentroid) {
  expect_reproduces(PlanarPolygon({{0.0, 0.0}, {2.5, 0.3}, {0.7, 1.9}}), 3);
}

TEST(PolygonPatches, PentagonIsFiveQuadsAroundTheCentroid) {
  std::vector<glm::dvec2> c;
  for (int k = 0; k < 5; ++k) {
    double a = 2.0 * 3.14159265358979 * k / 5 + 0.2;
    c.emplace_back((1.3 + 0.2 * (k % 2)) * std::cos(a), 1.1 * std::sin(a));
  }
  expect_reproduces(PlanarPolygon(c), 5);
}

TEST(PolygonPatches, MaterialsPrimIdsAndFlags) {
  mp::Mesh m;
  m.name = "two faces";
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}};
  m.face_vertex_counts = {4, 3};
  m.face_vertex_indices = {0, 1, 2, 3, 1, 4, 2};
  m.face_materials = {7, 9};
  m.double_sided = false;
  mp::PatchBuffer buf;
  buf.points.resize(MP_PATCH_POINTS);  // appends after what is there
  buf.info.push_back(glm::uvec4(0));
  const glm::mat4 mirror = glm::scale(glm::mat4(1.0f), glm::vec3(1, 1, -1));
  mp::append_polygon_patches(m, mirror, buf);
  ASSERT_EQ(buf.size(), 1u + 1u + 3u);
  EXPECT_EQ(buf.info[1], glm::uvec4(MP_PATCH_BEZIER, 7u, MP_PATCH_FLIP_ORIENTATION, 0u));
  for (size_t p = 2; p < 5; ++p) EXPECT_EQ(buf.info[p], glm::uvec4(MP_PATCH_BEZIER, 9u, MP_PATCH_FLIP_ORIENTATION, 1u));

  m.face_materials.clear();
  m.material = 4;
  m.double_sided = true;
  mp::PatchBuffer plain;
  mp::append_polygon_patches(m, glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 3)), plain);
  ASSERT_EQ(plain.size(), 4u);
  for (const glm::uvec4& info : plain.info) EXPECT_EQ(info.y, 4u);
  EXPECT_EQ(plain.info[0].z, unsigned(MP_PATCH_DOUBLE_SIDED));
  for (const glm::vec4& p : plain.points) EXPECT_FLOAT_EQ(p.z, 3.0f);
}

TEST(PolygonPatches, InvalidFacesThrowNamingTheMesh) {
  mp::Mesh m;
  m.name = "broken polygon";
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  m.face_vertex_counts = {3};
  m.face_vertex_indices = {0, 1, 3};
  mp::PatchBuffer buf;
  try {
    mp::append_polygon_patches(m, glm::mat4(1.0f), buf);
    ADD_FAILURE() << "no error";
  } catch (const mp::Error& e) {
    EXPECT_NE(std::string(e.what()).find("broken polygon"), std::string::npos) << e.what();
  }
  m.face_vertex_indices = {0, 1};
  m.face_vertex_counts = {2};
  EXPECT_THROW(mp::append_polygon_patches(m, glm::mat4(1.0f), buf), mp::Error);
  EXPECT_EQ(buf.size(), 0u);
}

TEST(BezierPatches, ControlPointsGoStraightIntoTheLayout) {
  mp::BezierPatches set;
  set.name = "teapot lid";
  set.material = 3;
  for (int p = 0; p < 2; ++p)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) set.control_points.emplace_back(i + 4 * p, j, 0.1f * i * j + p);
  mp::PatchBuffer buf;
  const glm::mat4 to_space = glm::translate(glm::mat4(1.0f), glm::vec3(1, 2, 3));
  mp::append_bezier_patches(set, to_space, buf);
  ASSERT_EQ(buf.size(), 2u);
  for (int p = 0; p < 2; ++p) {
    EXPECT_EQ(buf.info[size_t(p)], glm::uvec4(MP_PATCH_BEZIER, 3u, MP_PATCH_DOUBLE_SIDED, unsigned(p)));
    const glm::vec4* cp = &buf.points[size_t(p) * MP_PATCH_POINTS];
    for (int k = 0; k < 16; ++k)
      EXPECT_EQ(glm::vec3(cp[k]), set.control_points[size_t(16 * p + k)] + glm::vec3(1, 2, 3));
    for (int k = 0; k < 4; ++k) EXPECT_EQ(cp[mp_partner_index(k)], cp[mp_interior_index(k)]);
    float3 P, du, dv;
    mp_eval_patch(cp, MP_PATCH_BEZIER, 1.0f, 1.0f, &P, &du, &dv);
    EXPECT_LT(glm::length(P - glm::vec3(cp[15])), 1e-6f);
  }
  set.control_points.pop_back();
  try {
    mp::append_bezier_patches(set, to_space, buf);
    ADD_FAILURE() << "no error";
  } catch (const mp::Error& e) {
    EXPECT_NE(std::string(e.what()).find("teapot lid"), std::string::npos) << e.what();
  }
}

}  // namespace
