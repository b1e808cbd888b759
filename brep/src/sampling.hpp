#pragma once
// Where a coedge is sampled and how its pcurve's (u, v) is read: shared by the model's checks
// (model.cpp: edge gaps, loop areas) and the continuity of its edges (continuity.cpp). Internal.
#include <clay/brep/model.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <vector>

namespace clay::brep::detail {

/// The parameters at which a coedge is sampled: both ends, the breakpoints of the pcurve and of
/// the edge curve inside (t0, t1), and `per_span` points inside every piece between them.
inline std::vector<double> coedge_samples(const Edge& e, const Coedge& c, int per_span) {
  std::vector<double> breaks{e.t0, e.t1};
  auto add_breaks = [&](const surface::BSplineBasis& basis) {
    for (double k : surface::breakpoints(basis))
      if (k > e.t0 && k < e.t1) breaks.push_back(k);
  };
  add_breaks(c.pcurve.basis);
  if (!e.degenerate) add_breaks(e.curve.basis);
  std::sort(breaks.begin(), breaks.end());
  breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
  std::vector<double> ts;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    ts.push_back(breaks[k]);
    for (int s = 1; s < per_span; ++s)
      ts.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * s / per_span);
  }
  ts.push_back(breaks.back());
  return ts;
}

/// t clamped to a curve's domain: problems() lets an edge range end within a rounding slack past
/// it (a range read from a file), and evaluation refuses parameters outside.
inline double within(const surface::BSplineCurve& c, double t) {
  const auto [a, b] = c.basis.domain();
  return std::clamp(t, a, b);
}

/// (u, v) of a pcurve at t, clamped to the surface's domain (a pcurve leaving the domain is a
/// problem of its own; the face is measured at the nearest point of the domain).
inline Eigen::Vector2d uv_at(const surface::BSplineSurface& s, const surface::BSplineCurve& pcurve,
                             double t) {
  const Eigen::Vector3d p = surface::evaluate(pcurve, within(pcurve, t));
  const auto [u0, u1] = s.u.domain();
  const auto [v0, v1] = s.v.domain();
  return {std::clamp(p.x(), u0, u1), std::clamp(p.y(), v0, v1)};
}

}  // namespace clay::brep::detail
