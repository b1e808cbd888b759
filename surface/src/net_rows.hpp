#pragma once
// A control net seen as a "curve" of wide points (internal). Algorithms written once for curves of
// D-dimensional homogeneous points (knot insertion, refinement, degree elevation) apply to a surface
// direction by treating each row of control points across the other direction as one point of
// dimension 4 * count_other.
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include "homogeneous.hpp"

namespace clay::surface::detail {

using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// A basis and its control "points" (rows of any width), as the algorithms below consume them.
struct Strip {
  BSplineBasis basis;
  Rows rows;
  /// Every weight is exactly 1: the result's weights are set back to exactly 1, since sums like
  /// a + (1 - a) need not round to 1 and a polynomial object must stay polynomial.
  bool polynomial = false;
};

inline Strip curve_strip(const BSplineCurve& c) {
  return {c.basis, Rows(to_homogeneous(c.points, c.weights)), !c.is_rational()};
}

inline BSplineCurve curve_from_strip(Strip strip) {
  BSplineCurve c;
  c.basis = std::move(strip.basis);
  if (strip.polynomial) strip.rows.col(3).setOnes();
  from_homogeneous(Homogeneous(strip.rows), c.points, c.weights);
  return c;
}

enum class Direction { U, V };

/// The surface's homogeneous net as count_d rows of width 4 * count_other.
inline Strip surface_strip(const BSplineSurface& s, Direction d) {
  const Homogeneous h = to_homogeneous(s.points, s.weights);
  const int nu = s.count_u(), nv = s.count_v();
  if (d == Direction::U) {
    Rows rows(nu, 4 * nv);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) rows.block<1, 4>(i, 4 * j) = h.row(s.index(i, j));
    return {s.u, std::move(rows), !s.is_rational()};
  }
  Rows rows(nv, 4 * nu);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) rows.block<1, 4>(j, 4 * i) = h.row(s.index(i, j));
  return {s.v, std::move(rows), !s.is_rational()};
}

/// Inverse of surface_strip: `other` is the basis of the untouched direction.
inline BSplineSurface surface_from_strip(Strip strip, const BSplineBasis& other, Direction d) {
  BSplineSurface s;
  if (d == Direction::U) {
    s.u = std::move(strip.basis);
    s.v = other;
  } else {
    s.u = other;
    s.v = std::move(strip.basis);
  }
  const int nu = s.count_u(), nv = s.count_v();
  Homogeneous h(static_cast<Eigen::Index>(nu) * nv, 4);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      h.row(s.index(i, j)) = d == Direction::U ? strip.rows.block<1, 4>(i, 4 * j)
                                               : strip.rows.block<1, 4>(j, 4 * i);
  if (strip.polynomial) h.col(3).setOnes();
  from_homogeneous(h, s.points, s.weights);
  return s;
}

/// Applies `op(Strip&)` to one direction of the surface.
template <class Op>
BSplineSurface apply_in_direction(const BSplineSurface& s, Direction d, Op op) {
  Strip strip = surface_strip(s, d);
  op(strip);
  return surface_from_strip(std::move(strip), d == Direction::U ? s.v : s.u, d);
}

// Strip algorithms (knots.cpp, degree_elevation.cpp). Preconditions checked by the callers.
void insert_knot(Strip& strip, double t, int times);
void refine_knots(Strip& strip, std::vector<double> sorted_knots);
/// Knots to insert so every breakpoint of the domain has multiplicity >= degree (Bézier form).
std::vector<double> bezier_refinement_knots(const BSplineBasis& basis);
void clamp(Strip& strip);
void elevate_degree(Strip& strip, int times);
/// Removes every interior knot as often as A5.8 allows within `tolerance` (knot_removal.cpp).
int remove_knots(Strip& strip, double tolerance);

}  // namespace clay::surface::detail
