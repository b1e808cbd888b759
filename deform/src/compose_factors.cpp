// The patch coordinates and eq. (2) factors of compose_factors.hpp.
#include "compose_factors.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace clay::deform::detail {

/// Coordinates c_d = dual_d · (X − origin) of a Bézier patch, homogeneous: C = w dual · (P − X0).
PatchCoordinates patch_coordinates(const surface::BSplineSurface& patch,
                                   const Eigen::Vector3d& origin,
                                   const std::array<Eigen::Vector3d, 3>& dual) {
  const int p = patch.u.degree, q = patch.v.degree;
  PatchCoordinates pc;
  pc.w = Poly(p, q, 1);
  double wmax = 0, xmax = 0;
  for (int d = 0; d < 3; ++d) pc.c[static_cast<size_t>(d)] = Poly(p, q, 1);
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= q; ++j) {
      const Eigen::Index r = patch.index(i, j);
      const double w = patch.weights(r);
      const Eigen::Vector3d x = patch.points.row(r).transpose() - origin;
      pc.w.at(i, j) = w;
      wmax = std::max(wmax, w);
      xmax = std::max(xmax, x.norm());
      for (int d = 0; d < 3; ++d)
        pc.c[static_cast<size_t>(d)].at(i, j) = w * dual[static_cast<size_t>(d)].dot(x);
    }
  double dmax = 0;
  for (const auto& v : dual) dmax = std::max(dmax, v.norm());
  pc.w_scale = wmax;
  pc.c_scale = wmax * xmax * dmax;
  return pc;
}

/// Dual vectors of a frame: local coordinate d of X is dual[d] · (X − X0) (Sederberg–Parry eq.
/// (1)).
std::array<Eigen::Vector3d, 3> dual_vectors(const Frame& f) {
  const Eigen::Vector3d tu = f.t.cross(f.u), su = f.s.cross(f.u), st = f.s.cross(f.t);
  return {tu / tu.dot(f.s), su / su.dot(f.t), st / st.dot(f.u)};
}

/// W's exact degrees (reduced coefficients kept positive).
std::pair<int, int> weight_degrees(const PatchCoordinates& pc) {
  const double tol = degree_tolerance * pc.w_scale;
  return {exact_degree(pc.w, 0, tol, true), exact_degree(pc.w, 1, tol, true)};
}

namespace {

/// True when c = C / W is constant on the patch (C = c0 W coefficient by coefficient); sets c0.
bool constant_coordinate(const Poly& c, const Poly& w, double c_scale, double& c0) {
  double sum = 0, wsum = 0;
  for (size_t k = 0; k < c.c.size(); ++k) sum += c.c[k], wsum += w.c[k];
  c0 = sum / wsum;
  for (size_t k = 0; k < c.c.size(); ++k)
    if (std::abs(c.c[k] - c0 * w.c[k]) > degree_tolerance * c_scale) return false;
  return true;
}

}  // namespace

/// The factor of coordinate numerator `c` with weight `w` (scale `c_scale`), W's exact degrees
/// `wd`: constant, or the pair at the homogeneous degrees max(deg C, deg W) per direction.
Factor make_factor(const Poly& c, const Poly& w, double c_scale, std::pair<int, int> wd) {
  Factor f;
  f.w = to_degree(to_degree(w, wd.first, 0), wd.second, 1);
  scale(f.w, false);
  double c0 = 0;
  if (constant_coordinate(c, w, c_scale, c0)) {
    f.constant = true;
    f.value = c0;
    f.s = constant_poly(c0);
    f.v = constant_poly(1 - c0);
    return f;
  }
  const double tol = degree_tolerance * c_scale;
  f.du = std::max(exact_degree(c, 0, tol, false), wd.first);
  f.dv = std::max(exact_degree(c, 1, tol, false), wd.second);
  f.s = to_degree(to_degree(c, f.du, 0), f.dv, 1);
  const Poly wr = to_degree(to_degree(w, f.du, 0), f.dv, 1);
  f.v = wr;
  for (size_t k = 0; k < f.v.c.size(); ++k) f.v.c[k] -= f.s.c[k];
  scale(f.s, false);
  scale(f.v, false);
  return f;
}

/// Homogeneous de Casteljau with polynomial parameter: level r point i = V · P_i + S · P_{i+1}
/// (Sederberg–Parry eq. (2) in one direction), points given scaled; returns the scaled result.
Poly casteljau(std::vector<Poly> pts, const Factor& f) {
  for (size_t level = 1; level < pts.size(); ++level)
    for (size_t i = 0; i + level < pts.size(); ++i) {
      Poly next(pts[i].du + f.s.du, pts[i].dv + f.s.dv, pts[i].dim);
      mul_add(pts[i], f.v, next);
      mul_add(pts[i + 1], f.s, next);
      pts[i] = std::move(next);
    }
  return std::move(pts[0]);
}

/// C and W of coordinate d as one dim-2 poly.
Poly ratio_poly(const PatchCoordinates& pc, int d) {
  Poly cw(pc.w.du, pc.w.dv, 2);
  for (int i = 0; i <= cw.du; ++i)
    for (int j = 0; j <= cw.dv; ++j) {
      cw.at(i, j, 0) = pc.c[static_cast<size_t>(d)].at(i, j);
      cw.at(i, j, 1) = pc.w.at(i, j);
    }
  return cw;
}

/// Per coordinate d, the factor for composing a patch with a cell whose local coordinate is
/// (c_d − lo_d) / width_d in the coordinates of `pc`.
std::array<Factor, 3> cell_factors(const PatchCoordinates& pc, std::array<double, 3> lo,
                                   std::array<double, 3> width) {
  const auto wd = weight_degrees(pc);
  std::array<Factor, 3> f;
  for (size_t d = 0; d < 3; ++d) {
    Poly c = pc.c[d];
    for (size_t k = 0; k < c.c.size(); ++k) c.c[k] = (c.c[k] - lo[d] * pc.w.c[k]) / width[d];
    f[d] = make_factor(c, pc.w, pc.c_scale / width[d], wd);
  }
  return f;
}

}  // namespace clay::deform::detail
