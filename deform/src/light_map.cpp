// The light form of a lattice step as an affine map of the lattice's points (light_map.hpp).
#include <clay/deform/light_map.hpp>

#include <clay/deform/frozen_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/error.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "bernstein.hpp"
#include "fit_samples.hpp"
#include "seal.hpp"

namespace clay::deform {

namespace {

using surface::BSplineBasis;
using surface::BSplineSurface;

/// B_0^n(t) .. B_n^n(t), by the triangle of de Casteljau's algorithm.
void bernstein_values(int n, double t, std::vector<double>& b) {
  b.assign(static_cast<std::size_t>(n + 1), 0.0);
  b[0] = 1;
  for (int k = 1; k <= n; ++k)
    for (int i = k; i >= 0; --i)
      b[static_cast<std::size_t>(i)] = (1 - t) * b[static_cast<std::size_t>(i)] +
                                       (i > 0 ? t * b[static_cast<std::size_t>(i - 1)] : 0.0);
}

/// Row r of the result: the weights B_a(ξ(x_r)) of every lattice point a at samples[r] (zero for
/// a sample the lattice leaves where it is; `outside` marks those).
template <class Lattice>
Eigen::MatrixXd lattice_weights(const Lattice& lattice, const Points3& samples,
                                std::vector<char>& outside) {
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(samples.rows(), lattice.points.rows());
  outside.assign(static_cast<std::size_t>(samples.rows()), 0);
  std::array<std::vector<double>, 3> values;
  std::array<int, 3> first{0, 0, 0};
  for (Eigen::Index r = 0; r < samples.rows(); ++r) {
    Eigen::Vector3d local;
    if (!detail::clamped_local(lattice.frame, samples.row(r).transpose(), local)) {
      outside[static_cast<std::size_t>(r)] = 1;
      continue;
    }
    for (int d = 0; d < 3; ++d) {
      if constexpr (std::is_same_v<Lattice, BezierLattice>) {
        bernstein_values(lattice.degrees[static_cast<std::size_t>(d)], local[d],
                         values[static_cast<std::size_t>(d)]);
      } else {
        const BSplineBasis& b = lattice.bases[static_cast<std::size_t>(d)];
        const int span = surface::find_span(b, local[d]);
        values[static_cast<std::size_t>(d)].resize(static_cast<std::size_t>(b.degree + 1));
        surface::basis_functions(b, span, local[d], values[static_cast<std::size_t>(d)]);
        first[static_cast<std::size_t>(d)] = span - b.degree;
      }
    }
    for (std::size_t i = 0; i < values[0].size(); ++i)
      for (std::size_t j = 0; j < values[1].size(); ++j)
        for (std::size_t k = 0; k < values[2].size(); ++k)
          w(r, lattice.index(first[0] + static_cast<int>(i), first[1] + static_cast<int>(j),
                             first[2] + static_cast<int>(k))) =
              values[0][i] * values[1][j] * values[2][k];
  }
  return w;
}

/// The frame, degrees and knots of two lattices of one kind agree (points aside).
bool same_structure(const BezierLattice& a, const BezierLattice& b) {
  return a.frame.origin == b.frame.origin && a.frame.s == b.frame.s && a.frame.t == b.frame.t &&
         a.frame.u == b.frame.u && a.degrees == b.degrees && a.points.rows() == b.points.rows();
}
bool same_structure(const BSplineLattice& a, const BSplineLattice& b) {
  for (std::size_t d = 0; d < 3; ++d)
    if (a.bases[d].degree != b.bases[d].degree || a.bases[d].knots != b.bases[d].knots)
      return false;
  return a.frame.origin == b.frame.origin && a.frame.s == b.frame.s && a.frame.t == b.frame.t &&
         a.frame.u == b.frame.u && a.points.rows() == b.points.rows();
}

bool same_surface(const BSplineSurface& a, const BSplineSurface& b) {
  return a.u.degree == b.u.degree && a.v.degree == b.v.degree && a.u.knots == b.u.knots &&
         a.v.knots == b.v.knots && a.points.rows() == b.points.rows() &&
         a.weights.size() == b.weights.size() && a.points == b.points && a.weights == b.weights;
}

/// The lattice's points, for a Bézier or B-spline lattice; null for any other deformation.
const Points3* lattice_points(const Deformation& d) {
  if (const auto* b = std::get_if<BezierLattice>(&d)) return &b->points;
  if (const auto* b = std::get_if<BSplineLattice>(&d)) return &b->points;
  return nullptr;
}

/// Refit's least-squares parameters on a light form's bases (degree + 1 Chebyshev–Lobatto
/// intervals per span) and the pseudo-inverses A_u⁺, A_v⁺ of its collocations, by the same
/// column-pivoting QR as refit's least squares.
struct LightFit {
  std::vector<double> us, vs;
  Eigen::MatrixXd pu, pv;
  explicit LightFit(const BSplineSurface& light)
      : us(detail::fit_parameters(light.u, light.u.degree + 1)),
        vs(detail::fit_parameters(light.v, light.v.degree + 1)) {
    const auto mu = static_cast<Eigen::Index>(us.size()), mv = static_cast<Eigen::Index>(vs.size());
    pu = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(detail::collocation(light.u, us))
             .solve(Eigen::MatrixXd::Identity(mu, mu));
    pv = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(detail::collocation(light.v, vs))
             .solve(Eigen::MatrixXd::Identity(mv, mv));
  }
  /// A_u⁺ F A_vᵀ⁺ with F(r, s) = f(r mv + s), written to column `c` of `out` (row i cv + j).
  template <class Sample, class Out>
  void fit(Sample&& f, Out& out, Eigen::Index c) const {
    const auto mu = static_cast<Eigen::Index>(us.size()), mv = static_cast<Eigen::Index>(vs.size());
    Eigen::MatrixXd grid(mu, mv);
    for (Eigen::Index r = 0; r < mu; ++r)
      for (Eigen::Index s = 0; s < mv; ++s) grid(r, s) = f(r * mv + s);
    const Eigen::MatrixXd n = pu * grid * pv.transpose();
    const Eigen::Index cv = pv.rows();
    for (Eigen::Index i = 0; i < pu.rows(); ++i)
      for (Eigen::Index j = 0; j < cv; ++j) out(i * cv + j, c) = n(i, j);
  }
};

/// `what`'s arguments: a Bézier or B-spline lattice (the only deformations linear in their
/// points), a polynomial light form, valid surfaces.
void check_light(const Deformation& lattice, const BSplineSurface& input,
                 const BSplineSurface& light, const std::string& what) {
  if (!lattice_points(lattice))
    throw Error(ErrorCategory::InvalidArgument,
                what +
                    ": the deformation is not a Bézier or B-spline lattice, so its light form is "
                    "not linear in control points; refit it (refit_deformed) instead");
  if (light.is_rational())
    throw Error(ErrorCategory::InvalidArgument,
                what +
                    ": the light form is rational; give the polynomial net refit_deformed made "
                    "for this step");
  surface::validate(input, what + " input");
  surface::validate(light, what + " light form");
}

/// Closed sides and poles as the light form's fit keeps them (seal.hpp).
void seal(const BSplineSurface& input, BSplineSurface& out, const Deformation& d) {
  detail::keep_closed_and_collapsed(input, out, [&](const Eigen::Vector3d& x) {
    return std::visit([&](const auto& l) -> Eigen::Vector3d { return deform_point(l, x); }, d);
  });
}

}  // namespace

BSplineSurface light_fit(const Deformation& d, const BSplineSurface& input,
                         const BSplineSurface& light) {
  check_light(d, input, light, "light_fit");
  const LightFit fit(light);
  const Points3 samples = surface::evaluate_grid(input, fit.us, fit.vs);
  // The lattice frozen once (its power form, Sederberg–Parry eq. (2) to ~1e-15 of its size), as
  // a drag update deforms thousands of samples: de Casteljau per sample took most of the tank's
  // style drag update after the style itself.
  const Points3 moved = std::visit(
      [&](const auto& l) -> Points3 {
        using T = std::decay_t<decltype(l)>;
        if constexpr (std::is_same_v<T, BezierLattice> || std::is_same_v<T, BSplineLattice>) {
          validate(l, "light_fit lattice");
          return deform_points(l, samples);
        } else {
          return {};
        }
      },
      d);
  Points3 net(fit.pu.rows() * fit.pv.rows(), 3);
  for (Eigen::Index c = 0; c < 3; ++c) fit.fit([&](Eigen::Index k) { return moved(k, c); }, net, c);
  BSplineSurface out = surface::make_surface(light.u, light.v, std::move(net));
  seal(input, out, d);
  return out;
}

LatticeLightMap lattice_light_map(const Deformation& lattice, const BSplineSurface& input,
                                  const BSplineSurface& light) {
  check_light(lattice, input, light, "lattice_light_map");
  LatticeLightMap map;
  map.input = input;
  map.lattice = lattice;
  map.u = light.u;
  map.v = light.v;
  const LightFit fit(light);
  const Points3 samples = surface::evaluate_grid(input, fit.us, fit.vs);
  std::vector<char> outside;
  const Eigen::MatrixXd w = std::visit(
      [&](const auto& l) -> Eigen::MatrixXd {
        using T = std::decay_t<decltype(l)>;
        if constexpr (std::is_same_v<T, BezierLattice> || std::is_same_v<T, BSplineLattice>) {
          validate(l, "lattice_light_map lattice");
          return lattice_weights(l, samples, outside);
        } else {
          return {};
        }
      },
      lattice);
  // N_a = A_u⁺ F_a A_vᵀ⁺ with F_a(r, s) = w(r mv + s, a); row i cv + j of N is C_ij.
  const Eigen::Index cu = fit.pu.rows(), cv = fit.pv.rows();
  map.weights.resize(cu * cv, w.cols());
  for (Eigen::Index a = 0; a < w.cols(); ++a) {
    if (w.col(a).isZero(0))
      map.weights.col(a).setZero();
    else
      fit.fit([&](Eigen::Index k) { return w(k, a); }, map.weights, a);
  }
  map.outside = Points3::Zero(cu * cv, 3);
  if (std::find(outside.begin(), outside.end(), 1) != outside.end())
    for (Eigen::Index c = 0; c < 3; ++c)
      fit.fit(
          [&](Eigen::Index k) {
            return outside[static_cast<std::size_t>(k)] ? samples(k, c) : 0.0;
          },
          map.outside, c);
  return map;
}

bool applies_to(const LatticeLightMap& map, const Deformation& lattice,
                const BSplineSurface& input) noexcept {
  if (lattice.index() != map.lattice.index() || !same_surface(map.input, input)) return false;
  if (const auto* b = std::get_if<BezierLattice>(&lattice))
    return same_structure(*b, std::get<BezierLattice>(map.lattice));
  if (const auto* b = std::get_if<BSplineLattice>(&lattice))
    return same_structure(*b, std::get<BSplineLattice>(map.lattice));
  return false;
}

BSplineSurface light_net(const LatticeLightMap& map, const Deformation& lattice) {
  if (!applies_to(map, lattice, map.input))
    throw Error(ErrorCategory::InvalidArgument,
                "light_net: the lattice's kind, frame, degrees or knots differ from the ones the "
                "map was made for; make a new map (lattice_light_map) for this lattice");
  Points3 net = map.weights * *lattice_points(lattice) + map.outside;
  BSplineSurface out = surface::make_surface(map.u, map.v, std::move(net));
  seal(map.input, out, lattice);
  return out;
}

}  // namespace clay::deform
