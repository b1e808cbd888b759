// join_bezier_patches: a grid of Bézier patches as one C0 surface (knots.hpp), the inverse of
// extract_bezier. The NURBS Book §5.3: a B-spline with interior knots of multiplicity p is its
// Bézier segments side by side, sharing their end control points.
#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/knots.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace clay::surface {

namespace {

std::string number(double x) { return internal::shortest(x); }

/// True when `basis` is one clamped span [a, b] of degree p: p + 1 copies of a, then of b.
bool single_span(const BSplineBasis& basis, double a, double b) {
  const auto p = static_cast<std::size_t>(basis.degree);
  if (basis.degree < 1 || basis.knots.size() != 2 * (p + 1)) return false;
  for (std::size_t k = 0; k <= p; ++k)
    if (basis.knots[k] != a || basis.knots[p + 1 + k] != b) return false;
  return true;
}

}  // namespace

std::vector<double> c0_knots(const std::vector<double>& breaks, int p) {
  std::vector<double> k;
  for (std::size_t i = 0; i < breaks.size(); ++i)
    k.insert(k.end(), static_cast<std::size_t>(i == 0 || i + 1 == breaks.size() ? p + 1 : p),
             breaks[i]);
  return k;
}

BSplineSurface join_bezier_patches(const BezierPatches& bp, double relative_gap) {
  const int cu = bp.count_u(), cv = bp.count_v();
  if (cu < 1 || cv < 1 ||
      bp.patches.size() != static_cast<std::size_t>(cu) * static_cast<std::size_t>(cv))
    throw Error(
        ErrorCategory::InvalidArgument,
        "join_bezier_patches: " + std::to_string(bp.patches.size()) + " patches for " +
            std::to_string(std::max(cu, 0)) + " x " + std::to_string(std::max(cv, 0)) +
            " break intervals; give one patch per pair of intervals, (i, j) at i * count_v() + j");
  if (!(relative_gap >= 0 && std::isfinite(relative_gap)))
    throw Error(
        ErrorCategory::InvalidArgument,
        "join_bezier_patches: relative_gap = " + number(relative_gap) + " must be finite and >= 0");
  for (const auto* breaks : {&bp.breaks_u, &bp.breaks_v})
    for (std::size_t i = 0; i + 1 < breaks->size(); ++i)
      if (!((*breaks)[i] < (*breaks)[i + 1]) || !std::isfinite((*breaks)[i]) ||
          !std::isfinite((*breaks)[i + 1]))
        throw Error(ErrorCategory::InvalidArgument,
                    std::string("join_bezier_patches: breaks_") +
                        (breaks == &bp.breaks_u ? "u" : "v") +
                        " must be finite and strictly increasing; break " + std::to_string(i) +
                        " is " + number((*breaks)[i]) + ", the next " + number((*breaks)[i + 1]));
  int pu = 1, pv = 1;
  bool rational = false;
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b) {
      const BSplineSurface& s = bp.patch(a, b);
      const std::string name = "patch (" + std::to_string(a) + ", " + std::to_string(b) + ")";
      validate(s, "join_bezier_patches: " + name);
      if (!single_span(s.u, bp.breaks_u[static_cast<std::size_t>(a)],
                       bp.breaks_u[static_cast<std::size_t>(a) + 1]) ||
          !single_span(s.v, bp.breaks_v[static_cast<std::size_t>(b)],
                       bp.breaks_v[static_cast<std::size_t>(b) + 1]))
        throw Error(
            ErrorCategory::InvalidArgument,
            "join_bezier_patches: " + name + " is not one clamped Bézier span over [" +
                number(bp.breaks_u[static_cast<std::size_t>(a)]) + ", " +
                number(bp.breaks_u[static_cast<std::size_t>(a) + 1]) + "] x [" +
                number(bp.breaks_v[static_cast<std::size_t>(b)]) + ", " +
                number(bp.breaks_v[static_cast<std::size_t>(b) + 1]) +
                "]; give the patches extract_bezier makes (degree + 1 copies of each end knot)");
      if (s.is_rational() && (s.weights.array() <= 0).any())
        throw Error(ErrorCategory::InvalidGeometry,
                    "join_bezier_patches: " + name + " has a weight <= 0; give positive weights");
      pu = std::max(pu, s.u.degree);
      pv = std::max(pv, s.v.degree);
      rational = rational || s.is_rational();
    }
  const int nu = cu * pu + 1, nv = cv * pv + 1;
  // Homogeneous sums of the points that land on each net row, and how many did; a shared point
  // is compared with the mean of those before it (no second net is kept for the check).
  // Row-major: each control point's four values are adjacent (a column-major net scattered every
  // += over four cache lines, the largest cost of compose_exact's join).
  using Net = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;
  Net h = Net::Zero(static_cast<Eigen::Index>(nu) * nv, 4);
  Eigen::VectorXi count = Eigen::VectorXi::Zero(h.rows());
  double gap = 0, largest = 0;
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b) {
      const BSplineSurface& given = bp.patch(a, b);
      BSplineSurface elevated;  // only when the patch is below the common degrees
      if (given.u.degree < pu || given.v.degree < pv) {
        elevated = given;
        if (elevated.u.degree < pu) elevated = elevate_degree_u(elevated, pu - elevated.u.degree);
        if (elevated.v.degree < pv) elevated = elevate_degree_v(elevated, pv - elevated.v.degree);
      }
      const BSplineSurface& s = elevated.points.rows() > 0 ? elevated : given;
      const bool weighted =
          s.weights.size() == s.points.rows();  // once: is_rational() scans them all
      for (int i = 0; i <= pu; ++i)
        for (int j = 0; j <= pv; ++j) {
          const Eigen::Index k = s.index(i, j);
          const double w = weighted ? s.weights(k) : 1.0;
          Eigen::Matrix<double, 1, 4> hw;
          hw << w * s.points.row(k), w;
          const Eigen::Index r = static_cast<Eigen::Index>(a * pu + i) * nv + (b * pv + j);
          if (count(r) > 0) gap = std::max(gap, (hw - h.row(r) / count(r)).norm());
          largest = std::max(largest, hw.norm());
          h.row(r) += hw;
          ++count(r);
        }
    }
  if (!(gap <= relative_gap * largest))
    throw Error(
        ErrorCategory::InvalidGeometry,
        "join_bezier_patches: neighbouring patches do not meet: their shared homogeneous control "
        "points differ by up to " +
            number(gap) + " (" + number(largest > 0 ? gap / largest : gap) +
            " of the largest, allowed " + number(relative_gap) +
            "); give patches that share their boundaries, as extract_bezier makes them");
  BSplineSurface out;
  out.u = {pu, c0_knots(bp.breaks_u, pu)};
  out.v = {pv, c0_knots(bp.breaks_v, pv)};
  out.points.resize(h.rows(), 3);
  out.weights = Eigen::VectorXd::Ones(h.rows());
  for (Eigen::Index r = 0; r < h.rows(); ++r) {
    const Eigen::Matrix<double, 1, 4> avg = h.row(r) / count(r);
    out.points.row(r) =
        rational ? Eigen::RowVector3d(avg.head<3>() / avg(3)) : Eigen::RowVector3d(avg.head<3>());
    if (rational) out.weights(r) = avg(3);
  }
  return out;
}

}  // namespace clay::surface
