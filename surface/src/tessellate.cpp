// The grid tessellator and the surface area by quadrature (tessellate.hpp).
#include <clay/error.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/tessellate.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace clay::surface {

std::vector<double> tessellation_parameters(const BSplineBasis& basis, int per_span,
                                            int max_samples) {
  constexpr int min_samples = 17;
  // The upper bounds keep a grid within 4097 x 4097 points (16.8 M, 400 MB of positions and
  // normals): a billion per span was asked of the allocator as it was (issue #36).
  if (per_span < 1 || per_span > 4096 || max_samples < min_samples || max_samples > 4097)
    throw Error(ErrorCategory::InvalidArgument,
                "tessellation_parameters: per_span = " + std::to_string(per_span) +
                    " and max_samples = " + std::to_string(max_samples) +
                    " must be in [1, 4096] and [17, 4097]");
  const auto breaks = breakpoints(basis);
  const int spans = static_cast<int>(breaks.size()) - 1;
  const auto [t0, t1] = basis.domain();
  if (spans < 1 || spans > max_samples - 1) return linspace(t0, t1, max_samples);
  int per = std::clamp((max_samples - 1) / spans, 1, per_span);
  if (spans * per < min_samples - 1) per = (min_samples - 1 + spans - 1) / spans;
  return span_samples(basis, per);
}

std::array<std::array<int, 3>, 2> cell_triangles(const GridMesh& m, int i, int j) {
  const int a = i * m.cols + j, b = a + 1, c = a + m.cols,
            d = c + 1;  // (i,j) (i,j+1) (i+1,j) (i+1,j+1)
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
  const std::vector<SurfaceDerivatives> d = derivatives_grid(s, m.us, m.vs);
  double max_u = 0, max_v = 0;  // the scale below which a first derivative vanishes
  for (const SurfaceDerivatives& e : d) {
    max_u = std::max(max_u, e.du.norm());
    max_v = std::max(max_v, e.dv.norm());
  }
  auto point = [&](int i, int j) -> Eigen::Vector3d {
    return m.positions.row(i * m.cols + j).transpose();
  };
  // The cells around a point, each by its diagonals (a cell with one collapsed edge still has a
  // proper normal), oriented like S_u x S_v: the reference for the orientation at a pole.
  auto cell_normal = [&](int i, int j) -> Eigen::Vector3d {
    if (i < 0 || j < 0 || i >= m.rows - 1 || j >= m.cols - 1) return Eigen::Vector3d::Zero();
    const Eigen::Vector3d n =
        (point(i + 1, j + 1) - point(i, j)).cross(point(i, j + 1) - point(i + 1, j));
    const double len = n.norm();
    return len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  };
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j) {
      const SurfaceDerivatives& e = d[static_cast<std::size_t>(i * m.cols + j)];
      Eigen::Vector3d cells = cell_normal(i - 1, j - 1) + cell_normal(i - 1, j) +
                              cell_normal(i, j - 1) + cell_normal(i, j);
      if (cells.norm() > 0) cells.normalize();
      // Trusted when it exists and is within 60 degrees of the cells around it.
      auto trusted = [&](const Eigen::Vector3d& n, double scale) {
        return std::isfinite(n.norm()) && n.norm() > 1e-9 * scale &&
               (cells.norm() == 0 || n.normalized().dot(cells) > 0.5);
      };
      const double lu = max_u > 0 ? e.du.norm() / max_u : 0,
                   lv = max_v > 0 ? e.dv.norm() / max_v : 0;
      Eigen::Vector3d n = e.du.cross(e.dv);
      if (lu < 1e-8 || lv < 1e-8 || !trusted(n, e.du.norm() * e.dv.norm())) {
        // A pole (S_v ~ 0 along an edge u = a, exactly or nearly, as after a refit): near it
        // S_v ~ (u - a) S_uv, so the limit normal is S_u x S_uv (S_uv x S_v when S_u vanishes);
        // else the cells around the point.
        n = lv <= lu ? e.du.cross(e.duv) : e.duv.cross(e.dv);
        if (n.dot(cells) < 0) n = -n;
        if (!trusted(n, std::max(e.du.norm(), e.dv.norm()) * e.duv.norm())) n = cells;
      }
      const double len = n.norm();
      if (len > 0) m.normals.row(i * m.cols + j) = (n / len).transpose();
    }
  return m;
}

double mesh_area(const GridMesh& m) {
  double area = 0;
  for (int i = 0; i + 1 < m.rows; ++i)
    for (int j = 0; j + 1 < m.cols; ++j)
      for (const auto& t : cell_triangles(m, i, j)) {
        const Eigen::Vector3d a = m.positions.row(t[0]).transpose(),
                              b = m.positions.row(t[1]).transpose(),
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
      for (int p = 0; p < parts; ++p)
        out.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * p / parts);
    out.push_back(breaks.back());
    return out;
  };
  const std::vector<double> pu = pieces(s.u), pv = pieces(s.v);
  double area = 0;
  for (size_t a = 0; a + 1 < pu.size(); ++a)
    for (size_t b = 0; b + 1 < pv.size(); ++b)
      area += internal::gauss_legendre_8(pu[a], pu[a + 1], [&](double u) {
        return internal::gauss_legendre_8(pv[b], pv[b + 1], [&](double v) {
          const SurfaceDerivatives d = derivatives(s, u, v, 1);
          return d.du.cross(d.dv).norm();
        });
      });
  return area;
}

GridMesh tessellate_to_area(const BSplineSurface& s, double relative_area, int max_samples) {
  if (!(relative_area > 0 && relative_area < 0.5))
    throw Error(ErrorCategory::InvalidArgument,
                "tessellate_to_area: relative_area = " + std::to_string(relative_area) +
                    " must be in (0, 0.5)");
  if (max_samples < 17 || max_samples > 4097)
    throw Error(ErrorCategory::InvalidArgument,
                "tessellate_to_area: max_samples = " + std::to_string(max_samples) +
                    " must be in [17, 4097]");
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
                "tessellate_to_area: the finest grid allowed (%d x %d samples) has area %.6g mm^2, "
                "the surface "
                "%.6g mm^2: off by %.3g %%, more than %.3g %%",
                m.rows, m.cols, got, exact, 100 * std::abs(got - exact) / exact,
                100 * relative_area);
  throw Error(ErrorCategory::ToleranceNotMet, buffer);
}

}  // namespace clay::surface
