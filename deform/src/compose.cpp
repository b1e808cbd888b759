// Exact FFD composition (Sederberg–Parry 1986 §2.1): Bernstein products per Bézier patch of the
// surface, patches joined into one B-spline surface, exact knot removal (The NURBS Book A5.8).
#include <clay/cancel.hpp>
#include <clay/deform/compose.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/math.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bernstein_poly.hpp"
#include "compose_factors.hpp"
#include "compose_size.hpp"
#include "lattice_monomials.hpp"
#include "messages.hpp"
#include "patch_containment.hpp"
#include "seal.hpp"

namespace clay::deform {

namespace {

using surface::BSplineSurface;

using detail::format;

std::string fmt(double v) { return format(v, 6); }  // short figures for messages

constexpr const char* coordinate_name[3] = {"s", "t", "u"};

using detail::casteljau;
using detail::cell_factors;
using detail::constant_poly;
using detail::degree_tolerance;
using detail::dual_vectors;
using detail::exact_degree;
using detail::Factor;
using detail::halve;
using detail::LatticeMonomials;
using detail::leaves;
using detail::make_factor;
using detail::mul_add;
using detail::multiply;
using detail::patch_coordinates;
using detail::PatchCoordinates;
using detail::Poly;
using detail::ratio_poly;
using detail::scale;
using detail::to_degree;
using detail::value_at;
using detail::Violation;
using detail::weight_degrees;

/// A composed patch: unscaled homogeneous coefficients (x w, y w, z w, w), dim 4.
struct ComposedPatch {
  int du = 0, dv = 0;
  Poly h;
};

/// Degrees of eq. (2) composed on a patch with these factors: Σ_d degree_d · factor degree.
std::pair<int, int> composed_degrees(const std::array<Factor, 3>& f, std::array<int, 3> degrees) {
  int du = 0, dv = 0;
  for (size_t d = 0; d < 3; ++d) {
    du += degrees[d] * f[d].du;
    dv += degrees[d] * f[d].dv;
  }
  return {du, dv};
}

/// Sederberg–Parry eq. (2) with the factors' polynomials in place of s, t, u: u (k) innermost,
/// then t (j), then s (i). `dim` 3 (polynomial: the weight is W^0 = 1) or 4 (the weight
/// Σ B B B · 1 = W^L rides along).
ComposedPatch compose_patch(const BezierLattice& cell, const std::array<Factor, 3>& f,
                            bool rational) {
  const int dim = rational ? 4 : 3;
  const auto n = cell.counts();
  std::vector<Poly> along_s;
  along_s.reserve(static_cast<size_t>(n[0]));
  for (int i = 0; i < n[0]; ++i) {
    std::vector<Poly> along_t;
    along_t.reserve(static_cast<size_t>(n[1]));
    for (int j = 0; j < n[1]; ++j) {
      std::vector<Poly> along_u;
      along_u.reserve(static_cast<size_t>(n[2]));
      for (int k = 0; k < n[2]; ++k) {
        Poly p(0, 0, dim);
        for (int d = 0; d < 3; ++d)
          p.c[static_cast<size_t>(d)] = cell.points(cell.index(i, j, k), d);
        if (rational) p.c[3] = 1;
        along_u.push_back(std::move(p));
      }
      along_t.push_back(casteljau(std::move(along_u), f[2]));
    }
    along_s.push_back(casteljau(std::move(along_t), f[1]));
  }
  ComposedPatch out;
  out.h = casteljau(std::move(along_s), f[0]);
  scale(out.h, true);
  if (!rational) {  // append w = 1
    Poly h(out.h.du, out.h.dv, 4);
    for (int i = 0; i <= h.du; ++i)
      for (int j = 0; j <= h.dv; ++j) {
        for (int d = 0; d < 3; ++d) h.at(i, j, d) = out.h.at(i, j, d);
        h.at(i, j, 3) = 1;
      }
    out.h = std::move(h);
  }
  out.du = out.h.du;
  out.dv = out.h.dv;
  return out;
}

// ---- the same composition monomial by monomial, at the lattice's true total degree ----------

/// The exponent sum of a monomial over the coordinates that are not constant on the patch.
int varying_exponent(const std::array<Factor, 3>& f, const std::array<int, 3>& e) {
  int sum = 0;
  for (size_t d = 0; d < 3; ++d)
    if (!f[d].constant) sum += e[d];
  return sum;
}

/// The largest varying_exponent over the monomials: the power of W in the homogeneous form.
int varying_degree(const std::array<Factor, 3>& f, const LatticeMonomials& lm) {
  int t = 0;
  for (const auto& e : lm.exponents) t = std::max(t, varying_exponent(f, e));
  return t;
}

/// Degrees of the composition written term by term: X W^T = Σ_k x_k Π_d S_d^(a_d) W^(T − Σ a_d)
/// (constant coordinates contribute c_d^(a_d), no degree), so a term has degree Σ a_d deg S_d +
/// (T − Σ a_d) deg W in each direction, and the composition the largest of them. Never above
/// composed_degrees (a_d <= the lattice degree along d, deg W <= deg S_d).
std::pair<int, int> monomial_degrees(const std::array<Factor, 3>& f, const LatticeMonomials& lm) {
  const int t = varying_degree(f, lm);
  int du = 0, dv = 0;
  for (const auto& e : lm.exponents) {
    const int rest = t - varying_exponent(f, e);
    int tu = rest * f[0].w.du, tv = rest * f[0].w.dv;
    for (size_t d = 0; d < 3; ++d)
      if (!f[d].constant) tu += e[d] * f[d].du, tv += e[d] * f[d].dv;
    du = std::max(du, tu);
    dv = std::max(dv, tv);
  }
  return {du, dv};
}

/// The scaled Bernstein form of the constant 1 at degrees (du, dv): multiplying by it raises a
/// scaled poly's degrees exactly.
Poly scaled_one(int du, int dv) {
  Poly one(du, dv, 1);
  const auto& bu = internal::binomial_row(du);
  const auto& bv = internal::binomial_row(dv);
  for (int i = 0; i <= du; ++i)
    for (int j = 0; j <= dv; ++j)
      one.at(i, j) = bu[static_cast<size_t>(i)] * bv[static_cast<size_t>(j)];
  return one;
}

/// Sederberg–Parry eq. (2) expanded in the power basis of (s, t, u), with the factors'
/// polynomials in place of s, t, u: Σ_k x_k Π_d S_d^(a_d) W^(T − Σ a_d) over the lattice's
/// monomials, each term raised to the common degrees. Used when the lattice's true total degree
/// gives lower degrees than the tensor product (an affine lattice keeps the surface's degrees).
ComposedPatch compose_by_monomials(const LatticeMonomials& lm, const std::array<Factor, 3>& f,
                                   bool rational) {
  const int t = varying_degree(f, lm);
  const auto [du, dv] = monomial_degrees(f, lm);
  std::vector<Poly> w_power{constant_poly(1)};
  for (int k = 1; k <= t; ++k) w_power.push_back(multiply(w_power.back(), f[0].w));
  std::array<std::vector<Poly>, 3> s_power;
  for (size_t d = 0; d < 3; ++d) {
    if (f[d].constant) continue;
    s_power[d].push_back(constant_poly(1));
    for (const auto& e : lm.exponents)
      while (static_cast<int>(s_power[d].size()) <= e[d])
        s_power[d].push_back(multiply(s_power[d].back(), f[d].s));
  }
  Poly sum(du, dv, 3);
  for (size_t k = 0; k < lm.exponents.size(); ++k) {
    const auto& e = lm.exponents[k];
    double constant = 1;
    Poly term = w_power[static_cast<size_t>(t - varying_exponent(f, e))];
    for (size_t d = 0; d < 3; ++d) {
      if (f[d].constant)
        constant *= std::pow(f[d].value, e[d]);
      else
        term = multiply(term, s_power[d][static_cast<size_t>(e[d])]);
    }
    Poly vector_term(term.du, term.dv, 3);
    for (size_t c = 0; c < term.c.size(); ++c)
      for (size_t d = 0; d < 3; ++d)
        vector_term.c[3 * c + d] =
            term.c[c] * constant * lm.coefficients[k][static_cast<Eigen::Index>(d)];
    mul_add(vector_term, scaled_one(du - term.du, dv - term.dv), sum);
  }
  ComposedPatch out;
  out.h = Poly(du, dv, 4);
  const Poly weight = multiply(
      w_power[static_cast<size_t>(t)],
      scaled_one(du - w_power[static_cast<size_t>(t)].du, dv - w_power[static_cast<size_t>(t)].dv));
  for (size_t c = 0; c < weight.c.size(); ++c) {
    for (size_t d = 0; d < 3; ++d) out.h.c[4 * c + d] = sum.c[3 * c + d];
    out.h.c[4 * c + 3] = rational ? weight.c[c] : 0.0;  // set to 1 below
  }
  scale(out.h, true);
  if (!rational)  // exactly 1, as compose_patch appends it
    for (size_t c = 0; c < weight.c.size(); ++c) out.h.c[4 * c + 3] = 1;
  out.du = du;
  out.dv = dv;
  return out;
}

/// True when the lattice's monomials give lower degrees than the tensor product on this patch
/// (and the power basis is well enough conditioned to compose by it).
bool by_monomials(const std::array<Factor, 3>& f, const BezierLattice& cell,
                  const LatticeMonomials& lm) {
  if (!lm.usable()) return false;
  const auto tensor = composed_degrees(f, cell.degrees);
  const auto monomial = monomial_degrees(f, lm);
  return monomial.first < tensor.first || monomial.second < tensor.second;
}

/// The degrees of a cell's composition on a patch, by the route compose_cell takes.
std::pair<int, int> composition_degrees(const std::array<Factor, 3>& f, const BezierLattice& cell,
                                        const LatticeMonomials& lm) {
  return by_monomials(f, cell, lm) ? monomial_degrees(f, lm) : composed_degrees(f, cell.degrees);
}

/// One patch composed with one cell: monomial by monomial when that lowers the degrees,
/// otherwise the de Casteljau route.
ComposedPatch compose_cell(const BezierLattice& cell, const LatticeMonomials& lm,
                           const std::array<Factor, 3>& f, bool rational) {
  return by_monomials(f, cell, lm) ? compose_by_monomials(lm, f, rational)
                                   : compose_patch(cell, f, rational);
}

/// Name of a patch and its parameter box, and of a patch-local parameter, for messages.
std::string patch_name(const surface::BezierPatches& bp, int a, int b) {
  return "patch (" + std::to_string(a) + ", " + std::to_string(b) + ") over u in [" +
         fmt(bp.breaks_u[static_cast<size_t>(a)]) + ", " +
         fmt(bp.breaks_u[static_cast<size_t>(a + 1)]) + "], v in [" +
         fmt(bp.breaks_v[static_cast<size_t>(b)]) + ", " +
         fmt(bp.breaks_v[static_cast<size_t>(b + 1)]) + "]";
}
std::pair<double, double> global_parameter(const surface::BezierPatches& bp, int a, int b, double x,
                                           double y) {
  const double u0 = bp.breaks_u[static_cast<size_t>(a)],
               u1 = bp.breaks_u[static_cast<size_t>(a + 1)];
  const double v0 = bp.breaks_v[static_cast<size_t>(b)],
               v1 = bp.breaks_v[static_cast<size_t>(b + 1)];
  return {u0 + x * (u1 - u0), v0 + y * (v1 - v0)};
}

[[noreturn]] void throw_outside(const surface::BezierPatches& bp, int a, int b, int d,
                                const Violation& v, std::string_view lattice_kind,
                                std::string_view caller = "compose_exact") {
  const auto [u, w] = global_parameter(bp, a, b, v.x, v.y);
  throw Error(
      ErrorCategory::OutOfDomain,
      std::string(caller) + ": surface " + patch_name(bp, a, b) + " leaves the " +
          std::string(lattice_kind) + ": local coordinate " + coordinate_name[d] + " = " +
          format(v.value) + (v.certain ? " at" : " (bound; not certified inside) near") +
          " parameter (" + format(u) + ", " + format(w) +
          ") is outside [0, 1]; the FFD is the identity outside the lattice, so the deformed "
          "surface is not one polynomial there: enlarge the lattice frame to contain the "
          "whole surface");
}

// ---- joining patches (surface::join_bezier_patches, then surface::remove_knots) ---------------

/// The composed patches as the Bézier patches of surface::join_bezier_patches: control points
/// (x w, y w, z w) / w and weights w of each homogeneous Bernstein net (w = 1 when polynomial).
surface::BezierPatches as_bezier_patches(const surface::BezierPatches& bp,
                                         const std::vector<ComposedPatch>& patches, bool rational) {
  surface::BezierPatches out;
  out.breaks_u = bp.breaks_u;
  out.breaks_v = bp.breaks_v;
  out.patches.reserve(patches.size());
  const int cv = bp.count_v();
  for (std::size_t k = 0; k < patches.size(); ++k) {
    const ComposedPatch& p = patches[k];
    const auto a = static_cast<std::size_t>(static_cast<int>(k) / cv),
               b = static_cast<std::size_t>(static_cast<int>(k) % cv);
    const int du = std::max(p.du, 1), dv = std::max(p.dv, 1);
    const Poly h = to_degree(to_degree(p.h, du, 0), dv, 1);
    BSplineSurface s;
    s.u = {du, std::vector<double>(static_cast<std::size_t>(du + 1), bp.breaks_u[a])};
    s.u.knots.insert(s.u.knots.end(), static_cast<std::size_t>(du + 1), bp.breaks_u[a + 1]);
    s.v = {dv, std::vector<double>(static_cast<std::size_t>(dv + 1), bp.breaks_v[b])};
    s.v.knots.insert(s.v.knots.end(), static_cast<std::size_t>(dv + 1), bp.breaks_v[b + 1]);
    s.points.resize((du + 1) * (dv + 1), 3);
    s.weights = Eigen::VectorXd::Ones(s.points.rows());
    for (int i = 0; i <= du; ++i)
      for (int j = 0; j <= dv; ++j) {
        const Eigen::Index r = s.index(i, j);
        const double w = rational ? h.at(i, j, 3) : 1.0;
        for (int d = 0; d < 3; ++d) s.points(r, d) = h.at(i, j, d) / w;
        s.weights(r) = w;
      }
    out.patches.push_back(std::move(s));
  }
  return out;
}

/// The largest homogeneous control point |(w P, w)|: knot removal measures its gaps on those.
double largest_homogeneous_point(const BSplineSurface& s) {
  double hmax = 0;
  for (Eigen::Index r = 0; r < s.points.rows(); ++r) {
    const double w = s.weights.size() ? s.weights(r) : 1.0;
    hmax = std::max(hmax, std::sqrt((w * s.points.row(r)).squaredNorm() + w * w));
  }
  return hmax;
}

// ---- the pipeline shared by the entry points ------------------------------------------------

/// Why an exact composition is refused for its degree: the patch, its degree and the ways out.
std::string degree_message(int du, int dv, int max_degree, const std::string& what,
                           const std::string& ways_out) {
  return "compose_exact: the exact composition " + what + " has degree (" + std::to_string(du) +
         ", " + std::to_string(dv) + "), above the limit " + std::to_string(max_degree) +
         " (ComposeOptions::max_degree; 25 is OpenCASCADE's and most CAD systems'); " + ways_out;
}

/// Joins composed patches, removes knots, measures the deviation against `pointwise`.
ComposeResult finish(const surface::BezierPatches& bp, const std::vector<ComposedPatch>& patches,
                     bool rational, const BSplineSurface& original,
                     const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& pointwise,
                     double size, const ComposeOptions& options, int splits) {
  ComposeReport report;
  report.patches = static_cast<int>(patches.size());
  report.splits = splits;
  ComposeResult result{surface::join_bezier_patches(as_bezier_patches(bp, patches, rational)), {}};
  // A rational composition whose weights all came out equal is polynomial: weights 1.
  if (result.surface.weights.size() > 0 &&
      (result.surface.weights.array() == result.surface.weights(0)).all())
    result.surface.weights.setOnes();
  if (options.knot_tolerance > 0) {
    // The tolerance is relative to the largest homogeneous control point, as removal measures
    // its gaps on (w·P, w).
    const double tol = options.knot_tolerance * largest_homogeneous_point(result.surface);
    auto removal = surface::remove_knots(result.surface, tol);
    report.knots_removed = removal.removed;
    result.surface = std::move(removal.surface);
  }
  detail::keep_closed_and_collapsed(original, result.surface, pointwise);
  report.degree_u = result.surface.u.degree;
  report.degree_v = result.surface.v.degree;
  report.control_points = static_cast<long>(result.surface.points.rows());
  report.size = size;
  // The check: n x n samples inside every patch, the original and the result evaluated on the
  // whole grid at once (evaluate_grid), the original's points deformed one by one by the
  // reference evaluation.
  const int n = options.check_samples;
  if (n > 0) {
    auto samples = [n](const std::vector<double>& breaks) {
      std::vector<double> out;
      for (size_t a = 0; a + 1 < breaks.size(); ++a)
        for (int x = 0; x < n; ++x)
          out.push_back(breaks[a] + (x + 0.5) / n * (breaks[a + 1] - breaks[a]));
      return out;
    };
    const auto us = samples(bp.breaks_u), vs = samples(bp.breaks_v);
    const Points3 before = surface::evaluate_grid(original, us, vs);
    const Points3 after = surface::evaluate_grid(result.surface, us, vs);
    for (Eigen::Index r = 0; r < before.rows(); ++r) {
      const Eigen::Vector3d expected = pointwise(Eigen::Vector3d(before.row(r).transpose()));
      report.max_relative_deviation = std::max(report.max_relative_deviation,
                                               (after.row(r).transpose() - expected).norm() / size);
    }
  }
  report.exact = true;
  report.summary.termination = Termination::Converged;
  report.summary.final_residual = report.max_relative_deviation;
  report.summary.message = report.brief();
  result.report = report;
  return result;
}

double lattice_size(const Points3& points) {
  return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
}

/// Splits `surface` where a local coordinate that depends on one surface parameter only crosses
/// an interior knot plane of the lattice (HHK lattices meet the surface along iso-lines there):
/// knots inserted to full multiplicity. Returns the split surface, the number of knots added and
/// every crossing (also those at existing breaks, where nothing is inserted).
std::tuple<BSplineSurface, int, detail::PlaneCrossings> split_at_planes(
    const BSplineSurface& surface, const BSplineLattice& lattice,
    const std::array<std::vector<double>, 3>& breaks) {
  const auto dual = dual_vectors(lattice.frame);
  const auto bp = surface::extract_bezier(surface);
  std::array<std::vector<double>, 2> cuts, at_breaks;
  for (int a = 0; a < bp.count_u(); ++a)
    for (int b = 0; b < bp.count_v(); ++b) {
      const PatchCoordinates pc = patch_coordinates(bp.patch(a, b), lattice.frame.origin, dual);
      for (int d = 0; d < 3; ++d) {
        const Poly& c = pc.c[static_cast<size_t>(d)];
        for (int dir = 0; dir < 2; ++dir) {
          // c depends on the parameter `dir` only when C(x, y) W(x, y0) − C(x, y0) W(x, y) ≡ 0
          // (dir 0; y0 = the patch's first row), i.e. c(x, y) = c(x, y0).
          const int other = dir == 0 ? c.dv : c.du;
          const int p = dir == 0 ? c.du : c.dv;
          auto get = [&](const Poly& q, int k, int o) {
            return dir == 0 ? q.at(k, o) : q.at(o, k);
          };
          Poly c_row(p, 0, 1), w_row(p, 0, 1), c_all(p, other, 1), w_all(p, other, 1);
          for (int k = 0; k <= p; ++k) {
            c_row.at(k, 0) = get(c, k, 0);
            w_row.at(k, 0) = get(pc.w, k, 0);
            for (int o = 0; o <= other; ++o)
              c_all.at(k, o) = get(c, k, o), w_all.at(k, o) = get(pc.w, k, o);
          }
          scale(c_row, false), scale(w_row, false), scale(c_all, false), scale(w_all, false);
          Poly g = multiply(c_all, w_row);
          Poly neg_w = w_all;
          for (double& x : neg_w.c) x = -x;
          mul_add(neg_w, c_row, g);
          scale(g, true);
          bool one_parameter = true;
          for (double x : g.c)
            one_parameter = one_parameter && std::abs(x) <= 1e-13 * pc.c_scale * pc.w_scale;
          if (!one_parameter) continue;
          const auto& br = breaks[static_cast<size_t>(d)];
          const double x0 =
              dir == 0 ? bp.breaks_u[static_cast<size_t>(a)] : bp.breaks_v[static_cast<size_t>(b)];
          const double x1 = dir == 0 ? bp.breaks_u[static_cast<size_t>(a + 1)]
                                     : bp.breaks_v[static_cast<size_t>(b + 1)];
          for (size_t plane = 1; plane + 1 < br.size(); ++plane) {
            std::vector<double> h(static_cast<size_t>(p + 1));
            for (int k = 0; k <= p; ++k)
              h[static_cast<size_t>(k)] = get(c, k, 0) - br[plane] * get(pc.w, k, 0);
            for (double x : detail::bernstein_roots(h)) {
              const double t = x0 + x * (x1 - x0);
              if (t - x0 > 1e-13 * (x1 - x0) && x1 - t > 1e-13 * (x1 - x0))
                cuts[static_cast<size_t>(dir)].push_back(t);
            }
            // A crossing at the patch's own ends (an existing break) splits nothing, but the
            // composition is only as smooth as the lattice there (compose_size.hpp).
            for (const auto& [end, t] : {std::pair{h.front(), x0}, std::pair{h.back(), x1}})
              if (std::abs(end) <= 1e-10 * pc.c_scale * pc.w_scale)
                at_breaks[static_cast<size_t>(dir)].push_back(t);
          }
        }
      }
    }
  BSplineSurface out = surface;
  int added = 0;
  for (int dir = 0; dir < 2; ++dir) {
    auto& c = cuts[static_cast<size_t>(dir)];
    // The same crossing found from several patches of a row differs by rounding: merge cuts
    // closer than 1e-12 of the domain, and drop those that close to an existing break.
    const auto [d0, d1] = (dir == 0 ? surface.u : surface.v).domain();
    const double merge = 1e-12 * (d1 - d0);
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end(), [&](double x, double y) { return y - x <= merge; }),
            c.end());
    const int p = dir == 0 ? out.u.degree : out.v.degree;
    const auto existing = surface::breakpoints(dir == 0 ? surface.u : surface.v);
    for (double t : c) {
      if (std::any_of(existing.begin(), existing.end(),
                      [&](double b) { return std::abs(b - t) <= merge; }))
        continue;
      const int have = surface::multiplicity(dir == 0 ? out.u : out.v, t);
      if (have >= p) continue;
      out = dir == 0 ? surface::insert_knot_u(out, t, p - have)
                     : surface::insert_knot_v(out, t, p - have);
      added += p - have;
    }
  }
  for (int dir = 0; dir < 2; ++dir)
    cuts[static_cast<size_t>(dir)].insert(cuts[static_cast<size_t>(dir)].end(),
                                          at_breaks[static_cast<size_t>(dir)].begin(),
                                          at_breaks[static_cast<size_t>(dir)].end());
  return {out, added, cuts};
}

}  // namespace

// ---- public ---------------------------------------------------------------------------------

namespace detail {

void throw_leaves_lattice(const surface::BezierPatches& bp, int a, int b, int d, const Violation& v,
                          std::string_view lattice_kind, std::string_view caller) {
  throw_outside(bp, a, b, d, v, lattice_kind, caller);
}

LatticePatches locate_patches(const BSplineLattice& lattice, const BezierCells& cells,
                              const BSplineSurface& surface, std::string_view caller) {
  LatticePatches out;
  std::tie(out.split, out.splits, out.planes) = split_at_planes(surface, lattice, cells.breaks);
  out.bp = surface::extract_bezier(out.split);
  const auto& bp = out.bp;
  const auto dual = dual_vectors(lattice.frame);
  const auto counts = cells.counts();
  out.cells.resize(bp.patches.size());
  out.factors.resize(bp.patches.size());
  for (int a = 0; a < bp.count_u(); ++a)
    for (int b = 0; b < bp.count_v(); ++b) {
      const PatchCoordinates pc = patch_coordinates(bp.patch(a, b), lattice.frame.origin, dual);
      std::array<int, 3> index{};
      std::array<double, 3> lo{}, width{};
      for (int d = 0; d < 3; ++d) {
        const Poly cw = ratio_poly(pc, d);
        if (auto v = leaves(cw, 0, 1, face_tolerance))
          throw_outside(bp, a, b, d, *v, "B-spline lattice", caller);
        const auto& br = cells.breaks[static_cast<size_t>(d)];
        const double centre = value_at(cw, 0.5, 0.5, 0) / value_at(cw, 0.5, 0.5, 1);
        int cell =
            static_cast<int>(std::upper_bound(br.begin(), br.end(), centre) - br.begin()) - 1;
        cell = std::clamp(cell, 0, counts[static_cast<size_t>(d)] - 1);
        // The cell holding the patch's centre, or a neighbour: a patch touching a knot plane at
        // its centre lies in the cell on the other side.
        // When none holds it, the message shows the smallest excursion out of its cell (a bump
        // just over the plane rather than the far corner of the cell above).
        auto excess = [&](const Violation& x, int c) {
          return std::max(br[static_cast<size_t>(c)] - x.value,
                          x.value - br[static_cast<size_t>(c + 1)]);
        };
        std::optional<Violation> v = leaves(cw, br[static_cast<size_t>(cell)],
                                            br[static_cast<size_t>(cell + 1)], face_tolerance);
        int shown = cell;
        for (int next : {cell - 1, cell + 1}) {
          if (!v || next < 0 || next >= counts[static_cast<size_t>(d)]) continue;
          auto w = leaves(cw, br[static_cast<size_t>(next)], br[static_cast<size_t>(next + 1)],
                          face_tolerance);
          if (!w) {
            cell = next;
            v.reset();
          } else if (w->certain && (!v->certain || excess(*w, next) < excess(*v, shown))) {
            v = w;
            shown = next;
          }
        }
        const double c0 = br[static_cast<size_t>(v ? shown : cell)],
                     c1 = br[static_cast<size_t>((v ? shown : cell) + 1)];
        if (v) {
          const double plane = v->value < c0 ? c0 : c1;
          const auto [u, w] = global_parameter(bp, a, b, v->x, v->y);
          throw Error(
              ErrorCategory::InvalidArgument,
              std::string(caller) + ": surface " + patch_name(bp, a, b) +
                  " crosses the lattice knot plane " + coordinate_name[d] + " = " + format(plane) +
                  " (" +
                  (v->certain
                       ? coordinate_name[d] + std::string(" = ") + format(v->value) +
                             " at parameter ("
                       : std::string("not decided: the convex hull's bound ") + coordinate_name[d] +
                             " = " + format(v->value) + " near parameter (") +
                  format(u) + ", " + format(w) +
                  ")) other than along an iso-parameter line: no single polynomial patch is "
                  "exact there; approximate the deformed surface with a refit tolerance "
                  "(certified refit), or move the knot plane off the surface");
        }
        index[static_cast<size_t>(d)] = cell;
        lo[static_cast<size_t>(d)] = c0;
        width[static_cast<size_t>(d)] = c1 - c0;
      }
      const size_t k = static_cast<size_t>(a * bp.count_v() + b);
      out.cells[k] = index;
      out.factors[k] = cell_factors(pc, lo, width);
    }
  return out;
}

}  // namespace detail

namespace {
// The largest ComposeOptions::max_degree: the Bernstein products' binomials C(n, k) stay integers
// exactly representable in a double (below 2^53) up to n = 56; 50 leaves room for the products.
constexpr int kMaxComposeDegree = 50;
}  // namespace

std::vector<std::string> ComposeOptions::problems() const {
  std::vector<std::string> out;
  if (!(knot_tolerance >= 0 && knot_tolerance <= 1e-6))
    out.push_back(
        "ComposeOptions: knot_tolerance = " + format(knot_tolerance) +
        " breaks the rule 0 <= knot_tolerance <= 1e-6 (relative, exact removal only); give "
        "e.g. 1e-12, or 0 to keep every patch boundary");
  if (check_samples < 0 || check_samples > 64)
    out.push_back("ComposeOptions: check_samples = " + std::to_string(check_samples) +
                  " breaks the rule 0 <= check_samples <= 64; give e.g. 4, or 0 to skip the check");
  if (max_degree < 1 || max_degree > kMaxComposeDegree)
    out.push_back("ComposeOptions: max_degree = " + std::to_string(max_degree) +
                  " breaks the rule 1 <= max_degree <= " + std::to_string(kMaxComposeDegree) +
                  "; give the receiver's limit, e.g. 25 (OpenCASCADE) or 15 (CATIA's order 16)");
  if (max_control_points < 0)
    out.push_back("ComposeOptions: max_control_points = " + std::to_string(max_control_points) +
                  " breaks the rule max_control_points >= 0; give e.g. 10000, or 0 for no limit");
  return out;
}

void ComposeOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string ComposeReport::brief() const {
  std::ostringstream m;
  m.precision(3);
  m << "exact composition: degree " << degree_u << " x " << degree_v << ", " << patches
    << " patches, " << control_points << " control points, " << knots_removed << " knots removed, "
    << splits << " split knots, max relative deviation " << max_relative_deviation << " x " << size
    << " mm";
  return m.str();
}

ComposeResult compose_exact(const BezierLattice& lattice, const BSplineSurface& surface,
                            const ComposeOptions& options) {
  options.validate();
  validate(lattice, "compose_exact: Bézier lattice");
  surface::validate(surface, "compose_exact: surface");
  const bool rational = surface.is_rational();
  const auto bp = surface::extract_bezier(surface);
  const auto dual = dual_vectors(lattice.frame);
  const LatticeMonomials monomials = detail::lattice_monomials(lattice);
  const int np = static_cast<int>(bp.patches.size());
  std::vector<std::array<Factor, 3>> factors(static_cast<size_t>(np));
  std::vector<std::pair<int, int>> degrees(factors.size());
  std::string too_high;  // the first patch above max_degree
  for (int a = 0; a < bp.count_u(); ++a)
    for (int b = 0; b < bp.count_v(); ++b) {
      const PatchCoordinates pc = patch_coordinates(bp.patch(a, b), lattice.frame.origin, dual);
      for (int d = 0; d < 3; ++d)
        if (auto v = leaves(ratio_poly(pc, d), 0, 1, face_tolerance))
          throw_outside(bp, a, b, d, *v, "Bézier lattice");
      auto& f = factors[static_cast<size_t>(a * bp.count_v() + b)];
      f = cell_factors(pc, {0, 0, 0}, {1, 1, 1});
      const auto [du, dv] = composition_degrees(f, lattice, monomials);
      degrees[static_cast<size_t>(a * bp.count_v() + b)] = {du, dv};
      if (std::max(du, dv) > options.max_degree && too_high.empty())
        too_high = degree_message(
            du, dv, options.max_degree,
            "of surface " + patch_name(bp, a, b) + " (degree " + std::to_string(surface.u.degree) +
                " x " + std::to_string(surface.v.degree) + ") with a Bézier lattice of degrees (" +
                std::to_string(lattice.degrees[0]) + ", " + std::to_string(lattice.degrees[1]) +
                ", " + std::to_string(lattice.degrees[2]) + ")",
            "use a lattice of lower degree (e.g. in the thickness direction), or approximate "
            "the deformed surface with a refit tolerance (certified refit)");
    }
  detail::check_size(detail::predicted_size(surface, bp, degrees), options, too_high);
  std::vector<ComposedPatch> patches(static_cast<size_t>(np));
  for (size_t k = 0; k < patches.size(); ++k) {
    throw_if_cancelled("an exact composition");
    patches[k] = compose_cell(lattice, monomials, factors[k], rational);
  }
  return finish(
      bp, patches, rational, surface,
      [&](const Eigen::Vector3d& x) { return deform_point(lattice, x); },
      lattice_size(lattice.points), options, 0);
}

ComposeResult compose_exact(const BSplineLattice& lattice, const BSplineSurface& surface,
                            const ComposeOptions& options) {
  options.validate();
  validate(lattice, "compose_exact: B-spline lattice");
  surface::validate(surface, "compose_exact: surface");
  const BezierCells cells = bezier_cells(lattice);
  const detail::LatticePatches located = detail::locate_patches(lattice, cells, surface);
  const BSplineSurface& split = located.split;
  const auto& bp = located.bp;
  const auto& factors = located.factors;
  const bool rational = split.is_rational();
  std::vector<const BezierLattice*> cell_of(bp.patches.size());
  std::vector<std::pair<int, int>> degrees(bp.patches.size());
  std::string too_high;  // the first patch above max_degree
  // Each cell's monomials, found once for all the patches in it.
  std::map<const BezierLattice*, LatticeMonomials> monomials_of;
  for (int a = 0; a < bp.count_u(); ++a)
    for (int b = 0; b < bp.count_v(); ++b) {
      const size_t k = static_cast<size_t>(a * bp.count_v() + b);
      const auto& index = located.cells[k];
      cell_of[k] = &cells.cell(index[0], index[1], index[2]);
      auto known = monomials_of.find(cell_of[k]);
      if (known == monomials_of.end())
        known = monomials_of.emplace(cell_of[k], detail::lattice_monomials(*cell_of[k])).first;
      const auto [du, dv] = composition_degrees(factors[k], *cell_of[k], known->second);
      degrees[k] = {du, dv};
      if (std::max(du, dv) > options.max_degree && too_high.empty())
        too_high = degree_message(
            du, dv, options.max_degree,
            "of surface " + patch_name(bp, a, b) + " with a B-spline lattice of degrees (" +
                std::to_string(lattice.bases[0].degree) + ", " +
                std::to_string(lattice.bases[1].degree) + ", " +
                std::to_string(lattice.bases[2].degree) + ")",
            "use a lattice of lower degree (e.g. in the thickness direction), or approximate "
            "the deformed surface with a refit tolerance (certified refit)");
    }
  // A rational patch's homogeneous weight is W^t, t the degree its route composes with: the
  // tensor product's, or a cell's true total degree by monomials (lower where the cell is
  // undisplaced, affine). Neighbouring patches composed with different t are the same rational
  // surface with different homogeneous points, and joining them fails (a rational fillet under
  // a bulged B-spline lattice, issue #39). So when the patches' t differ, every patch takes the
  // tensor route, whose t is the same in every cell.
  bool tensor_only = false;
  if (rational) {
    auto power = [&](size_t k) {
      const LatticeMonomials& lm = monomials_of.at(cell_of[k]);
      return by_monomials(factors[k], *cell_of[k], lm) ? varying_degree(factors[k], lm) : -1;
    };
    for (size_t k = 1; k < bp.patches.size() && !tensor_only; ++k)
      tensor_only = power(k) != power(0);
  }
  if (tensor_only) {
    too_high.clear();
    for (size_t k = 0; k < bp.patches.size(); ++k) {
      degrees[k] = composed_degrees(factors[k], cell_of[k]->degrees);
      const auto [du, dv] = degrees[k];
      if (std::max(du, dv) > options.max_degree && too_high.empty()) {
        const int a = static_cast<int>(k) / bp.count_v(), b = static_cast<int>(k) % bp.count_v();
        too_high = degree_message(
            du, dv, options.max_degree,
            "of rational surface " + patch_name(bp, a, b) +
                " with a B-spline lattice whose cells differ in degree",
            "use a lattice of lower degree, or approximate the deformed surface with a refit "
            "tolerance (certified refit)");
      }
    }
  }
  detail::check_size(detail::predicted_size(surface, bp, degrees, located.planes,
                                            detail::lattice_continuity(lattice)),
                     options, too_high);
  std::vector<ComposedPatch> patches(bp.patches.size());
  for (size_t k = 0; k < patches.size(); ++k) {
    throw_if_cancelled("an exact composition");
    patches[k] = tensor_only
                     ? compose_patch(*cell_of[k], factors[k], rational)
                     : compose_cell(*cell_of[k], monomials_of.at(cell_of[k]), factors[k], rational);
  }
  return finish(
      bp, patches, rational, split,
      [&](const Eigen::Vector3d& x) { return deform_point(lattice, x); },
      lattice_size(lattice.points), options, located.splits);
}

ComposeResult compose_exact(const Taper& taper, const BSplineSurface& surface,
                            const ComposeOptions& options) {
  options.validate();
  validate(taper, "compose_exact: taper");
  surface::validate(surface, "compose_exact: surface");
  const bool rational = surface.is_rational();
  // Barr's local axes (regular.hpp): z = axis, x = reference without its axial part, y = z × x.
  const Eigen::Vector3d ez = taper.frame.axis.normalized();
  const Eigen::Vector3d ref = taper.frame.reference - taper.frame.reference.dot(ez) * ez;
  const Eigen::Vector3d ex = ref.normalized(), ey = ez.cross(ex);
  std::vector<double> profile = taper.profile;
  while (profile.size() > 1 && profile.back() == 0) profile.pop_back();
  const int D = static_cast<int>(profile.size()) - 1;
  auto r_of = [&](double z) {
    double v = profile.back();
    for (size_t i = profile.size() - 1; i-- > 0;) v = v * z + profile[i];
    return v;
  };
  const auto bp = surface::extract_bezier(surface);
  std::vector<ComposedPatch> patches(bp.patches.size());
  std::vector<std::pair<int, int>> degrees(bp.patches.size());
  for (int a = 0; a < bp.count_u(); ++a)
    for (int b = 0; b < bp.count_v(); ++b) {
      const PatchCoordinates pc =
          patch_coordinates(bp.patch(a, b), taper.frame.origin, {ex, ey, ez});
      const auto wd = weight_degrees(pc);
      const double tol = degree_tolerance * pc.c_scale;
      // e: joint exact degrees of (X, Y, Z, W) on the patch.
      int eu = wd.first, ev = wd.second;
      for (const auto& c : pc.c) {
        eu = std::max(eu, exact_degree(c, 0, tol, false));
        ev = std::max(ev, exact_degree(c, 1, tol, false));
      }
      auto at_e = [&](const Poly& q) {
        Poly r = to_degree(to_degree(q, eu, 0), ev, 1);
        scale(r, false);
        return r;
      };
      Poly xy(eu, ev, 2), zw(eu, ev, 2);
      {
        const Poly X = at_e(pc.c[0]), Y = at_e(pc.c[1]), Z = at_e(pc.c[2]), W = at_e(pc.w);
        for (size_t k = 0; k < X.c.size(); ++k) {
          xy.c[2 * k] = X.c[k], xy.c[2 * k + 1] = Y.c[k];
          zw.c[2 * k] = Z.c[k], zw.c[2 * k + 1] = W.c[k];
        }
      }
      // Taper (Güdükbay–Özgüç §3.1.1) homogeneous: with z = Z / W and r(z) = Σ c_i z^i,
      // W^(D+1) X' = ex R X + ey R Y + ez W^D Z + o W^D W, R = Σ c_i Z^i W^(D−i).
      const Factor fz = make_factor(pc.c[2], pc.w, pc.c_scale, wd);
      Poly R, WD;
      if (fz.constant || D == 0) {
        R = constant_poly(r_of(fz.value));
        if (D == 0) R = constant_poly(profile[0]);
        WD = constant_poly(1);
      } else {
        // fz.s = Z, fz.v = W − Z at d(z) (scaled); W = fz.s + fz.v.
        Poly Wz = fz.s;
        for (size_t k = 0; k < Wz.c.size(); ++k) Wz.c[k] += fz.v.c[k];
        std::vector<Poly> zp{constant_poly(1)}, wp{constant_poly(1)};
        for (int i = 1; i <= D; ++i) {
          zp.push_back(multiply(zp.back(), fz.s));
          wp.push_back(multiply(wp.back(), Wz));
        }
        R = Poly(D * fz.du, D * fz.dv, 1);
        for (int i = 0; i <= D; ++i) {
          if (profile[static_cast<size_t>(i)] == 0) continue;
          Poly term = multiply(zp[static_cast<size_t>(i)], wp[static_cast<size_t>(D - i)]);
          for (size_t k = 0; k < R.c.size(); ++k)
            R.c[k] += profile[static_cast<size_t>(i)] * term.c[k];
        }
        WD = std::move(wp.back());
      }
      const int du = R.du + eu, dv = R.dv + ev;
      degrees[static_cast<size_t>(a * bp.count_v() + b)] = {du, dv};
      if (std::max(du, dv) > options.max_degree)
        detail::check_size(
            {du, dv, 0}, options,
            degree_message(
                du, dv, options.max_degree,
                "of surface " + patch_name(bp, a, b) + " with a taper profile of degree " +
                    std::to_string(D),
                "use a taper profile of lower degree, or approximate the deformed surface with a "
                "refit tolerance (certified refit)"));
      Poly rxy = multiply(xy, R), wzw = multiply(zw, WD);
      scale(rxy, true);
      scale(wzw, true);
      ComposedPatch out;
      out.du = du, out.dv = dv;
      out.h = Poly(du, dv, 4);
      for (int i = 0; i <= du; ++i)
        for (int j = 0; j <= dv; ++j) {
          const double X = rxy.at(i, j, 0), Y = rxy.at(i, j, 1), Z = wzw.at(i, j, 0),
                       W = wzw.at(i, j, 1);
          for (int d = 0; d < 3; ++d)
            out.h.at(i, j, d) = ex[d] * X + ey[d] * Y + ez[d] * Z + taper.frame.origin[d] * W;
          out.h.at(i, j, 3) = rational ? W : 1.0;
        }
      patches[static_cast<size_t>(a * bp.count_v() + b)] = std::move(out);
    }
  // A taper's patches are cheap to compose; the joined net is checked before it is built.
  detail::check_size(detail::predicted_size(surface, bp, degrees), options, "");
  const auto box = surface::control_box(surface);
  return finish(
      bp, patches, rational, surface,
      [&](const Eigen::Vector3d& x) { return deform_point(taper, x); },
      (box.second - box.first).norm(), options, 0);
}

}  // namespace clay::deform
