// Geometric primitives (RI spec 3.2, section 5): polygons, subdivision
// meshes and bilinear/bicubic patches. Every count and index is checked
// against the arrays actually present before anything is allocated from it,
// so a hostile count (nverts = 2^31) is an error, not an allocation.
#include <algorithm>
#include <climits>
#include <cmath>

#include "rib/rib_parser.h"
#include "scene/points.h"
#include "scene/quadrics.h"

namespace mp::rib {
namespace {

constexpr long long kIntMax = INT_MAX;

int64_t sum(const std::vector<int>& v) {
  int64_t s = 0;
  for (int x : v) s += x;
  return s;
}

// Face vertex counts (each >= 3) and the vertex list they index, checked to
// agree in length (PointsPolygons, PointsGeneralPolygons, SubdivisionMesh).
std::vector<int> face_counts(ArgReader& args, const Arg& nverts_arg, const Arg& verts_arg) {
  std::vector<int> counts = args.int_array(nverts_arg, 3, kIntMax, "nvertices");
  if (sum(counts) != static_cast<int64_t>(verts_arg.numbers.size()))
    args.fail_at(verts_arg.line, "vertices has " + std::to_string(verts_arg.numbers.size()) +
                                     " entries but nvertices adds up to " +
                                     std::to_string(sum(counts)));
  return counts;
}

// Checks that every index refers to one of `npoints` points.
void check_indices(ArgReader& args, const Arg& where, const std::vector<int>& indices,
                   size_t npoints) {
  for (size_t i = 0; i < indices.size(); ++i)
    if (static_cast<size_t>(indices[i]) >= npoints)
      args.fail_at(where.line, "vertex index " + std::to_string(indices[i]) + " (entry " +
                                   std::to_string(i) + ") is out of range: \"P\" has " +
                                   std::to_string(npoints) + " points");
}

// Per-mesh parameters rib_micropoly.cpp reads (Micropoly's, and "N").
bool is_mesh_extension(const std::string& name) {
  return name == "micropoly:material" || name == "N" || name == "micropoly:texspacelocation" ||
         name == "micropoly:texspacesize" || name.rfind("micropoly:uv", 0) == 0;
}

std::vector<int> identity(size_t n) {
  std::vector<int> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = static_cast<int>(i);
  return v;
}

void fill_polygons(Mesh& mesh, std::vector<int> counts, std::vector<int> indices) {
  mesh.face_vertex_counts = std::move(counts);
  mesh.face_vertex_indices = std::move(indices);
}

}  // namespace

Primitive Parser::make_primitive(Primitive::Kind kind, const ArgReader& args) const {
  Primitive p;
  p.kind = kind;
  p.origin = args.request().name + " (" + where(args.request().line) + ")";
  return p;
}

bool Parser::read_positions(ArgReader& args, const ParamList& params, bool patch,
                            std::vector<glm::vec3>* out) {
  const int line = args.request().line;
  for (const Param& p : params.params())
    if (p.name != "P" && p.name != "Pw" && p.name != "Pz" && (patch || !is_mesh_extension(p.name)))
      warn_once("primvar:" + p.name, p.line, "primitive variable \"" + p.name + "\" is ignored");
  const Param* P = params.find("P");
  const Param* Pw = params.find("Pw");
  out->clear();
  if (P) {
    if (P->decl.is_string() || P->decl.components() != 3)
      args.fail_at(P->line, "\"P\" must hold points (3 values each)");
    const std::vector<double>& v = P->value->numbers;
    out->reserve(v.size() / 3);
    for (size_t i = 0; i + 2 < v.size(); i += 3) out->emplace_back(v[i], v[i + 1], v[i + 2]);
    return true;
  }
  if (Pw) {
    if (Pw->decl.is_string() || Pw->decl.components() != 4)
      args.fail_at(Pw->line, "\"Pw\" must hold homogeneous points (4 values each)");
    const std::vector<double>& v = Pw->value->numbers;
    out->reserve(v.size() / 4);
    for (size_t i = 0; i + 3 < v.size(); i += 4) {
      const double w = v[i + 3];
      if (w == 0.0) args.fail_at(Pw->line, "\"Pw\" has a point with w = 0");
      if (patch && w != 1.0)
        warn_once("rational", Pw->line,
                  "rational patches (\"Pw\" with w != 1) are not supported; control points "
                  "are divided by w, which only approximates the surface");
      const glm::dvec3 p = glm::dvec3(v[i], v[i + 1], v[i + 2]) / w;
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) ||
          std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > 3.0e38)
        args.fail_at(Pw->line, "\"Pw\" point out of range after dividing by w");
      out->emplace_back(p);
    }
    return true;
  }
  if (params.find("Pz")) {
    warn_once("Pz", line, "height fields (\"Pz\") are not supported; the primitive is skipped");
    return false;
  }
  args.fail("missing \"P\" (vertex positions)");
}

// --- polygons -------------------------------------------------------------------

void Parser::req_polygon(ArgReader& args) {
  ParamList params(args, decls_);
  Primitive prim = make_primitive(Primitive::Kind::Mesh, args);
  if (!read_positions(args, params, false, &prim.mesh.points)) return;
  const size_t n = prim.mesh.points.size();
  if (n < 3) args.fail("a polygon needs at least 3 vertices, \"P\" has " + std::to_string(n));
  if (n > static_cast<size_t>(kIntMax)) args.fail("too many vertices");
  std::vector<int> indices = identity(n);
  read_mesh_primvars(args, params, indices, n, &prim.mesh);
  fill_polygons(prim.mesh, {static_cast<int>(n)}, std::move(indices));
  prim.mergeable = true;
  place(std::move(prim), args);
}

void Parser::req_general_polygon(ArgReader& args) {
  const Arg& nloops_arg = args.number_array();
  const std::vector<int> loops = args.int_array(nloops_arg, 3, kIntMax, "nvertices");
  ParamList params(args, decls_);
  if (loops.empty()) args.fail_at(nloops_arg.line, "no loops");
  Primitive prim = make_primitive(Primitive::Kind::Mesh, args);
  std::vector<glm::vec3> points;
  if (!read_positions(args, params, false, &points)) return;
  if (sum(loops) != static_cast<int64_t>(points.size()))
    args.fail("\"P\" has " + std::to_string(points.size()) + " points but the loops need " +
              std::to_string(sum(loops)));
  if (loops.size() > 1)
    warn_once("holes", args.request().line,
              "holes in general polygons are not supported; only the outer loop is rendered");
  // The outer loop comes first; holes are dropped.
  const int n = loops[0];
  read_mesh_primvars(args, params, identity(points.size()), points.size(), &prim.mesh);
  for (auto& layer : prim.mesh.uv_layers) layer.resize(static_cast<size_t>(n));
  if (!prim.mesh.corner_normals.empty()) prim.mesh.corner_normals.resize(static_cast<size_t>(n));
  prim.mesh.points.assign(points.begin(), points.begin() + n);
  std::vector<int> indices = identity(static_cast<size_t>(n));
  fill_polygons(prim.mesh, {n}, std::move(indices));
  prim.mergeable = true;
  place(std::move(prim), args);
}

void Parser::req_points_polygons(ArgReader& args) {
  const Arg& nverts_arg = args.number_array();
  const Arg& verts_arg = args.number_array();
  ParamList params(args, decls_);
  std::vector<int> counts = face_counts(args, nverts_arg, verts_arg);
  std::vector<int> indices = args.int_array(verts_arg, 0, kIntMax, "vertices");
  Primitive prim = make_primitive(Primitive::Kind::Mesh, args);
  if (!read_positions(args, params, false, &prim.mesh.points)) return;
  check_indices(args, verts_arg, indices, prim.mesh.points.size());
  read_face_materials(args, params, counts.size(), &prim.mesh.face_materials);
  read_mesh_primvars(args, params, indices, prim.mesh.points.size(), &prim.mesh);
  fill_polygons(prim.mesh, std::move(counts), std::move(indices));
  place(std::move(prim), args);
}

void Parser::req_points_general_polygons(ArgReader& args) {
  const Arg& nloops_arg = args.number_array();
  const Arg& nverts_arg = args.number_array();
  const Arg& verts_arg = args.number_array();
  ParamList params(args, decls_);
  const std::vector<int> loops = args.int_array(nloops_arg, 1, kIntMax, "nloops");
  if (sum(loops) != static_cast<int64_t>(nverts_arg.numbers.size()))
    args.fail_at(nverts_arg.line, "nvertices has " + std::to_string(nverts_arg.numbers.size()) +
                                      " entries but nloops adds up to " + std::to_string(sum(loops)));
  const std::vector<int> counts = face_counts(args, nverts_arg, verts_arg);
  const std::vector<int> all = args.int_array(verts_arg, 0, kIntMax, "vertices");
  Primitive prim = make_primitive(Primitive::Kind::Mesh, args);
  if (!read_positions(args, params, false, &prim.mesh.points)) return;
  check_indices(args, verts_arg, all, prim.mesh.points.size());
  read_mesh_primvars(args, params, all, prim.mesh.points.size(), &prim.mesh);
  // Keep the outer (first) loop of each polygon; holes are dropped.
  std::vector<int> outer_counts, outer_indices, outer_corners;
  size_t loop = 0, offset = 0;
  bool holes = false;
  for (int nl : loops) {
    const int c = counts[loop];
    outer_counts.push_back(c);
    outer_indices.insert(outer_indices.end(), all.begin() + static_cast<long>(offset),
                         all.begin() + static_cast<long>(offset) + c);
    for (int k = 0; k < c; ++k) outer_corners.push_back(static_cast<int>(offset) + k);
    for (int k = 0; k < nl; ++k) offset += static_cast<size_t>(counts[loop++]);
    holes = holes || nl > 1;
  }
  if (holes)
    warn_once("holes", args.request().line,
              "holes in general polygons are not supported; only the outer loop is rendered");
  read_face_materials(args, params, loops.size(), &prim.mesh.face_materials);
  for (auto& layer : prim.mesh.uv_layers) {
    std::vector<glm::vec2> kept(outer_corners.size());
    for (size_t i = 0; i < kept.size(); ++i) kept[i] = layer[static_cast<size_t>(outer_corners[i])];
    layer = std::move(kept);
  }
  if (!prim.mesh.corner_normals.empty()) {
    std::vector<glm::vec3> kept(outer_corners.size());
    for (size_t i = 0; i < kept.size(); ++i) kept[i] = prim.mesh.corner_normals[static_cast<size_t>(outer_corners[i])];
    prim.mesh.corner_normals = std::move(kept);
  }
  fill_polygons(prim.mesh, std::move(outer_counts), std::move(outer_indices));
  place(std::move(prim), args);
}

// --- subdivision meshes -----------------------------------------------------------

void Parser::req_subdivision_mesh(ArgReader& args) {
  const int line = args.request().line;
  const std::string scheme = args.string();
  const Arg& nverts_arg = args.number_array();
  const Arg& verts_arg = args.number_array();
  // The tag arrays are optional: present when an array follows (a parameter
  // list starts with a name string instead).
  const Arg* tags = nullptr;
  const Arg* nargs = nullptr;
  const Arg* intargs = nullptr;
  const Arg* floatargs = nullptr;
  if (!args.at_end() && args.peek().is_array()) {
    tags = &args.string_array();
    nargs = &args.number_array();
    intargs = &args.number_array();
    floatargs = &args.number_array();
    // Later RIB adds string arguments: then nargs has 3 entries per tag.
    if (nargs->numbers.size() == 3 * tags->strings.size() && !tags->strings.empty())
      args.string_array();
  }
  ParamList params(args, decls_);

  Primitive prim = make_primitive(Primitive::Kind::Mesh, args);
  Mesh& mesh = prim.mesh;
  if (scheme == "catmull-clark") {
    mesh.scheme = SubdivScheme::CatmullClark;
  } else if (scheme == "bilinear") {
    // Bilinear subdivision converges to the flat faces themselves.
    mesh.scheme = SubdivScheme::None;
  } else {
    warn_once("scheme:" + scheme, line,
              "SubdivisionMesh scheme \"" + scheme + "\" is not supported; the mesh is skipped");
    return;
  }
  std::vector<int> counts = face_counts(args, nverts_arg, verts_arg);
  std::vector<int> indices = args.int_array(verts_arg, 0, kIntMax, "vertices");
  if (!read_positions(args, params, false, &mesh.points)) return;
  const size_t npoints = mesh.points.size();
  const size_t nfaces = counts.size();
  check_indices(args, verts_arg, indices, npoints);
  read_face_materials(args, params, nfaces, &mesh.face_materials);
  read_mesh_primvars(args, params, indices, npoints, &mesh);
  if (!mesh.corner_normals.empty() && mesh.scheme == SubdivScheme::CatmullClark) {
    warn_once("subdiv-N", line, "\"N\" on a Catmull-Clark SubdivisionMesh is ignored: the limit surface's own "
                                "normals shade it");
    mesh.corner_normals.clear();
  }
  fill_polygons(mesh, std::move(counts), std::move(indices));

  // RenderMan's default without an "interpolateboundary" tag is no boundary
  // interpolation (the limit surface pulls away from the boundary).
  mesh.boundary = BoundaryInterpolation::None;
  if (tags) {
    const size_t ntags = tags->strings.size();
    const size_t per = nargs->numbers.size() == 3 * ntags && ntags > 0 ? 3 : 2;
    if (nargs->numbers.size() != per * ntags)
      args.fail_at(nargs->line, "nargs needs 2 entries per tag (" + std::to_string(2 * ntags) +
                                    "), found " + std::to_string(nargs->numbers.size()));
    const std::vector<int> n = args.int_array(*nargs, 0, kIntMax, "nargs");
    int64_t total_ints = 0, total_floats = 0;
    for (size_t t = 0; t < ntags; ++t) {
      total_ints += n[per * t];
      total_floats += n[per * t + 1];
    }
    if (total_ints != static_cast<int64_t>(intargs->numbers.size()))
      args.fail_at(intargs->line, "intargs has " + std::to_string(intargs->numbers.size()) +
                                      " entries, nargs asks for " + std::to_string(total_ints));
    if (total_floats != static_cast<int64_t>(floatargs->numbers.size()))
      args.fail_at(floatargs->line, "floatargs has " + std::to_string(floatargs->numbers.size()) +
                                        " entries, nargs asks for " + std::to_string(total_floats));
    const std::vector<int> ints = args.int_array(*intargs, 0, kIntMax, "intargs");
    const std::vector<double>& floats = floatargs->numbers;
    size_t ii = 0, fi = 0;
    for (size_t t = 0; t < ntags; ++t) {
      const std::string& tag = tags->strings[t];
      const size_t ni = static_cast<size_t>(n[per * t]);
      const size_t nf = static_cast<size_t>(n[per * t + 1]);
      const int* iv = ints.data() + ii;
      const double* fv = floats.data() + fi;
      ii += ni;
      fi += nf;
      auto tag_fail = [&](const std::string& why) { args.fail_at(tags->line, "tag \"" + tag + "\": " + why); };
      auto check_vertex = [&](int v) {
        if (static_cast<size_t>(v) >= npoints)
          tag_fail("vertex " + std::to_string(v) + " is out of range (" + std::to_string(npoints) +
                   " points)");
      };
      auto sharpness = [&](double s) {
        if (s < 0) tag_fail("negative sharpness");
        return static_cast<float>(s);
      };
      if (tag == "crease") {
        // A chain of ni vertices: ni-1 creased edges with one sharpness, or one per edge.
        if (ni < 2 || !(nf == 1 || nf == ni - 1))
          tag_fail("needs >= 2 vertices and 1 sharpness (or one per edge)");
        for (size_t k = 0; k + 1 < ni; ++k) {
          check_vertex(iv[k]);
          check_vertex(iv[k + 1]);
          mesh.crease_vertices.push_back(iv[k]);
          mesh.crease_vertices.push_back(iv[k + 1]);
          mesh.crease_sharpness.push_back(sharpness(fv[nf == 1 ? 0 : k]));
        }
      } else if (tag == "corner") {
        if (ni < 1 || !(nf == 1 || nf == ni)) tag_fail("needs vertices and 1 sharpness (or one per vertex)");
        for (size_t k = 0; k < ni; ++k) {
          check_vertex(iv[k]);
          mesh.corner_vertices.push_back(iv[k]);
          mesh.corner_sharpness.push_back(sharpness(fv[nf == 1 ? 0 : k]));
        }
      } else if (tag == "hole") {
        if (nf != 0) tag_fail("takes no float arguments");
        for (size_t k = 0; k < ni; ++k) {
          if (static_cast<size_t>(iv[k]) >= nfaces)
            tag_fail("face " + std::to_string(iv[k]) + " is out of range (" +
                     std::to_string(nfaces) + " faces)");
          mesh.hole_faces.push_back(iv[k]);
        }
      } else if (tag == "interpolateboundary") {
        // No integer means 1. RenderMan: 0 none, 1 sharp edges and corners,
        // 2 sharp edges only (corners stay smooth).
        if (ni > 1 || nf != 0) tag_fail("takes at most one integer and no floats");
        const int mode = ni == 0 ? 1 : iv[0];
        if (mode == 0)
          mesh.boundary = BoundaryInterpolation::None;
        else if (mode == 1)
          mesh.boundary = BoundaryInterpolation::EdgeAndCorner;
        else if (mode == 2)
          mesh.boundary = BoundaryInterpolation::EdgeOnly;
        else
          tag_fail("mode must be 0, 1 or 2");
      } else {
        warn_once("subdiv-tag:" + tag, tags->line,
                  "SubdivisionMesh tag \"" + tag + "\" is not supported and is ignored");
      }
    }
  }
  place(std::move(prim), args);
}

// --- patches ------------------------------------------------------------------------

void Parser::req_basis(ArgReader& args) {
  auto read = [&](Basis* out) {
    const Arg& a = args.any();
    if (a.kind == Arg::Kind::String) {
      if (!named_basis(a.strings[0], out)) args.fail_at(a.line, "unknown basis \"" + a.strings[0] + "\"");
    } else if (a.kind == Arg::Kind::NumberArray && a.numbers.size() == 16) {
      out->matrix = basis_from_array(a.numbers);
    } else {
      args.fail_at(a.line, std::string("a basis is a name or 16 numbers, found ") + a.describe() +
                               " of " + std::to_string(a.size()));
    }
    out->step = args.integer(1, 65536);
  };
  Basis u, v;
  read(&u);
  read(&v);
  args.done();
  attrs_.ubasis = u;
  attrs_.vbasis = v;
}

void Parser::req_patch(ArgReader& args) {
  const std::string type = args.string();
  ParamList params(args, decls_);
  if (type != "bilinear" && type != "bicubic")
    args.fail("patch type must be \"bilinear\" or \"bicubic\", not \"" + type + "\"");
  const bool bicubic = type == "bicubic";
  Primitive prim = make_primitive(Primitive::Kind::Patches, args);
  std::vector<glm::vec3> points;
  if (!read_positions(args, params, true, &points)) return;
  const size_t need = bicubic ? 16 : 4;
  if (points.size() != need)
    args.fail("a " + type + " patch needs " + std::to_string(need) + " points, \"P\" has " +
              std::to_string(points.size()));
  glm::vec3 net[16];
  if (bicubic)
    bicubic_to_bezier(points.data(), to_bezier_conversion(attrs_.ubasis.matrix),
                      to_bezier_conversion(attrs_.vbasis.matrix), net);
  else
    bilinear_to_bezier(points.data(), net);
  prim.patch_points.assign(net, net + 16);
  read_patch_primvars(args, params, &prim);
  prim.mergeable = true;
  place(std::move(prim), args);
}

void Parser::req_patch_mesh(ArgReader& args) {
  const std::string type = args.string();
  const int nu = args.integer(1, kIntMax);
  const std::string uwrap = args.string();
  const int nv = args.integer(1, kIntMax);
  const std::string vwrap = args.string();
  ParamList params(args, decls_);
  if (type != "bilinear" && type != "bicubic")
    args.fail("patch type must be \"bilinear\" or \"bicubic\", not \"" + type + "\"");
  for (const std::string* w : {&uwrap, &vwrap})
    if (*w != "periodic" && *w != "nonperiodic")
      args.fail("wrap mode must be \"periodic\" or \"nonperiodic\", not \"" + *w + "\"");
  const bool bicubic = type == "bicubic";
  const bool uper = uwrap == "periodic", vper = vwrap == "periodic";
  const int64_t npu = patches_along(bicubic, nu, uper, attrs_.ubasis.step);
  const int64_t npv = patches_along(bicubic, nv, vper, attrs_.vbasis.step);
  auto explain = [&](const char* dir, int n, bool periodic, int step) {
    if (!bicubic) return std::string(dir) + " = " + std::to_string(n) + ": needs at least 2 vertices";
    return std::string(dir) + " = " + std::to_string(n) + " does not fit the basis step " +
           std::to_string(step) +
           (periodic ? " (periodic meshes need a multiple of the step)"
                     : " (nonperiodic meshes need 4 + k * step vertices)");
  };
  if (npu < 0) args.fail(explain("nu", nu, uper, attrs_.ubasis.step));
  if (npv < 0) args.fail(explain("nv", nv, vper, attrs_.vbasis.step));
  Primitive prim = make_primitive(Primitive::Kind::Patches, args);
  std::vector<glm::vec3> points;
  if (!read_positions(args, params, true, &points)) return;
  const int64_t need = static_cast<int64_t>(nu) * nv;
  if (static_cast<int64_t>(points.size()) != need)
    args.fail("\"P\" has " + std::to_string(points.size()) + " points, nu * nv = " +
              std::to_string(need));
  if (npu * npv * 16 > static_cast<int64_t>(Limits::kMaxSceneElements))
    args.fail("too many patches");
  patch_mesh_to_bezier(bicubic, nu, uper, nv, vper, attrs_.ubasis, attrs_.vbasis, points,
                       prim.patch_points);
  prim.mergeable = true;
  place(std::move(prim), args);
}

// --- quadrics -------------------------------------------------------------------

// RenderMan's quadrics become Bezier nets (scene/quadrics.h) and go on as a
// Patch would: orientation, sides, visibility and instancing alike.
void Parser::req_quadric(ArgReader& args) {
  QuadricKind kind{};
  quadric_kind(args.request().name, &kind);
  // The numbers as scalars or one array; a Hyperboloid's points may also be
  // arrays of 3 each ("Hyperboloid [x1 y1 z1] [x2 y2 z2] thetamax").
  std::vector<double> numbers;
  if (kind == QuadricKind::Hyperboloid && !args.at_end() && args.peek().is_array() && args.peek().size() == 3) {
    numbers = args.numbers(3);
    for (double v : args.numbers(3)) numbers.push_back(v);
    numbers.push_back(args.number());
  } else {
    numbers = args.numbers(quadric_arg_count(kind));
  }
  ParamList params(args, decls_);
  for (const Param& p : params.params())
    warn_once("primvar:" + p.name, p.line, "primitive variable \"" + p.name + "\" is ignored");
  Primitive prim = make_primitive(Primitive::Kind::Patches, args);
  try {
    prim.patch_points = quadric_patches(kind, numbers);
  } catch (const Error& e) {
    args.fail(e.what());
  }
  if (prim.patch_points.empty()) {
    warn_once("quadric-empty:" + args.request().name, args.request().line,
              args.request().name + " with no area (a zero radius, height or sweep) is skipped");
    return;
  }
  place(std::move(prim), args);
}

// --- points ---------------------------------------------------------------------

// RenderMan's Points: discs of diameter "width" (per point) or
// "constantwidth" (one for all; 1 by default) facing the camera, each an
// instance of one unit disc (scene/points.h).
void Parser::req_points(ArgReader& args) {
  ParamList params(args, decls_);
  const int line = args.request().line;
  for (const Param& p : params.params())
    if (p.name != "P" && p.name != "width" && p.name != "constantwidth")
      warn_once("primvar:" + p.name, p.line, "primitive variable \"" + p.name + "\" is ignored");
  const Param* P = params.find("P");
  if (!P) args.fail("missing \"P\" (point positions)");
  if (P->decl.is_string() || P->decl.components() != 3) args.fail_at(P->line, "\"P\" must hold points (3 values each)");
  PointCloud cloud;
  cloud.shape = PointShape::Disc;
  const std::vector<double>& v = P->value->numbers;
  cloud.positions.reserve(v.size() / 3);
  for (size_t i = 0; i + 2 < v.size(); i += 3) cloud.positions.emplace_back(v[i], v[i + 1], v[i + 2]);
  const size_t n = cloud.positions.size();
  const std::vector<float> widths = params.get_float_list("width");
  if (!widths.empty()) {
    if (widths.size() != n)
      args.fail("\"width\" has " + std::to_string(widths.size()) + " values for " + std::to_string(n) + " points");
    for (float w : widths) cloud.radii.push_back(0.5f * w);
  } else {
    cloud.radii.assign(n, 0.5f * params.get_float("constantwidth", 1.0f));
  }
  if (defining_active_) {
    warn_once("points-in-object", line, "Points inside ObjectBegin/ObjectEnd are not supported and are skipped");
    return;
  }
  if (!in_world_) args.fail("geometry outside WorldBegin/WorldEnd");
  charge(n, line);
  note_primitive(attrs_, line);
  cloud.name = attrs_.has_identifier ? attrs_.identifier : make_primitive(Primitive::Kind::Patches, args).origin;
  cloud.object_to_world = attrs_.ctm;
  cloud.material = material_index(attrs_);
  cloud.info = attrs_.object_info;
  cloud.visible_camera = attrs_.visible_camera;
  cloud.cast_shadows = attrs_.cast_shadows;
  // Discs face the eye (an orthographic camera: its backward axis).
  const Camera& camera = result_.scene.camera;
  const glm::mat4 to_world = glm::inverse(camera.world_to_camera);
  const bool ortho = camera.projection == Camera::Projection::Orthographic;
  const glm::vec3 eye = ortho ? glm::normalize(glm::vec3(to_world * glm::vec4(0, 0, 1, 0)))
                              : glm::vec3(to_world * glm::vec4(0, 0, 0, 1));
  const size_t skipped = add_point_cloud(result_.scene, cloud, eye, ortho);
  if (skipped > 0)
    warn_once("points-skipped", line, "Points: " + std::to_string(skipped) +
                                          " points with a position or width that is not finite and positive are skipped");
  has_merge_target_ = false;
}

}  // namespace mp::rib
