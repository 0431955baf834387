// RiNuPatch (RI spec 3.2, section 5.5): NURBS surfaces of any order, rational
// ("Pw", homogeneous) or not ("P"), over their [umin, umax] x [vmin, vmax],
// as the Bezier nets of scene/nurbs.h, placed as a Patch is (orientation,
// sides, visibility, instancing). Trim curves are not applied (TrimCurve is
// skipped with a warning).
#include <climits>

#include "rib/rib_parser.h"
#include "scene/nurbs.h"

namespace mp::rib {

void Parser::req_nupatch(ArgReader& args) {
  NurbsSurface s;
  s.nu = args.integer(1, INT_MAX);
  s.uorder = args.integer(1, 16);
  s.uknot = args.number_array().numbers;
  s.umin = args.number();
  s.umax = args.number();
  s.nv = args.integer(1, INT_MAX);
  s.vorder = args.integer(1, 16);
  s.vknot = args.number_array().numbers;
  s.vmin = args.number();
  s.vmax = args.number();
  ParamList params(args, decls_);
  for (const Param& p : params.params())
    if (p.name != "P" && p.name != "Pw")
      warn_once("primvar:" + p.name, p.line, "primitive variable \"" + p.name + "\" is ignored");
  const Param* P = params.find("P");
  const Param* Pw = params.find("Pw");
  if (!P && !Pw) args.fail("missing \"P\" or \"Pw\" (control points)");
  const Param* use = Pw ? Pw : P;
  const size_t n = Pw ? 4 : 3;
  if (use->decl.is_string() || use->decl.components() != int(n))
    args.fail_at(use->line, Pw ? "\"Pw\" must hold homogeneous points (4 values each)" : "\"P\" must hold points (3 values each)");
  if (int64_t(s.nu) * s.nv > int64_t(Limits::kMaxSceneElements)) args.fail("too many control points");
  const std::vector<double>& v = use->value->numbers;
  s.points.reserve(v.size() / n);
  for (size_t i = 0; i + n - 1 < v.size(); i += n)
    s.points.emplace_back(v[i], v[i + 1], v[i + 2], n == 4 ? v[i + 3] : 1.0);
  Primitive prim = make_primitive(Primitive::Kind::Patches, args);
  try {
    prim.patch_points = nurbs_patches(s);
  } catch (const Error& e) {
    args.fail(e.what());
  }
  place(std::move(prim), args);
}

}  // namespace mp::rib
