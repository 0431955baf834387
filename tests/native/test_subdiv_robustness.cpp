// Catmull-Clark input that is legal but awkward, or plain broken, must give
// patches or a clear error, never a crash: repeated vertices in a face,
// non-manifold edges and vertices, high valence, unused vertices, random faces.
#include <gtest/gtest.h>

#include <random>

#include "micropoly/error.h"
#include "scene_fixtures.h"
#include "subdiv/patch_buffer.h"

namespace mp::test {
namespace {

size_t build(const Mesh& m) {
  PatchBuffer out;
  append_subdiv_patches(m, glm::mat4(1.0f), out);
  for (const glm::vec4& p : out.points)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(p[k]));
  return out.size();
}

TEST(SubdivRobustness, NonManifoldAndDegenerateTopology) {
  Mesh fan;  // three quads sharing one edge (non-manifold edge)
  fan.scheme = SubdivScheme::CatmullClark;
  fan.name = "fan";
  fan.points = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, 1, 0}, {0, 0, 1}, {0, 1, 1}};
  fan.face_vertex_counts = {4, 4, 4};
  fan.face_vertex_indices = {0, 2, 3, 1, 0, 1, 5, 4, 0, 6, 7, 1};
  EXPECT_NO_FATAL_FAILURE(build(fan));

  Mesh repeated = fan;  // a face that uses one vertex twice
  repeated.name = "repeated";
  repeated.face_vertex_counts = {4};
  repeated.face_vertex_indices = {0, 2, 2, 1};
  try {
    build(repeated);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("repeated"), std::string::npos) << e.what();
  }

  Mesh pole = grid_mesh(1, 1.0f, SubdivScheme::CatmullClark);  // valence-24 vertex
  pole.name = "pole";
  pole.points = {{0, 0, 0}};
  pole.face_vertex_counts.clear();
  pole.face_vertex_indices.clear();
  const int n = 24;
  for (int i = 0; i < n; ++i) {
    float a = 6.2831853f * i / n;
    pole.points.push_back({std::cos(a), std::sin(a), 0.0f});
  }
  for (int i = 0; i < n; ++i) {
    pole.face_vertex_counts.push_back(3);
    pole.face_vertex_indices.insert(pole.face_vertex_indices.end(), {0, 1 + i, 1 + (i + 1) % n});
  }
  EXPECT_GT(build(pole), 0u);

  Mesh unused = cube_mesh(SubdivScheme::CatmullClark);
  unused.points.push_back({5, 5, 5});
  EXPECT_GT(build(unused), 0u);
}

TEST(SubdivRobustness, RandomFacesNeverCrash) {
  std::mt19937 rng(1234);
  for (int iteration = 0; iteration < 200; ++iteration) {
    Mesh m;
    m.name = "random";
    m.scheme = SubdivScheme::CatmullClark;
    int nv = 3 + int(rng() % 12);
    for (int i = 0; i < nv; ++i) m.points.push_back({float(rng() % 100) / 10, float(rng() % 100) / 10, float(rng() % 7)});
    int nf = 1 + int(rng() % 10);
    for (int f = 0; f < nf; ++f) {
      int count = 3 + int(rng() % 4);
      m.face_vertex_counts.push_back(count);
      for (int k = 0; k < count; ++k) m.face_vertex_indices.push_back(int(rng() % nv));
    }
    if (rng() % 2) {
      m.crease_vertices = {0, 1};
      m.crease_sharpness = {float(rng() % 12)};
    }
    try {
      build(m);
    } catch (const Error&) {
      // A clear error is a fine answer to broken topology.
    }
  }
}

}  // namespace
}  // namespace mp::test
