#include <clay/surface/basis.hpp>

#include <clay/error.hpp>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <sstream>

#include "validation.hpp"

namespace clay::surface {

BSplineBasis clamped_uniform_basis(int degree, int count, double first, double last) {
  if (degree < 1 || count < degree + 1 || !(first < last) || !std::isfinite(first) ||
      !std::isfinite(last)) {
    std::ostringstream m;
    m << "clamped_uniform_basis(degree " << degree << ", count " << count << ", [" << first << ", "
      << last << "]): needs degree >= 1, count >= degree + 1 and first < last";
    throw Error(ErrorCategory::InvalidArgument, m.str());
  }
  BSplineBasis basis;
  basis.degree = degree;
  basis.knots.assign(static_cast<size_t>(count + degree + 1), first);
  const int spans = count - degree;
  for (int i = 1; i < spans; ++i)
    basis.knots[static_cast<size_t>(degree + i)] = first + (last - first) * i / spans;
  for (int i = 0; i <= degree; ++i) basis.knots[static_cast<size_t>(count + i)] = last;
  return basis;
}

std::vector<std::string> problems(const BSplineBasis& basis, std::string_view name) {
  std::vector<std::string> found;
  auto say = [&](const std::string& what) { found.push_back(std::string(name) + ": " + what); };
  const int p = basis.degree;
  const int m = static_cast<int>(basis.knots.size());
  if (p < 1 || p > max_kernel_degree) {
    say("degree " + std::to_string(p) + " is outside [1, " + std::to_string(max_kernel_degree) +
        "]; use a degree in that range");
    return found;
  }
  if (m < 2 * (p + 1)) {
    say("knot vector has " + std::to_string(m) + " knots; degree " + std::to_string(p) +
        " needs at least " + std::to_string(2 * (p + 1)) +
        " (count + degree + 1 with count >= degree + 1)");
    return found;
  }
  for (int i = 0; i < m; ++i) {
    if (!std::isfinite(basis.knots[static_cast<size_t>(i)])) {
      say("knot " + std::to_string(i) + " is not finite; give finite knot values");
      return found;
    }
  }
  for (int i = 1; i < m; ++i) {
    if (basis.knots[static_cast<size_t>(i)] < basis.knots[static_cast<size_t>(i - 1)]) {
      std::ostringstream s;
      s.precision(17);
      s << "knots decrease at index " << i << " (" << basis.knots[static_cast<size_t>(i - 1)]
        << " then " << basis.knots[static_cast<size_t>(i)] << "); sort the knot vector";
      say(s.str());
      return found;
    }
  }
  const auto [a, b] = basis.domain();
  if (!(a < b)) say("parameter domain [knots[p], knots[n]] is empty; spread the knots");
  // Multiplicity runs: interior values at most p, end values at most p + 1.
  for (int i = 0; i < m;) {
    int j = i;
    while (j + 1 < m &&
           basis.knots[static_cast<size_t>(j + 1)] == basis.knots[static_cast<size_t>(i)])
      ++j;
    const int mult = j - i + 1;
    const bool end = (i == 0 || j == m - 1);
    const int limit = end ? p + 1 : p;
    if (mult > limit) {
      std::ostringstream s;
      s.precision(17);
      s << "knot " << basis.knots[static_cast<size_t>(i)] << " has multiplicity " << mult
        << ", above " << limit << (end ? " (degree + 1 at an end)" : " (the degree, inside)")
        << "; remove repeated knots";
      say(s.str());
    }
    i = j + 1;
  }
  return found;
}

void validate(const BSplineBasis& basis, std::string_view name) {
  internal::throw_if(ErrorCategory::InvalidGeometry, problems(basis, name));
}

bool is_clamped(const BSplineBasis& basis) noexcept {
  const auto& k = basis.knots;
  if (static_cast<int>(k.size()) < 2 * (basis.degree + 1)) return false;
  for (int i = 1; i <= basis.degree; ++i) {
    if (k[static_cast<size_t>(i)] != k.front() ||
        k[k.size() - 1 - static_cast<size_t>(i)] != k.back())
      return false;
  }
  return true;
}

int multiplicity(const BSplineBasis& basis, double t) noexcept {
  return static_cast<int>(std::count(basis.knots.begin(), basis.knots.end(), t));
}

std::vector<double> breakpoints(const BSplineBasis& basis) {
  const auto [a, b] = basis.domain();
  std::vector<double> out;
  for (double k : basis.knots) {
    if (k < a || k > b) continue;
    if (out.empty() || k != out.back()) out.push_back(k);
  }
  return out;
}

std::vector<double> span_samples(const BSplineBasis& basis, int per_span) {
  if (per_span < 1)
    throw Error(ErrorCategory::InvalidArgument,
                "span_samples: per_span = " + std::to_string(per_span) + " must be >= 1");
  const auto breaks = breakpoints(basis);
  std::vector<double> out;
  for (size_t k = 0; k + 1 < breaks.size(); ++k)
    for (int i = 0; i < per_span; ++i)
      out.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * i / per_span);
  out.push_back(breaks.back());
  return out;
}

std::vector<double> greville_abscissae(const BSplineBasis& basis) {
  const int p = basis.degree;
  std::vector<double> xi(static_cast<size_t>(basis.count()));
  for (int i = 0; i < basis.count(); ++i) {
    double sum = 0;
    for (int r = 1; r <= p; ++r) sum += basis.knots[static_cast<size_t>(i + r)];
    xi[static_cast<size_t>(i)] = sum / p;
  }
  return xi;
}

int find_span(const BSplineBasis& basis, double t) {
  const int p = basis.degree;
  const int n = basis.count();
  const auto& k = basis.knots;
  const double a = k[static_cast<size_t>(p)];
  const double b = k[static_cast<size_t>(n)];
  // isfinite first: an ordered comparison with NaN would raise FE_INVALID where traps are on.
  // A parameter past an end by rounding (1.9999999999999998 on [2, 10], -2.8284271247451125 on
  // [-2.828427124744922, 0]: issue #39's refusals) is in the end span: its polynomial is
  // evaluated 1e-12 of the domain's scale past the end, a difference far below any tolerance.
  const double rounding = 1e-12 * std::max({b - a, std::abs(a), std::abs(b)});
  if (std::isfinite(t) && t < a && t >= a - rounding) t = a;
  if (std::isfinite(t) && t > b && t <= b + rounding) t = b;
  if (!std::isfinite(t) || t < a || t > b) {
    std::ostringstream m;
    m.precision(17);
    m << "parameter " << t << " is outside the domain [" << a << ", " << b
      << "]; evaluate inside the domain";
    throw Error(ErrorCategory::OutOfDomain, m.str());
  }
  if (t == b) {
    // The domain end belongs to the last non-empty span.
    int s = n - 1;
    while (s > p && k[static_cast<size_t>(s)] == b) --s;
    return s;
  }
  // upper_bound over knots[p .. n]: first knot > t, minus one.
  const auto first = k.begin() + p;
  const auto last = k.begin() + n + 1;
  return static_cast<int>(std::upper_bound(first, last, t) - k.begin()) - 1;
}

void basis_functions(const BSplineBasis& basis, int span, double t, std::span<double> values) {
  const int p = basis.degree;
  assert(static_cast<int>(values.size()) >= p + 1);
  const double* U = basis.knots.data();
  double left[max_kernel_degree + 1], right[max_kernel_degree + 1];
  assert(p <= max_kernel_degree);
  values[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[span + 1 - j];
    right[j] = U[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = values[static_cast<size_t>(r)] / (right[r + 1] + left[j - r]);
      values[static_cast<size_t>(r)] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    values[static_cast<size_t>(j)] = saved;
  }
}

void basis_derivatives(const BSplineBasis& basis, int span, double t, int order,
                       std::span<double> derivs) {
  const int p = basis.degree;
  const int w = p + 1;
  assert(p <= max_kernel_degree && order >= 0);
  // Derivatives above the degree vanish: compute up to du and zero the rest (A2.3).
  const int du = std::min(order, p);
  for (int k = du + 1; k <= order; ++k)
    for (int j = 0; j <= p; ++j) derivs[static_cast<size_t>(k * w + j)] = 0.0;
  assert(static_cast<int>(derivs.size()) >= (order + 1) * w);
  const double* U = basis.knots.data();
  // ndu: (p+1) x (p+1), lower triangle knot differences, upper triangle basis values (A2.3).
  // Stack storage (32 KiB at the kernel's degree limit): this runs once per evaluated point.
  std::array<double, (max_kernel_degree + 1) * (max_kernel_degree + 1)> ndu;
  auto NDU = [&](int r, int c) -> double& { return ndu[static_cast<size_t>(r * w + c)]; };
  double left[max_kernel_degree + 1], right[max_kernel_degree + 1];
  NDU(0, 0) = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[span + 1 - j];
    right[j] = U[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      NDU(j, r) = right[r + 1] + left[j - r];
      const double temp = NDU(r, j - 1) / NDU(j, r);
      NDU(r, j) = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    NDU(j, j) = saved;
  }
  auto D = [&](int k, int j) -> double& { return derivs[static_cast<size_t>(k * w + j)]; };
  for (int j = 0; j <= p; ++j) D(0, j) = NDU(j, p);
  std::array<double, 2 * (max_kernel_degree + 1)> a;
  auto A = [&](int s, int j) -> double& { return a[static_cast<size_t>(s * w + j)]; };
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    A(0, 0) = 1.0;
    for (int k = 1; k <= du; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        A(s2, 0) = A(s1, 0) / NDU(pk + 1, rk);
        d = A(s2, 0) * NDU(rk, pk);
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        A(s2, j) = (A(s1, j) - A(s1, j - 1)) / NDU(pk + 1, rk + j);
        d += A(s2, j) * NDU(rk + j, pk);
      }
      if (r <= pk) {
        A(s2, k) = -A(s1, k - 1) / NDU(pk + 1, r);
        d += A(s2, k) * NDU(r, pk);
      }
      D(k, r) = d;
      std::swap(s1, s2);
    }
  }
  int factor = p;
  for (int k = 1; k <= du; ++k) {
    for (int j = 0; j <= p; ++j) D(k, j) *= factor;
    factor *= (p - k);
  }
}

}  // namespace clay::surface
