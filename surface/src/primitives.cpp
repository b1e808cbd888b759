#include <clay/surface/primitives.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <sstream>
#include <string>

namespace clay::surface {

std::vector<std::string> SuperquadricOptions::problems() const {
  std::vector<std::string> out;
  auto bad = [&out](const std::string& field, double value, const std::string& rule) {
    std::ostringstream m;
    m << "SuperquadricOptions::" << field << " = " << value << " " << rule;
    out.push_back(m.str());
  };
  if (!(std::isfinite(tolerance_mm) && tolerance_mm > 0.0))
    bad("tolerance_mm", tolerance_mm, "must be a positive length in mm");
  if (degree < 2 || degree > 7) bad("degree", degree, "must be in [2, 7]");
  if (max_spans < 8) bad("max_spans", max_spans, "must be >= 8");
  return out;
}

void SuperquadricOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

namespace {

constexpr double pi = std::numbers::pi;
constexpr double half_pi = 0.5 * std::numbers::pi;

/// An angle as base + offset. Near a segment end the offset is tiny, and keeping it apart keeps
/// its digits: -pi/2 + 1e-17 is not a double, but {-pi/2, 1e-17} is, and cos of it is 1e-17
/// (which matters for |cos|^e with small e).
struct Angle {
  double base = 0;
  double offset = 0;
};

/// cos and sin of a base angle, exact at multiples of pi/2 (cos(pi/2) is 6e-17 in floating point).
std::array<double, 2> cos_sin(double t) {
  const double k = std::round(t / half_pi);
  if (std::abs(t - k * half_pi) <= 1e-15 * std::max(1.0, std::abs(t))) {
    const long q = ((static_cast<long>(k) % 4) + 4) % 4;
    static constexpr double c[4] = {1, 0, -1, 0}, s[4] = {0, 1, 0, -1};
    return {c[q], s[q]};
  }
  return {std::cos(t), std::sin(t)};
}

/// cos and sin of base + offset by the angle-addition formulas.
std::array<double, 2> cos_sin(const Angle& a) {
  const auto b = cos_sin(a.base);
  if (a.offset == 0.0) return b;
  const double co = std::cos(a.offset), so = std::sin(a.offset);
  return {b[0] * co - b[1] * so, b[1] * co + b[0] * so};
}

/// sign(x) |x|^e.
double signed_pow(double x, double e) { return std::copysign(std::pow(std::abs(x), e), x); }

using Planar = std::function<Eigen::Vector2d(const Angle&)>;

/// A planar curve standing for the analytic curve f on [t0, t1].
struct Profile {
  BSplineCurve curve;                                                       // z = 0
  Planar f;                                                                 // the analytic curve
  std::function<Angle(double, const Eigen::Vector3d&)> analytic_parameter;  // angle of curve(s)
  bool exact = false;
  double error = 0;  // max |curve(s) - f(t(s))| on the check sample
  Eigen::Vector2d magnitude = Eigen::Vector2d::Zero();  // max |f_x|, |f_y| on the sample
  std::vector<double> samples;                          // curve parameters of the check sample
};

/// Curve parameters at fixed fractions of every span, ends included; singular ends of power
/// functions make the error largest near span ends, so those are sampled closely.
std::vector<double> check_samples(const BSplineBasis& basis) {
  static constexpr double fractions[] = {0.0, 0.005, 0.02, 0.1, 0.25, 0.4,
                                         0.5, 0.6,   0.75, 0.9, 0.98, 0.995};
  const auto breaks = breakpoints(basis);
  std::vector<double> out;
  for (size_t k = 0; k + 1 < breaks.size(); ++k)
    for (double f : fractions) out.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * f);
  out.push_back(breaks.back());
  return out;
}

void measure(Profile& profile) {
  profile.samples = check_samples(profile.curve.basis);
  const Points3 pts = evaluate_many(profile.curve, profile.samples);
  profile.error = 0;
  profile.magnitude.setZero();
  for (size_t k = 0; k < profile.samples.size(); ++k) {
    const Eigen::Vector3d p = pts.row(static_cast<Eigen::Index>(k)).transpose();
    const Eigen::Vector2d f = profile.f(profile.analytic_parameter(profile.samples[k], p));
    profile.error = std::max(profile.error, (p.head<2>() - f).norm());
    profile.magnitude = profile.magnitude.cwiseMax(f.cwiseAbs());
  }
}

/// The stretched angle of a profile (see primitives.hpp): curve parameter s in [k, k + 1] covers
/// the k-th segment [breaks[k], breaks[k+1]] of the angle through w(sigma) = sigma^m /
/// (sigma^m + (1 - sigma)^m), m = max(1, 1/e). Signed powers |cos|^e, |sin|^e with e < 1 have
/// infinite slope where cos or sin vanish (the segment ends); in sigma they become smooth there.
Angle stretched_angle(double s, const std::vector<double>& breaks, double m) {
  const int segments = static_cast<int>(breaks.size()) - 1;
  const int k = std::clamp(static_cast<int>(std::floor(s)), 0, segments - 1);
  const double sigma = std::clamp(s - k, 0.0, 1.0);
  const double a = std::pow(sigma, m), b = std::pow(1.0 - sigma, m);
  const double lo = breaks[static_cast<size_t>(k)], hi = breaks[static_cast<size_t>(k + 1)];
  // Measured from the nearer end, so the small offset keeps its relative accuracy.
  if (a <= b) return {lo, (hi - lo) * (a / (a + b))};
  return {hi, -(hi - lo) * (b / (a + b))};
}

/// Degree-p interpolation of f(stretched_angle(s)) at the Greville abscissae, with C0 joins
/// (multiplicity p) at the segment ends and spans bisected where the error exceeds `tol`, until it
/// holds everywhere.
Profile interpolate(const Planar& f_of_angle, const std::vector<double>& angle_breaks, double e,
                    bool closed, double tol, const SuperquadricOptions& o,
                    const std::string& what) {
  const int p = o.degree;
  const double stretch = std::max(1.0, 1.0 / e);
  const std::function<Eigen::Vector2d(double)> f = [f_of_angle, angle_breaks, stretch](double s) {
    return f_of_angle(stretched_angle(s, angle_breaks, stretch));
  };
  std::vector<double> breaks;
  for (size_t k = 0; k < angle_breaks.size(); ++k) breaks.push_back(static_cast<double>(k));
  std::vector<double> cuts;  // span ends, increasing; `breaks` among them
  for (size_t k = 0; k + 1 < breaks.size(); ++k)
    for (int i = 0; i < 4; ++i) cuts.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * i / 4.0);
  cuts.push_back(breaks.back());
  Profile profile;
  profile.f = f_of_angle;
  profile.analytic_parameter = [angle_breaks, stretch](double s, const Eigen::Vector3d&) {
    return stretched_angle(s, angle_breaks, stretch);
  };
  for (;;) {
    BSplineCurve& c = profile.curve;
    c.basis.degree = p;
    c.basis.knots.assign(static_cast<size_t>(p + 1), cuts.front());
    for (size_t k = 1; k + 1 < cuts.size(); ++k) {
      const bool joint = std::find(breaks.begin(), breaks.end(), cuts[k]) != breaks.end();
      c.basis.knots.insert(c.basis.knots.end(), joint ? static_cast<size_t>(p) : 1, cuts[k]);
    }
    c.basis.knots.insert(c.basis.knots.end(), static_cast<size_t>(p + 1), cuts.back());
    const int n = c.basis.count();
    // Collocation at the Greville abscissae (Schoenberg–Whitney holds): banded, solved sparse.
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::MatrixX2d rhs(n, 2);
    std::vector<double> values(static_cast<size_t>(p + 1));
    for (int k = 0; k < n; ++k) {
      double tau = 0;
      for (int i = 1; i <= p; ++i) tau += c.basis.knots[static_cast<size_t>(k + i)];
      tau /= p;
      const int span = find_span(c.basis, tau);
      basis_functions(c.basis, span, tau, values);
      for (int i = 0; i <= p; ++i)
        if (values[static_cast<size_t>(i)] != 0.0)
          entries.emplace_back(k, span - p + i, values[static_cast<size_t>(i)]);
      rhs.row(k) = f(tau).transpose();
    }
    Eigen::SparseMatrix<double> a(n, n);
    a.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(a);
    if (lu.info() != Eigen::Success)
      throw Error(ErrorCategory::Internal, what + ": the interpolation system is singular");
    const Eigen::MatrixX2d sol = lu.solve(rhs);
    c.points = Points3::Zero(n, 3);
    c.points.leftCols<2>() = sol;
    c.points.row(0).head<2>() = f(cuts.front()).transpose();  // interpolated exactly anyway
    c.points.row(n - 1).head<2>() = f(cuts.back()).transpose();
    if (closed) c.points.row(n - 1) = c.points.row(0);
    c.weights = Eigen::VectorXd::Ones(n);
    // Error per span; bisect the spans that miss the tolerance.
    std::vector<double> next = {cuts.front()};
    bool all_good = true;
    double worst = 0;
    static constexpr double fractions[] = {0.005, 0.02, 0.1, 0.25, 0.4,  0.5,
                                           0.6,   0.75, 0.9, 0.98, 0.995};
    for (size_t k = 0; k + 1 < cuts.size(); ++k) {
      double err = 0;
      for (double fr : fractions) {
        const double t = cuts[k] + (cuts[k + 1] - cuts[k]) * fr;
        err = std::max(err, (evaluate(c, t).head<2>() - f(t)).norm());
      }
      worst = std::max(worst, err);
      if (err > tol) {
        all_good = false;
        next.push_back(0.5 * (cuts[k] + cuts[k + 1]));
      }
      next.push_back(cuts[k + 1]);
    }
    if (all_good) break;
    if (static_cast<int>(next.size()) - 1 > o.max_spans) {
      std::ostringstream m;
      m << what << ": could not reach " << tol << " (relative to the radii) with " << o.max_spans
        << " spans (error " << worst
        << "); loosen SuperquadricOptions::tolerance_mm, raise max_spans, "
        << "or use exponents further from 0";
      throw Error(ErrorCategory::InvalidArgument, m.str());
    }
    cuts = std::move(next);
  }
  measure(profile);
  return profile;
}

/// Exact unit circle arc around `center` (z = 0) from angle t0 to t1.
Profile circle_profile(const Eigen::Vector2d& center, double t0, double t1) {
  Profile profile;
  profile.exact = true;
  profile.curve = circular_arc(Eigen::Vector3d(center.x(), center.y(), 0.0),
                               Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1.0, t0, t1);
  profile.f = [center](const Angle& t) {
    const auto cs = cos_sin(t);
    return Eigen::Vector2d(center.x() + cs[0], center.y() + cs[1]);
  };
  profile.analytic_parameter = [center](double, const Eigen::Vector3d& p) {
    return Angle{std::atan2(p.y() - center.y(), p.x() - center.x()), 0.0};
  };
  measure(profile);
  return profile;
}

/// Exact hyperbola arc (sec t, tan t), t in [-limit, limit]: one rational quadratic with end
/// points (sec L, -+tan L), tangent intersection (cos L, 0) and middle weight sec L.
Profile hyperbola_profile(double limit) {
  Profile profile;
  profile.exact = true;
  const double c = std::cos(limit), s = std::tan(limit);
  Points3 pts(3, 3);
  pts << 1.0 / c, -s, 0, c, 0, 0, 1.0 / c, s, 0;
  profile.curve = make_curve(2, {0, 0, 0, 1, 1, 1}, pts, Eigen::Vector3d(1.0, 1.0 / c, 1.0));
  profile.f = [](const Angle& t) {
    const auto cs = cos_sin(t);
    return Eigen::Vector2d(1.0 / cs[0], cs[1] / cs[0]);
  };
  profile.analytic_parameter = [](double, const Eigen::Vector3d& p) {
    return Angle{std::asin(p.y() / p.x()), 0.0};
  };
  measure(profile);
  return profile;
}

void check_shape(const Eigen::Vector3d& radii, double e1, double e2, const char* what) {
  std::ostringstream m;
  if (!internal::all_finite(radii) || (radii.array() <= 0.0).any())
    m << what << ": radii (" << radii.transpose() << ") must be positive and finite";
  else if (!(std::isfinite(e1) && e1 > 0.0 && e1 <= 10.0))
    m << what << ": exponent e1 = " << e1 << " is outside (0, 10]";
  else if (!(std::isfinite(e2) && e2 > 0.0 && e2 <= 10.0))
    m << what << ": exponent e2 = " << e2 << " is outside (0, 10]";
  if (!m.str().empty()) throw Error(ErrorCategory::InvalidArgument, m.str());
}

/// The primitive from its two profiles, scaled by the radii, with its measured deviation.
/// Approximated profiles are tightened until the surface error bound holds.
BuiltSurface assemble(const std::function<Profile(double)>& make_m,
                      const std::function<Profile(double)>& make_h, const Eigen::Vector3d& radii,
                      const SuperquadricOptions& o, const std::string& method) {
  // Per-profile tolerance (relative to unit radii) from |S - x| <= a (|dm||H| + |m||dh|).
  double share = o.tolerance_mm / (4.0 * radii.maxCoeff());
  Profile m, h;
  for (int attempt = 0;; ++attempt) {
    m = make_m(share);
    h = make_h(share);
    const double hx = h.magnitude.maxCoeff() + h.error, mx = m.magnitude.x() + m.error;
    const Eigen::Vector3d bound(radii.x() * (m.error * hx + mx * h.error),
                                radii.y() * (m.error * hx + mx * h.error), radii.z() * m.error);
    if (bound.norm() <= o.tolerance_mm || attempt == 6) break;
    share *= 0.25;
  }
  BSplineSurface s = spherical_product(m.curve, h.curve);
  for (Eigen::Index r = 0; r < s.points.rows(); ++r)
    s.points.row(r) = s.points.row(r).cwiseProduct(radii.transpose());
  // Measured deviation at matching analytic parameters on a sample of both profiles' samples.
  auto thin = [](const std::vector<double>& v) {
    if (v.size() <= 160) return v;
    std::vector<double> out;
    for (size_t k = 0; k < 160; ++k) out.push_back(v[k * (v.size() - 1) / 159]);
    return out;
  };
  const auto ss = thin(m.samples), ts = thin(h.samples);
  const Points3 grid = evaluate_grid(s, ss, ts);
  const Points3 mp = evaluate_many(m.curve, ss), hp = evaluate_many(h.curve, ts);
  double worst = 0;
  for (size_t i = 0; i < ss.size(); ++i) {
    const Eigen::Vector2d fm =
        m.f(m.analytic_parameter(ss[i], mp.row(static_cast<Eigen::Index>(i)).transpose()));
    for (size_t j = 0; j < ts.size(); ++j) {
      const Eigen::Vector2d fh =
          h.f(h.analytic_parameter(ts[j], hp.row(static_cast<Eigen::Index>(j)).transpose()));
      const Eigen::Vector3d x(radii.x() * fm.x() * fh.x(), radii.y() * fm.x() * fh.y(),
                              radii.z() * fm.y());
      worst = std::max(
          worst, (grid.row(static_cast<Eigen::Index>(i * ts.size() + j)).transpose() - x).norm());
    }
  }
  BuiltSurface out{s, describe(s, method)};
  out.report.exact = m.exact && h.exact;
  out.report.max_deviation_mm = worst;
  out.report.samples = static_cast<int>(ss.size() * ts.size());
  return out;
}

std::string name_of(const char* kind, double e1, double e2) {
  std::ostringstream m;
  m << kind << " (e1 " << e1 << ", e2 " << e2 << ")";
  return m.str();
}

/// The east–west profile (C^e, S^e), omega in [-pi, pi]: exact circle when e = 1.
Profile around_profile(double e, double tol, const SuperquadricOptions& o,
                       const std::string& what) {
  if (e == 1.0) return circle_profile(Eigen::Vector2d::Zero(), -pi, pi);
  return interpolate(
      [e](const Angle& t) {
        const auto cs = cos_sin(t);
        return Eigen::Vector2d(signed_pow(cs[0], e), signed_pow(cs[1], e));
      },
      {-pi, -half_pi, 0.0, half_pi, pi}, e, true, tol, o, what);
}

/// (sec^e, tan^e) on [-limit, limit]: exact hyperbola arc when e = 1.
Profile hyperbolic_profile(double e, double limit, double tol, const SuperquadricOptions& o,
                           const std::string& what) {
  if (e == 1.0) return hyperbola_profile(limit);
  return interpolate(
      [e](const Angle& t) {
        const auto cs = cos_sin(t);
        return Eigen::Vector2d(signed_pow(1.0 / cs[0], e), signed_pow(cs[1] / cs[0], e));
      },
      {-limit, 0.0, limit}, e, false, tol, o, what);
}

void check_limit(double limit, const char* field, const char* what) {
  if (!(std::isfinite(limit) && limit > 0.0 && limit < half_pi - 1e-6)) {
    std::ostringstream m;
    m << what << ": " << field << " = " << limit
      << " rad is outside (0, pi/2); the surface is unbounded at pi/2";
    throw Error(ErrorCategory::InvalidArgument, m.str());
  }
}

}  // namespace

BSplineSurface spherical_product(const BSplineCurve& m, const BSplineCurve& h) {
  validate(m, "spherical product curve m");
  validate(h, "spherical product curve h");
  BSplineSurface s;
  s.u = m.basis;
  s.v = h.basis;
  const int nu = s.count_u(), nv = s.count_v();
  s.points.resize(static_cast<Eigen::Index>(nu) * nv, 3);
  s.weights.resize(s.points.rows());
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Eigen::Index r = s.index(i, j);
      s.points(r, 0) = m.points(i, 0) * h.points(j, 0);
      s.points(r, 1) = m.points(i, 0) * h.points(j, 1);
      s.points(r, 2) = m.points(i, 1);
      s.weights[r] = m.weights[i] * h.weights[j];
    }
  return s;
}

BuiltSurface superellipsoid(const Superellipsoid& shape, const SuperquadricOptions& options) {
  options.validate();
  check_shape(shape.radii, shape.e1, shape.e2, "superellipsoid");
  const double e1 = shape.e1, e2 = shape.e2;
  const std::string method = name_of("superellipsoid", e1, e2);
  return assemble(
      [&](double tol) {
        if (e1 == 1.0) return circle_profile(Eigen::Vector2d::Zero(), -half_pi, half_pi);
        return interpolate(
            [e1](const Angle& t) {
              const auto cs = cos_sin(t);
              return Eigen::Vector2d(signed_pow(cs[0], e1), signed_pow(cs[1], e1));
            },
            {-half_pi, 0.0, half_pi}, e1, false, tol, options, method);
      },
      [&](double tol) { return around_profile(e2, tol, options, method); }, shape.radii, options,
      method);
}

BuiltSurface supertoroid(const Supertoroid& shape, const SuperquadricOptions& options) {
  options.validate();
  check_shape(shape.radii, shape.e1, shape.e2, "supertoroid");
  if (!(std::isfinite(shape.hole) && shape.hole > 1.0))
    throw Error(ErrorCategory::InvalidArgument,
                "supertoroid: hole = " + std::to_string(shape.hole) +
                    " must be > 1 (else the tube crosses the axis)");
  const double e1 = shape.e1, e2 = shape.e2, a4 = shape.hole;
  const std::string method = name_of("supertoroid", e1, e2);
  return assemble(
      [&](double tol) {
        if (e1 == 1.0) return circle_profile(Eigen::Vector2d(a4, 0.0), -pi, pi);
        return interpolate(
            [e1, a4](const Angle& t) {
              const auto cs = cos_sin(t);
              return Eigen::Vector2d(a4 + signed_pow(cs[0], e1), signed_pow(cs[1], e1));
            },
            {-pi, -half_pi, 0.0, half_pi, pi}, e1, true, tol, options, method);
      },
      [&](double tol) { return around_profile(e2, tol, options, method); }, shape.radii, options,
      method);
}

BuiltSurface superhyperboloid_one_sheet(const Superhyperboloid& shape,
                                        const SuperquadricOptions& options) {
  options.validate();
  check_shape(shape.radii, shape.e1, shape.e2, "superhyperboloid of one sheet");
  check_limit(shape.eta_limit, "eta_limit", "superhyperboloid of one sheet");
  const std::string method = name_of("superhyperboloid of one sheet", shape.e1, shape.e2);
  return assemble(
      [&](double tol) {
        return hyperbolic_profile(shape.e1, shape.eta_limit, tol, options, method);
      },
      [&](double tol) { return around_profile(shape.e2, tol, options, method); }, shape.radii,
      options, method);
}

std::vector<BuiltSurface> superhyperboloid_two_sheets(const Superhyperboloid& shape,
                                                      const SuperquadricOptions& options) {
  options.validate();
  check_shape(shape.radii, shape.e1, shape.e2, "superhyperboloid of two sheets");
  check_limit(shape.eta_limit, "eta_limit", "superhyperboloid of two sheets");
  check_limit(shape.omega_limit, "omega_limit", "superhyperboloid of two sheets");
  const std::string method = name_of("superhyperboloid of two sheets", shape.e1, shape.e2);
  BuiltSurface first = assemble(
      [&](double tol) {
        return hyperbolic_profile(shape.e1, shape.eta_limit, tol, options, method);
      },
      [&](double tol) {
        return hyperbolic_profile(shape.e2, shape.omega_limit, tol, options, method);
      },
      shape.radii, options, method);
  // The second sheet is omega = pi + phi: sec(pi + phi) = -sec(phi), tan(pi + phi) = tan(phi),
  // so it is the first sheet mirrored in the yz plane (exact: negate x).
  BuiltSurface second = first;
  second.surface.points.col(0) *= -1.0;
  return {first, second};
}

}  // namespace clay::surface
