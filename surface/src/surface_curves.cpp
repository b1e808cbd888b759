// Curves taken from a surface: exact iso-curves, and fitted projections and normal offsets.
#include <clay/surface/surface_curves.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <clay/surface/detail/builder_tools.hpp>
#include "curve_fit.hpp"
#include "homogeneous.hpp"

namespace clay::surface {
namespace {

std::string num(double x) { return detail::short_number(x); }

/// The iso-curve along direction `along` (the other direction fixed at t): the homogeneous
/// control points of the other direction contracted with its basis functions at t.
BSplineCurve iso_curve(const BSplineSurface& s, bool fixed_u, double t) {
  validate(s, "iso-curve surface");
  const BSplineBasis& fixed = fixed_u ? s.u : s.v;
  const BSplineBasis& along = fixed_u ? s.v : s.u;
  const int span = find_span(fixed, t);
  std::vector<double> n(static_cast<size_t>(fixed.degree + 1));
  basis_functions(fixed, span, t, n);
  const int count = along.count();
  detail::Homogeneous h = detail::Homogeneous::Zero(count, 4);
  for (int k = 0; k <= fixed.degree; ++k) {
    const int f = span - fixed.degree + k;
    for (int j = 0; j < count; ++j) {
      const Eigen::Index row = fixed_u ? s.index(f, j) : s.index(j, f);
      const double w = s.weights[row];
      h.row(j).head<3>() += n[static_cast<size_t>(k)] * w * s.points.row(row);
      h(j, 3) += n[static_cast<size_t>(k)] * w;
    }
  }
  BSplineCurve c;
  c.basis = along;
  detail::from_homogeneous(h, c.points, c.weights);
  if (!s.is_rational()) c.weights.setOnes();
  return c;
}

/// Least-squares fits of target(t) on a basis starting from the input's breakpoints, spans
/// halved where 16 samples per span miss the tolerance.
FittedCurve fit_target(const BSplineCurve& input,
                       const std::function<Eigen::Vector3d(double)>& target,
                       const CurveFitOptions& o, const std::string& who) {
  const int p = o.degree;
  BSplineBasis basis;
  basis.degree = p;
  const std::vector<double> breaks = breakpoints(input.basis);
  basis.knots.assign(static_cast<size_t>(p + 1), breaks.front());
  for (size_t k = 1; k + 1 < breaks.size(); ++k) {
    // Keep the input's corners (C0 knots) as corners; smoother joins get a simple knot.
    const int continuity = input.basis.degree - multiplicity(input.basis, breaks[k]);
    const int m = continuity <= 0 ? p : 1;
    basis.knots.insert(basis.knots.end(), static_cast<size_t>(m), breaks[k]);
  }
  basis.knots.insert(basis.knots.end(), static_cast<size_t>(p + 1), breaks.back());
  FittedCurve out;
  for (out.iterations = 1;; ++out.iterations) {
    const int n = basis.count();
    const Eigen::MatrixXd net =
        detail::fit_with_ends(basis, detail::lobatto_parameters(breakpoints(basis), 2 * (p + 1)),
                              [&](double t) { return Eigen::RowVectorXd(target(t).transpose()); });
    out.curve.basis = basis;
    out.curve.points = net;
    out.curve.weights = Eigen::VectorXd::Ones(n);

    const std::vector<double> spans = breakpoints(basis);
    std::vector<char> missed(spans.size() - 1, 0);
    out.max_deviation_mm = 0;
    out.samples = 0;
    double worst_at = spans.front();
    for (size_t s = 0; s + 1 < spans.size(); ++s)
      for (int k = 0; k <= 16; ++k) {
        const double u = spans[s] + (spans[s + 1] - spans[s]) * k / 16.0;
        const double e = (evaluate(out.curve, u) - target(u)).norm();
        ++out.samples;
        if (e > o.tolerance_mm) missed[s] = 1;
        if (e > out.max_deviation_mm) out.max_deviation_mm = e, worst_at = u;
      }
    const long more = std::count(missed.begin(), missed.end(), 1);
    if (more == 0) return out;
    if (n + more > o.max_control_points)
      throw Error(ErrorCategory::InvalidGeometry,
                  who + ": the fit still misses by " + num(out.max_deviation_mm) +
                      " mm at t = " + num(worst_at) + " with " + std::to_string(n) +
                      " control points (tolerance " + num(o.tolerance_mm) +
                      " mm, max_control_points " + std::to_string(o.max_control_points) +
                      "); the points there may jump between two branches of closest points: "
                      "draw the curve nearer the surface, split it there, or raise the tolerance");
    for (size_t s = 0; s + 1 < spans.size(); ++s)
      if (missed[s]) basis.knots.push_back(0.5 * (spans[s] + spans[s + 1]));
    std::sort(basis.knots.begin(), basis.knots.end());
  }
}

}  // namespace

BSplineCurve iso_curve_u(const BSplineSurface& surface, double u) {
  return iso_curve(surface, true, u);
}

BSplineCurve iso_curve_v(const BSplineSurface& surface, double v) {
  return iso_curve(surface, false, v);
}

std::vector<std::string> CurveFitOptions::problems() const {
  std::vector<std::string> out;
  if (!(tolerance_mm > 0 && std::isfinite(tolerance_mm)))
    out.push_back("CurveFitOptions::tolerance_mm is " + num(tolerance_mm) +
                  "; it must be > 0 and finite");
  if (degree < 1 || degree > 9)
    out.push_back("CurveFitOptions::degree is " + std::to_string(degree) +
                  "; it must be in [1, 9]");
  if (max_control_points <= degree)
    out.push_back("CurveFitOptions::max_control_points is " + std::to_string(max_control_points) +
                  "; it must be > degree");
  return out;
}

void CurveFitOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

FittedCurve project_curve(const BSplineCurve& curve, const BSplineSurface& surface,
                          const CurveFitOptions& options) {
  options.validate();
  validate(curve, "projected curve");
  const SurfaceProjector projector(surface);
  return fit_target(
      curve, [&](double t) { return projector.closest_point(evaluate(curve, t)).point; }, options,
      "project_curve");
}

FittedCurve offset_along_normal(const BSplineCurve& curve, const BSplineSurface& surface,
                                double distance, const CurveFitOptions& options) {
  options.validate();
  if (!std::isfinite(distance))
    throw Error(ErrorCategory::InvalidArgument, "offset_along_normal: the distance is " +
                                                    num(distance) + "; give a finite distance");
  validate(curve, "offset curve");
  const SurfaceProjector projector(surface);
  return fit_target(
      curve,
      [&](double t) {
        const SurfaceProjection foot = projector.closest_point(evaluate(curve, t));
        return Eigen::Vector3d(foot.point + distance * unit_normal(surface, foot.u, foot.v));
      },
      options, "offset_along_normal");
}

}  // namespace clay::surface
