#pragma once
// Internal to clay_deform: what the exact image of a surface keeps exactly, a computed image
// (an exact composition, a refit) keeps exactly too.
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <utility>

namespace clay::deform::detail {

/// A side of `original` that is closed (its first and last rows, or columns, of control points
/// and weights equal to rounding, see closed_sides) stays closed in `image`, and a collapsed
/// side (a pole: one point, to the same rounding) stays one point, `map` of the pole. `image` is
/// `original` deformed by `map`, computed with rounding (composition: ~1e-14 of the size) or
/// approximated (refit: poles left up to ~1e-3 mm open, which shades as a dark spot); a closed side
/// that is open by rounding is also "closed" by a STEP reader, so the file would not read back as
/// written. The changes are within that rounding or approximation; callers measure or certify the
/// result after this. Which sides of `original` are closed: its first and last columns (u: i = 0
/// and i = last) or rows (v) of control points and weights equal to rounding (seam_rounding: 1e-9
/// of the control points' largest coordinate, 1e-7 mm on a 100 mm part, a typical edge
/// tolerance: a STEP sphere's pole row spread over 1e-16 mm and a CATIA cone's apex row over
/// 1.5e-10 mm, and their refits' poles, left to the fit, missed the poles' edges by 3.5e-5 and
/// 1e-6 mm).
struct ClosedSides {
  bool u = false, v = false;
};
inline double seam_rounding(const surface::BSplineSurface& original) {
  return 1e-9 * std::max(original.points.cwiseAbs().maxCoeff(), 1e-300);
}
inline bool same_point(const surface::BSplineSurface& s, Eigen::Index a, Eigen::Index b,
                       double rounding) {
  return (s.points.row(a) - s.points.row(b)).cwiseAbs().maxCoeff() <= rounding &&
         std::abs(s.weights[a] - s.weights[b]) <= 1e-9 * std::abs(s.weights[a]);
}
inline ClosedSides closed_sides(const surface::BSplineSurface& original) {
  const int nu = original.count_u(), nv = original.count_v();
  const double rounding = seam_rounding(original);
  auto same = [&](int i0, int j0, int i1, int j1) {
    return same_point(original, original.index(i0, j0), original.index(i1, j1), rounding);
  };
  ClosedSides out{true, true};
  for (int j = 0; j < nv && out.u; ++j) out.u = same(0, j, nu - 1, j);
  for (int i = 0; i < nu && out.v; ++i) out.v = same(i, 0, i, nv - 1);
  return out;
}

template <class Map>
void keep_closed_and_collapsed(const surface::BSplineSurface& original,
                               surface::BSplineSurface& image, Map&& map) {
  const int nu = original.count_u(), nv = original.count_v(), mu = image.count_u(),
            mv = image.count_v();
  auto copy = [&](Eigen::Index to, Eigen::Index from) {
    image.points.row(to) = image.points.row(from);
    image.weights[to] = image.weights[from];
  };
  const ClosedSides closed = closed_sides(original);
  if (closed.v)
    for (int i = 0; i < mu; ++i) copy(image.index(i, mv - 1), image.index(i, 0));
  if (closed.u)
    for (int j = 0; j < mv; ++j) copy(image.index(mu - 1, j), image.index(0, j));
  auto point = [&](int i, int j) { return original.points.row(original.index(i, j)); };
  const double rounding = seam_rounding(original);
  auto near = [&](int i0, int j0, int i1, int j1) {
    return (point(i0, j0) - point(i1, j1)).cwiseAbs().maxCoeff() <= rounding;
  };
  for (const auto& [side, image_side] : {std::pair{0, 0}, std::pair{nu - 1, mu - 1}}) {
    bool collapsed = true;
    for (int j = 1; j < nv && collapsed; ++j) collapsed = near(side, j, side, 0);
    if (!collapsed) continue;
    const Eigen::RowVector3d pole = map(Eigen::Vector3d(point(side, 0).transpose())).transpose();
    for (int j = 0; j < mv; ++j) image.points.row(image.index(image_side, j)) = pole;
  }
  for (const auto& [side, image_side] : {std::pair{0, 0}, std::pair{nv - 1, mv - 1}}) {
    bool collapsed = true;
    for (int i = 1; i < nu && collapsed; ++i) collapsed = near(i, side, 0, side);
    if (!collapsed) continue;
    const Eigen::RowVector3d pole = map(Eigen::Vector3d(point(0, side).transpose())).transpose();
    for (int i = 0; i < mu; ++i) image.points.row(image.index(i, image_side)) = pole;
  }
}

}  // namespace clay::deform::detail
