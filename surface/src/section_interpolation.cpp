// Interpolation of compatible sections across v (The NURBS Book §10.3), shared by loft and sweep
// (section_interpolation.hpp).
#include "section_interpolation.hpp"

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/tolerance.hpp>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <clay/surface/detail/builder_tools.hpp>

namespace clay::surface::detail {

/// Knots by averaging (The NURBS Book eq. 9.8) for parameters v (v.front() = 0, v.back() = 1).
BSplineBasis averaged_basis(const std::vector<double>& v, int q) {
  const int count = static_cast<int>(v.size());
  BSplineBasis basis;
  basis.degree = q;
  basis.knots.assign(static_cast<size_t>(q + 1), 0.0);
  for (int j = 1; j <= count - q - 1; ++j) {
    double sum = 0;
    for (int i = j; i <= j + q - 1; ++i) sum += v[static_cast<size_t>(i)];
    basis.knots.push_back(sum / q);
  }
  basis.knots.insert(basis.knots.end(), static_cast<size_t>(q + 1), 1.0);
  return basis;
}

/// The surface whose iso-curve v = v[k] is sections[k] (all compatible: same basis), degree q in
/// v. Rational sections are interpolated in homogeneous coordinates; polynomial ones in Cartesian
/// coordinates so the weights stay exactly 1.
BSplineSurface interpolate_sections(const std::vector<BSplineCurve>& sections,
                                    const std::vector<double>& v, const BSplineBasis& basis_v) {
  const int count = static_cast<int>(sections.size());
  const int n = sections.front().basis.count();
  const int q = basis_v.degree;
  if (basis_v.count() != count)
    throw Error(ErrorCategory::Internal, "loft: " + std::to_string(basis_v.count()) +
                                             " basis functions across " + std::to_string(count) +
                                             " sections (please report this input)");
  const bool rational = std::any_of(sections.begin(), sections.end(),
                                    [](const BSplineCurve& c) { return c.is_rational(); });

  // Collocation matrix N_j(v_k): banded and totally positive (de Boor), sparse LU solves it.
  Eigen::SparseMatrix<double> A(count, count);
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<double> values(static_cast<size_t>(q + 1));
  for (int k = 0; k < count; ++k) {
    const int span = find_span(basis_v, v[static_cast<size_t>(k)]);
    basis_functions(basis_v, span, v[static_cast<size_t>(k)], values);
    for (int j = 0; j <= q; ++j)
      if (values[static_cast<size_t>(j)] != 0.0)
        entries.emplace_back(k, span - q + j, values[static_cast<size_t>(j)]);
  }
  A.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  lu.compute(A);
  if (lu.info() != Eigen::Success)
    throw Error(ErrorCategory::Internal,
                "loft: the interpolation matrix across the sections is singular; the section "
                "parameters are not increasing (please report this input)");

  const int width = rational ? 4 : 3;
  Eigen::MatrixXd rhs(count, width * n);
  for (int k = 0; k < count; ++k) {
    const BSplineCurve& c = sections[static_cast<size_t>(k)];
    for (int i = 0; i < n; ++i) {
      const double w = c.weights[i];
      for (int d = 0; d < 3; ++d)
        rhs(k, width * i + d) = rational ? w * c.points(i, d) : c.points(i, d);
      if (rational) rhs(k, width * i + 3) = w;
    }
  }
  const Eigen::MatrixXd x = lu.solve(rhs);

  BSplineSurface s;
  s.u = sections.front().basis;
  s.v = basis_v;
  s.points.resize(static_cast<Eigen::Index>(n) * count, 3);
  s.weights = Eigen::VectorXd::Ones(s.points.rows());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < count; ++j) {
      const Eigen::Index r = s.index(i, j);
      if (rational) {
        const double w = x(j, width * i + 3);
        if (!(w > 0.0))
          throw Error(ErrorCategory::InvalidGeometry,
                      "loft: the weights interpolated across the rational sections are not "
                      "positive at control point (" +
                          std::to_string(i) + ", " + std::to_string(j) + ") (weight " +
                          short_number(w) +
                          "); give sections with similar weights or lower the "
                          "loft degree");
        s.weights[r] = w;
        for (int d = 0; d < 3; ++d) s.points(r, d) = x(j, width * i + d) / w;
      } else {
        for (int d = 0; d < 3; ++d) s.points(r, d) = x(j, width * i + d);
      }
    }
  return s;
}

/// Same with knots by averaging (The NURBS Book eq. 9.8) for degree q.
BSplineSurface interpolate_sections(const std::vector<BSplineCurve>& sections,
                                    const std::vector<double>& v, int q) {
  return interpolate_sections(sections, v, averaged_basis(v, q));
}

}  // namespace clay::surface::detail
