// Catmull-Clark patches in the device layout, evaluated by mp_eval_patch (the
// same header the kernels compile), against OpenSubdiv's own evaluation of
// the same patch table (Far::PatchTable::EvaluateBasis, double precision).
#include <cstring>  // mp_compat.h uses std::memcpy

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <opensubdiv/far/patchTable.h>

#include "micropoly/error.h"
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "geometry/mp_patch_eval.h"
#include "subdiv/patch_buffer.h"
#include "subdiv/subdiv_refinement.h"

namespace {

namespace Far = OpenSubdiv::Far;

// ---------------------------------------------------------------- meshes ---

mp::Mesh make_cube() {
  mp::Mesh m;
  m.name = "cube";
  m.scheme = mp::SubdivScheme::CatmullClark;
  m.points = {{-1, -1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 1}, {-1, 1, -1}, {1, 1, -1}, {-1, -1, -1}, {1, -1, -1}};
  m.face_vertex_counts = {4, 4, 4, 4, 4, 4};
  m.face_vertex_indices = {0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4};
  return m;
}

// A bumpy (nx x ny)-quad grid in the xy plane, counter-clockwise seen from +z.
mp::Mesh make_grid(int nx, int ny) {
  mp::Mesh m;
  m.name = "grid";
  m.scheme = mp::SubdivScheme::CatmullClark;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      m.points.emplace_back(float(i), float(j), 0.3f * std::sin(1.3f * i + 0.7f * j) + 0.1f * i * j / nx);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      int v = j * (nx + 1) + i;
      m.face_vertex_counts.push_back(4);
      m.face_vertex_indices.insert(m.face_vertex_indices.end(), {v, v + 1, v + nx + 2, v + nx + 1});
    }
  return m;
}

int grid_vertex(int nx, int i, int j) { return j * (nx + 1) + i; }

// A polar grid: n quads around the centre (valence n), then `rings` bands of
// 2n quads. Odd vertices of the first ring have valence 3.
mp::Mesh make_polar(int n, int rings) {
  mp::Mesh m;
  m.name = "polar";
  m.scheme = mp::SubdivScheme::CatmullClark;
  const int ring_size = 2 * n;
  m.points.emplace_back(0.0f, 0.0f, 0.4f);
  for (int r = 1; r <= rings; ++r)
    for (int k = 0; k < ring_size; ++k) {
      float a = 3.14159265f * k / n;
      m.points.emplace_back(r * std::cos(a), r * std::sin(a), 0.2f * std::cos(3.0f * a + r));
    }
  auto ring = [&](int r, int k) { return 1 + (r - 1) * ring_size + (k % ring_size); };
  for (int k = 0; k < n; ++k) {
    m.face_vertex_counts.push_back(4);
    m.face_vertex_indices.insert(m.face_vertex_indices.end(), {0, ring(1, 2 * k), ring(1, 2 * k + 1), ring(1, 2 * k + 2)});
  }
  for (int r = 1; r < rings; ++r)
    for (int k = 0; k < ring_size; ++k) {
      m.face_vertex_counts.push_back(4);
      m.face_vertex_indices.insert(m.face_vertex_indices.end(),
                                   {ring(r, k), ring(r + 1, k), ring(r + 1, k + 1), ring(r, k + 1)});
    }
  return m;
}

// A closed pentagonal "house": pentagon floor, five quad walls, a roof of five
// triangles meeting at an apex of valence 5.
mp::Mesh make_house() {
  mp::Mesh m;
  m.name = "house";
  m.scheme = mp::SubdivScheme::CatmullClark;
  for (int k = 0; k < 5; ++k) {
    float a = 2.0f * 3.14159265f * k / 5;
    m.points.emplace_back(std::cos(a), std::sin(a), 0.0f);
  }
  for (int k = 0; k < 5; ++k) {
    float a = 2.0f * 3.14159265f * k / 5;
    m.points.emplace_back(std::cos(a), std::sin(a), 1.0f);
  }
  m.points.emplace_back(0.0f, 0.0f, 1.8f);
  m.face_vertex_counts.push_back(5);  // floor, seen from below
  m.face_vertex_indices.insert(m.face_vertex_indices.end(), {4, 3, 2, 1, 0});
  for (int k = 0; k < 5; ++k) {
    int n = (k + 1) % 5;
    m.face_vertex_counts.push_back(4);
    m.face_vertex_indices.insert(m.face_vertex_indices.end(), {k, n, 5 + n, 5 + k});
  }
  for (int k = 0; k < 5; ++k) {
    m.face_vertex_counts.push_back(3);
    m.face_vertex_indices.insert(m.face_vertex_indices.end(), {5 + k, 5 + (k + 1) % 5, 10});
  }
  return m;
}

void add_crease(mp::Mesh& m, int a, int b, float s) {
  m.crease_vertices.insert(m.crease_vertices.end(), {a, b});
  m.crease_sharpness.push_back(s);
}

// ----------------------------------------------------------- comparison ---

struct Coverage {
  int regular = 0, regular_with_boundary = 0, gregory = 0, non_quad_root = 0;
};

const std::vector<double> kSamples = {0.0, 0.13, 0.25, 0.5, 0.71, 0.9, 1.0};

// OpenSubdiv's position and patch-local derivatives at patch-local (s, t).
// EvaluateBasis takes ptex-face coordinates and scales derivatives by
// 2^depth (PatchParam, patchBasis.cpp), so both are undone here.
void osd_eval(const mp::subdiv_detail::SubdivRefinement& r, const Far::PatchTable::PatchHandle& h,
              double s, double t, glm::dvec3& P, glm::dvec3& du, glm::dvec3& dv) {
  const Far::PatchTable& table = *r.patch_table;
  const Far::PatchParam param = table.GetPatchParam(h);
  double u = s, v = t;
  param.Unnormalize(u, v);
  double wP[20], wDu[20], wDv[20];
  table.EvaluateBasis(h, u, v, wP, wDu, wDv);
  const Far::ConstIndexArray cvs = table.GetPatchVertices(h);
  P = du = dv = glm::dvec3(0.0);
  for (int k = 0; k < cvs.size(); ++k) {
    const glm::dvec3& c = r.points[size_t(cvs[k])];
    P += wP[k] * c;
    du += wDu[k] * c;
    dv += wDv[k] * c;
  }
  const double depth_scale = double(1 << param.GetDepth());
  du /= depth_scale;
  dv /= depth_scale;
}

double bbox_diagonal(const std::vector<glm::vec3>& pts) {
  glm::dvec3 lo(1e30), hi(-1e30);
  for (const glm::vec3& p : pts) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  return glm::length(hi - lo);
}

// Compares every patch of `mesh` on a grid of (u, v), counting what it saw.
void compare_with_opensubdiv(const mp::Mesh& mesh, Coverage& seen) {
  SCOPED_TRACE("mesh " + mesh.name);
  const mp::subdiv_detail::SubdivRefinement r = mp::subdiv_detail::refine_subdiv_mesh(mesh);
  mp::PatchBuffer buf;
  mp::append_subdiv_patches(mesh, glm::mat4(1.0f), buf);
  EXPECT_EQ(buf.points.size(), buf.size() * MP_PATCH_POINTS);
  if (!r.patch_table) {
    EXPECT_EQ(buf.size(), 0u);
    return;
  }
  const Far::PatchTable& table = *r.patch_table;
  EXPECT_EQ(int(buf.size()), table.GetNumPatchesTotal());
  if (int(buf.size()) != table.GetNumPatchesTotal()) return;
  const double tol_p = 1e-5 * bbox_diagonal(mesh.points);
  double worst_osd_gregory_deriv = 0.0;

  int index = 0;
  for (int array = 0; array < table.GetNumPatchArrays(); ++array) {
    for (int k = 0; k < table.GetNumPatches(array); ++k, ++index) {
      Far::PatchTable::PatchHandle h;
      h.arrayIndex = array;
      h.patchIndex = index;
      h.vertIndex = k * table.GetPatchArrayDescriptor(array).GetNumControlVertices();  // within the array
      const Far::PatchParam param = table.GetPatchParam(array, k);
      const bool gregory = table.GetPatchArrayDescriptor(array).GetType() == Far::PatchDescriptor::GREGORY_BASIS;
      const glm::uvec4 info = buf.info[size_t(index)];
      EXPECT_EQ(info.x, gregory ? MP_PATCH_GREGORY : MP_PATCH_BEZIER);
      seen.gregory += gregory;
      seen.regular += !gregory;
      seen.regular_with_boundary += !gregory && param.GetBoundary() != 0;
      seen.non_quad_root += param.NonQuadRoot();

      // Derivative scale of this patch: the largest OpenSubdiv derivative.
      double tol_d = 0.0;
      for (double s : kSamples)
        for (double t : kSamples) {
          glm::dvec3 P, du, dv;
          osd_eval(r, h, s, t, P, du, dv);
          tol_d = std::max({tol_d, glm::length(du), glm::length(dv)});
        }
      // Float control points carry rounding relative to the mesh size, which
      // the derivatives see at the patch's parametric scale.
      tol_d = 1e-5 * std::max(tol_d, bbox_diagonal(mesh.points) * param.GetParamFraction());

      const glm::vec4* cp = &buf.points[size_t(index) * MP_PATCH_POINTS];
      for (double s : kSamples)
        for (double t : kSamples) {
          float3 P, dPdu, dPdv;
          mp_eval_patch(cp, info.x, float(s), float(t), &P, &dPdu, &dPdv);
          glm::dvec3 oP, odu, odv;
          osd_eval(r, h, s, t, oP, odu, odv);
          const std::string where = "patch " + std::to_string(index) + (gregory ? " (gregory)" : " (regular)") +
                                    " at (" + std::to_string(s) + ", " + std::to_string(t) + ")";
          ASSERT_LE(glm::length(glm::dvec3(P) - oP), tol_p) << where;
          const bool on_edge = s == 0.0 || s == 1.0 || t == 0.0 || t == 1.0;
          if (gregory && !on_edge) {
            // OpenSubdiv (built without OPENSUBDIV_GREGORY_EVAL_TRUE_DERIVATIVES)
            // omits the rational weights' derivatives inside Gregory patches;
            // the exact derivatives are the central differences of its positions.
            const double e = 1e-5;
            glm::dvec3 a, b, unused1, unused2;
            osd_eval(r, h, s + e, t, a, unused1, unused2);
            osd_eval(r, h, s - e, t, b, unused1, unused2);
            glm::dvec3 fdu = (a - b) / (2 * e);
            osd_eval(r, h, s, t + e, a, unused1, unused2);
            osd_eval(r, h, s, t - e, b, unused1, unused2);
            glm::dvec3 fdv = (a - b) / (2 * e);
            worst_osd_gregory_deriv = std::max(worst_osd_gregory_deriv, glm::length(odu - fdu) / (tol_d * 1e5));
            odu = fdu;
            odv = fdv;
          }
          ASSERT_LE(glm::length(glm::dvec3(dPdu) - odu), tol_d) << where << " dP/du";
          ASSERT_LE(glm::length(glm::dvec3(dPdv) - odv), tol_d) << where << " dP/dv";
        }
    }
  }
  if (seen.gregory > 0)
    std::printf("  [%s] %d regular (%d with boundary), %d gregory, %d from non-quad faces; "
                "OpenSubdiv's approximate Gregory derivatives deviate up to %.2e (relative)\n",
                mesh.name.c_str(), seen.regular, seen.regular_with_boundary, seen.gregory, seen.non_quad_root,
                worst_osd_gregory_deriv);
}

Coverage expect_matches_opensubdiv(const mp::Mesh& mesh) {
  Coverage seen;
  compare_with_opensubdiv(mesh, seen);
  return seen;
}

Coverage& operator+=(Coverage& a, const Coverage& b) {
  a.regular += b.regular;
  a.regular_with_boundary += b.regular_with_boundary;
  a.gregory += b.gregory;
  a.non_quad_root += b.non_quad_root;
  return a;
}

// ----------------------------------------------------------------- tests ---

TEST(SubdivPatchEval, CubeMatchesOpenSubdiv) {
  Coverage c = expect_matches_opensubdiv(make_cube());
  EXPECT_GT(c.regular, 0);
  EXPECT_GT(c.gregory, 0);
}

TEST(SubdivPatchEval, Valence3And5WithBothBoundaryRulesMatchOpenSubdiv) {
  for (mp::BoundaryInterpolation b : {mp::BoundaryInterpolation::EdgeOnly, mp::BoundaryInterpolation::EdgeAndCorner}) {
    mp::Mesh polar = make_polar(5, 3);
    polar.boundary = b;
    polar.name = b == mp::BoundaryInterpolation::EdgeOnly ? "polar-edge-only" : "polar-edge-and-corner";
    Coverage c = expect_matches_opensubdiv(polar);
    EXPECT_GT(c.gregory, 0);
    EXPECT_GT(c.regular_with_boundary, 0);

    // Corners of valence 1 (sharp under EdgeAndCorner, smooth under EdgeOnly).
    mp::Mesh grid = make_grid(4, 3);
    grid.boundary = b;
    grid.name = b == mp::BoundaryInterpolation::EdgeOnly ? "grid-edge-only" : "grid-edge-and-corner";
    c = expect_matches_opensubdiv(grid);
    EXPECT_GT(c.regular_with_boundary, 0);
    if (b == mp::BoundaryInterpolation::EdgeOnly) {
      EXPECT_GT(c.gregory, 0);  // smooth corners are irregular
    }
  }
}

TEST(SubdivPatchEval, CreasesCornersAndHolesMatchOpenSubdiv) {
  const int nx = 6, ny = 6;
  mp::Mesh m = make_grid(nx, ny);
  m.name = "creased-grid";
  for (int i = 0; i < nx; ++i) add_crease(m, grid_vertex(nx, i, 2), grid_vertex(nx, i + 1, 2), 1.5f);
  for (int j = 1; j < 5; ++j) add_crease(m, grid_vertex(nx, 4, j), grid_vertex(nx, 4, j + 1), 2.7f);
  for (int j = 0; j < ny; ++j) add_crease(m, grid_vertex(nx, 2, j), grid_vertex(nx, 2, j + 1), 10.0f);
  m.corner_vertices = {grid_vertex(nx, 5, 5), grid_vertex(nx, 1, 4)};
  m.corner_sharpness = {10.0f, 2.0f};
  m.hole_faces = {0, 20};
  EXPECT_EQ(mp::subdiv_detail::subdiv_isolation_level(m), 3);
  Coverage c = expect_matches_opensubdiv(m);
  EXPECT_GT(c.regular, 0);
  EXPECT_GT(c.regular_with_boundary, 0);
  EXPECT_GT(c.gregory, 0);

  // A crease of sharpness 4.2 needs five levels before it is smooth.
  m.crease_sharpness[0] = 4.2f;
  EXPECT_EQ(mp::subdiv_detail::subdiv_isolation_level(m), 5);
  m.name = "creased-grid-deep";
  expect_matches_opensubdiv(m);

  // Infinitely sharp creases on the closed cube (around one face).
  mp::Mesh cube = make_cube();
  cube.name = "creased-cube";
  add_crease(cube, 0, 1, 10.0f);
  add_crease(cube, 1, 3, 10.0f);
  add_crease(cube, 3, 2, 10.0f);
  add_crease(cube, 2, 0, 10.0f);
  c = expect_matches_opensubdiv(cube);
  EXPECT_GT(c.regular_with_boundary, 0);

  // A hole opens a boundary in the cube.
  mp::Mesh holed = make_cube();
  holed.name = "holed-cube";
  holed.hole_faces = {1};
  holed.boundary = mp::BoundaryInterpolation::EdgeOnly;
  mp::PatchBuffer buf;
  mp::append_subdiv_patches(holed, glm::mat4(1.0f), buf);
  for (const glm::uvec4& info : buf.info) EXPECT_NE(info.w, 1u);  // no patch of the hole face
  expect_matches_opensubdiv(holed);
}

TEST(SubdivPatchEval, TrianglesAndPentagonsMatchOpenSubdiv) {
  Coverage c = expect_matches_opensubdiv(make_house());
  EXPECT_GT(c.non_quad_root, 0);
  EXPECT_GT(c.gregory, 0);
  EXPECT_GT(c.regular, 0);
}

// Every device patch kind was exercised by the comparisons above.
TEST(SubdivPatchEval, AllPatchKindsExercised) {
  Coverage all;
  all += expect_matches_opensubdiv(make_cube());
  all += expect_matches_opensubdiv(make_house());
  mp::Mesh grid = make_grid(3, 3);
  all += expect_matches_opensubdiv(grid);
  EXPECT_GT(all.regular, 0);
  EXPECT_GT(all.regular_with_boundary, 0);
  EXPECT_GT(all.gregory, 0);
  EXPECT_GT(all.non_quad_root, 0);
}

// Points of the patch at the sample grid with its normal.
template <typename F>
void for_each_sample(const mp::PatchBuffer& buf, F f) {
  for (size_t p = 0; p < buf.size(); ++p)
    for (double s : kSamples)
      for (double t : kSamples) {
        float3 P, du, dv;
        mp_eval_patch(&buf.points[p * MP_PATCH_POINTS], buf.info[p].x, float(s), float(t), &P, &du, &dv);
        f(p, s, t, P, cross(du, dv));
      }
}

TEST(SubdivPatchEval, ClosedMeshNormalsPointOutward) {
  for (const mp::Mesh& mesh : {make_cube(), make_house()}) {
    SCOPED_TRACE(mesh.name);
    mp::PatchBuffer buf;
    mp::append_subdiv_patches(mesh, glm::mat4(1.0f), buf);
    ASSERT_GT(buf.size(), 0u);
    glm::vec3 centre(0.0f);
    for (const glm::vec3& p : mesh.points) centre += p;
    centre /= float(mesh.points.size());
    int checked = 0;
    for_each_sample(buf, [&](size_t p, double s, double t, float3 P, float3 n) {
      // Corners of patches at extraordinary vertices have a degenerate normal.
      if (glm::length(n) < 1e-6f) return;
      ASSERT_GT(dot(glm::normalize(n), glm::normalize(P - centre)), 0.0f)
          << "patch " << p << " at (" << s << ", " << t << ")";
      ++checked;
    });
    EXPECT_GT(checked, int(buf.size()) * 40);
  }
}

TEST(SubdivPatchEval, PatchInfoNamesBaseFaceAndMaterial) {
  mp::Mesh cube = make_cube();
  cube.face_materials = {10, 11, 12, 13, 14, 15};
  cube.double_sided = false;
  mp::PatchBuffer buf;
  mp::append_subdiv_patches(cube, glm::mat4(1.0f), buf);
  ASSERT_GT(buf.size(), 0u);
  for (size_t p = 0; p < buf.size(); ++p) {
    const glm::uvec4 info = buf.info[p];
    ASSERT_LT(info.w, 6u);
    EXPECT_EQ(info.y, 10u + info.w);
    EXPECT_EQ(info.z, 0u);
    // The patch lies on its base face: its centre normal is the face normal.
    const int* f = &cube.face_vertex_indices[4 * info.w];
    glm::vec3 face_normal = glm::normalize(glm::cross(cube.points[f[1]] - cube.points[f[0]], cube.points[f[3]] - cube.points[f[0]]));
    float3 P, du, dv;
    mp_eval_patch(&buf.points[p * MP_PATCH_POINTS], info.x, 0.5f, 0.5f, &P, &du, &dv);
    EXPECT_GT(dot(glm::normalize(cross(du, dv)), face_normal), 0.5f) << "patch " << p;
  }

  // Non-quad faces: patches of the pentagon floor and triangles keep their face.
  mp::Mesh house = make_house();
  house.face_materials = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  mp::PatchBuffer hb;
  mp::append_subdiv_patches(house, glm::mat4(1.0f), hb);
  std::vector<int> per_face(11, 0), first_index(11, 0);
  for (int f = 1; f < 11; ++f) first_index[f] = first_index[f - 1] + house.face_vertex_counts[f - 1];
  for (size_t p = 0; p < hb.size(); ++p) {
    const glm::uvec4 info = hb.info[p];
    ASSERT_LT(info.w, 11u);
    EXPECT_EQ(info.y, info.w);
    EXPECT_EQ(info.z, unsigned(MP_PATCH_DOUBLE_SIDED));
    ++per_face[info.w];
    // Newell normal of the base face against the patch normal at its centre.
    glm::vec3 face_normal(0.0f);
    const int n = house.face_vertex_counts[info.w];
    for (int k = 0; k < n; ++k) {
      glm::vec3 a = house.points[house.face_vertex_indices[first_index[info.w] + k]];
      glm::vec3 b = house.points[house.face_vertex_indices[first_index[info.w] + (k + 1) % n]];
      face_normal += glm::cross(a, b);
    }
    float3 P, du, dv;
    mp_eval_patch(&hb.points[p * MP_PATCH_POINTS], info.x, 0.5f, 0.5f, &P, &du, &dv);
    EXPECT_GT(dot(glm::normalize(cross(du, dv)), glm::normalize(face_normal)), 0.3f) << "patch " << p;
  }
  for (int f = 0; f < 11; ++f) EXPECT_GT(per_face[f], 0) << "face " << f;
}

TEST(SubdivPatchEval, TransformAndMirrorFlag) {
  const mp::Mesh cube = make_cube();
  mp::PatchBuffer plain, mirrored;
  mp::append_subdiv_patches(cube, glm::mat4(1.0f), plain);
  glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(3, -2, 5)) * glm::scale(glm::mat4(1.0f), glm::vec3(-2, 1, 0.5f));
  mp::append_subdiv_patches(cube, m, mirrored);
  ASSERT_EQ(plain.size(), mirrored.size());
  for (size_t k = 0; k < plain.points.size(); ++k) {
    glm::vec4 expected = m * glm::vec4(glm::vec3(plain.points[k]), 1.0f);
    ASSERT_NEAR(glm::length(glm::vec3(expected) - glm::vec3(mirrored.points[k])), 0.0f, 1e-5f);
  }
  for (size_t p = 0; p < plain.size(); ++p) {
    EXPECT_EQ(plain.info[p].z, unsigned(MP_PATCH_DOUBLE_SIDED));
    EXPECT_EQ(mirrored.info[p].z, unsigned(MP_PATCH_DOUBLE_SIDED | MP_PATCH_FLIP_ORIENTATION));
  }
}

TEST(SubdivPatchEval, MeshesWithoutRenderablePatches) {
  mp::Mesh empty;
  empty.name = "empty";
  empty.scheme = mp::SubdivScheme::CatmullClark;
  mp::PatchBuffer buf;
  mp::append_subdiv_patches(empty, glm::mat4(1.0f), buf);
  EXPECT_EQ(buf.size(), 0u);

  mp::Mesh holes = make_cube();
  holes.hole_faces = {0, 1, 2, 3, 4, 5};
  mp::append_subdiv_patches(holes, glm::mat4(1.0f), buf);
  EXPECT_EQ(buf.size(), 0u);

  // Boundary interpolation "none" drops the faces at the boundary.
  mp::Mesh quad = make_grid(1, 1);
  quad.boundary = mp::BoundaryInterpolation::None;
  mp::append_subdiv_patches(quad, glm::mat4(1.0f), buf);
  EXPECT_EQ(buf.size(), 0u);
  mp::Mesh grid = make_grid(4, 4);
  grid.boundary = mp::BoundaryInterpolation::None;
  grid.name = "grid-boundary-none";
  Coverage c = expect_matches_opensubdiv(grid);
  EXPECT_GT(c.regular, 0);
}

TEST(SubdivPatchEval, InvalidTopologyThrowsNamingTheMesh) {
  auto expect_error = [](mp::Mesh m) {
    m.name = "bad-mesh";
    mp::PatchBuffer buf;
    try {
      mp::append_subdiv_patches(m, glm::mat4(1.0f), buf);
      ADD_FAILURE() << "no error";
    } catch (const mp::Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad-mesh"), std::string::npos) << e.what();
    }
  };
  mp::Mesh m = make_cube();
  m.face_vertex_indices[5] = 8;
  expect_error(m);
  m = make_cube();
  m.face_vertex_indices[5] = -1;
  expect_error(m);
  m = make_cube();
  m.face_vertex_counts[0] = 2;
  expect_error(m);
  m = make_cube();
  m.face_vertex_counts.push_back(4);
  expect_error(m);
  m = make_cube();
  m.crease_vertices = {0, 1, 2};
  m.crease_sharpness = {1.0f};
  expect_error(m);
  m = make_cube();
  m.crease_vertices = {0, 99};
  m.crease_sharpness = {1.0f};
  expect_error(m);
  m = make_cube();
  m.corner_vertices = {0};
  expect_error(m);
  m = make_cube();
  m.hole_faces = {6};
  expect_error(m);
  m = make_cube();
  m.face_materials = {1, 2};
  expect_error(m);
}

// Topology OpenSubdiv accepts with warnings (non-manifold edges, repeated
// vertices, unused points) must not crash; it may be rejected with mp::Error.
TEST(SubdivPatchEval, IrregularTopologyDoesNotCrash) {
  std::vector<mp::Mesh> meshes;
  mp::Mesh fin = make_cube();  // a third face on edge (0, 1)
  fin.points.push_back({0, -2, 2});
  fin.points.push_back({1, -2, 2});
  fin.face_vertex_counts.push_back(4);
  fin.face_vertex_indices.insert(fin.face_vertex_indices.end(), {0, 1, 9, 8});
  meshes.push_back(fin);
  mp::Mesh repeated = make_grid(2, 2);
  repeated.face_vertex_counts.push_back(4);
  repeated.face_vertex_indices.insert(repeated.face_vertex_indices.end(), {0, 1, 1, 3});
  meshes.push_back(repeated);
  mp::Mesh unused = make_cube();
  unused.points.push_back({5, 5, 5});
  meshes.push_back(unused);
  mp::Mesh bowtie = make_grid(2, 1);  // two faces sharing only a vertex
  bowtie.face_vertex_counts = {4, 4};
  bowtie.face_vertex_indices = {0, 1, 4, 3, 4, 5, 2, 1};
  meshes.push_back(bowtie);
  for (mp::Mesh& m : meshes) {
    m.name = "irregular";
    mp::PatchBuffer buf;
    try {
      mp::append_subdiv_patches(m, glm::mat4(1.0f), buf);
    } catch (const mp::Error& e) {
      EXPECT_NE(std::string(e.what()).find("irregular"), std::string::npos);
    }
    for (const glm::vec4& p : buf.points) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
}

// Direct checks of the device math: a Gregory patch whose partners equal the
// interior points is the Bezier patch, and the derivatives are those of the
// evaluated position (central differences).
TEST(PatchEvalMath, GregoryDerivativesAreExact) {
  std::vector<glm::vec4> cp(MP_PATCH_POINTS);
  for (int k = 0; k < MP_PATCH_POINTS; ++k)
    cp[k] = glm::vec4(std::sin(1.7f * k), std::cos(0.9f * k + 0.3f), 0.5f * std::sin(2.3f * k + 1.0f), 1.0f);
  for (double s : kSamples)
    for (double t : kSamples) {
      if (s == 0.0 || s == 1.0 || t == 0.0 || t == 1.0) continue;
      const float e = 1e-3f;
      float3 P, du, dv, a, b, unused1, unused2;
      mp_eval_patch(cp.data(), MP_PATCH_GREGORY, float(s), float(t), &P, &du, &dv);
      mp_eval_patch(cp.data(), MP_PATCH_GREGORY, float(s) + e, float(t), &a, &unused1, &unused2);
      mp_eval_patch(cp.data(), MP_PATCH_GREGORY, float(s) - e, float(t), &b, &unused1, &unused2);
      EXPECT_LT(glm::length((a - b) / (2 * e) - du), 2e-3f) << s << " " << t;
      mp_eval_patch(cp.data(), MP_PATCH_GREGORY, float(s), float(t) + e, &a, &unused1, &unused2);
      mp_eval_patch(cp.data(), MP_PATCH_GREGORY, float(s), float(t) - e, &b, &unused1, &unused2);
      EXPECT_LT(glm::length((a - b) / (2 * e) - dv), 2e-3f) << s << " " << t;
    }
  // Partners ignored for Bezier patches; equal partners give the Bezier patch.
  std::vector<glm::vec4> bez = cp;
  for (int k = 0; k < 4; ++k) bez[mp_partner_index(k)] = bez[mp_interior_index(k)];
  for (double s : kSamples)
    for (double t : kSamples) {
      float3 P1, du1, dv1, P2, du2, dv2, P3, du3, dv3;
      mp_eval_patch(cp.data(), MP_PATCH_BEZIER, float(s), float(t), &P1, &du1, &dv1);
      mp_eval_patch(bez.data(), MP_PATCH_GREGORY, float(s), float(t), &P2, &du2, &dv2);
      mp_eval_patch(bez.data(), MP_PATCH_BEZIER, float(s), float(t), &P3, &du3, &dv3);
      EXPECT_EQ(P1, P3);
      EXPECT_LT(glm::length(P1 - P2) + glm::length(du1 - du2) + glm::length(dv1 - dv2), 1e-5f);
    }
  // Corners are finite and equal to the corner control points.
  const float corners[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  const int corner_index[4] = {0, 3, 12, 15};
  for (int c = 0; c < 4; ++c) {
    float3 P, du, dv;
    mp_eval_patch(cp.data(), MP_PATCH_GREGORY, corners[c][0], corners[c][1], &P, &du, &dv);
    EXPECT_LT(glm::length(P - glm::vec3(cp[corner_index[c]])), 1e-6f);
    EXPECT_TRUE(std::isfinite(du.x + du.y + du.z + dv.x + dv.y + dv.z));
  }
}

}  // namespace
