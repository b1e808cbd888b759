// The refit's matched curves (refit_edges.hpp): a model face fitted with its edges, so that two
// faces fitted alone still meet where the exact result's faces meet (issue #38 step 7).
#include "refit_edges.hpp"

#include "fit_samples.hpp"

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace clay::deform::detail {

namespace {

// The tie of the sides a = a0 and a = a1 of `s` (a = u when `along_u`): see seam_ties.
SeamTie side_tie(const surface::BSplineSurface& s, bool along_u) {
  SeamTie tie;
  tie.order = 0;
  const auto [a0, a1] = along_u ? s.u.domain() : s.v.domain();
  const std::vector<double> across = surface::span_samples(along_u ? s.v : s.u, 4);
  struct End {
    Eigen::Vector3d d1, d2;
  };
  std::vector<End> near, far;
  for (const double t : across) {
    const surface::SurfaceDerivatives n =
        along_u ? surface::derivatives(s, a0, t, 2) : surface::derivatives(s, t, a0, 2);
    const surface::SurfaceDerivatives f =
        along_u ? surface::derivatives(s, a1, t, 2) : surface::derivatives(s, t, a1, 2);
    near.push_back(along_u ? End{n.du, n.duu} : End{n.dv, n.dvv});
    far.push_back(along_u ? End{f.du, f.duu} : End{f.dv, f.dvv});
  }
  // r from the fastest sample (a pole's samples have no speed), then every sample checked
  std::size_t fastest = 0;
  for (std::size_t k = 0; k < near.size(); ++k)
    if (near[k].d1.norm() > near[fastest].d1.norm()) fastest = k;
  const double speed = near[fastest].d1.norm();
  if (!(speed > 0)) return tie;
  const double r = far[fastest].d1.norm() / speed;
  const double scale1 = std::max(speed * r, far[fastest].d1.norm());
  for (std::size_t k = 0; k < near.size(); ++k)
    if ((far[k].d1 - r * near[k].d1).norm() > 1e-9 * scale1) return tie;
  tie.order = 1, tie.ratio = r;
  // t by least squares over the samples, then every sample checked
  double along = 0, squared = 0, scale2 = scale1 * scale1 / std::max(speed, 1e-300) * 1e-6;
  for (std::size_t k = 0; k < near.size(); ++k) {
    along += (far[k].d2 - r * r * near[k].d2).dot(near[k].d1);
    squared += near[k].d1.squaredNorm();
    scale2 = std::max({scale2, far[k].d2.norm(), r * r * near[k].d2.norm()});
  }
  const double t = along / squared;
  for (std::size_t k = 0; k < near.size(); ++k)
    if ((far[k].d2 - r * r * near[k].d2 - t * near[k].d1).norm() > 1e-9 * scale2) return tie;
  tie.order = 2, tie.tangential = t;
  return tie;
}

// A fit direction's control points as combinations of its unknowns: rows[i] lists (unknown,
// coefficient); the last order + 1 rows of a tied side combine the first order + 1.
struct DirectionTie {
  int unknowns = 0;
  std::vector<std::vector<std::pair<int, double>>> rows;
};

DirectionTie direction_tie(const surface::BSplineBasis& b, SeamTie tie) {
  const int n = b.count(), p = b.degree;
  // the tie this basis holds: derivatives up to p - 1 across, and the two ends' rows apart
  int order = std::min(tie.order, p - 1);
  while (order >= 0 && n <= 2 * order + 1) --order;
  DirectionTie out;
  out.unknowns = n - (order + 1);
  out.rows.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < out.unknowns; ++i) out.rows[static_cast<std::size_t>(i)] = {{i, 1.0}};
  if (order < 0) return out;
  const auto [a0, a1] = b.domain();
  const auto width = static_cast<std::size_t>(p + 1);
  std::vector<double> first((order + 1) * width), last((order + 1) * width);
  surface::basis_derivatives(b, surface::find_span(b, a0), a0, order, first);
  surface::basis_derivatives(b, surface::find_span(b, a1), a1, order, last);
  // the near end's m-th derivative on the first m + 1 points, the far end's on the last m + 1
  // (clamped ends): far_m = r^m near_m (+ t near_1 for m = 2), solved for point n - 1 - m.
  std::vector<std::vector<double>> combination;  // over unknowns 0..order
  for (int m = 0; m <= order; ++m) {
    std::vector<double> c(static_cast<std::size_t>(order + 1), 0.0);
    const double rm = std::pow(tie.ratio, m);
    for (int a = 0; a <= m; ++a) c[static_cast<std::size_t>(a)] += rm * first[m * width + a];
    if (m == 2)
      for (int a = 0; a <= 1; ++a)
        c[static_cast<std::size_t>(a)] += tie.tangential * first[width + a];
    for (int j = 0; j < m; ++j) {
      const double beta = last[m * width + static_cast<std::size_t>(p - j)];
      for (int a = 0; a <= order; ++a)
        c[static_cast<std::size_t>(a)] -= beta * combination[static_cast<std::size_t>(j)][a];
    }
    const double pivot = last[m * width + static_cast<std::size_t>(p - m)];
    for (double& x : c) x /= pivot;
    combination.push_back(c);
    auto& row = out.rows[static_cast<std::size_t>(n - 1 - m)];
    for (int a = 0; a <= order; ++a)
      if (c[static_cast<std::size_t>(a)] != 0) row.emplace_back(a, c[static_cast<std::size_t>(a)]);
  }
  return out;
}

}  // namespace

SeamTies seam_ties(const surface::BSplineSurface& source, ClosedSides closed) {
  SeamTies out;
  if (closed.u) out.u = side_tie(source, true);
  if (closed.v) out.v = side_tie(source, false);
  return out;
}

void mark_seams(std::vector<EdgeSample>& samples, int per_curve,
                const surface::BSplineSurface& surface, SeamTies ties) {
  // (plain copies: a lambda may not capture a structured binding before C++20 in clang 14)
  const double u0 = surface.u.domain().first, u1 = surface.u.domain().second;
  const double v0 = surface.v.domain().first, v1 = surface.v.domain().second;
  const double eu = 1e-9 * (u1 - u0), ev = 1e-9 * (v1 - v0);  // a pcurve's rounding
  const auto per = static_cast<std::size_t>(per_curve);
  for (std::size_t start = 0; start + per <= samples.size(); start += per) {
    auto all = [&](auto on) {
      for (std::size_t k = start; k < start + per; ++k)
        if (!on(samples[k])) return false;
      return true;
    };
    const bool seam =
        (ties.u.order >= 1 &&
         (all([&](const EdgeSample& s) { return std::abs(s.u - u0) <= eu; }) ||
          all([&](const EdgeSample& s) { return std::abs(s.u - u1) <= eu; }))) ||
        (ties.v.order >= 1 && (all([&](const EdgeSample& s) { return std::abs(s.v - v0) <= ev; }) ||
                               all([&](const EdgeSample& s) { return std::abs(s.v - v1) <= ev; })));
    for (std::size_t k = start; k < start + per; ++k) samples[k].seam = seam;
  }
}

std::vector<EdgeSample> edge_samples(
    const surface::BSplineSurface& surface, const std::vector<MatchedCurve>& curves,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& map, double size, int per_curve,
    bool second_derivatives) {
  const auto [u0, u1] = surface.u.domain();
  const auto [v0, v1] = surface.v.domain();
  const double step = 1e-5 * size;
  // D'(x) w by central differences along w's direction, scaled back by |w|.
  auto directional = [&](const Eigen::Vector3d& x, const Eigen::Vector3d& w) -> Eigen::Vector3d {
    const double length = w.norm();
    if (!(length > 0)) return Eigen::Vector3d::Zero();
    const Eigen::Vector3d e = (step / length) * w;
    return (map(x + e) - map(x - e)) * (length / (2 * step));
  };
  // D''(x)[w, w] by a second difference along w, scaled back by |w|^2; D''[a, b] by
  // polarization, (D''[a + b, a + b] - D''[a - b, a - b]) / 4.
  const double step2 = 1e-3 * size;
  auto second = [&](const Eigen::Vector3d& x, const Eigen::Vector3d& w) -> Eigen::Vector3d {
    const double length = w.norm();
    if (!(length > 0)) return Eigen::Vector3d::Zero();
    const Eigen::Vector3d e = (step2 / length) * w;
    return (map(x + e) - 2 * map(x) + map(x - e)) * (length * length / (step2 * step2));
  };
  std::vector<EdgeSample> out;
  out.reserve(curves.size() * static_cast<std::size_t>(per_curve));
  for (const MatchedCurve& c : curves)
    for (int k = 0; k < per_curve; ++k) {
      // The last sample at t1 itself: t0 + (t1 - t0) rounds past t1 (by one step of 3.14 on a
      // cylinder's pcurve, outside its domain), so it is the end, not the sum.
      const double t = k == per_curve - 1 ? c.t1 : c.t0 + (c.t1 - c.t0) * k / (per_curve - 1);
      const Eigen::Vector3d uv = surface::evaluate(c.pcurve, t);
      const Eigen::Vector3d tangent = surface::derivatives(c.pcurve, t, 1).d1;
      EdgeSample s;
      s.order = c.order;
      s.along_u = std::abs(tangent.x()) / (u1 - u0);
      s.along_v = std::abs(tangent.y()) / (v1 - v0);
      s.u = std::clamp(uv.x(), u0, u1);
      s.v = std::clamp(uv.y(), v0, v1);
      const surface::SurfaceDerivatives d = surface::derivatives(surface, s.u, s.v, 2);
      s.point = map(d.point);
      s.du = directional(d.point, d.du);
      s.dv = directional(d.point, d.dv);
      const double slow = std::min(s.du.norm(), s.dv.norm()),
                   fast = std::max(s.du.norm(), s.dv.norm());
      if (!(slow >= 0.01 * fast)) s.order = 0;  // near a pole: no normal to match
      if (second_derivatives && s.order >= 2) {
        s.duu = second(d.point, d.du) + directional(d.point, d.duu);
        s.dvv = second(d.point, d.dv) + directional(d.point, d.dvv);
        s.duv = 0.25 * (second(d.point, d.du + d.dv) - second(d.point, d.du - d.dv)) +
                directional(d.point, d.duv);
      } else {
        s.duu = s.duv = s.dvv = Eigen::Vector3d::Zero();
      }
      out.push_back(s);
    }
  return out;
}

surface::BSplineSurface least_squares_matching(
    const surface::BSplineBasis& bu, const surface::BSplineBasis& bv, const std::vector<double>& us,
    const std::vector<double>& vs, const surface::Points3& values,
    const std::vector<EdgeSample>& samples, double weight, double gap_mm, double angle_deg,
    double curvature, double size, SeamTies ties) {
  const int nu = bu.count(), nv = bv.count();
  const Eigen::MatrixXd au = collocation(bu, us), av = collocation(bv, vs);
  const Eigen::MatrixXd gu = au.transpose() * au, gv = av.transpose() * av;
  // The system is assembled on every control point, index i nv + j, then reduced to the
  // unknowns: control points = T x unknowns, T = T_u ⊗ T_v (identity but for a tied side's last
  // rows), so the normal equations become T^T N T.
  const DirectionTie tu = direction_tie(bu, ties.u), tv = direction_tie(bv, ties.v);
  const bool tied = tu.unknowns < nu || tv.unknowns < nv;
  const Eigen::Index n = static_cast<Eigen::Index>(nu) * nv;
  auto index = [&](Eigen::Index i, Eigen::Index j) { return i * nv + j; };

  // The grid: (A_u^T A_u) ⊗ (A_v^T A_v), both banded.
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> nz_u, nz_v;
  for (Eigen::Index i = 0; i < nu; ++i)
    for (Eigen::Index k = 0; k < nu; ++k)
      if (gu(i, k) != 0) nz_u.emplace_back(i, k);
  for (Eigen::Index j = 0; j < nv; ++j)
    for (Eigen::Index l = 0; l < nv; ++l)
      if (gv(j, l) != 0) nz_v.emplace_back(j, l);
  entries.reserve(nz_u.size() * nz_v.size() +
                  samples.size() * static_cast<std::size_t>((bu.degree + 1) * (bv.degree + 1)) *
                      static_cast<std::size_t>((bu.degree + 1) * (bv.degree + 1)));
  for (const auto& [i, k] : nz_u)
    for (const auto& [j, l] : nz_v)
      entries.emplace_back(index(i, j), index(k, l), gu(i, k) * gv(j, l));
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
  const auto mu = static_cast<Eigen::Index>(us.size()), mv = static_cast<Eigen::Index>(vs.size());
  for (int c = 0; c < 3; ++c) {
    Eigen::MatrixXd f(mu, mv);
    for (Eigen::Index i = 0; i < mu; ++i)
      for (Eigen::Index j = 0; j < mv; ++j) f(i, j) = values(i * mv + j, c);
    const Eigen::MatrixXd r = au.transpose() * f * av;
    for (Eigen::Index i = 0; i < nu; ++i)
      for (Eigen::Index j = 0; j < nv; ++j) rhs(index(i, j), c) += r(i, j);
  }

  // The samples: three weighted rows each (position, h_u d/du, h_v d/dv) on (p+1)(q+1) points,
  // each row in units of its allowance: a derivative error of angle |(D∘S)_u| tilts the normal
  // by about the angle, so h_u = gap / (angle |(D∘S)_u|) makes both rows count as much at their
  // limits. (The span's width instead would weaken the derivative rows just where refinement
  // made spans short: a cylinder's joins kept missing the angle at 32 spans.)
  // With `curvature`: three more rows, the second derivatives, each in units of its allowance
  // curvature x k x |(D∘S)_a| |(D∘S)_b|, k the larger normal curvature of D∘S along u and v
  // (at least 1 / size): an error e in (D∘S)_uu changes the normal curvature along u by at most
  // e / |(D∘S)_u|^2, so at its allowance by that fraction of k. Two faces fitted so meet with
  // their curvatures within twice the fraction where the exact result is G2.
  const double angle = angle_deg * std::numbers::pi / 180;
  const int pu = bu.degree, pv = bv.degree;
  const int local = (pu + 1) * (pv + 1);
  const int order = curvature > 0 ? 2 : 1, count = curvature > 0 ? 6 : 3;
  std::vector<double> du(static_cast<std::size_t>((order + 1) * (pu + 1))),
      dv(static_cast<std::size_t>((order + 1) * (pv + 1)));
  Eigen::MatrixXd rows(count, local);
  Eigen::MatrixXd targets(count, 3);
  const double w2 = weight * weight;
  for (const EdgeSample& s : samples) {
    const int su = surface::find_span(bu, s.u), sv = surface::find_span(bv, s.v);
    surface::basis_derivatives(bu, su, s.u, order, du);
    surface::basis_derivatives(bv, sv, s.v, order, dv);
    // Near a pole one speed vanishes, and the allowance of its derivative row with it would grow
    // without bound (a sphere's seam reached rows 1e12 times a grid sample's, and the least
    // squares came out singular): each speed counts as at least 1 % of the other.
    const double speed_u = std::max(s.du.norm(), 0.01 * s.dv.norm());
    const double speed_v = std::max(s.dv.norm(), 0.01 * s.du.norm());
    // a sharp edge's sample: its position only; a tangent edge's: no curvature
    const double hu = speed_u > 0 && s.order >= 1 ? gap_mm / (angle * speed_u) : 0;
    const double hv = speed_v > 0 && s.order >= 1 ? gap_mm / (angle * speed_v) : 0;
    double huu = 0, huv = 0, hvv = 0;
    if (curvature > 0 && s.order >= 2 && speed_u > 0 && speed_v > 0) {
      const Eigen::Vector3d normal = s.du.cross(s.dv);
      if (normal.norm() > 1e-12 * speed_u * speed_v) {
        const Eigen::Vector3d unit = normal.normalized();
        const double k = std::max({std::abs(s.duu.dot(unit)) / (speed_u * speed_u),
                                   std::abs(s.dvv.dot(unit)) / (speed_v * speed_v), 1 / size});
        huu = gap_mm / (curvature * k * speed_u * speed_u);
        huv = gap_mm / (curvature * k * speed_u * speed_v);
        hvv = gap_mm / (curvature * k * speed_v * speed_v);
      }
    }
    for (int a = 0; a <= pu; ++a)
      for (int b = 0; b <= pv; ++b) {
        const auto ua = static_cast<std::size_t>(a), vb = static_cast<std::size_t>(b);
        const auto up = static_cast<std::size_t>(pu + 1 + a),
                   vp = static_cast<std::size_t>(pv + 1 + b);
        const Eigen::Index col = a * (pv + 1) + b;
        rows(0, col) = du[ua] * dv[vb];
        rows(1, col) = hu * du[up] * dv[vb];
        rows(2, col) = hv * du[ua] * dv[vp];
        if (count == 6) {
          const auto upp = static_cast<std::size_t>(2 * (pu + 1) + a),
                     vpp = static_cast<std::size_t>(2 * (pv + 1) + b);
          rows(3, col) = huu * du[upp] * dv[vb];
          rows(4, col) = huv * du[up] * dv[vp];
          rows(5, col) = hvv * du[ua] * dv[vpp];
        }
      }
    targets.row(0) = s.point.transpose();
    targets.row(1) = hu * s.du.transpose();
    targets.row(2) = hv * s.dv.transpose();
    if (count == 6) {
      targets.row(3) = huu * s.duu.transpose();
      targets.row(4) = huv * s.duv.transpose();
      targets.row(5) = hvv * s.dvv.transpose();
    }
    const Eigen::MatrixXd block = w2 * rows.transpose() * rows;
    const Eigen::MatrixXd pulled = w2 * rows.transpose() * targets;
    for (int a = 0; a < local; ++a) {
      const Eigen::Index ga = index(su - pu + a / (pv + 1), sv - pv + a % (pv + 1));
      rhs.row(ga) += pulled.row(a);
      for (int b = 0; b < local; ++b)
        entries.emplace_back(ga, index(su - pu + b / (pv + 1), sv - pv + b % (pv + 1)),
                             block(a, b));
    }
  }
  Eigen::SparseMatrix<double> normal(n, n);
  normal.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseMatrix<double> t;
  if (tied) {
    std::vector<Eigen::Triplet<double>> kron;
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j)
        for (const auto& [a, ca] : tu.rows[static_cast<std::size_t>(i)])
          for (const auto& [b, cb] : tv.rows[static_cast<std::size_t>(j)])
            kron.emplace_back(index(i, j), static_cast<Eigen::Index>(a) * tv.unknowns + b, ca * cb);
    t.resize(n, static_cast<Eigen::Index>(tu.unknowns) * tv.unknowns);
    t.setFromTriplets(kron.begin(), kron.end());
    const Eigen::SparseMatrix<double> tt = t.transpose();
    normal = tt * normal * t;
    rhs = tt * rhs;
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success)
    throw Error(ErrorCategory::Internal,
                "refit_deformed: the least squares with matched curves is singular (" +
                    std::to_string(nu) + " x " + std::to_string(nv) + " control points)");
  const Eigen::MatrixXd solved = solver.solve(rhs);
  surface::Points3 net = tied ? surface::Points3(t * solved) : surface::Points3(solved);
  return surface::make_surface(bu, bv, std::move(net));
}

std::vector<EdgeMiss> edge_misses(const surface::BSplineSurface& fit,
                                  const std::vector<EdgeSample>& samples) {
  std::vector<EdgeMiss> out;
  out.reserve(samples.size());
  for (const EdgeSample& s : samples) {
    const surface::SurfaceDerivatives d = surface::derivatives(fit, s.u, s.v, 1);
    EdgeMiss m;
    m.gap_mm = (d.point - s.point).norm();
    const Eigen::Vector3d n_map = s.du.cross(s.dv), n_fit = d.du.cross(d.dv);
    if (n_map.norm() > 1e-12 * s.du.norm() * s.dv.norm() && n_fit.norm() > 0)
      m.angle_deg =
          std::atan2(n_fit.cross(n_map).norm(), n_fit.dot(n_map)) * 180 / std::numbers::pi;
    out.push_back(m);
  }
  return out;
}

}  // namespace clay::deform::detail
