// Certified refit of a deformed surface (issue #7 item 4): least-squares B-spline fit of D(S(u, v))
// refined span by span, and per cell a bound of |fit − D∘S| from a dense sample plus a Taylor
// remainder whose derivatives are bounded by convex hulls of difference nets (fit, S) and by
// bounds of D' and D'' over the cell's hull. See refit.hpp and docs/deform.md.
//
// Note for the lead: the other certificate, comparing control nets after splitting and
// degree elevation to a common basis, needs the exact Bézier composition (compose.hpp, written in
// parallel); it is not used here. This file has no Bernstein-product routine of its own.
#include <clay/deform/refit.hpp>

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/internal/checks.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "extended_internal.hpp"
#include "seal.hpp"
#include "messages.hpp"

namespace clay::deform {

namespace {

using surface::BSplineBasis;
using surface::BSplineSurface;

constexpr double infinity = std::numeric_limits<double>::infinity();

using detail::format;

std::string short_format(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

// ---- bounds of a deformation over the convex hull of some points ----------------------------

/// sup ||D'|| (operator norm) and sup ||D''|| (|D''[a, a]| <= second |a|^2) over a region;
/// second = inf where D' is not Lipschitz there (a kink of D crosses the region).
struct Bounds {
  double first = infinity;
  double second = infinity;
};

/// A plane of a lattice crossed by a region.
struct Plane {
  int step = 0;
  int axis = 0;
  double value = 0;
};

struct HullInfo {
  Bounds bounds;
  std::vector<Plane> planes;
};

/// What the refit needs of a deformation: the map, and (when certifiable) bounds over the convex
/// hull of a set of points.
struct Certifier {
  std::string name;
  PointMap map;
  std::function<HullInfo(const Points3& hull)> info;  // empty: not certifiable
  std::string why_not;                                // why `info` is empty
};

/// Σ_{i >= order} |c_i| i! / (i − order)! Z^(i − order): a bound of |p^(order)(z)| for |z| <= Z.
double polynomial_bound(const std::vector<double>& c, int order, double z_abs) {
  double total = 0;
  for (std::size_t i = static_cast<std::size_t>(order); i < c.size(); ++i) {
    double factor = 1;
    for (int k = 0; k < order; ++k) factor *= static_cast<double>(i) - k;
    total += std::abs(c[i]) * factor * std::pow(z_abs, static_cast<double>(i) - order);
  }
  return total;
}

/// Barr's local axes as rows of r (regular.cpp's basis_of): axial_z: rows x = reference, y =
/// z × x, z = axis; otherwise (bend) rows x = y × z, y = axis, z = reference.
struct LocalAxes {
  Eigen::Vector3d origin;
  Eigen::Matrix3d r;
  Eigen::Vector3d local(const Eigen::Vector3d& x) const { return r * (x - origin); }
};

LocalAxes local_axes(const AxisFrame& f, bool axial_z) {
  const Eigen::Vector3d a = f.axis / f.axis.norm();
  const Eigen::Vector3d perpendicular = f.reference - f.reference.dot(a) * a;
  const Eigen::Vector3d ref = perpendicular / perpendicular.norm();
  const Eigen::Vector3d third = a.cross(ref);
  LocalAxes l{f.origin, Eigen::Matrix3d()};
  if (axial_z) {
    l.r.row(0) = ref, l.r.row(1) = third, l.r.row(2) = a;
  } else {
    l.r.row(0) = third, l.r.row(1) = a, l.r.row(2) = ref;
  }
  return l;
}

/// Axial range and largest distance from the axis of the hull (local z, rho = |(x, y)|; rho is
/// convex, so its maximum over the hull is at a point).
struct AxialRange {
  double z_abs = 0, rho = 0;
};
AxialRange axial_range(const LocalAxes& axes, const Points3& hull) {
  AxialRange a;
  for (Eigen::Index r = 0; r < hull.rows(); ++r) {
    const Eigen::Vector3d l = axes.local(hull.row(r).transpose());
    a.z_abs = std::max(a.z_abs, std::abs(l.z()));
    a.rho = std::max(a.rho, std::hypot(l.x(), l.y()));
  }
  return a;
}

/// Taper X = (r x, r y, z): D' has columns r e_x, r e_y, (r' x, r' y, 1), so ||D'|| <=
/// sqrt(2 r^2 + rho^2 r'^2 + 1); D''[a, a] = 2 a_z r' (a_x, a_y) + a_z^2 r'' (x, y), so
/// ||D''|| <= |r'| + rho |r''|. Rotations to and from local coordinates keep both norms.
HullInfo taper_info(const Taper& d, const Points3& hull) {
  const AxialRange a = axial_range(local_axes(d.frame, true), hull);
  const double r0 = polynomial_bound(d.profile, 0, a.z_abs);
  const double r1 = polynomial_bound(d.profile, 1, a.z_abs);
  const double r2 = polynomial_bound(d.profile, 2, a.z_abs);
  return {{std::sqrt(2 * r0 * r0 + a.rho * a.rho * r1 * r1 + 1), r1 + a.rho * r2}, {}};
}

/// Twist X = (R(θ(z)) (x, y), z): ||D'|| <= sqrt(3 + rho^2 θ'^2); the only second derivatives
/// are D_xz, D_yz (norm |θ'|) and D_zz = θ'^2 R'' (x, y) + θ'' R' (x, y), so ||D''|| <=
/// |θ'| + rho (θ'^2 + |θ''|).
HullInfo twist_info(const Twist& d, const Points3& hull) {
  const AxialRange a = axial_range(local_axes(d.frame, true), hull);
  const double t1 = polynomial_bound(d.angle, 1, a.z_abs);
  const double t2 = polynomial_bound(d.angle, 2, a.z_abs);
  return {{std::sqrt(3 + a.rho * a.rho * t1 * t1), t1 + a.rho * (t1 * t1 + t2)}, {}};
}

/// Bend: in the region D' has columns e_x, (1 − k z)(0, Cθ, Sθ), (0, −Sθ, Cθ) and D'' the
/// entries D_yy = k (1 − k z)(0, −Sθ, Cθ), D_yz = −k (0, Cθ, Sθ), so ||D''|| <= |k| (|1 − k z| +
/// 1); the parts outside are rigid (||D'|| = 1, D'' = 0). Across y_min and y_max D' jumps off the
/// neutral plane: a hull crossing them gets second = inf.
HullInfo bend_info(const Bend& d, const Points3& hull) {
  const LocalAxes axes = local_axes(d.frame, false);
  double y_lo = infinity, y_hi = -infinity, z_lo = infinity, z_hi = -infinity;
  for (Eigen::Index r = 0; r < hull.rows(); ++r) {
    const Eigen::Vector3d l = axes.local(hull.row(r).transpose());
    y_lo = std::min(y_lo, l.y()), y_hi = std::max(y_hi, l.y());
    z_lo = std::min(z_lo, l.z()), z_hi = std::max(z_hi, l.z());
  }
  if (d.rate == 0) return {{1, 0}, {}};
  const double k = std::abs(d.rate);
  const double stretch = std::max(std::abs(1 - d.rate * z_lo), std::abs(1 - d.rate * z_hi));
  const bool meets_region = y_hi >= d.y_min && y_lo <= d.y_max;
  Bounds b{1, 0};
  if (meets_region) b = {std::sqrt(2 + stretch * stretch), k * (stretch + 1)};
  const bool kink = (y_lo < d.y_min && y_hi > d.y_min) || (y_lo < d.y_max && y_hi > d.y_max);
  if (kink) b.second = infinity;
  return {b, {}};
}

/// Bounds of a Bézier lattice (Sederberg–Parry eq. (2)) over its whole cube, world coordinates:
/// the derivatives in local coordinates are Bernstein polynomials with the difference nets as
/// control points (convex hull), and d(local)/dx = M^-1 with M = [S T U], so ||D'|| <=
/// sqrt(Σ_a max|D_a|^2) ||M^-1|| and ||D''|| <= sqrt(Σ_ab max|D_ab|^2) ||M^-1||^2.
Bounds bezier_lattice_bounds(const BezierLattice& lattice) {
  Eigen::Matrix3d m;
  m.col(0) = lattice.frame.s, m.col(1) = lattice.frame.t, m.col(2) = lattice.frame.u;
  const double inverse_norm =
      Eigen::JacobiSVD<Eigen::Matrix3d>(m.inverse()).singularValues()(0);
  const auto n = lattice.counts();
  const auto& d = lattice.degrees;
  auto point = [&](int i, int j, int k) -> Eigen::Vector3d {
    return lattice.points.row(lattice.index(i, j, k)).transpose();
  };
  std::array<double, 3> first{0, 0, 0};
  std::array<std::array<double, 3>, 3> second{};
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        const std::array<int, 3> at{i, j, k};
        auto shifted = [&](int a, int b) {  // at + e_a + e_b (a or b = -1: no shift)
          std::array<int, 3> s = at;
          if (a >= 0) ++s[static_cast<std::size_t>(a)];
          if (b >= 0) ++s[static_cast<std::size_t>(b)];
          return s;
        };
        auto valid = [&](const std::array<int, 3>& s) {
          return s[0] < n[0] && s[1] < n[1] && s[2] < n[2];
        };
        auto p = [&](const std::array<int, 3>& s) { return point(s[0], s[1], s[2]); };
        for (int a = 0; a < 3; ++a) {
          const auto ua = static_cast<std::size_t>(a);
          const auto s1 = shifted(a, -1);
          if (!valid(s1)) continue;
          first[ua] = std::max(first[ua], d[ua] * (p(s1) - p(at)).norm());
          for (int b = a; b < 3; ++b) {
            const auto ub = static_cast<std::size_t>(b);
            const auto s2 = shifted(a, b);
            if (!valid(s2)) continue;
            double value;
            if (a == b) {
              value = d[ua] * (d[ua] - 1) * (p(s2) - 2 * p(s1) + p(at)).norm();
            } else {
              value = d[ua] * d[ub] * (p(s2) - p(s1) - p(shifted(b, -1)) + p(at)).norm();
            }
            second[ua][ub] = std::max(second[ua][ub], value);
          }
        }
      }
  double f2 = 0, s2 = 0;
  for (int a = 0; a < 3; ++a) {
    const auto ua = static_cast<std::size_t>(a);
    f2 += first[ua] * first[ua];
    for (int b = 0; b < 3; ++b) {
      const double v = second[std::min(ua, static_cast<std::size_t>(b))]
                             [std::max(ua, static_cast<std::size_t>(b))];
      s2 += v * v;
    }
  }
  return {std::sqrt(f2) * inverse_norm, std::sqrt(s2) * inverse_norm * inverse_norm};
}

/// A lattice as Bézier cells with their bounds, and the planes across which it is only C0.
struct LatticeCells {
  Frame frame;
  std::array<std::vector<double>, 3> breaks;
  std::array<std::vector<char>, 3> smooth;  // per break: D' continuous across it (interior only)
  std::array<int, 3> counts{1, 1, 1};
  std::vector<Bounds> bounds;  // cell (a, b, c) at (a * counts[1] + b) * counts[2] + c

  /// Bounds over the hull (local box from the hull's points); the planes (faces and interior
  /// breaks) its local box crosses. Entirely outside: identity.
  HullInfo info(const Points3& hull, int step) const {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(infinity), hi = -lo;
    for (Eigen::Index r = 0; r < hull.rows(); ++r) {
      const Eigen::Vector3d l = local_coordinates(frame, hull.row(r).transpose());
      lo = lo.cwiseMin(l), hi = hi.cwiseMax(l);
    }
    for (int a = 0; a < 3; ++a)
      if (hi[a] < -face_tolerance || lo[a] > 1 + face_tolerance) return {{1, 0}, {}};
    HullInfo out{{0, 0}, {}};
    bool kink = false, face = false;
    std::array<int, 3> first_cell{}, last_cell{};
    for (int a = 0; a < 3; ++a) {
      const auto ua = static_cast<std::size_t>(a);
      const auto& br = breaks[ua];
      const int last = static_cast<int>(br.size()) - 1;
      for (int b = 0; b <= last; ++b) {
        const double plane = br[static_cast<std::size_t>(b)];
        if (!(lo[a] < plane - face_tolerance && hi[a] > plane + face_tolerance)) continue;
        out.planes.push_back({step, a, plane});
        if (b == 0 || b == last) {
          face = true;
        } else if (!smooth[ua][static_cast<std::size_t>(b)]) {
          kink = true;
        }
      }
      first_cell[ua] = 0, last_cell[ua] = last - 1;
      // every cell the box meets, a touched neighbour included (strict comparisons)
      while (first_cell[ua] < last - 1 && br[static_cast<std::size_t>(first_cell[ua] + 1)] < lo[a])
        ++first_cell[ua];
      while (last_cell[ua] > 0 && br[static_cast<std::size_t>(last_cell[ua])] > hi[a])
        --last_cell[ua];
    }
    for (int a = first_cell[0]; a <= last_cell[0]; ++a)
      for (int b = first_cell[1]; b <= last_cell[1]; ++b)
        for (int c = first_cell[2]; c <= last_cell[2]; ++c) {
          const Bounds& cb = bounds[static_cast<std::size_t>((a * counts[1] + b) * counts[2] + c)];
          out.bounds.first = std::max(out.bounds.first, cb.first);
          out.bounds.second = std::max(out.bounds.second, cb.second);
        }
    if (face) out.bounds.first = std::max(out.bounds.first, 1.0);
    if (face || kink) out.bounds.second = infinity;
    return out;
  }
};

LatticeCells lattice_cells(const BezierLattice& lattice) {
  LatticeCells c;
  c.frame = lattice.frame;
  for (auto& b : c.breaks) b = {0.0, 1.0};
  for (auto& s : c.smooth) s = {1, 1};
  c.bounds = {bezier_lattice_bounds(lattice)};
  return c;
}

LatticeCells lattice_cells(const BSplineLattice& lattice) {
  const BezierCells cells = bezier_cells(lattice);
  LatticeCells c;
  c.frame = lattice.frame;
  c.breaks = cells.breaks;
  c.counts = cells.counts();
  for (std::size_t a = 0; a < 3; ++a) {
    c.smooth[a].clear();
    for (double b : c.breaks[a]) {
      const int continuity = lattice.bases[a].degree - surface::multiplicity(lattice.bases[a], b);
      c.smooth[a].push_back(continuity >= 1 ? 1 : 0);
    }
  }
  for (const BezierLattice& cell : cells.cells) c.bounds.push_back(bezier_lattice_bounds(cell));
  return c;
}

/// The eight corners of the cube around the ball that holds D(hull) (D Lipschitz with constant
/// `first` on the hull: |D(x) − D(c)| <= first |x − c|).
Points3 image_hull(const PointMap& map, const Points3& hull, double first) {
  const Eigen::Vector3d c = hull.colwise().mean().transpose();
  double radius = 0;
  for (Eigen::Index r = 0; r < hull.rows(); ++r)
    radius = std::max(radius, (hull.row(r).transpose() - c).norm());
  const Eigen::Vector3d centre = map(c);
  const double half = first * radius * (1 + 1e-12) + 1e-12 * (centre.norm() + radius);
  Points3 corners(8, 3);
  for (int k = 0; k < 8; ++k)
    corners.row(k) = (centre + half * Eigen::Vector3d((k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0,
                                                      (k & 4) ? 1.0 : -1.0))
                         .transpose();
  return corners;
}

// ---- certifiers per deformation ---------------------------------------------------------------

Certifier certifier(const Taper& d) {
  return {"taper", [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [d](const Points3& h) { return taper_info(d, h); }, {}};
}
Certifier certifier(const Twist& d) {
  return {"twist", [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [d](const Points3& h) { return twist_info(d, h); }, {}};
}
Certifier certifier(const Bend& d) {
  return {"bend", [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [d](const Points3& h) { return bend_info(d, h); }, {}};
}
Certifier certifier(const BezierLattice& d) {
  auto cells = std::make_shared<LatticeCells>(lattice_cells(d));
  return {"Bézier lattice", [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [cells](const Points3& h) { return cells->info(h, 0); }, {}};
}
Certifier certifier(const BSplineLattice& d) {
  auto cells = std::make_shared<LatticeCells>(lattice_cells(d));
  return {"B-spline lattice", [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [cells](const Points3& h) { return cells->info(h, 0); }, {}};
}
Certifier certifier(const ExtendedLattice& d) {
  return {"extended lattice", detail::prepared_point_map(d), {},
          "an extended lattice is evaluated through Newton-frozen chunk coordinates, for which no "
          "derivative bounds are known"};
}

Certifier certifier(const DeformationStack& stack) {
  struct Step {
    PointMap map;
    std::function<HullInfo(const Points3&, int)> info;
    int index;
  };
  std::vector<Step> steps;
  std::string why_not;
  for (std::size_t i = 0; i < stack.steps.size(); ++i) {
    const DeformationStep& step = stack.steps[i];
    if (!step.enabled) continue;
    const int index = static_cast<int>(i);
    std::visit(
        [&](const auto& d) {
          using T = std::decay_t<decltype(d)>;
          if constexpr (std::is_same_v<T, ExtendedLattice>) {
            if (why_not.empty())
              why_not = "steps[" + std::to_string(i) + "] is an extended lattice, evaluated through "
                        "Newton-frozen chunk coordinates, for which no derivative bounds are known";
            steps.push_back({detail::prepared_point_map(d), {}, index});
          } else if constexpr (std::is_same_v<T, BezierLattice> ||
                               std::is_same_v<T, BSplineLattice>) {
            auto cells = std::make_shared<LatticeCells>(lattice_cells(d));
            steps.push_back({[d](const Eigen::Vector3d& x) { return deform_point(d, x); },
                             [cells](const Points3& h, int s) { return cells->info(h, s); },
                             index});
          } else {
            const Certifier c = certifier(d);
            auto info = c.info;
            steps.push_back(
                {c.map, [info](const Points3& h, int) { return info(h); }, index});
          }
        },
        step.deformation);
  }
  Certifier c;
  c.name = "deformation stack";
  c.map = [stack](const Eigen::Vector3d& x) { return deform_point(stack, x); };
  if (!why_not.empty()) {
    c.why_not = why_not;
    return c;
  }
  // (D2 ∘ D1)'' [a, a] = D2''[D1' a, D1' a] + D2' D1''[a, a]: chained bounds.
  c.info = [steps](const Points3& hull) {
    HullInfo total{{1, 0}, {}};
    Points3 current = hull;
    for (const Step& s : steps) {
      HullInfo h = s.info(current, s.index);
      const double second = h.bounds.second * total.bounds.first * total.bounds.first +
                            h.bounds.first * total.bounds.second;
      total.bounds.second = std::isnan(second) ? infinity : second;
      total.bounds.first *= h.bounds.first;
      total.planes.insert(total.planes.end(), h.planes.begin(), h.planes.end());
      current = image_hull(s.map, current, h.bounds.first);
    }
    return total;
  };
  return c;
}

// ---- surfaces: bases, fit, derivative bounds of Bézier patches --------------------------------

/// The fit's basis in one direction: the original's breakpoints, degree p_fit, and at each
/// interior breakpoint the multiplicity that keeps the original's continuity C^(p − m) there
/// (at least 1, at most p_fit).
BSplineBasis initial_basis(const BSplineBasis& original, int degree) {
  const std::vector<double> breaks = surface::breakpoints(original);
  BSplineBasis b;
  b.degree = degree;
  b.knots.assign(static_cast<std::size_t>(degree + 1), breaks.front());
  for (std::size_t k = 1; k + 1 < breaks.size(); ++k) {
    const int continuity = original.degree - surface::multiplicity(original, breaks[k]);
    const int m = std::clamp(degree - continuity, 1, degree);
    b.knots.insert(b.knots.end(), static_cast<std::size_t>(m), breaks[k]);
  }
  b.knots.insert(b.knots.end(), static_cast<std::size_t>(degree + 1), breaks.back());
  return b;
}

/// Chebyshev–Lobatto parameters, `intervals` per non-empty span, ends shared.
std::vector<double> fit_parameters(const BSplineBasis& basis, int intervals) {
  const std::vector<double> breaks = surface::breakpoints(basis);
  std::vector<double> t;
  for (std::size_t s = 0; s + 1 < breaks.size(); ++s) {
    const double a = breaks[s], b = breaks[s + 1];
    for (int k = 0; k < intervals; ++k)
      t.push_back(a + (b - a) * 0.5 * (1 - std::cos(std::numbers::pi * k / intervals)));
  }
  t.push_back(breaks.back());
  return t;
}

/// Collocation matrix: row r holds N_j(t_r).
Eigen::MatrixXd collocation(const BSplineBasis& basis, const std::vector<double>& t) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(t.size()), basis.count());
  std::vector<double> values(static_cast<std::size_t>(basis.degree + 1));
  for (std::size_t r = 0; r < t.size(); ++r) {
    const int span = surface::find_span(basis, t[r]);
    surface::basis_functions(basis, span, t[r], values);
    for (int k = 0; k <= basis.degree; ++k)
      a(static_cast<Eigen::Index>(r), span - basis.degree + k) = values[static_cast<std::size_t>(k)];
  }
  return a;
}

/// Tensor-product least squares: the net C minimising Σ |Σ N_i(u_r) N_j(v_s) C_ij − F_rs|^2 is
/// C = A_u^+ F A_v^+T per coordinate (the problem separates).
BSplineSurface least_squares(const BSplineBasis& bu, const BSplineBasis& bv,
                             const std::vector<double>& us, const std::vector<double>& vs,
                             const Points3& values) {
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qu(collocation(bu, us));
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qv(collocation(bv, vs));
  const auto mu = static_cast<Eigen::Index>(us.size()), mv = static_cast<Eigen::Index>(vs.size());
  Points3 net(static_cast<Eigen::Index>(bu.count()) * bv.count(), 3);
  for (int c = 0; c < 3; ++c) {
    Eigen::MatrixXd f(mu, mv);
    for (Eigen::Index i = 0; i < mu; ++i)
      for (Eigen::Index j = 0; j < mv; ++j) f(i, j) = values(i * mv + j, c);
    const Eigen::MatrixXd x = qu.solve(f);                          // count_u x mv
    const Eigen::MatrixXd y = qv.solve(x.transpose()).transpose();  // count_u x count_v
    for (Eigen::Index i = 0; i < y.rows(); ++i)
      for (Eigen::Index j = 0; j < y.cols(); ++j) net(i * y.cols() + j, c) = y(i, j);
  }
  return surface::make_surface(bu, bv, std::move(net));
}

/// Bounds of |S_u|, |S_uu|, |S_v|, |S_vv| over a (rational) Bézier patch, from the hodograph nets
/// of the homogeneous form (convex hull) and the quotient rule: with c the mean control point,
/// A = Σ B w (P − c), W = Σ B w, S − c = A / W,
///   S_u = (A_u − (S − c) W_u) / W,  S_uu = (A_uu − 2 S_u W_u − (S − c) W_uu) / W,
/// |S − c| <= max|P − c| and W >= min w (convex hull, positive weights).
struct PatchBounds {
  double d1u = 0, d2u = 0, d1v = 0, d2v = 0;
};
PatchBounds patch_bounds(const BSplineSurface& patch) {
  const int p = patch.u.degree, q = patch.v.degree;
  const double du = patch.u.knots.back() - patch.u.knots.front();
  const double dv = patch.v.knots.back() - patch.v.knots.front();
  const Eigen::Vector3d c = patch.points.colwise().mean().transpose();
  double radius = 0, w_min = infinity;
  for (Eigen::Index r = 0; r < patch.points.rows(); ++r) {
    radius = std::max(radius, (patch.points.row(r).transpose() - c).norm());
    w_min = std::min(w_min, patch.weights(r));
  }
  auto h = [&](int i, int j) -> Eigen::Vector4d {
    const Eigen::Index r = patch.index(i, j);
    const double w = patch.weights(r);
    Eigen::Vector4d out;
    out << w * (patch.points.row(r).transpose() - c), w;
    return out;
  };
  // first / second differences along one direction: max norms of the vector and weight parts
  auto differences = [&](bool along_u, double& a1, double& w1, double& a2, double& w2) {
    const int n = along_u ? p : q;
    const int other = along_u ? q : p;
    a1 = w1 = a2 = w2 = 0;
    for (int o = 0; o <= other; ++o)
      for (int k = 0; k <= n; ++k) {
        auto at = [&](int s) { return along_u ? h(s, o) : h(o, s); };
        if (k + 1 <= n) {
          const Eigen::Vector4d d = at(k + 1) - at(k);
          a1 = std::max(a1, d.head<3>().norm()), w1 = std::max(w1, std::abs(d(3)));
        }
        if (k + 2 <= n) {
          const Eigen::Vector4d d = at(k + 2) - 2 * at(k + 1) + at(k);
          a2 = std::max(a2, d.head<3>().norm()), w2 = std::max(w2, std::abs(d(3)));
        }
      }
    const double span = along_u ? du : dv;
    a1 *= n / span, w1 *= n / span;
    a2 *= n * (n - 1) / (span * span), w2 *= n * (n - 1) / (span * span);
  };
  PatchBounds b;
  double a1, w1, a2, w2;
  differences(true, a1, w1, a2, w2);
  b.d1u = (a1 + radius * w1) / w_min;
  b.d2u = (a2 + 2 * b.d1u * w1 + radius * w2) / w_min;
  differences(false, a1, w1, a2, w2);
  b.d1v = (a1 + radius * w1) / w_min;
  b.d2v = (a2 + 2 * b.d1v * w1 + radius * w2) / w_min;
  return b;
}

/// Distinct values of `refined` not in `original` (both sorted).
std::vector<double> added_breaks(const std::vector<double>& refined,
                                 const std::vector<double>& original) {
  std::vector<double> out;
  std::set_difference(refined.begin(), refined.end(), original.begin(), original.end(),
                      std::back_inserter(out));
  return out;
}

Eigen::Vector3d deformed(const Certifier& d, const Eigen::Vector3d& x) {
  const Eigen::Vector3d y = d.map(x);
  if (!internal::all_finite(y))
    throw Error(ErrorCategory::InvalidArgument,
                "refit_deformed: the " + d.name + " maps (" + format(x.x()) + ", " +
                    format(x.y()) + ", " + format(x.z()) +
                    ") to a non-finite point; use a deformation defined on the whole surface");
  return y;
}

// ---- the certificate ------------------------------------------------------------------------

struct CellResult {
  double sampled = 0;
  double bound = infinity;
  bool lipschitz = false;
  std::vector<Plane> planes;
};

struct Certificate {
  std::vector<CellResult> cells;  // (iu, iv) at iu * cells_v + iv
  int cells_u = 0, cells_v = 0;
  double sampled = 0, bound = 0;
  long samples = 0;
  bool certified = true;
};

/// Every cell of `fit` (pair of its non-empty spans): sampled deviation on a uniform grid of at
/// least `base` intervals per direction, and (when the certifier has bounds) the bound
/// max|e(grid)| + remainder + rounding allowance.
Certificate certify(const BSplineSurface& original, const BSplineSurface& fit,
                    const Certifier& d, int base, double budget, double rounding) {
  const surface::BezierPatches fit_patches = surface::extract_bezier(fit);
  const std::vector<double> added_u =
      added_breaks(fit_patches.breaks_u, surface::breakpoints(original.u));
  const std::vector<double> added_v =
      added_breaks(fit_patches.breaks_v, surface::breakpoints(original.v));
  BSplineSurface refined = original;
  if (!added_u.empty()) refined = surface::refine_knots_u(refined, added_u);
  if (!added_v.empty()) refined = surface::refine_knots_v(refined, added_v);
  const surface::BezierPatches s_patches = surface::extract_bezier(refined);
  if (s_patches.count_u() != fit_patches.count_u() || s_patches.count_v() != fit_patches.count_v())
    throw Error(ErrorCategory::Internal, "refit_deformed: the fit's and the surface's cells differ");

  const int cap = std::max(base, 64);
  Certificate out;
  out.cells_u = fit_patches.count_u(), out.cells_v = fit_patches.count_v();
  out.certified = static_cast<bool>(d.info);
  for (int iu = 0; iu < out.cells_u; ++iu)
    for (int iv = 0; iv < out.cells_v; ++iv) {
      const std::size_t index = static_cast<std::size_t>(iu * out.cells_v + iv);
      const BSplineSurface& sp = s_patches.patches[index];
      const BSplineSurface& fp = fit_patches.patches[index];
      const double du = fit_patches.breaks_u[static_cast<std::size_t>(iu + 1)] -
                        fit_patches.breaks_u[static_cast<std::size_t>(iu)];
      const double dv = fit_patches.breaks_v[static_cast<std::size_t>(iv + 1)] -
                        fit_patches.breaks_v[static_cast<std::size_t>(iv)];
      CellResult cell;
      int nu = base, nv = base;
      // the remainder as a function of the grid, chosen below
      std::function<double(int, int)> remainder;
      if (d.info) {
        const HullInfo info = d.info(sp.points);
        cell.planes = info.planes;
        const PatchBounds s = patch_bounds(sp), f = patch_bounds(fp);
        const double l1 = info.bounds.first, l2 = info.bounds.second;
        auto grid = [&](double need) {
          return static_cast<int>(std::clamp(std::ceil(need), static_cast<double>(base),
                                             static_cast<double>(cap)));
        };
        if (std::isfinite(l2)) {
          // Taylor: |e − I e| <= (h_u^2 / 8) sup|e_uu| + (h_v^2 / 8) sup|e_vv|
          const double euu = f.d2u + l2 * s.d1u * s.d1u + l1 * s.d2u;
          const double evv = f.d2v + l2 * s.d1v * s.d1v + l1 * s.d2v;
          nu = grid(du * std::sqrt(euu / (4 * budget)));
          nv = grid(dv * std::sqrt(evv / (4 * budget)));
          remainder = [=](int a, int b) {
            const double hu = du / a, hv = dv / b;
            return hu * hu / 8 * euu + hv * hv / 8 * evv;
          };
        } else if (std::isfinite(l1)) {
          // Lipschitz: |e(x) − e(nearest node)| <= (h_u / 2) sup|e_u| + (h_v / 2) sup|e_v|
          cell.lipschitz = true;
          const double eu = f.d1u + l1 * s.d1u, ev = f.d1v + l1 * s.d1v;
          nu = grid(du * eu / budget);
          nv = grid(dv * ev / budget);
          remainder = [=](int a, int b) { return du / a / 2 * eu + dv / b / 2 * ev; };
        } else {
          out.certified = false;
        }
      }
      const std::vector<double> us = surface::linspace(sp.u.knots.front(), sp.u.knots.back(), nu + 1);
      const std::vector<double> vs = surface::linspace(sp.v.knots.front(), sp.v.knots.back(), nv + 1);
      const Points3 s_values = surface::evaluate_grid(sp, us, vs);
      const Points3 f_values = surface::evaluate_grid(fp, us, vs);
      for (Eigen::Index r = 0; r < s_values.rows(); ++r) {
        const Eigen::Vector3d target = deformed(d, s_values.row(r).transpose());
        cell.sampled = std::max(cell.sampled, (f_values.row(r).transpose() - target).norm());
      }
      out.samples += s_values.rows();
      if (remainder) cell.bound = cell.sampled + remainder(nu, nv) + rounding;
      out.sampled = std::max(out.sampled, cell.sampled);
      out.bound = std::max(out.bound, cell.bound);
      out.cells.push_back(std::move(cell));
    }
  if (!out.certified) out.bound = infinity;
  return out;
}

/// The basis with a knot added at the middle of every marked non-empty span.
BSplineBasis split_spans(const BSplineBasis& basis, const std::vector<char>& marked) {
  const std::vector<double> breaks = surface::breakpoints(basis);
  BSplineBasis out = basis;
  for (std::size_t s = 0; s < marked.size(); ++s)
    if (marked[s]) out.knots.push_back(0.5 * (breaks[s] + breaks[s + 1]));
  std::sort(out.knots.begin(), out.knots.end());
  return out;
}

RefitResult refit(const BSplineSurface& surface, const Certifier& d, const RefitOptions& options) {
  options.validate();
  surface::validate(surface, "refit_deformed surface");
  const int p = options.degree;
  const int intervals = p + 1;  // fit parameters per span, per direction
  const int base = 4 * intervals;

  // size: the deformed surface sampled 8 x 8 per span
  const std::vector<double> su = surface::span_samples(surface.u, 8);
  const std::vector<double> sv = surface::span_samples(surface.v, 8);
  Points3 sample = surface::evaluate_grid(surface, su, sv);
  for (Eigen::Index r = 0; r < sample.rows(); ++r)
    sample.row(r) = deformed(d, sample.row(r).transpose()).transpose();
  const double size = (sample.colwise().maxCoeff() - sample.colwise().minCoeff()).norm();
  const double magnitude = sample.cwiseAbs().maxCoeff();
  if (options.relative && !(size > 0))
    throw Error(ErrorCategory::InvalidGeometry,
                "refit_deformed: the deformed surface has zero size (" + format(size) +
                    " mm), so a relative tolerance is zero; give an absolute tolerance "
                    "(RefitOptions::relative = false)");
  const double tolerance = options.relative ? options.tolerance * size : options.tolerance;
  const double rounding = 1e-12 * (size + magnitude);
  const double budget = options.certificate_share * tolerance;

  RefitResult result;
  RefitReport& report = result.report;
  report.tolerance = tolerance;
  report.size = size;
  report.degree_u = report.degree_v = p;
  BSplineBasis bu = initial_basis(surface.u, p), bv = initial_basis(surface.v, p);
  const std::size_t initial_u = bu.knots.size(), initial_v = bv.knots.size();
  std::string limit;
  for (int iteration = 1;; ++iteration) {
    const std::vector<double> us = fit_parameters(bu, intervals), vs = fit_parameters(bv, intervals);
    Points3 values = surface::evaluate_grid(surface, us, vs);
    for (Eigen::Index r = 0; r < values.rows(); ++r)
      values.row(r) = deformed(d, values.row(r).transpose()).transpose();
    result.surface = least_squares(bu, bv, us, vs, values);
    detail::keep_closed_and_collapsed(surface, result.surface,
                                      [&](const Eigen::Vector3d& x) { return deformed(d, x); });
    const Certificate cert = certify(surface, result.surface, d, base, budget, rounding);

    report.summary.iterations = iteration;
    report.certified = cert.certified;
    report.sampled_max = cert.sampled;
    report.certified_bound = cert.certified ? cert.bound : infinity;
    report.samples = cert.samples;
    report.knots_added_u = static_cast<int>(bu.knots.size() - initial_u);
    report.knots_added_v = static_cast<int>(bv.knots.size() - initial_v);
    report.lipschitz_cells = 0;
    report.crossings.clear();
    std::vector<char> mark_u(static_cast<std::size_t>(cert.cells_u), 0);
    std::vector<char> mark_v(static_cast<std::size_t>(cert.cells_v), 0);
    for (int iu = 0; iu < cert.cells_u; ++iu)
      for (int iv = 0; iv < cert.cells_v; ++iv) {
        const CellResult& c = cert.cells[static_cast<std::size_t>(iu * cert.cells_v + iv)];
        if (c.lipschitz) ++report.lipschitz_cells;
        for (const Plane& pl : c.planes)
          report.crossings.push_back({iu, iv, pl.step, pl.axis, pl.value, c.sampled, c.bound});
        const double measure = cert.certified ? c.bound : c.sampled;
        if (measure > tolerance)
          mark_u[static_cast<std::size_t>(iu)] = mark_v[static_cast<std::size_t>(iv)] = 1;
      }
    const double measure = cert.certified ? cert.bound : cert.sampled;
    if (iteration == 1) report.summary.initial_residual = measure;
    report.summary.final_residual = measure;
    if (measure <= tolerance) {
      report.summary.termination = Termination::Converged;
      break;
    }
    if (iteration >= options.max_iterations) {
      limit = "iteration limit " + std::to_string(options.max_iterations) + " reached";
      break;
    }
    BSplineBasis nu = split_spans(bu, mark_u), nv = split_spans(bv, mark_v);
    // The least squares are dense per direction ((degree + 1) rows per span x count columns), so
    // one long direction costs count^2 memory even within max_control_points: a twist of 1e6
    // degrees grew one direction to 10,000 and took 4.4 GB (issue #18).
    if (std::max(nu.count(), nv.count()) > options.max_count_per_direction) {
      limit = "control point limit per direction " + std::to_string(options.max_count_per_direction) +
              " reached (next net " + std::to_string(nu.count()) + " x " + std::to_string(nv.count()) + ")";
      break;
    }
    if (static_cast<long>(nu.count()) * nv.count() > options.max_control_points) {
      limit = "control point limit " + std::to_string(options.max_control_points) +
              " reached (next net " + std::to_string(nu.count()) + " x " +
              std::to_string(nv.count()) + ")";
      break;
    }
    bu = std::move(nu), bv = std::move(nv);
  }

  std::string message;
  if (report.summary.termination == Termination::Converged) {
    message = report.certified ? "certified bound " + short_format(report.certified_bound) +
                                     " mm within the tolerance " + short_format(tolerance) + " mm"
                               : "sampled maximum " + short_format(report.sampled_max) +
                                     " mm within the tolerance " + short_format(tolerance) +
                                     " mm, not certified";
  } else {
    report.summary.termination = Termination::NotConverged;
    message = limit + ": " +
              (report.certified ? "certified bound " + short_format(report.certified_bound)
                                : "sampled maximum " + short_format(report.sampled_max)) +
              " mm above the tolerance " + short_format(tolerance) +
              " mm; raise the limits, the tolerance or the degree";
  }
  if (!report.certified) {
    message += "; not certified: ";
    message += d.info ? "the deformation's derivatives are unbounded in some cell" : d.why_not;
  }
  if (report.lipschitz_cells > 0)
    message += "; " + std::to_string(report.lipschitz_cells) +
               " cells cross a plane where the deformation is only C0 (first-derivative bound)";
  if (!report.crossings.empty())
    message += "; " + std::to_string(report.crossings.size()) +
               " lattice plane crossings by cells of the fit (see crossings)";
  report.summary.message = message;
  return result;
}

}  // namespace

std::vector<std::string> RefitOptions::problems() const {
  std::vector<std::string> out;
  auto fail = [&out](const std::string& what) {
    out.push_back("RefitOptions::" + what);
  };
  if (degree < 1 || degree > 25)
    fail("degree = " + std::to_string(degree) +
         ": must be in [1, 25] (the exchange degree limit); 3 is usual");
  if (!(std::isfinite(tolerance) && tolerance > 0))
    fail("tolerance = " + format(tolerance) + ": must be finite and > 0 (e.g. 1e-4 relative)");
  if (max_iterations < 1)
    fail("max_iterations = " + std::to_string(max_iterations) + ": must be >= 1");
  if (max_control_points < (degree + 1) * (degree + 1))
    fail("max_control_points = " + std::to_string(max_control_points) +
         ": must be >= (degree + 1)^2 = " + std::to_string((degree + 1) * (degree + 1)));
  if (max_count_per_direction < degree + 1)
    fail("max_count_per_direction = " + std::to_string(max_count_per_direction) +
         ": must be >= degree + 1 = " + std::to_string(degree + 1));
  if (!(certificate_share > 0 && certificate_share < 1))
    fail("certificate_share = " + format(certificate_share) + ": must be in (0, 1), e.g. 0.1");
  return out;
}

void RefitOptions::validate() const { internal::throw_if(ErrorCategory::InvalidArgument, problems()); }

std::string RefitReport::brief() const {
  char buffer[256];
  if (certified) {
    std::snprintf(buffer, sizeof buffer, "certified %.3g mm %s %.3g mm (sampled %.3g mm)",
                  certified_bound, certified_bound <= tolerance ? "<=" : ">", tolerance,
                  sampled_max);
  } else {
    std::snprintf(buffer, sizeof buffer, "not certified, sampled %.3g mm %s %.3g mm", sampled_max,
                  sampled_max <= tolerance ? "<=" : ">", tolerance);
  }
  std::string line = buffer;
  std::snprintf(buffer, sizeof buffer,
                ", %d + %d knots added, %d iterations, %zu knot-plane crossings", knots_added_u,
                knots_added_v, summary.iterations, crossings.size());
  return line + buffer;
}

namespace {

// Every deformation kind: validated, then fitted and certified by its certifier.
template <class D>
RefitResult refit_validated(const BSplineSurface& surface, const D& deformation, const RefitOptions& options) {
  validate(deformation);
  return refit(surface, certifier(deformation), options);
}

}  // namespace

RefitResult refit_deformed(const Taper& taper, const BSplineSurface& surface,
                           const RefitOptions& options) {
  return refit_validated(surface, taper, options);
}

RefitResult refit_deformed(const Twist& twist, const BSplineSurface& surface,
                           const RefitOptions& options) {
  return refit_validated(surface, twist, options);
}

RefitResult refit_deformed(const Bend& bend, const BSplineSurface& surface,
                           const RefitOptions& options) {
  return refit_validated(surface, bend, options);
}

RefitResult refit_deformed(const BezierLattice& lattice, const BSplineSurface& surface,
                           const RefitOptions& options) {
  return refit_validated(surface, lattice, options);
}

RefitResult refit_deformed(const BSplineLattice& lattice, const BSplineSurface& surface,
                           const RefitOptions& options) {
  return refit_validated(surface, lattice, options);
}

RefitResult refit_deformed(const ExtendedLattice& lattice, const BSplineSurface& surface,
                           const RefitOptions& options) {
  return refit_validated(surface, lattice, options);
}

RefitResult refit_deformed(const DeformationStack& stack, const BSplineSurface& surface,
                           const RefitOptions& options) {
  return refit_validated(surface, stack, options);
}

RefitResult refit_deformed(const PointMap& map, const BSplineSurface& surface,
                           const RefitOptions& options) {
  if (!map)
    throw Error(ErrorCategory::InvalidArgument,
                "refit_deformed: the point map is empty; pass a callable Eigen::Vector3d -> "
                "Eigen::Vector3d");
  return refit(surface, {"point map", map, {}, "nothing is known of a point map's derivatives"},
               options);
}

}  // namespace clay::deform
