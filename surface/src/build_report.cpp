#include <clay/surface/build_report.hpp>

#include <cstdio>

namespace clay::surface {

std::string BuildReport::brief() const {
  char buffer[256];
  std::snprintf(
      buffer, sizeof buffer,
      "%s: degree (%d, %d), %d x %d control points, %s, %s (max deviation %.2g mm on %d samples)",
      method.c_str(), degree_u, degree_v, count_u, count_v, rational ? "rational" : "polynomial",
      exact ? "exact" : "approximated", max_deviation_mm, samples);
  return buffer;
}

BuildReport describe(const BSplineSurface& surface, std::string method) {
  BuildReport r;
  r.method = std::move(method);
  r.degree_u = surface.u.degree;
  r.degree_v = surface.v.degree;
  r.count_u = surface.count_u();
  r.count_v = surface.count_v();
  r.rational = surface.is_rational();
  return r;
}

}  // namespace clay::surface
