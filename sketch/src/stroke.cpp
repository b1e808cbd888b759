#include <clay/sketch/stroke.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "stroke_points.hpp"

namespace clay::sketch {
namespace detail {

Points3 working_points(const Stroke& stroke) {
  if (!stroke.plane) return stroke.points;
  Points3 out(stroke.points.rows(), 3);
  for (Eigen::Index i = 0; i < stroke.points.rows(); ++i) {
    const Eigen::Vector2d xy = to_plane(*stroke.plane, stroke.points.row(i).transpose());
    out.row(i) << xy.x(), xy.y(), 0.0;
  }
  return out;
}

double duplicate_distance(const Points3& points) {
  if (points.rows() == 0) return 0.0;
  const double size = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  return 1e-12 * size;
}

bool zero_length(const Points3& points) {
  const double size = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  const double magnitude = std::max(1.0, points.cwiseAbs().maxCoeff());
  return !(size > 1e-12 * magnitude);
}

}  // namespace detail

std::vector<std::string> problems(const Stroke& stroke, std::string_view name,
                                  bool allow_duplicates) {
  std::vector<std::string> found;
  auto say = [&](const std::string& what) { found.push_back(std::string(name) + ": " + what); };
  const Eigen::Index n = stroke.points.rows();
  if (n == 0) {
    say("is empty; a stroke needs at least 2 points");
    return found;
  }
  if (n == 1) {
    say("has a single point; a stroke needs at least 2 points");
    return found;
  }
  int bad = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (internal::all_finite(stroke.points.row(i))) continue;
    if (bad++ < 3) {
      std::ostringstream s;
      s << "point " << i << " has a non-finite coordinate (" << stroke.points(i, 0) << ", "
        << stroke.points(i, 1) << ", " << stroke.points(i, 2) << "); remove or repair that point";
      say(s.str());
    }
  }
  if (bad > 3) say(std::to_string(bad) + " points have non-finite coordinates in all");
  if (stroke.plane) {
    for (const auto& f : problems(*stroke.plane, std::string(name) + " plane")) found.push_back(f);
  }
  if (!found.empty()) return found;
  const Points3 w = detail::working_points(stroke);
  if (detail::zero_length(w)) {
    say(std::string("has zero length: all ") + std::to_string(n) + " points are at the same place" +
        (stroke.plane ? " once projected onto its plane" : "") + "; draw a stroke that moves");
    return found;
  }
  if (allow_duplicates) return found;
  const double eps = detail::duplicate_distance(w);
  int dups = 0;
  for (Eigen::Index i = 1; i < n; ++i) {
    if ((w.row(i) - w.row(i - 1)).norm() > eps) continue;
    if (dups++ < 3) {
      std::ostringstream s;
      s << "points " << i - 1 << " and " << i << (stroke.plane ? " project onto" : " are at")
        << " the same place" << (stroke.plane ? " of its plane" : "")
        << "; remove the repeated point or set FitOptions::drop_duplicates";
      say(s.str());
    }
  }
  if (dups > 3) say(std::to_string(dups) + " repeated consecutive points in all");
  return found;
}

void validate(const Stroke& stroke, std::string_view name, bool allow_duplicates) {
  internal::throw_if(ErrorCategory::InvalidGeometry, problems(stroke, name, allow_duplicates));
}

double length(const Stroke& stroke) {
  const Points3 w = detail::working_points(stroke);
  double total = 0;
  for (Eigen::Index i = 1; i < w.rows(); ++i) total += (w.row(i) - w.row(i - 1)).norm();
  return total;
}

}  // namespace clay::sketch
