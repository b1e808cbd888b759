// Bounds of each deformation over the convex hull of some points, and the certifiers the refit
// uses (certifier.hpp): closed forms for taper, twist and bend (Barr, in Güdükbay–Özgüç), the
// difference nets of lattice cells for Bézier and B-spline lattices, chained bounds for stacks.
#include "certifier.hpp"

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

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

namespace clay::deform::detail {

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

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
  const double inverse_norm = Eigen::JacobiSVD<Eigen::Matrix3d>(m.inverse()).singularValues()(0);
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

}  // namespace

// ---- certifiers per deformation ---------------------------------------------------------------

Certifier certifier(const Taper& d) {
  return {"taper",
          [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [d](const Points3& h) { return taper_info(d, h); },
          {}};
}
Certifier certifier(const Twist& d) {
  return {"twist",
          [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [d](const Points3& h) { return twist_info(d, h); },
          {}};
}
Certifier certifier(const Bend& d) {
  return {"bend",
          [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [d](const Points3& h) { return bend_info(d, h); },
          {}};
}
Certifier certifier(const BezierLattice& d) {
  auto cells = std::make_shared<LatticeCells>(lattice_cells(d));
  return {"Bézier lattice",
          [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [cells](const Points3& h) { return cells->info(h, 0); },
          {}};
}
Certifier certifier(const BSplineLattice& d) {
  auto cells = std::make_shared<LatticeCells>(lattice_cells(d));
  return {"B-spline lattice",
          [d](const Eigen::Vector3d& x) { return deform_point(d, x); },
          [cells](const Points3& h) { return cells->info(h, 0); },
          {}};
}
Certifier certifier(const ExtendedLattice& d) {
  return {"extended lattice",
          detail::prepared_point_map(d),
          {},
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
              why_not = "steps[" + std::to_string(i) +
                        "] is an extended lattice, evaluated through "
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
            steps.push_back({c.map, [info](const Points3& h, int) { return info(h); }, index});
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

}  // namespace clay::deform::detail
