// The grid tessellator and the surface area by quadrature (tessellate.hpp).
#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/tessellate.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "quadrature.hpp"

namespace clay::surface {

std::vector<double> tessellation_parameters(const BSplineBasis& basis, int per_span, int max_samples) {
  constexpr int min_samples = 17;
  if (per_span < 1 || max_samples < min_samples)
    throw Error(ErrorCategory::InvalidArgument,
                "tessellation_parameters: per_span = " + std::to_string(per_span) + " and max_samples = " +
                    std::to_string(max_samples) + " must be >= 1 and >= 17");
  const auto breaks = breakpoints(basis);
  const int spans = static_cast<int>(breaks.size()) - 1;
  const auto [t0, t1] = basis.domain();
  if (spans < 1 || spans > max_samples - 1) return linspace(t0, t1, max_samples);
  int per = std::clamp((max_samples - 1) / spans, 1, per_span);
  if (spans * per < min_samples - 1) per = (min_samples - 1 + spans - 1) / spans;
  return span_samples(basis, per);
}

std::array<std::array<int, 3>, 2> cell_triangles(const GridMesh& m, int i, int j) {
  const int a = i * m.cols + j, b = a + 1, c = a + m.cols, d = c + 1;  // (i,j) (i,j+1) (i+1,j) (i+1,j+1)
  const double ad = (m.positions.row(d) - m.positions.row(a)).squaredNorm();
  const double bc = (m.positions.row(c) - m.positions.row(b)).squaredNorm();
  // Counter-clockwise in (u, v), so the triangles face along S_u x S_v.
  if (ad <= bc) return {{{a, c, d}, {a, d, b}}};
  return {{{a, c, b}, {b, c, d}}};
}

GridMesh tessellate(const BSplineSurface& s, int per_span, int max_samples) {
  validate(s, "surface to tessellate");
  GridMesh m;
  m.us = tessellation_parameters(s.u, per_span, max_samples);
  m.vs = tessellation_parameters(s.v, per_span, max_samples);
  m.rows = static_cast<int>(m.us.size());
  m.cols = static_cast<int>(m.vs.size());
  m.positions = evaluate_grid(s, m.us, m.vs);
  m.normals = Points3::Zero(m.positions.rows(), 3);
  std::vector<char> degenerate(static_cast<size_t>(m.positions.rows()), 0);
  std::vector<SurfaceDerivatives> d(static_cast<size_t>(m.positions.rows()));
  double max_u = 0, max_v = 0;
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j) {
      auto& e = d[static_cast<size_t>(i * m.cols + j)];
      e = derivatives(s, m.us[static_cast<size_t>(i)], m.vs[static_cast<size_t>(j)], 1);
      max_u = std::max(max_u, e.du.norm());
      max_v = std::max(max_v, e.dv.norm());
    }
  // Degenerate where a first derivative is below 1e-5 of its largest on the grid (a pole of a
  // rational revolve has |S_u| of rounding size, not 0, and its cross product is noise) or the
  // two are parallel (the view's rule).
  for (size_t k = 0; k < d.size(); ++k) {
    const Eigen::Vector3d n = d[k].du.cross(d[k].dv);
    const double nn = n.norm(), nu = d[k].du.norm(), nv = d[k].dv.norm();
    if (std::isfinite(nn) && nu > 1e-5 * max_u && nv > 1e-5 * max_v && nn > 1e-8 * nu * nv)
      m.normals.row(static_cast<Eigen::Index>(k)) = (n / nn).transpose();
    else
      degenerate[k] = 1;
  }
  // Where S_u x S_v vanishes: the neighbouring triangles' normals, weighted by area.
  if (std::any_of(degenerate.begin(), degenerate.end(), [](char c) { return c != 0; })) {
    Points3 sum = Points3::Zero(m.positions.rows(), 3);
    for (int i = 0; i + 1 < m.rows; ++i)
      for (int j = 0; j + 1 < m.cols; ++j)
        for (const auto& t : cell_triangles(m, i, j)) {
          const Eigen::Vector3d a = m.positions.row(t[0]).transpose(), b = m.positions.row(t[1]).transpose(),
                                c = m.positions.row(t[2]).transpose();
          const Eigen::Vector3d n = (b - a).cross(c - a);
          for (int v : t) sum.row(v) += n.transpose();
        }
    // Vertices at one point (a pole: a whole grid line collapsed) share the sum of all their
    // triangles, so a pole's normal is the axis, not tilted toward one meridian.
    // Points within 1e-9 of the mesh's size are one point (rational evaluation rounds).
    const double quantum = 1e-9 * std::max(1e-300, (m.positions.colwise().maxCoeff() - m.positions.colwise().minCoeff()).norm());
    auto key = [&](Eigen::Index k) {
      return std::array<long long, 3>{std::llround(m.positions(k, 0) / quantum), std::llround(m.positions(k, 1) / quantum),
                                      std::llround(m.positions(k, 2) / quantum)};
    };
    std::map<std::array<long long, 3>, Eigen::RowVector3d> at_point;
    for (Eigen::Index k = 0; k < m.positions.rows(); ++k)
      if (degenerate[static_cast<size_t>(k)]) {
        auto [it, fresh] = at_point.try_emplace(key(k), Eigen::RowVector3d::Zero());
        it->second += sum.row(k);
      }
    for (Eigen::Index k = 0; k < m.positions.rows(); ++k)
      if (degenerate[static_cast<size_t>(k)]) {
        const Eigen::RowVector3d n = at_point.at(key(k));
        if (n.norm() > 0) m.normals.row(k) = n / n.norm();
      }
  }
  return m;
}

double mesh_area(const GridMesh& m) {
  double area = 0;
  for (int i = 0; i + 1 < m.rows; ++i)
    for (int j = 0; j + 1 < m.cols; ++j)
      for (const auto& t : cell_triangles(m, i, j)) {
        const Eigen::Vector3d a = m.positions.row(t[0]).transpose(), b = m.positions.row(t[1]).transpose(),
                              c = m.positions.row(t[2]).transpose();
        area += 0.5 * (b - a).cross(c - a).norm();
      }
  return area;
}

double surface_area(const BSplineSurface& s, int refine) {
  validate(s, "surface whose area is wanted");
  if (refine < 0 || refine > 10)
    throw Error(ErrorCategory::InvalidArgument,
                "surface_area: refine = " + std::to_string(refine) + " must be in [0, 10]");
  auto pieces = [&](const BSplineBasis& b) {
    const auto breaks = breakpoints(b);
    std::vector<double> out;
    const int parts = 1 << refine;
    for (size_t k = 0; k + 1 < breaks.size(); ++k)
      for (int p = 0; p < parts; ++p) out.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * p / parts);
    out.push_back(breaks.back());
    return out;
  };
  const std::vector<double> pu = pieces(s.u), pv = pieces(s.v);
  double area = 0;
  for (size_t a = 0; a + 1 < pu.size(); ++a)
    for (size_t b = 0; b + 1 < pv.size(); ++b)
      area += detail::gauss_legendre_8(pu[a], pu[a + 1], [&](double u) {
        return detail::gauss_legendre_8(pv[b], pv[b + 1], [&](double v) {
          const SurfaceDerivatives d = derivatives(s, u, v, 1);
          return d.du.cross(d.dv).norm();
        });
      });
  return area;
}

GridMesh tessellate_to_area(const BSplineSurface& s, double relative_area, int max_samples) {
  if (!(relative_area > 0 && relative_area < 0.5))
    throw Error(ErrorCategory::InvalidArgument,
                "tessellate_to_area: relative_area = " + std::to_string(relative_area) + " must be in (0, 0.5)");
  if (max_samples < 17 || max_samples > 4097)
    throw Error(ErrorCategory::InvalidArgument,
                "tessellate_to_area: max_samples = " + std::to_string(max_samples) + " must be in [17, 4097]");
  const double exact = surface_area(s, 2);
  // First the viewer's grid, then twice as many samples per span each round, until the area is
  // met or both directions are at max_samples.
  GridMesh m = tessellate(s, 8, std::min(161, max_samples));
  for (int per_span = 16; per_span <= 2 * max_samples; per_span *= 2) {
    if (std::abs(mesh_area(m) - exact) <= relative_area * exact) return m;
    // A few spans keep at least 17 samples, so the first doublings may not change the grid.
    const std::size_t rows = tessellation_parameters(s.u, per_span, max_samples).size();
    const std::size_t cols = tessellation_parameters(s.v, per_span, max_samples).size();
    if (static_cast<int>(rows) == m.rows && static_cast<int>(cols) == m.cols) continue;
    m = tessellate(s, per_span, max_samples);
  }
  if (std::abs(mesh_area(m) - exact) <= relative_area * exact) return m;
  const double got = mesh_area(m);
  char buffer[240];
  std::snprintf(buffer, sizeof buffer,
                "tessellate_to_area: the finest grid allowed (%d x %d samples) has area %.6g mm^2, the surface "
                "%.6g mm^2: off by %.3g %%, more than %.3g %%",
                m.rows, m.cols, got, exact, 100 * std::abs(got - exact) / exact, 100 * relative_area);
  throw Error(ErrorCategory::ToleranceNotMet, buffer);
}

}  // namespace clay::surface
