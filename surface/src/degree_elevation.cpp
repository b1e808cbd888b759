#include <clay/surface/degree_elevation.hpp>

#include <algorithm>
#include <clay/error.hpp>
#include <clay/internal/math.hpp>
#include <string>
#include <vector>

#include "net_rows.hpp"

namespace clay::surface {
namespace detail {
namespace {

/// Clamps the start of the strip: the domain start gets multiplicity degree + 1 at the front.
void clamp_front(Strip& strip) {
  const int p = strip.basis.degree;
  const double a = strip.basis.knots[static_cast<size_t>(p)];
  int s = multiplicity(strip.basis, a);
  if (strip.basis.knots.front() == a) return;  // a at index 0..p: already clamped
  if (s < p) insert_knot(strip, a, p - s);
  // Now a occupies knots f .. f+p-1 with f >= 1; basis functions 0..f-2 vanish on the domain, and
  // knot f-1 only matters outside it, so it can become a.
  const auto& U = strip.basis.knots;
  const int f = static_cast<int>(std::find(U.begin(), U.end(), a) - U.begin());
  const int drop = f - 1;
  strip.basis.knots.erase(strip.basis.knots.begin(), strip.basis.knots.begin() + drop);
  strip.basis.knots.front() = a;
  strip.rows = Rows(strip.rows.bottomRows(strip.rows.rows() - drop));
}

/// Mirrors the parameter (t -> -t): knots negated and reversed, rows reversed.
void mirror(Strip& strip) {
  std::reverse(strip.basis.knots.begin(), strip.basis.knots.end());
  for (double& k : strip.basis.knots) k = -k;
  strip.rows = Rows(strip.rows.colwise().reverse());
}

}  // namespace

void clamp(Strip& strip) {
  clamp_front(strip);
  mirror(strip);
  clamp_front(strip);
  mirror(strip);
}

void elevate_degree(Strip& strip, int t) {
  if (t == 0) return;
  clamp(strip);
  // Degree elevation of a clamped B-spline (The NURBS Book A5.9), on rows of any width.
  const int p = strip.basis.degree;
  const std::vector<double>& U = strip.basis.knots;
  const Rows& Pw = strip.rows;
  const int n = strip.basis.count() - 1;
  const int m = n + p + 1;
  const int ph = p + t;
  const int ph2 = ph / 2;
  const Eigen::Index dim = Pw.cols();
  const int segments = static_cast<int>(breakpoints(strip.basis).size()) - 1;
  const int new_count = n + 1 + t * segments;

  Eigen::MatrixXd bezalfs = Eigen::MatrixXd::Zero(ph + 1, p + 1);
  bezalfs(0, 0) = bezalfs(ph, p) = 1.0;
  for (int i = 1; i <= ph2; ++i) {
    const double inv = 1.0 / internal::binomial(ph, i);
    const int mpi = std::min(p, i);
    for (int j = std::max(0, i - t); j <= mpi; ++j)
      bezalfs(i, j) = inv * internal::binomial(p, j) * internal::binomial(t, i - j);
  }
  for (int i = ph2 + 1; i <= ph - 1; ++i) {
    const int mpi = std::min(p, i);
    for (int j = std::max(0, i - t); j <= mpi; ++j) bezalfs(i, j) = bezalfs(ph - i, p - j);
  }

  Rows Qw = Rows::Zero(new_count, dim);
  std::vector<double> Uh(static_cast<size_t>(new_count + ph + 1));
  Rows bpts(p + 1, dim), ebpts(ph + 1, dim), next_bpts(std::max(p - 1, 1), dim);
  std::vector<double> alfs(static_cast<size_t>(std::max(p - 1, 1)));

  int mh = ph, kind = ph + 1;
  int r = -1, a = p, b = p + 1, cind = 1;
  double ua = U[0];
  Qw.row(0) = Pw.row(0);
  for (int i = 0; i <= ph; ++i) Uh[static_cast<size_t>(i)] = ua;
  for (int i = 0; i <= p; ++i) bpts.row(i) = Pw.row(i);
  while (b < m) {
    int i = b;
    while (b < m && U[static_cast<size_t>(b)] == U[static_cast<size_t>(b + 1)]) ++b;
    const int mul = b - i + 1;
    mh += mul + t;
    const double ub = U[static_cast<size_t>(b)];
    const int oldr = r;
    r = p - mul;
    const int lbz = oldr > 0 ? (oldr + 2) / 2 : 1;
    const int rbz = r > 0 ? ph - (r + 1) / 2 : ph;
    if (r > 0) {  // insert knot ub r times to get the Bézier segment
      const double numer = ub - ua;
      for (int k = p; k > mul; --k)
        alfs[static_cast<size_t>(k - mul - 1)] = numer / (U[static_cast<size_t>(a + k)] - ua);
      for (int j = 1; j <= r; ++j) {
        const int save = r - j, s = mul + j;
        for (int k = p; k >= s; --k) {
          const double al = alfs[static_cast<size_t>(k - s)];
          bpts.row(k) = al * bpts.row(k) + (1.0 - al) * bpts.row(k - 1);
        }
        next_bpts.row(save) = bpts.row(p);
      }
    }
    for (int ii = lbz; ii <= ph; ++ii) {  // degree-elevate the Bézier segment
      ebpts.row(ii).setZero();
      const int mpi = std::min(p, ii);
      for (int j = std::max(0, ii - t); j <= mpi; ++j)
        ebpts.row(ii) += bezalfs(ii, j) * bpts.row(j);
    }
    if (oldr > 1) {  // remove knot ua oldr times
      int first = kind - 2, last = kind;
      const double den = ub - ua;
      const double bet = (ub - Uh[static_cast<size_t>(kind - 1)]) / den;
      for (int tr = 1; tr < oldr; ++tr) {
        int ii = first, j = last, kj = j - kind + 1;
        while (j - ii > tr) {
          if (ii < cind) {
            const double alf =
                (ub - Uh[static_cast<size_t>(ii)]) / (ua - Uh[static_cast<size_t>(ii)]);
            Qw.row(ii) = alf * Qw.row(ii) + (1.0 - alf) * Qw.row(ii - 1);
          }
          if (j >= lbz) {
            if (j - tr <= kind - ph + oldr) {
              const double gam = (ub - Uh[static_cast<size_t>(j - tr)]) / den;
              ebpts.row(kj) = gam * ebpts.row(kj) + (1.0 - gam) * ebpts.row(kj + 1);
            } else {
              ebpts.row(kj) = bet * ebpts.row(kj) + (1.0 - bet) * ebpts.row(kj + 1);
            }
          }
          ++ii;
          --j;
          --kj;
        }
        --first;
        ++last;
      }
    }
    if (a != p)  // load the knot ua
      for (int ii = 0; ii < ph - oldr; ++ii) Uh[static_cast<size_t>(kind++)] = ua;
    for (int j = lbz; j <= rbz; ++j) Qw.row(cind++) = ebpts.row(j);
    if (b < m) {  // set up the next pass
      for (int j = 0; j < r; ++j) bpts.row(j) = next_bpts.row(j);
      for (int j = r; j <= p; ++j) bpts.row(j) = Pw.row(b - p + j);
      a = b;
      ++b;
      ua = ub;
    } else {
      for (int ii = 0; ii <= ph; ++ii) Uh[static_cast<size_t>(kind + ii)] = ub;
    }
  }
  const int nh = mh - ph - 1;  // last control point index
  if (nh + 1 != new_count || cind != new_count)
    throw Error(ErrorCategory::Internal,
                "elevate_degree: control point count " + std::to_string(nh + 1) +
                    " differs from the expected " + std::to_string(new_count));
  strip.basis.degree = ph;
  strip.basis.knots = std::move(Uh);
  strip.rows = std::move(Qw);
}

}  // namespace detail

namespace {

void check_elevation(int degree, int times, const char* what) {
  if (times < 0 || degree + times > max_kernel_degree)
    throw Error(ErrorCategory::InvalidArgument,
                std::string(what) + ": cannot raise degree " + std::to_string(degree) + " by " +
                    std::to_string(times) +
                    "; give 0 <= times <= " + std::to_string(max_kernel_degree - degree) +
                    " (kernel limit " + std::to_string(max_kernel_degree) + ")");
}

}  // namespace

BSplineCurve elevate_degree(const BSplineCurve& curve, int times) {
  validate(curve);
  check_elevation(curve.basis.degree, times, "elevate_degree");
  detail::Strip strip = detail::curve_strip(curve);
  detail::elevate_degree(strip, times);
  return detail::curve_from_strip(std::move(strip));
}

BSplineSurface elevate_degree_u(const BSplineSurface& surface, int times) {
  validate(surface);
  check_elevation(surface.u.degree, times, "elevate_degree_u");
  return detail::apply_in_direction(surface, detail::Direction::U,
                                    [&](detail::Strip& s) { detail::elevate_degree(s, times); });
}

BSplineSurface elevate_degree_v(const BSplineSurface& surface, int times) {
  validate(surface);
  check_elevation(surface.v.degree, times, "elevate_degree_v");
  return detail::apply_in_direction(surface, detail::Direction::V,
                                    [&](detail::Strip& s) { detail::elevate_degree(s, times); });
}

BSplineCurve clamp(const BSplineCurve& curve) {
  validate(curve);
  if (is_clamped(curve.basis)) return curve;  // bit for bit (no trip through x w / w)
  detail::Strip strip = detail::curve_strip(curve);
  detail::clamp(strip);
  return detail::curve_from_strip(std::move(strip));
}

BSplineSurface clamp(const BSplineSurface& surface) {
  validate(surface);
  BSplineSurface out = surface;  // directions already clamped are kept bit for bit
  if (!is_clamped(out.u))
    out = detail::apply_in_direction(out, detail::Direction::U,
                                     [](detail::Strip& s) { detail::clamp(s); });
  if (!is_clamped(out.v))
    out = detail::apply_in_direction(out, detail::Direction::V,
                                     [](detail::Strip& s) { detail::clamp(s); });
  return out;
}

}  // namespace clay::surface
