#pragma once
// A control net seen as a "curve" of wide points (internal). Algorithms written once for curves of
// D-dimensional homogeneous points (knot insertion, refinement, degree elevation) apply to a
// surface direction by treating each row of control points across the other direction as one point
// of dimension 4 * count_other.
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

/// The surface's homogeneous net as count_d rows of width 4 * count_other, written straight from
/// the points and weights (no intermediate homogeneous net: these strips are the largest
/// temporaries of knot removal and refinement).
inline Strip surface_strip(const BSplineSurface& s, Direction d) {
  const int nu = s.count_u(), nv = s.count_v();
  const bool along_u = d == Direction::U;
  Rows rows(along_u ? nu : nv, 4 * (along_u ? nv : nu));
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Eigen::Index r = s.index(i, j);
      const double w = s.weights(r);
      auto out = along_u ? rows.block<1, 4>(i, 4 * j) : rows.block<1, 4>(j, 4 * i);
      out.head<3>() = w * s.points.row(r);
      out(3) = w;
    }
  return {along_u ? s.u : s.v, std::move(rows), !s.is_rational()};
}

/// Inverse of surface_strip: `other` is the basis of the untouched direction. Weights exactly 1
/// stay exactly 1 (as from_homogeneous), so a polynomial net stays bit-identical.
inline BSplineSurface surface_from_strip(Strip strip, const BSplineBasis& other, Direction d) {
  BSplineSurface s;
  const bool along_u = d == Direction::U;
  if (along_u) {
    s.u = std::move(strip.basis);
    s.v = other;
  } else {
    s.u = other;
    s.v = std::move(strip.basis);
  }
  const int nu = s.count_u(), nv = s.count_v();
  s.points.resize(static_cast<Eigen::Index>(nu) * nv, 3);
  s.weights.resize(s.points.rows());
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Eigen::Index r = s.index(i, j);
      const auto h = along_u ? strip.rows.block<1, 4>(i, 4 * j) : strip.rows.block<1, 4>(j, 4 * i);
      const double w = strip.polynomial ? 1.0 : h(3);
      s.weights(r) = w;
      if (w == 1.0)
        s.points.row(r) = h.head<3>();
      else
        s.points.row(r) = h.head<3>() / w;
    }
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
