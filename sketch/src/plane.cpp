#include <clay/sketch/plane.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <sstream>

namespace clay::sketch {

std::vector<std::string> problems(const SketchPlane& plane, std::string_view name) {
  std::vector<std::string> found;
  auto say = [&](const std::string& what) { found.push_back(std::string(name) + ": " + what); };
  if (!internal::all_finite(plane.origin))
    say("origin has a non-finite coordinate; give a finite origin");
  if (!internal::all_finite(plane.x_axis))
    say("x axis has a non-finite coordinate; give a finite unit vector");
  if (!internal::all_finite(plane.y_axis))
    say("y axis has a non-finite coordinate; give a finite unit vector");
  if (!found.empty()) return found;
  std::ostringstream s;
  s.precision(17);
  const double lx = plane.x_axis.norm(), ly = plane.y_axis.norm();
  if (std::abs(lx - 1.0) > plane_axis_tolerance) {
    s << "x axis has length " << lx << ", not 1; normalize it (or build the plane with make_plane)";
    say(s.str());
    s.str("");
  }
  if (std::abs(ly - 1.0) > plane_axis_tolerance) {
    s << "y axis has length " << ly << ", not 1; normalize it (or build the plane with make_plane)";
    say(s.str());
    s.str("");
  }
  const double dot = plane.x_axis.dot(plane.y_axis);
  if (std::abs(dot) > plane_axis_tolerance) {
    s << "axes are not orthogonal (x · y = " << dot
      << "); build the plane with make_plane(origin, normal, x direction)";
    say(s.str());
  }
  return found;
}

void validate(const SketchPlane& plane, std::string_view name) {
  internal::throw_if(ErrorCategory::InvalidGeometry, problems(plane, name));
}

SketchPlane make_plane(const Eigen::Vector3d& origin, const Eigen::Vector3d& normal,
                       const std::optional<Eigen::Vector3d>& x_direction) {
  auto bad = [](const std::string& what) {
    throw Error(ErrorCategory::InvalidArgument, "make_plane: " + what);
  };
  if (!internal::all_finite(origin))
    bad("origin has a non-finite coordinate; give a finite origin");
  if (!internal::all_finite(normal))
    bad("normal has a non-finite coordinate; give a finite normal");
  const double ln = normal.norm();
  if (!(ln > 0.0)) bad("normal has zero length; give the plane's normal direction");
  const Eigen::Vector3d n = normal / ln;
  Eigen::Vector3d x;
  if (x_direction) {
    if (!internal::all_finite(*x_direction))
      bad("x direction has a non-finite coordinate; give a finite vector");
    const double lx = x_direction->norm();
    if (!(lx > 0.0)) bad("x direction has zero length; give a direction in the plane");
    x = *x_direction / lx;
    x -= x.dot(n) * n;
    if (!(x.norm() > 1e-9))
      bad("x direction is parallel to the normal; give a direction lying in the plane");
  } else {
    // The world axis least aligned with the normal, made orthogonal to it.
    Eigen::Index k = 0;
    n.cwiseAbs().minCoeff(&k);
    x = Eigen::Vector3d::Unit(k) - n[k] * n;
  }
  x.normalize();
  SketchPlane plane;
  plane.origin = origin;
  plane.x_axis = x;
  plane.y_axis = n.cross(x).normalized();
  return plane;
}

Eigen::Vector2d to_plane(const SketchPlane& plane, const Eigen::Vector3d& point) {
  const Eigen::Vector3d d = point - plane.origin;
  return {d.dot(plane.x_axis), d.dot(plane.y_axis)};
}

Eigen::Vector3d to_world(const SketchPlane& plane, const Eigen::Vector2d& coordinates) {
  return plane.origin + coordinates.x() * plane.x_axis + coordinates.y() * plane.y_axis;
}

double signed_distance(const SketchPlane& plane, const Eigen::Vector3d& point) {
  return (point - plane.origin).dot(plane.normal());
}

}  // namespace clay::sketch
