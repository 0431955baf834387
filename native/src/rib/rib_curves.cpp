// RiCurves (RI spec 3.2, section 5.6): linear and cubic curves in the
// current v basis and step, periodic or not, with widths per segment end
// ("varying"), per control point ("vertex") or one for all. Each segment is
// turned into a cubic Bezier centre line with its radius and drawn, as
// RenderMan draws curves without normals, as a ribbon facing the eye
// (scene/curves.h, kernels/geometry/mp_ribbon.h). Every count is checked
// against the arrays present before anything is built.
#include <climits>
#include <cmath>

#include "rib/rib_basis.h"
#include "rib/rib_parser.h"
#include "scene/curves.h"

namespace mp::rib {
namespace {

// A cubic segment's four geometry values in Bezier form through the basis
// conversion C = B^-1 M (rib_basis.h), for a scalar or a point.
template <typename T>
void to_bezier(const Mat4d& c, const T g[4], T out[4]) {
  for (int r = 0; r < 4; ++r) {
    out[r] = T(0.0);
    for (int k = 0; k < 4; ++k) out[r] += c[r][k] * g[k];
  }
}

}  // namespace

void Parser::req_curves(ArgReader& args) {
  const int line = args.request().line;
  const std::string type = args.string();
  const bool cubic = type == "cubic";
  if (!cubic && type != "linear") args.fail("curve type must be \"linear\" or \"cubic\", not \"" + type + "\"");
  const Arg& nverts_arg = args.number_array();
  const std::string wrap = args.string();
  const bool periodic = wrap == "periodic";
  if (!periodic && wrap != "nonperiodic") args.fail("wrap must be \"periodic\" or \"nonperiodic\", not \"" + wrap + "\"");
  ParamList params(args, decls_);
  const std::vector<int> nverts = args.int_array(nverts_arg, 1, INT_MAX, "nvertices");
  for (const Param& p : params.params())
    if (p.name != "P" && p.name != "width" && p.name != "constantwidth")
      warn_once("primvar:" + p.name, p.line,
                "primitive variable \"" + p.name + "\" is ignored" +
                    (p.name == "N" ? " (curves are drawn as ribbons facing the eye, not N)" : ""));
  const Param* P = params.find("P");
  if (!P) args.fail("missing \"P\" (control points)");
  if (P->decl.is_string() || P->decl.components() != 3) args.fail_at(P->line, "\"P\" must hold points (3 values each)");
  const std::vector<double>& pv = P->value->numbers;
  const int step = cubic ? attrs_.vbasis.step : 1;
  // Segments per curve, and the varying values (segment ends) each has.
  int64_t vertices = 0, segments_total = 0, varying = 0;
  std::vector<int64_t> segments(nverts.size());
  for (size_t c = 0; c < nverts.size(); ++c) {
    const int n = nverts[c];
    int64_t s;
    if (cubic)
      s = periodic ? (n % step == 0 ? n / step : -1) : (n >= 4 && (n - 4) % step == 0 ? (n - 4) / step + 1 : -1);
    else
      s = periodic ? (n >= 2 ? n : -1) : (n >= 2 ? n - 1 : -1);
    if (s <= 0)
      args.fail_at(nverts_arg.line, "curve " + std::to_string(c) + " has " + std::to_string(n) + " vertices, which a " +
                                        type + (periodic ? " periodic" : " nonperiodic") + " curve of step " +
                                        std::to_string(step) + " cannot use");
    segments[c] = s;
    vertices += n;
    segments_total += s;
    varying += periodic ? s : s + 1;
  }
  if (int64_t(pv.size()) != 3 * vertices)
    args.fail_at(P->line, "\"P\" has " + std::to_string(pv.size() / 3) + " points but nvertices adds up to " +
                              std::to_string(vertices));
  const std::vector<float> widths = params.get_float_list("width");
  const bool per_vertex = !widths.empty() && int64_t(widths.size()) == vertices && vertices != varying;
  if (!widths.empty() && !per_vertex && int64_t(widths.size()) != varying)
    args.fail("\"width\" has " + std::to_string(widths.size()) + " values; these curves need " +
              std::to_string(varying) + " (one per segment end) or " + std::to_string(vertices) + " (one per vertex)");
  const double constant = 0.5 * params.get_float("constantwidth", 1.0f);
  if (defining_active_) {
    warn_once("curves-in-object", line, "Curves inside ObjectBegin/ObjectEnd are not supported and are skipped");
    return;
  }
  if (!in_world_) args.fail("geometry outside WorldBegin/WorldEnd");
  charge(size_t(segments_total) * 16, line);  // one ribbon patch a segment
  note_primitive(attrs_, line);

  const Mat4d conv = to_bezier_conversion(attrs_.vbasis.matrix);
  std::vector<std::vector<CurveSegment>> runs;
  size_t skipped = 0;
  int64_t first_vertex = 0, first_varying = 0;
  for (size_t c = 0; c < nverts.size(); ++c) {
    const int n = nverts[c];
    auto point = [&](int64_t i) {
      const size_t k = size_t(first_vertex + (i % n)) * 3;
      return glm::dvec3(pv[k], pv[k + 1], pv[k + 2]);
    };
    auto vertex_radius = [&](int64_t i) { return 0.5 * double(widths[size_t(first_vertex + (i % n))]); };
    auto end_radius = [&](int64_t j) {
      const int64_t ends = periodic ? segments[c] : segments[c] + 1;
      return widths.empty() ? constant : 0.5 * double(widths[size_t(first_varying + (j % ends))]);
    };
    std::vector<std::vector<CurveSegment>> pieces;
    std::vector<CurveSegment> run;
    bool ok = true;
    for (int64_t s = 0; s < segments[c]; ++s) {
      CurveSegment seg;
      const double r0 = end_radius(s), r1 = end_radius(s + 1);
      if (cubic) {
        glm::dvec3 g[4];
        double w[4];
        for (int k = 0; k < 4; ++k) g[k] = point(s * step + k), w[k] = per_vertex ? vertex_radius(s * step + k) : 0.0;
        to_bezier(conv, g, seg.p);
        if (per_vertex) to_bezier(conv, w, seg.r);
      } else {
        const glm::dvec3 a = point(s), b = point(s + 1);
        for (int k = 0; k < 4; ++k) seg.p[k] = a + (b - a) * (k / 3.0);
        if (per_vertex)
          for (int k = 0; k < 4; ++k) seg.r[k] = vertex_radius(s) + (vertex_radius(s + 1) - vertex_radius(s)) * (k / 3.0);
      }
      if (!per_vertex)
        for (int k = 0; k < 4; ++k) seg.r[k] = r0 + (r1 - r0) * (k / 3.0);
      for (int k = 0; k < 4; ++k)
        ok = ok && std::isfinite(seg.p[k].x) && std::isfinite(seg.p[k].y) && std::isfinite(seg.p[k].z) &&
             std::isfinite(seg.r[k]) && seg.r[k] >= 0.0;
      // A basis whose segments do not join (a step that skips) starts a new
      // tube, and so does each segment of a linear curve: its rings stay
      // square to its own direction (RenderMan's linear curves do not miter
      // their corners; a ring square to the mean direction would pinch the
      // whole segment at a sharp turn).
      if (!run.empty() && (!cubic || run.back().p[3] != seg.p[0])) pieces.push_back(std::move(run)), run.clear();
      run.push_back(seg);
    }
    first_vertex += n;
    first_varying += periodic ? segments[c] : segments[c] + 1;
    if (!ok) {
      ++skipped;
      continue;
    }
    pieces.push_back(std::move(run));
    for (std::vector<CurveSegment>& piece : pieces) runs.push_back(std::move(piece));
  }
  if (skipped > 0)
    warn_once("curves-skipped", line, "Curves: " + std::to_string(skipped) +
                                          " curves with a point or width that is not finite, or a negative width, are skipped");
  CurveSet meta;
  meta.name = attrs_.has_identifier ? attrs_.identifier : make_primitive(Primitive::Kind::Patches, args).origin;
  meta.object_to_world = attrs_.ctm;
  meta.material = material_index(attrs_);
  meta.info = attrs_.object_info;
  meta.visible_camera = attrs_.visible_camera;
  meta.cast_shadows = attrs_.cast_shadows;
  meta.ribbons = true;
  add_bezier_curves(result_.scene, meta, runs);
  has_merge_target_ = false;
}

}  // namespace mp::rib
