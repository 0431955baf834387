#include "rib/rib_basis.h"

namespace mp::rib {
namespace {

Mat4d scaled(const Mat4d& m, double s) {
  Mat4d out = m;
  for (auto& row : out)
    for (double& v : row) v *= s;
  return out;
}

// Inverse of the Bezier basis: row k gives Bezier point k from the power
// coefficients [a b c d] of a*u^3 + b*u^2 + c*u + d.
const Mat4d kInverseBezier = {{{0, 0, 0, 1},
                               {0, 0, 1.0 / 3.0, 1},
                               {0, 1.0 / 3.0, 2.0 / 3.0, 1},
                               {1, 1, 1, 1}}};

}  // namespace

Basis bezier_basis() {
  Basis b;
  b.matrix = {{{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 3, 0, 0}, {1, 0, 0, 0}}};
  b.step = 3;
  return b;
}

bool named_basis(const std::string& name, Basis* out) {
  // Matrices and steps of RiBezierBasis, RiBSplineBasis, RiCatmullRomBasis,
  // RiHermiteBasis and RiPowerBasis (RI spec 3.2, section 5.2).
  if (name == "bezier") {
    *out = bezier_basis();
  } else if (name == "b-spline" || name == "bspline") {
    out->matrix = scaled({{{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 0, 3, 0}, {1, 4, 1, 0}}}, 1.0 / 6.0);
    out->step = 1;
  } else if (name == "catmull-rom") {
    out->matrix = scaled({{{-1, 3, -3, 1}, {2, -5, 4, -1}, {-1, 0, 1, 0}, {0, 2, 0, 0}}}, 0.5);
    out->step = 1;
  } else if (name == "hermite") {
    // Geometry vector (P0, R0, P1, R1): points and tangents interleaved.
    out->matrix = {{{2, 1, -2, 1}, {-3, -2, 3, -1}, {0, 1, 0, 0}, {1, 0, 0, 0}}};
    out->step = 2;
  } else if (name == "power") {
    out->matrix = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    out->step = 4;
  } else {
    return false;
  }
  return true;
}

Mat4d basis_from_array(const std::vector<double>& values) {
  Mat4d m{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[r][c] = values[static_cast<size_t>(4 * r + c)];
  return m;
}

Mat4d to_bezier_conversion(const Mat4d& basis) {
  Mat4d c{};
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k) {
      double s = 0;
      for (int m = 0; m < 4; ++m) s += kInverseBezier[r][m] * basis[m][k];
      c[r][k] = s;
    }
  return c;
}

void bicubic_to_bezier(const glm::vec3 g[16], const Mat4d& cu, const Mat4d& cv, glm::vec3 out[16]) {
  // Along u first (tmp[a][j]), then along v; in double to keep the exact
  // bases (Bezier, B-spline) close to exact in float.
  glm::dvec3 tmp[4][4];
  for (int a = 0; a < 4; ++a)
    for (int j = 0; j < 4; ++j) {
      glm::dvec3 s(0.0);
      for (int i = 0; i < 4; ++i) s += cu[a][i] * glm::dvec3(g[i + 4 * j]);
      tmp[a][j] = s;
    }
  for (int b = 0; b < 4; ++b)
    for (int a = 0; a < 4; ++a) {
      glm::dvec3 s(0.0);
      for (int j = 0; j < 4; ++j) s += cv[b][j] * tmp[a][j];
      out[a + 4 * b] = glm::vec3(s);
    }
}

void bilinear_to_bezier(const glm::vec3 p[4], glm::vec3 out[16]) {
  // Degree elevation of a bilinear patch: the cubic Bezier net with evenly
  // spaced points reproduces the bilinear map exactly.
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const float u = static_cast<float>(i) / 3.0f, v = static_cast<float>(j) / 3.0f;
      out[i + 4 * j] = (1 - u) * (1 - v) * p[0] + u * (1 - v) * p[1] + (1 - u) * v * p[2] + u * v * p[3];
    }
}

int64_t patches_along(bool bicubic, int n, bool periodic, int step) {
  if (!bicubic) {
    if (n < 2) return -1;
    return periodic ? n : n - 1;
  }
  if (step < 1) return -1;
  if (periodic) return (n >= 1 && n % step == 0) ? n / step : -1;
  return (n >= 4 && (n - 4) % step == 0) ? (n - 4) / step + 1 : -1;
}

void patch_mesh_to_bezier(bool bicubic, int nu, bool uperiodic, int nv, bool vperiodic,
                          const Basis& ubasis, const Basis& vbasis,
                          const std::vector<glm::vec3>& points, std::vector<glm::vec3>& out) {
  const int64_t npu = patches_along(bicubic, nu, uperiodic, ubasis.step);
  const int64_t npv = patches_along(bicubic, nv, vperiodic, vbasis.step);
  const Mat4d cu = to_bezier_conversion(ubasis.matrix);
  const Mat4d cv = to_bezier_conversion(vbasis.matrix);
  const int order = bicubic ? 4 : 2;
  const int64_t ustep = bicubic ? ubasis.step : 1, vstep = bicubic ? vbasis.step : 1;
  for (int64_t pv = 0; pv < npv; ++pv)
    for (int64_t pu = 0; pu < npu; ++pu) {
      glm::vec3 g[16];
      for (int l = 0; l < order; ++l)
        for (int k = 0; k < order; ++k) {
          // Periodic meshes wrap around; nonperiodic indices never exceed n-1.
          const int64_t u = (pu * ustep + k) % nu;
          const int64_t v = (pv * vstep + l) % nv;
          g[k + order * l] = points[static_cast<size_t>(u + static_cast<int64_t>(nu) * v)];
        }
      glm::vec3 net[16];
      if (bicubic)
        bicubic_to_bezier(g, cu, cv, net);
      else
        bilinear_to_bezier(g, net);
      out.insert(out.end(), net, net + 16);
    }
}

}  // namespace mp::rib
