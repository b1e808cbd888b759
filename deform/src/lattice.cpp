#include <clay/deform/lattice.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/basis.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "bernstein.hpp"
#include "messages.hpp"

namespace clay::deform {

namespace {

using detail::format;
using internal::all_finite;
using internal::throw_problems;

constexpr const char* direction_name[3] = {"s", "t", "u"};

void check_degrees(std::array<int, 3> degrees, std::string_view what) {
  for (int d = 0; d < 3; ++d)
    if (degrees[d] < 1 || degrees[d] > surface::max_kernel_degree)
      throw Error(ErrorCategory::InvalidArgument,
                  std::string(what) + ": degree along " + direction_name[d] + " = " +
                      std::to_string(degrees[d]) + " breaks the rule 1 <= degree <= " +
                      std::to_string(surface::max_kernel_degree) + "; give a degree of at least 1");
}

/// Problems of the control points: their count and finiteness, naming P_ijk.
void point_problems(const Points3& points, std::array<int, 3> counts, std::string_view name,
                    std::vector<std::string>& out) {
  const Eigen::Index expected = static_cast<Eigen::Index>(counts[0]) * counts[1] * counts[2];
  if (points.rows() != expected) {
    out.push_back(std::string(name) + ": " + std::to_string(points.rows()) +
                  " control points where the degrees/knots need " + std::to_string(counts[0]) +
                  " x " + std::to_string(counts[1]) + " x " + std::to_string(counts[2]) + " = " +
                  std::to_string(expected) + "; give one row per control point P_ijk");
    return;
  }
  for (Eigen::Index r = 0; r < points.rows(); ++r)
    if (!all_finite(points.row(r))) {
      const int k = static_cast<int>(r % counts[2]);
      const int j = static_cast<int>((r / counts[2]) % counts[1]);
      const int i = static_cast<int>(r / (static_cast<Eigen::Index>(counts[1]) * counts[2]));
      out.push_back(std::string(name) + ": control point P_" + std::to_string(i) + "," +
                    std::to_string(j) + "," + std::to_string(k) + " (row " + std::to_string(r) +
                    ") is not finite " + format(Eigen::Vector3d(points.row(r))) +
                    "; give finite coordinates");
      return;  // one is enough to name the culprit
    }
}

Points3 grid_points(const Frame& frame, const std::array<std::vector<double>, 3>& xi) {
  Points3 points(static_cast<Eigen::Index>(xi[0].size() * xi[1].size() * xi[2].size()), 3);
  Eigen::Index r = 0;
  for (double a : xi[0])
    for (double b : xi[1])
      for (double c : xi[2]) points.row(r++) = frame.point(a, b, c).transpose();
  return points;
}

/// de Casteljau on `count` points in place; the result is left in pts[0].
void de_casteljau(Eigen::Vector3d* pts, int count, double t) {
  for (int level = 1; level < count; ++level)
    for (int i = 0; i < count - level; ++i) pts[i] = (1 - t) * pts[i] + t * pts[i + 1];
}

}  // namespace

// ---- Frame ----------------------------------------------------------------------------------

std::vector<std::string> problems(const Frame& frame, std::string_view name) {
  std::vector<std::string> out;
  const std::string n(name);
  const std::pair<const char*, const Eigen::Vector3d*> vectors[4] = {{"origin X0", &frame.origin},
                                                                     {"edge S", &frame.s},
                                                                     {"edge T", &frame.t},
                                                                     {"edge U", &frame.u}};
  for (const auto& [what, v] : vectors)
    if (!all_finite(*v))
      out.push_back(n + ": " + what + " " + format(*v) + " is not finite; give finite coordinates");
  if (!out.empty()) return out;
  for (int d = 1; d < 4; ++d)
    if (vectors[d].second->norm() == 0)
      out.push_back(n + ": " + vectors[d].first + " has zero length; give a non-zero edge vector");
  if (!out.empty()) return out;
  const double scale = frame.s.norm() * frame.t.norm() * frame.u.norm();
  const double volume = frame.volume();
  if (!(std::abs(volume) > 1e-12 * scale))
    out.push_back(n + ": edges S " + format(frame.s) + ", T " + format(frame.t) + ", U " +
                  format(frame.u) + " are coplanar (S x T . U = " + format(volume) + ", relative " +
                  format(volume / scale) +
                  "): the lattice has zero volume; give three independent edge vectors");
  return out;
}

void validate(const Frame& frame, std::string_view name) {
  const auto list = problems(frame, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}

Eigen::Vector3d local_coordinates(const Frame& frame, const Eigen::Vector3d& x) noexcept {
  // Sederberg–Parry eq. (1).
  const Eigen::Vector3d d = x - frame.origin;
  const Eigen::Vector3d tu = frame.t.cross(frame.u);
  const Eigen::Vector3d su = frame.s.cross(frame.u);
  const Eigen::Vector3d st = frame.s.cross(frame.t);
  return {tu.dot(d) / tu.dot(frame.s), su.dot(d) / su.dot(frame.t), st.dot(d) / st.dot(frame.u)};
}

bool inside(const Eigen::Vector3d& local) noexcept {
  for (int d = 0; d < 3; ++d)  // isfinite first: no ordered comparison with NaN
    if (!std::isfinite(local[d]) || local[d] < -face_tolerance || local[d] > 1 + face_tolerance)
      return false;
  return true;
}

namespace detail {

bool clamped_local(const Frame& frame, const Eigen::Vector3d& x, Eigen::Vector3d& local) noexcept {
  local = local_coordinates(frame, x);
  if (!inside(local)) return false;
  local = local.cwiseMax(0.0).cwiseMin(1.0);
  return true;
}

Points3 cell_points(const BSplineLattice& lattice, const SpanExtraction& ea,
                    const SpanExtraction& eb, const SpanExtraction& ec) {
  const int p = lattice.bases[0].degree, q = lattice.bases[1].degree, r = lattice.bases[2].degree;
  const int P = p + 1, Q = q + 1, R = r + 1;
  // Contract one direction at a time: u, then t, then s.
  std::vector<Eigen::Vector3d> a(static_cast<size_t>(P * Q * R)), b(a.size());
  for (int i = 0; i < P; ++i)
    for (int j = 0; j < Q; ++j)
      for (int k = 0; k < R; ++k) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int kk = 0; kk < R; ++kk)
          sum += ec.matrix(k, kk) *
                 lattice.points.row(lattice.index(ea.first + i, eb.first + j, ec.first + kk))
                     .transpose();
        a[static_cast<size_t>((i * Q + j) * R + k)] = sum;
      }
  for (int i = 0; i < P; ++i)
    for (int j = 0; j < Q; ++j)
      for (int k = 0; k < R; ++k) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int jj = 0; jj < Q; ++jj)
          sum += eb.matrix(j, jj) * a[static_cast<size_t>((i * Q + jj) * R + k)];
        b[static_cast<size_t>((i * Q + j) * R + k)] = sum;
      }
  Points3 out(P * Q * R, 3);
  for (int i = 0; i < P; ++i)
    for (int j = 0; j < Q; ++j)
      for (int k = 0; k < R; ++k) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int ii = 0; ii < P; ++ii)
          sum += ea.matrix(i, ii) * b[static_cast<size_t>((ii * Q + j) * R + k)];
        out.row((i * Q + j) * R + k) = sum.transpose();
      }
  return out;
}

std::vector<double> bernstein_to_power(const std::vector<double>& bernstein,
                                       std::array<int, 3> degrees, int dim) {
  std::vector<double> c = bernstein;
  const std::array<int, 3> n = {degrees[0] + 1, degrees[1] + 1, degrees[2] + 1};
  const std::array<long, 3> stride = {static_cast<long>(n[1]) * n[2] * dim,
                                      static_cast<long>(n[2]) * dim, dim};
  std::vector<double> line;
  for (int d = 0; d < 3; ++d) {
    const int p = degrees[d];
    line.resize(static_cast<size_t>(n[d]));
    // Every line along direction d: all index combinations of the other two directions.
    const int o1 = (d + 1) % 3, o2 = (d + 2) % 3;
    for (int a = 0; a < n[o1]; ++a)
      for (int b = 0; b < n[o2]; ++b)
        for (int v = 0; v < dim; ++v) {
          const long base = a * stride[o1] + b * stride[o2] + v;
          for (int e = 0; e < n[d]; ++e)
            line[static_cast<size_t>(e)] = c[static_cast<size_t>(base + e * stride[d])];
          // Forward differences in place: line[e] becomes Δ^e b_0.
          for (int level = 1; level <= p; ++level)
            for (int e = p; e >= level; --e)
              line[static_cast<size_t>(e)] -= line[static_cast<size_t>(e - 1)];
          for (int e = 0; e < n[d]; ++e)
            c[static_cast<size_t>(base + e * stride[d])] =
                internal::binomial(p, e) * line[static_cast<size_t>(e)];
        }
  }
  return c;
}

}  // namespace detail

// ---- Bézier lattice -------------------------------------------------------------------------

BezierLattice make_bezier_lattice(const Frame& frame, std::array<int, 3> degrees) {
  check_degrees(degrees, "make_bezier_lattice");
  validate(frame);
  BezierLattice lattice;
  lattice.frame = frame;
  lattice.degrees = degrees;
  lattice.points = undisplaced_points(lattice);
  return lattice;
}

std::vector<std::string> problems(const BezierLattice& lattice, std::string_view name) {
  std::vector<std::string> out = problems(lattice.frame, std::string(name) + " frame");
  bool degrees_ok = true;
  for (int d = 0; d < 3; ++d)
    if (lattice.degrees[d] < 1 || lattice.degrees[d] > surface::max_kernel_degree) {
      degrees_ok = false;
      out.push_back(std::string(name) + ": degree along " + direction_name[d] + " = " +
                    std::to_string(lattice.degrees[d]) + " breaks the rule 1 <= degree <= " +
                    std::to_string(surface::max_kernel_degree));
    }
  if (degrees_ok) point_problems(lattice.points, lattice.counts(), name, out);
  return out;
}

void validate(const BezierLattice& lattice, std::string_view name) {
  const auto list = problems(lattice, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}

Points3 undisplaced_points(const BezierLattice& lattice) {
  std::array<std::vector<double>, 3> xi;
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i <= lattice.degrees[d]; ++i)
      xi[d].push_back(static_cast<double>(i) / lattice.degrees[d]);
  return grid_points(lattice.frame, xi);
}

Eigen::Vector3d deform_point(const BezierLattice& lattice, const Eigen::Vector3d& x) {
  Eigen::Vector3d local;
  if (!detail::clamped_local(lattice.frame, x, local)) return x;
  const auto [P, Q, R] = lattice.counts();
  // Sederberg–Parry eq. (2) by de Casteljau: in u for every (i, j), then in t, then in s.
  std::vector<Eigen::Vector3d> row(static_cast<size_t>(std::max({P, Q, R})));
  std::vector<Eigen::Vector3d> ti(static_cast<size_t>(Q)), si(static_cast<size_t>(P));
  for (int i = 0; i < P; ++i) {
    for (int j = 0; j < Q; ++j) {
      for (int k = 0; k < R; ++k)
        row[static_cast<size_t>(k)] = lattice.points.row(lattice.index(i, j, k)).transpose();
      de_casteljau(row.data(), R, local.z());
      ti[static_cast<size_t>(j)] = row[0];
    }
    de_casteljau(ti.data(), Q, local.y());
    si[static_cast<size_t>(i)] = ti[0];
  }
  de_casteljau(si.data(), P, local.x());
  return si[0];
}

// ---- B-spline lattice -----------------------------------------------------------------------

BSplineLattice make_bspline_lattice(const Frame& frame, std::array<int, 3> degrees,
                                    std::array<int, 3> cells, LatticeKnots knots) {
  check_degrees(degrees, "make_bspline_lattice");
  for (int d = 0; d < 3; ++d)
    if (cells[d] < 1)
      throw Error(ErrorCategory::InvalidArgument,
                  std::string("make_bspline_lattice: cells along ") + direction_name[d] + " = " +
                      std::to_string(cells[d]) + " breaks the rule cells >= 1");
  std::array<surface::BSplineBasis, 3> bases;
  for (int d = 0; d < 3; ++d) {
    const int p = degrees[d], n = cells[d];
    if (knots == LatticeKnots::Clamped) {
      bases[d] = surface::clamped_uniform_basis(p, n + p, 0.0, 1.0);
    } else {
      bases[d].degree = p;
      for (int i = -p; i <= n + p; ++i) bases[d].knots.push_back(static_cast<double>(i) / n);
    }
  }
  return make_bspline_lattice(frame, std::move(bases));
}

namespace {

/// Problems of the frame and the bases (everything but the control points).
std::vector<std::string> structure_problems(const BSplineLattice& lattice, const std::string& n,
                                            bool& bases_ok) {
  std::vector<std::string> out = problems(lattice.frame, n + " frame");
  bases_ok = true;
  for (int d = 0; d < 3; ++d) {
    const std::string basis_name = n + " " + direction_name[d] + " basis";
    auto list = surface::problems(lattice.bases[d], basis_name);
    if (list.empty()) {
      const auto [a, b] = lattice.bases[d].domain();
      if (a != 0.0 || b != 1.0)
        list.push_back(basis_name + ": domain [" + format(a) + ", " + format(b) +
                       "] is not [0, 1]; scale the knots so the domain is the unit interval");
    }
    if (!list.empty()) bases_ok = false;
    out.insert(out.end(), list.begin(), list.end());
  }
  return out;
}

}  // namespace

BSplineLattice make_bspline_lattice(const Frame& frame,
                                    std::array<surface::BSplineBasis, 3> bases) {
  BSplineLattice lattice;
  lattice.frame = frame;
  lattice.bases = std::move(bases);
  bool bases_ok = true;
  const auto list = structure_problems(lattice, "make_bspline_lattice", bases_ok);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
  lattice.points = undisplaced_points(lattice);
  return lattice;
}

std::vector<std::string> problems(const BSplineLattice& lattice, std::string_view name) {
  bool bases_ok = true;
  std::vector<std::string> out = structure_problems(lattice, std::string(name), bases_ok);
  if (bases_ok) point_problems(lattice.points, lattice.counts(), name, out);
  return out;
}

void validate(const BSplineLattice& lattice, std::string_view name) {
  const auto list = problems(lattice, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}

Points3 undisplaced_points(const BSplineLattice& lattice) {
  return grid_points(lattice.frame, {surface::greville_abscissae(lattice.bases[0]),
                                     surface::greville_abscissae(lattice.bases[1]),
                                     surface::greville_abscissae(lattice.bases[2])});
}

Eigen::Vector3d deform_point(const BSplineLattice& lattice, const Eigen::Vector3d& x) {
  Eigen::Vector3d local;
  if (!detail::clamped_local(lattice.frame, x, local)) return x;
  // Hsu–Hughes–Kaufman eq. (1): sum over the non-zero basis functions of each direction.
  std::array<int, 3> span;
  std::array<std::vector<double>, 3> N;
  for (int d = 0; d < 3; ++d) {
    span[d] = surface::find_span(lattice.bases[d], local[d]);
    N[d].resize(static_cast<size_t>(lattice.bases[d].degree + 1));
    surface::basis_functions(lattice.bases[d], span[d], local[d], N[d]);
  }
  const int p = lattice.bases[0].degree, q = lattice.bases[1].degree, r = lattice.bases[2].degree;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= q; ++j)
      for (int k = 0; k <= r; ++k)
        sum += N[0][static_cast<size_t>(i)] * N[1][static_cast<size_t>(j)] *
               N[2][static_cast<size_t>(k)] *
               lattice.points.row(lattice.index(span[0] - p + i, span[1] - q + j, span[2] - r + k))
                   .transpose();
  return sum;
}

BezierCells bezier_cells(const BSplineLattice& lattice) {
  validate(lattice);
  std::array<std::vector<detail::SpanExtraction>, 3> spans;
  BezierCells out;
  for (int d = 0; d < 3; ++d) {
    spans[d] = surface::bezier_extraction(lattice.bases[d]);
    for (const auto& e : spans[d]) out.breaks[d].push_back(e.a);
    out.breaks[d].push_back(spans[d].back().b);
  }
  const std::array<int, 3> degrees = {lattice.bases[0].degree, lattice.bases[1].degree,
                                      lattice.bases[2].degree};
  const Frame& f = lattice.frame;
  for (const auto& ea : spans[0])
    for (const auto& eb : spans[1])
      for (const auto& ec : spans[2]) {
        BezierLattice cell;
        cell.frame.origin = f.point(ea.a, eb.a, ec.a);
        cell.frame.s = (ea.b - ea.a) * f.s;
        cell.frame.t = (eb.b - eb.a) * f.t;
        cell.frame.u = (ec.b - ec.a) * f.u;
        cell.degrees = degrees;
        cell.points = detail::cell_points(lattice, ea, eb, ec);
        out.cells.push_back(std::move(cell));
      }
  return out;
}

}  // namespace clay::deform
