// Catmull-Clark meshes as device patches through OpenSubdiv Far.
//
// Feature-adaptive refinement (Niessner, Loop, Meyer, DeRose 2012) isolates
// extraordinary vertices and semi-sharp features; every remaining face is
// either a regular bicubic B-spline patch (exact limit surface), converted
// here to Bezier form, or a Gregory-basis end cap (Loop, Schaefer, Ni,
// Castano 2009) next to an extraordinary vertex, converted to the Bezier net +
// partners form. See docs/subdivision.md for the options and why.
#include <algorithm>
#include <cmath>
#include <string>

#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include "subdiv/patch_buffer.h"
#include "subdiv/subdiv_refinement.h"

namespace mp {
namespace subdiv_detail {
namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

// Sdc treats sharpness >= 10 as infinitely sharp (Sdc::Crease::SHARPNESS_INFINITE).
constexpr float kInfiniteSharpness = 10.0f;

// Primvar type for Far's refinement and stencil evaluation.
struct PointSum {
  glm::dvec3 p{0.0};
  void Clear(void* = nullptr) { p = glm::dvec3(0.0); }
  void AddWithWeight(const PointSum& src, double weight) { p += weight * src.p; }
};

// Face-varying (UV) values for Far's refinement.
struct UVSum {
  glm::dvec2 uv{0.0};
  void Clear(void* = nullptr) { uv = glm::dvec2(0.0); }
  void AddWithWeight(const UVSum& src, double weight) { uv += weight * src.uv; }
};

Sdc::Options::VtxBoundaryInterpolation to_sdc(BoundaryInterpolation b) {
  switch (b) {
    case BoundaryInterpolation::None: return Sdc::Options::VTX_BOUNDARY_NONE;
    case BoundaryInterpolation::EdgeOnly: return Sdc::Options::VTX_BOUNDARY_EDGE_ONLY;
    case BoundaryInterpolation::EdgeAndCorner: break;
  }
  return Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER;
}

void check_tags(const Mesh& mesh) {
  const size_t nv = mesh.points.size();
  auto vertex_ok = [nv](int v) { return v >= 0 && size_t(v) < nv; };
  if (mesh.crease_vertices.size() != 2 * mesh.crease_sharpness.size())
    throw_mesh_error(mesh, "crease_vertices must hold one vertex pair per crease sharpness");
  if (!std::all_of(mesh.crease_vertices.begin(), mesh.crease_vertices.end(), vertex_ok))
    throw_mesh_error(mesh, "a crease vertex index is out of range");
  if (mesh.corner_vertices.size() != mesh.corner_sharpness.size())
    throw_mesh_error(mesh, "corner_vertices and corner_sharpness differ in length");
  if (!std::all_of(mesh.corner_vertices.begin(), mesh.corner_vertices.end(), vertex_ok))
    throw_mesh_error(mesh, "a corner vertex index is out of range");
  auto is_nan = [](float s) { return std::isnan(s); };
  if (std::any_of(mesh.crease_sharpness.begin(), mesh.crease_sharpness.end(), is_nan) ||
      std::any_of(mesh.corner_sharpness.begin(), mesh.corner_sharpness.end(), is_nan))
    throw_mesh_error(mesh, "a sharpness is not a number");
  const size_t nf = mesh.face_vertex_counts.size();
  for (int f : mesh.hole_faces)
    if (f < 0 || size_t(f) >= nf) throw_mesh_error(mesh, "hole face index " + std::to_string(f) + " is out of range");
}

std::vector<int> map_ptex_faces_to_base_faces(const Far::TopologyRefiner& refiner, const Mesh& mesh) {
  Far::PtexIndices ptex(refiner);
  std::vector<int> map(size_t(ptex.GetNumFaces()), -1);
  for (size_t f = 0; f < mesh.face_vertex_counts.size(); ++f) {
    const int first = ptex.GetFaceId(Far::Index(f));
    const int count = mesh.face_vertex_counts[f] == 4 ? 1 : mesh.face_vertex_counts[f];
    for (int k = 0; k < count; ++k) map[size_t(first + k)] = int(f);
  }
  return map;
}

// Uniform cubic B-spline to Bezier, one direction: Bezier point k of the span
// between B-spline points 1 and 2 is sum_m kBSplineToBezier[k][m] * P_m.
constexpr double kBSplineToBezier[4][4] = {
    {1.0 / 6, 4.0 / 6, 1.0 / 6, 0.0},
    {0.0, 4.0 / 6, 2.0 / 6, 0.0},
    {0.0, 2.0 / 6, 4.0 / 6, 0.0},
    {0.0, 1.0 / 6, 4.0 / 6, 1.0 / 6},
};

// A regular patch: 16 B-spline points, row-major with u fastest (the same
// orientation as the device net). Boundary bits of the PatchParam mark rows
// or columns that are absent: OpenSubdiv extrapolates them linearly as
// 2 * (adjacent row) - (next row), which is what makes the B-spline patch
// interpolate the boundary/infinitely sharp crease curve.
void regular_patch_to_bezier(const SubdivRefinement& r, Far::ConstIndexArray cvs, int boundary,
                             DevicePatch& out) {
  const bool row_absent[4] = {(boundary & 1) != 0, false, false, (boundary & 4) != 0};
  const bool col_absent[4] = {(boundary & 8) != 0, false, false, (boundary & 2) != 0};
  glm::dvec3 b[16];
  for (int j = 0; j < 4; ++j) {
    if (row_absent[j]) continue;
    for (int i = 0; i < 4; ++i)
      if (!col_absent[i]) b[4 * j + i] = r.points[size_t(cvs[4 * j + i])];
    if (col_absent[0]) b[4 * j] = 2.0 * b[4 * j + 1] - b[4 * j + 2];
    if (col_absent[3]) b[4 * j + 3] = 2.0 * b[4 * j + 2] - b[4 * j + 1];
  }
  for (int i = 0; i < 4; ++i) {
    if (row_absent[0]) b[i] = 2.0 * b[4 + i] - b[8 + i];
    if (row_absent[3]) b[12 + i] = 2.0 * b[8 + i] - b[4 + i];
  }
  glm::dvec3 rows[16];  // converted along u
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k) {
      glm::dvec3 s(0.0);
      for (int m = 0; m < 4; ++m) s += kBSplineToBezier[k][m] * b[4 * j + m];
      rows[4 * j + k] = s;
    }
  for (int l = 0; l < 4; ++l)
    for (int i = 0; i < 4; ++i) {
      glm::dvec3 s(0.0);
      for (int m = 0; m < 4; ++m) s += kBSplineToBezier[l][m] * rows[4 * m + i];
      out[4 * l + i] = s;
    }
  set_bezier_partners(out);
}

// OpenSubdiv's 20-point Gregory basis groups five points per corner c
// (corners (0,0), (1,0), (1,1), (0,1)): P, E+, E-, F+, F- at 5c + 0..4, where
// E+/F+ lie towards the next corner (counter-clockwise) and E-/F- towards the
// previous one. The device net takes the boundary points directly; each
// interior slot takes the face point that pairs with the edge point on the
// v = 0 / v = 1 edge, and its partner the one that pairs with the u = 0 /
// u = 1 edge (see mp_patch_eval.h).
constexpr int kGregoryToDevice[MP_PATCH_POINTS] = {
    0,  1,  7,  5,   // row 0: P0, E0+, E1-, P1
    2,  3,  9,  6,   // row 1: E0-, F0+, F1-, E1+
    16, 19, 13, 12,  // row 2: E3+, F3-, F2+, E2-
    15, 17, 11, 10,  // row 3: P3, E3-, E2+, P2
    4,  8,  18, 14,  // partners of (1,1), (2,1), (1,2), (2,2): F0-, F1+, F3+, F2-
};

void gregory_patch_to_device(const SubdivRefinement& r, Far::ConstIndexArray cvs, DevicePatch& out) {
  for (int k = 0; k < MP_PATCH_POINTS; ++k) out[k] = r.points[size_t(cvs[kGregoryToDevice[k]])];
}

}  // namespace

int subdiv_isolation_level(const Mesh& mesh) {
  float sharpest = 0.0f;
  for (const std::vector<float>* tags : {&mesh.crease_sharpness, &mesh.corner_sharpness})
    for (float s : *tags)
      if (s > 0.0f && s < kInfiniteSharpness) sharpest = std::max(sharpest, s);
  const int level = std::max(kSmoothIsolationLevel, int(std::ceil(sharpest)));
  return std::min(level, 10);  // Far's maximum isolation level
}

SubdivRefinement refine_subdiv_mesh(const Mesh& mesh) {
  check_face_topology(mesh);
  check_tags(mesh);
  SubdivRefinement r;
  if (mesh.face_vertex_counts.empty()) return r;

  Far::TopologyDescriptor desc;
  desc.numVertices = int(mesh.points.size());
  desc.numFaces = int(mesh.face_vertex_counts.size());
  desc.numVertsPerFace = mesh.face_vertex_counts.data();
  desc.vertIndicesPerFace = mesh.face_vertex_indices.data();
  desc.numCreases = int(mesh.crease_sharpness.size());
  desc.creaseVertexIndexPairs = mesh.crease_vertices.data();
  desc.creaseWeights = mesh.crease_sharpness.data();
  desc.numCorners = int(mesh.corner_sharpness.size());
  desc.cornerVertexIndices = mesh.corner_vertices.data();
  desc.cornerWeights = mesh.corner_sharpness.data();
  desc.numHoles = int(mesh.hole_faces.size());
  desc.holeIndices = mesh.hole_faces.data();
  desc.isLeftHanded = false;  // counter-clockwise faces are front faces

  // UV maps: one face-varying channel each, one value per face corner. Every
  // face has values of its own, so each edge is a face-varying seam; with
  // linear interpolation that changes nothing where neighbours agree, and
  // keeps real seams.
  const int layers = int(mesh.uv_layers.size());
  std::vector<int> corner_ids(mesh.face_vertex_indices.size());
  for (size_t k = 0; k < corner_ids.size(); ++k) corner_ids[k] = int(k);
  std::vector<Far::TopologyDescriptor::FVarChannel> channels(static_cast<size_t>(layers));
  for (Far::TopologyDescriptor::FVarChannel& c : channels) {
    c.numValues = int(corner_ids.size());
    c.valueIndices = corner_ids.data();
  }
  desc.numFVarChannels = layers;
  desc.fvarChannels = channels.data();

  Sdc::Options sdc;
  // Linear UVs inside each face, as Cycles interpolates face-corner
  // attributes of adaptively subdivided meshes (docs/subdivision.md).
  sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
  sdc.SetVtxBoundaryInterpolation(to_sdc(mesh.boundary));
  sdc.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
  sdc.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);

  using RefinerFactory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  r.refiner.reset(RefinerFactory::Create(desc, RefinerFactory::Options(Sdc::SCHEME_CATMARK, sdc)));
  if (!r.refiner) throw_mesh_error(mesh, "OpenSubdiv rejected the mesh topology");

  r.isolation_level = subdiv_isolation_level(mesh);
  Far::PatchTableFactory::Options options(unsigned(r.isolation_level));
  options.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
  options.useInfSharpPatch = true;        // inf-sharp creases as boundary-masked regular patches
  options.useSingleCreasePatch = false;   // the device has no single-crease patch type
  options.generateLegacySharpCornerPatches = false;  // smooth corners stay smooth
  options.generateVaryingTables = false;
  options.generateVaryingLocalPoints = false;
  options.generateFVarTables = layers > 0;
  options.SetPatchPrecision<double>();

  Far::TopologyRefiner::AdaptiveOptions adaptive = options.GetRefineAdaptiveOptions();
  // Semi-sharp features need the full depth; smooth extraordinary vertices
  // only kSmoothIsolationLevel.
  adaptive.SetSecondaryLevel(std::min(kSmoothIsolationLevel, r.isolation_level));
  r.refiner->RefineAdaptive(adaptive);

  r.patch_table.reset(Far::PatchTableFactory::Create(*r.refiner, options));
  if (!r.patch_table) throw_mesh_error(mesh, "OpenSubdiv could not build patches");

  const int refined = r.refiner->GetNumVerticesTotal();
  const int local = r.patch_table->GetNumLocalPoints();
  std::vector<PointSum> values(size_t(refined) + size_t(local));
  for (size_t v = 0; v < mesh.points.size(); ++v) values[v].p = glm::dvec3(mesh.points[v]);
  Far::PrimvarRefinerReal<double> primvars(*r.refiner);
  PointSum* src = values.data();
  for (int level = 1; level <= r.refiner->GetMaxLevel(); ++level) {
    PointSum* dst = src + r.refiner->GetLevel(level - 1).GetNumVertices();
    primvars.Interpolate(level, src, dst);
    src = dst;
  }
  // The end-cap points are stencils (double precision, see SetPatchPrecision)
  // over the base and refined points.
  if (local > 0)
    r.patch_table->GetLocalPointStencilTable<double>()->UpdateValues(values.data(), values.data() + refined);

  r.fvar.resize(size_t(layers));
  for (int c = 0; c < layers; ++c) {
    std::vector<UVSum> uv(size_t(r.refiner->GetNumFVarValuesTotal(c)));
    for (size_t k = 0; k < corner_ids.size(); ++k) uv[k].uv = glm::dvec2(mesh.uv_layers[size_t(c)][k]);
    UVSum* from = uv.data();
    for (int level = 1; level <= r.refiner->GetMaxLevel(); ++level) {
      UVSum* to = from + r.refiner->GetLevel(level - 1).GetNumFVarValues(c);
      primvars.InterpolateFaceVarying(level, from, to, c);
      from = to;
    }
    r.fvar[size_t(c)].resize(uv.size());
    for (size_t k = 0; k < uv.size(); ++k) r.fvar[size_t(c)][k] = uv[k].uv;
  }

  r.points.resize(values.size());
  for (size_t k = 0; k < values.size(); ++k) r.points[k] = values[k].p;
  r.ptex_to_face = map_ptex_faces_to_base_faces(*r.refiner, mesh);
  return r;
}

unsigned convert_far_patch(const SubdivRefinement& r, int array, int patch, DevicePatch& out) {
  const Far::PatchTable& table = *r.patch_table;
  const Far::ConstIndexArray cvs = table.GetPatchVertices(array, patch);
  switch (table.GetPatchArrayDescriptor(array).GetType()) {
    case Far::PatchDescriptor::REGULAR:
      regular_patch_to_bezier(r, cvs, table.GetPatchParam(array, patch).GetBoundary(), out);
      return MP_PATCH_BEZIER;
    case Far::PatchDescriptor::GREGORY_BASIS:
      gregory_patch_to_device(r, cvs, out);
      return MP_PATCH_GREGORY;
    default:
      throw Error("unexpected OpenSubdiv patch type " +
                  std::to_string(int(table.GetPatchArrayDescriptor(array).GetType())));
  }
}

void far_patch_corner_uvs(const SubdivRefinement& r, int array, int absolute_patch, glm::vec2* out) {
  const Far::PatchTable& table = *r.patch_table;
  Far::PatchTable::PatchHandle handle;
  handle.arrayIndex = array;
  handle.patchIndex = absolute_patch;
  handle.vertIndex = 0;  // unused by the face-varying queries
  const Far::PatchParam param = table.GetPatchParam(handle);
  constexpr double kCorner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (size_t c = 0; c < r.fvar.size(); ++c) {
    const Far::ConstIndexArray values = table.GetPatchFVarValues(handle, int(c));
    double w[20];
    for (int k = 0; k < 4; ++k) {
      // Face-varying patches are evaluated in the base face's parametrisation.
      double s = kCorner[k][0], t = kCorner[k][1];
      param.Unnormalize(s, t);
      table.EvaluateBasisFaceVarying(handle, s, t, w, nullptr, nullptr, nullptr, nullptr, nullptr, int(c));
      glm::dvec2 uv(0.0);
      for (int i = 0; i < values.size(); ++i) uv += w[i] * r.fvar[c][size_t(values[i])];
      out[4 * c + size_t(k)] = glm::vec2(uv);
    }
  }
}

}  // namespace subdiv_detail

void append_subdiv_patches(const Mesh& mesh, const glm::mat4& to_space, PatchBuffer& out) {
  const subdiv_detail::SubdivRefinement r = subdiv_detail::refine_subdiv_mesh(mesh);
  if (!r.patch_table) return;
  const OpenSubdiv::Far::PatchTable& table = *r.patch_table;
  const subdiv_detail::PatchInfoCommon common =
      subdiv_detail::make_patch_info_common(to_space, mesh.double_sided);
  out.points.reserve(out.points.size() + size_t(table.GetNumPatchesTotal()) * MP_PATCH_POINTS);
  out.info.reserve(out.info.size() + size_t(table.GetNumPatchesTotal()));

  subdiv_detail::DevicePatch patch;
  std::vector<glm::vec2> uvs(4 * size_t(out.uv_layers), glm::vec2(0.0f));
  int absolute = 0;
  for (int array = 0; array < table.GetNumPatchArrays(); ++array) {
    for (int k = 0; k < table.GetNumPatches(array); ++k, ++absolute) {
      const unsigned type = subdiv_detail::convert_far_patch(r, array, k, patch);
      if (!r.fvar.empty()) subdiv_detail::far_patch_corner_uvs(r, array, absolute, uvs.data());
      const int ptex_face = table.GetPatchParam(array, k).GetFaceId();
      if (ptex_face < 0 || size_t(ptex_face) >= r.ptex_to_face.size() || r.ptex_to_face[size_t(ptex_face)] < 0)
        subdiv_detail::throw_mesh_error(mesh, "OpenSubdiv patch refers to an unknown face");
      const int face = r.ptex_to_face[size_t(ptex_face)];
      subdiv_detail::append_device_patch(patch, type, subdiv_detail::face_material(mesh, size_t(face)),
                                         face, common, out, uvs.data());
    }
  }
}

}  // namespace mp
