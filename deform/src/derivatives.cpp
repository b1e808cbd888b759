// composition_jacobian (derivatives.hpp, issue #41): Sederberg–Parry eq. (2) composed with each
// Bézier patch of a surface as compose_exact's tensor route does (compose_factors.hpp), with the
// lattice's points replaced by unit vectors, one channel per lattice point.
#include <clay/deform/derivatives.hpp>
#include <clay/error.hpp>
#include <clay/surface/knots.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "bernstein_poly.hpp"
#include "compose_factors.hpp"
#include "messages.hpp"
#include "patch_containment.hpp"

namespace clay::deform {

namespace {

using detail::Poly;

/// Eq. (2) on one patch for every lattice point at once: channel j of the result holds the
/// homogeneous Bernstein coefficients of B_j(s, t, u) · W^(l+m+n) (u innermost, then t, then s,
/// as compose_exact). Unscaled.
Poly compose_channels(const BezierLattice& lattice, const std::array<detail::Factor, 3>& f) {
  const auto n = lattice.counts();
  const int channels = n[0] * n[1] * n[2];
  std::vector<Poly> along_s;
  for (int i = 0; i < n[0]; ++i) {
    std::vector<Poly> along_t;
    for (int j = 0; j < n[1]; ++j) {
      std::vector<Poly> along_u;
      for (int k = 0; k < n[2]; ++k) {
        Poly unit(0, 0, channels);
        unit.c[static_cast<std::size_t>(lattice.index(i, j, k))] = 1;
        along_u.push_back(std::move(unit));
      }
      along_t.push_back(detail::casteljau(std::move(along_u), f[2]));
    }
    along_s.push_back(detail::casteljau(std::move(along_t), f[1]));
  }
  Poly h = detail::casteljau(std::move(along_s), f[0]);
  detail::scale(h, true);
  return h;
}

/// Knots of degree p over `breaks`: ends p + 1 times, interior breaks p times (C0).
std::vector<double> c0_knots(const std::vector<double>& breaks, int p) {
  std::vector<double> k;
  for (std::size_t i = 0; i < breaks.size(); ++i)
    k.insert(k.end(), static_cast<std::size_t>(i == 0 || i + 1 == breaks.size() ? p + 1 : p),
             breaks[i]);
  return k;
}

}  // namespace

CompositionJacobian composition_jacobian(const BezierLattice& lattice,
                                         const surface::BSplineSurface& surface) {
  validate(lattice, "composition_jacobian: Bézier lattice");
  surface::validate(surface, "composition_jacobian: surface");
  const bool rational = surface.is_rational();
  const auto bp = surface::extract_bezier(surface);
  const auto dual = detail::dual_vectors(lattice.frame);
  const int cu = bp.count_u(), cv = bp.count_v();
  std::vector<Poly> patches(bp.patches.size());
  int pu = 1, pv = 1;
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b) {
      const auto pc = detail::patch_coordinates(bp.patch(a, b), lattice.frame.origin, dual);
      for (int d = 0; d < 3; ++d)
        if (const auto v = detail::leaves(detail::ratio_poly(pc, d), 0, 1, face_tolerance))
          throw Error(ErrorCategory::OutOfDomain,
                      "composition_jacobian: patch (" + std::to_string(a) + ", " +
                          std::to_string(b) +
                          ") of the surface leaves the Bézier lattice: " + "local coordinate " +
                          std::string(1, "stu"[d]) + " = " + detail::format(v->value) +
                          " is outside [0, 1]; the FFD is the identity outside the lattice, so "
                          "the deformed surface is not one polynomial there: enlarge the "
                          "lattice frame to contain the whole surface");
      Poly& h = patches[static_cast<std::size_t>(a * cv + b)];
      h = compose_channels(lattice, detail::cell_factors(pc, {0, 0, 0}, {1, 1, 1}));
      pu = std::max(pu, h.du);
      pv = std::max(pv, h.dv);
    }
  // Joined as join_bezier_patches joins: each patch elevated to (pu, pv), the homogeneous points
  // that neighbours share summed. A composed point's weight is the sum of its channels (the B_j
  // sum to 1, so eq. (2) with every point's weight 1 gives W^(l+m+n)), and its control point is
  // H_r / W_r: row r of C is the summed channels over the summed weights.
  const int nu = cu * pu + 1, nv = cv * pv + 1;
  const Eigen::Index rows = static_cast<Eigen::Index>(nu) * nv;
  const auto n = lattice.counts();
  const int channels = n[0] * n[1] * n[2];
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(rows);
  Eigen::VectorXi shared = Eigen::VectorXi::Zero(rows);
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b) {
      const Poly h = detail::to_degree(
          detail::to_degree(patches[static_cast<std::size_t>(a * cv + b)], pu, 0), pv, 1);
      for (int i = 0; i <= pu; ++i)
        for (int j = 0; j <= pv; ++j) {
          const Eigen::Index r = static_cast<Eigen::Index>(a * pu + i) * nv + (b * pv + j);
          ++shared(r);
          for (int c = 0; c < channels; ++c) {
            const double x = h.at(i, j, c);
            weight(r) += x;
            if (x != 0) entries.emplace_back(static_cast<int>(r), c, x);
          }
        }
    }
  CompositionJacobian out;
  out.matrix.resize(rows, channels);
  out.matrix.setFromTriplets(entries.begin(), entries.end());
  out.matrix = weight.cwiseInverse().asDiagonal() * out.matrix;
  out.surface.u = {pu, c0_knots(bp.breaks_u, pu)};
  out.surface.v = {pv, c0_knots(bp.breaks_v, pv)};
  out.surface.points = out.matrix * lattice.points;
  out.surface.weights = rational ? Eigen::VectorXd(weight.cwiseQuotient(shared.cast<double>()))
                                 : Eigen::VectorXd::Ones(rows);
  return out;
}

}  // namespace clay::deform
