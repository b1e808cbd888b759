#include <clay/surface/bspline_surface.hpp>

#include <clay/error.hpp>

#include "validation.hpp"

namespace clay::surface {

bool BSplineSurface::is_rational() const noexcept { return (weights.array() != 1.0).any(); }

BSplineSurface make_surface(BSplineBasis u, BSplineBasis v, Points3 points,
                            Eigen::VectorXd weights) {
  BSplineSurface surface;
  surface.u = std::move(u);
  surface.v = std::move(v);
  if (weights.size() == 0) weights = Eigen::VectorXd::Ones(points.rows());
  surface.points = std::move(points);
  surface.weights = std::move(weights);
  validate(surface);
  return surface;
}

std::vector<std::string> problems(const BSplineSurface& surface, std::string_view name) {
  std::vector<std::string> found = problems(surface.u, std::string(name) + " u basis");
  for (auto& f : problems(surface.v, std::string(name) + " v basis")) found.push_back(std::move(f));
  if (!found.empty()) return found;
  const Eigen::Index nu = surface.u.count(), nv = surface.v.count();
  if (surface.points.rows() != nu * nv) {
    found.push_back(std::string(name) + ": has " + std::to_string(surface.points.rows()) +
                    " control points but its knot vectors need " + std::to_string(nu) + " x " +
                    std::to_string(nv) + " = " + std::to_string(nu * nv) +
                    " (knots - degree - 1 in each direction)");
    return found;
  }
  detail::check_net(
      surface.points, surface.weights, name,
      [&](Eigen::Index r) {
        return "control point (" + std::to_string(r / nv) + ", " + std::to_string(r % nv) + ")";
      },
      found);
  return found;
}

void validate(const BSplineSurface& surface, std::string_view name) {
  internal::throw_if(ErrorCategory::InvalidGeometry, problems(surface, name));
}

bool identical(const BSplineSurface& a, const BSplineSurface& b) noexcept {
  return a.u.degree == b.u.degree && a.v.degree == b.v.degree && a.u.knots == b.u.knots &&
         a.v.knots == b.v.knots && a.points.rows() == b.points.rows() &&
         a.weights.size() == b.weights.size() && a.points == b.points && a.weights == b.weights;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> control_box(const BSplineSurface& surface) {
  if (surface.points.rows() == 0)
    throw Error(ErrorCategory::InvalidGeometry, "control_box: the surface has no control points");
  return {surface.points.colwise().minCoeff().transpose(),
          surface.points.colwise().maxCoeff().transpose()};
}

}  // namespace clay::surface
