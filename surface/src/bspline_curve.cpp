#include <clay/surface/bspline_curve.hpp>

#include <clay/error.hpp>

#include <cmath>

#include "validation.hpp"

namespace clay::surface {

bool BSplineCurve::is_rational() const noexcept { return (weights.array() != 1.0).any(); }

BSplineCurve make_curve(int degree, std::vector<double> knots, Points3 points,
                        Eigen::VectorXd weights) {
  BSplineCurve curve;
  curve.basis.degree = degree;
  curve.basis.knots = std::move(knots);
  if (weights.size() == 0) weights = Eigen::VectorXd::Ones(points.rows());
  curve.points = std::move(points);
  curve.weights = std::move(weights);
  validate(curve);
  return curve;
}

std::vector<std::string> problems(const BSplineCurve& curve, std::string_view name) {
  std::vector<std::string> found = problems(curve.basis, std::string(name) + " basis");
  if (!found.empty()) return found;
  const Eigen::Index n = curve.basis.count();
  if (curve.points.rows() != n) {
    found.push_back(std::string(name) + ": has " + std::to_string(curve.points.rows()) +
                    " control points but its knot vector (" +
                    std::to_string(curve.basis.knots.size()) + " knots, degree " +
                    std::to_string(curve.basis.degree) + ") needs " + std::to_string(n) +
                    " (knots - degree - 1)");
    return found;
  }
  detail::check_net(
      curve.points, curve.weights, name,
      [&](Eigen::Index r) { return "control point " + std::to_string(r); }, found);
  return found;
}

void validate(const BSplineCurve& curve, std::string_view name) {
  internal::throw_if(ErrorCategory::InvalidGeometry, problems(curve, name));
}

bool identical(const BSplineCurve& a, const BSplineCurve& b) noexcept {
  return a.basis.degree == b.basis.degree && a.basis.knots == b.basis.knots &&
         a.points.rows() == b.points.rows() && a.weights.size() == b.weights.size() &&
         a.points == b.points && a.weights == b.weights;
}

BSplineCurve reversed(const BSplineCurve& curve) {
  validate(curve);
  BSplineCurve c = curve;
  const auto [a, b] = curve.basis.domain();
  const size_t m = curve.basis.knots.size();
  for (size_t i = 0; i < m; ++i) c.basis.knots[i] = a + b - curve.basis.knots[m - 1 - i];
  c.points = curve.points.colwise().reverse();
  c.weights = curve.weights.reverse();
  return c;
}

}  // namespace clay::surface
