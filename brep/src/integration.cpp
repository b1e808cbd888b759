// Quadrature helpers of clay_brep (see integration.hpp).
#include "integration.hpp"

#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <array>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace clay::brep::detail {

const internal::GaussRule& rule(int n) {
  static const std::vector<internal::GaussRule> rules = [] {
    std::vector<internal::GaussRule> all;
    for (int k = 0; k <= 64; ++k) all.push_back(internal::gauss_legendre(std::max(k, 1)));
    return all;
  }();
  return rules[static_cast<std::size_t>(n)];
}

std::vector<double> breaks(const surface::BSplineBasis& basis, double a, double b) {
  std::vector<double> out{a};
  for (double k : basis.knots)
    if (k > a && k < b && k != out.back()) out.push_back(k);
  out.push_back(b);
  return out;
}

std::vector<double> with_knot_crossings(const surface::BSplineCurve& pcurve,
                                        const std::vector<double>& pieces,
                                        const surface::BSplineBasis& v_basis, double t_lo,
                                        double t_hi) {
  const auto [v0, v1] = v_basis.domain();
  const std::vector<double> knots = breaks(v_basis, v0, v1);
  if (knots.size() <= 2) return pieces;
  auto v_at = [&](double t) {
    return surface::derivatives(pcurve, std::clamp(t, t_lo, t_hi), 0).point.y();
  };
  std::vector<double> out;
  constexpr int samples = 32;
  for (std::size_t k = 0; k + 1 < pieces.size(); ++k) {
    out.push_back(pieces[k]);
    const double a = pieces[k], b = pieces[k + 1];
    double ta = a, va = v_at(a);
    for (int i = 1; i <= samples; ++i) {
      const double tb = i == samples ? b : a + (b - a) * i / samples;
      const double vb = v_at(tb);
      for (std::size_t j = 1; j + 1 < knots.size(); ++j) {
        const double kappa = knots[j];
        if (vb == kappa && i < samples) out.push_back(tb);  // a sample on the knot line
        if ((va - kappa) * (vb - kappa) >= 0) continue;     // no strict crossing in [ta, tb]
        double lo = ta, hi = tb, vlo = va;
        for (int it = 0; it < 200 && hi - lo > 4 * std::numeric_limits<double>::epsilon() *
                                                   std::max({1.0, std::abs(lo), std::abs(hi)});
             ++it) {
          const double mid = 0.5 * (lo + hi);
          const double vm = v_at(mid);
          if ((vlo - kappa) * (vm - kappa) <= 0) {
            hi = mid;
          } else {
            lo = mid;
            vlo = vm;
          }
        }
        out.push_back(0.5 * (lo + hi));
      }
      ta = tb;
      va = vb;
    }
  }
  out.push_back(pieces.back());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

long face_budget(const surface::BSplineSurface& s) {
  const long spans =
      static_cast<long>(breaks(s.u, s.u.domain().first, s.u.domain().second).size() - 1) *
      static_cast<long>(breaks(s.v, s.v.domain().first, s.v.domain().second).size() - 1);
  return 200000 + 1000 * std::min(spans, 1800L);
}

double size_cubed(const Model& m) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const Face& f : m.faces)
    for (Eigen::Index r = 0; r < f.surface.points.rows(); ++r) {
      lo = lo.cwiseMin(f.surface.points.row(r).transpose());
      hi = hi.cwiseMax(f.surface.points.row(r).transpose());
    }
  const double d = m.faces.empty() ? 1.0 : (hi - lo).norm();
  return d * d * d;
}

Isocurve::Isocurve(const surface::BSplineSurface& s, double v, double lo, double hi) : s_(s) {
  v = std::clamp(v, s.v.domain().first, s.v.domain().second);
  const int p = s.u.degree, q = s.v.degree;
  const int sv = surface::find_span(s.v, v);
  std::array<double, 2 * (surface::max_kernel_degree + 1)> nv{};
  surface::basis_derivatives(s.v, sv, v, 1, nv);
  row0_ = surface::find_span(s.u, lo) - p;
  const int row1 = surface::find_span(s.u, hi);
  rows_.resize(static_cast<std::size_t>(2 * (row1 - row0_ + 1)));
  for (int i = row0_; i <= row1; ++i) {
    Eigen::Vector4d h = Eigen::Vector4d::Zero(), hv = Eigen::Vector4d::Zero();
    for (int j = 0; j <= q; ++j) {
      const Eigen::Index r = s.index(i, sv - q + j);
      const double w = s.weights[r];
      const Eigen::Vector4d pw(s.points(r, 0) * w, s.points(r, 1) * w, s.points(r, 2) * w, w);
      h += nv[static_cast<std::size_t>(j)] * pw;
      hv += nv[static_cast<std::size_t>(q + 1 + j)] * pw;
    }
    rows_[static_cast<std::size_t>(2 * (i - row0_))] = h;
    rows_[static_cast<std::size_t>(2 * (i - row0_) + 1)] = hv;
  }
}

void Isocurve::at(double u, Point& out) const {
  u = std::clamp(u, s_.u.domain().first, s_.u.domain().second);
  const int p = s_.u.degree;
  out.span = surface::find_span(s_.u, u);
  surface::basis_derivatives(s_.u, out.span, u, 1, out.basis);
  Eigen::Vector4d h = Eigen::Vector4d::Zero(), hu = Eigen::Vector4d::Zero(),
                  hv = Eigen::Vector4d::Zero();
  for (int i = 0; i <= p; ++i) {
    const auto k = static_cast<std::size_t>(2 * (out.span - p + i - row0_));
    h += out.basis[static_cast<std::size_t>(i)] * rows_[k];
    hv += out.basis[static_cast<std::size_t>(i)] * rows_[k + 1];
    hu += out.basis[static_cast<std::size_t>(p + 1 + i)] * rows_[k];
  }
  // the rational quotient rule (The NURBS Book A4.4) at first order
  out.point = h.head<3>() / h[3];
  out.du = (hu.head<3>() - hu[3] * out.point) / h[3];
  out.dv = (hv.head<3>() - hv[3] * out.point) / h[3];
  out.weight = h[3];
  out.weight_u = hu[3];
  out.weight_v = hv[3];
}

void Isocurve::at(double u, Eigen::Vector3d& point, Eigen::Vector3d& du,
                  Eigen::Vector3d& dv) const {
  Point p;
  at(u, p);
  point = p.point;
  du = p.du;
  dv = p.dv;
}

CentrePoints centre_points(const Model& m, const std::vector<int>& bodies) {
  CentrePoints out;
  std::vector<char> seen(m.vertices.size(), 0);
  for (int b : bodies)
    for (const Shell& shell : m.bodies[static_cast<std::size_t>(b)].shells)
      for (int f : shell.faces)
        for (const Loop& loop : m.faces[static_cast<std::size_t>(f)].loops)
          for (const Coedge& coedge : loop.coedges) {
            const Edge& e = m.edges[static_cast<std::size_t>(coedge.edge)];
            for (int v : {e.start, e.end})
              if (!seen[static_cast<std::size_t>(v)]) {
                seen[static_cast<std::size_t>(v)] = 1;
                out.vertices.push_back(v);
              }
          }
  if (out.vertices.empty())
    for (int b : bodies)
      for (const Shell& shell : m.bodies[static_cast<std::size_t>(b)].shells)
        for (int f : shell.faces) out.faces.push_back(f);
  return out;
}

Eigen::Vector3d body_centre(const Model& m, const std::vector<int>& bodies) {
  const CentrePoints c = centre_points(m, bodies);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  long count = 0;
  for (int v : c.vertices) {
    sum += m.vertices[static_cast<std::size_t>(v)].point;
    ++count;
  }
  for (int f : c.faces) {
    const auto& points = m.faces[static_cast<std::size_t>(f)].surface.points;
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      sum += points.row(r).transpose();
      ++count;
    }
  }
  return count > 0 ? Eigen::Vector3d(sum / static_cast<double>(count)) : Eigen::Vector3d::Zero();
}

}  // namespace clay::brep::detail
