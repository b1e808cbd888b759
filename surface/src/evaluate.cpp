#include <clay/surface/evaluate.hpp>

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

// The grid kernel is compiled for AVX-512, AVX2+FMA and baseline x86-64 and picked at load time
// (GCC target_clones), as the FFD kernels of clay_deform are.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define CLAY_SURFACE_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define CLAY_SURFACE_CLONES
#endif

namespace clay::surface {
namespace {

void check_order(int order) {
  if (order < 0 || order > 2)
    throw Error(ErrorCategory::InvalidArgument, "derivative order " + std::to_string(order) +
                                                    " is outside [0, 2]; ask for 0, 1 or 2");
}

void check_shape(const BSplineCurve& c) {
  if (c.basis.degree < 1 || c.basis.degree > max_kernel_degree ||
      c.basis.count() < c.basis.degree + 1 || c.points.rows() != c.basis.count() ||
      c.weights.size() != c.points.rows())
    throw Error(ErrorCategory::InvalidGeometry,
                "curve: degree, knot count, control point count and weight count disagree; "
                "call validate(curve) for details");
}

void check_shape(const BSplineSurface& s) {
  const auto ok = [](const BSplineBasis& b) {
    return b.degree >= 1 && b.degree <= max_kernel_degree && b.count() >= b.degree + 1;
  };
  if (!ok(s.u) || !ok(s.v) ||
      s.points.rows() != static_cast<Eigen::Index>(s.u.count()) * s.v.count() ||
      s.weights.size() != s.points.rows())
    throw Error(ErrorCategory::InvalidGeometry,
                "surface: degrees, knot counts, control point count and weight count disagree; "
                "call validate(surface) for details");
}

constexpr int max_width = max_kernel_degree + 1;

}  // namespace

CurveDerivatives derivatives(const BSplineCurve& curve, double t, int order) {
  check_order(order);
  check_shape(curve);
  const int p = curve.basis.degree;
  const int span = find_span(curve.basis, t);
  std::array<double, 3 * max_width> nd;
  if (order == 0)
    basis_functions(curve.basis, span, t, nd);
  else
    basis_derivatives(curve.basis, span, t, order, nd);
  // Homogeneous derivatives A^(k) (x w, y w, z w, w).
  Eigen::Vector4d a[3] = {Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero(),
                          Eigen::Vector4d::Zero()};
  for (int j = 0; j <= p; ++j) {
    const Eigen::Index r = span - p + j;
    const double w = curve.weights[r];
    const Eigen::Vector4d pw(curve.points(r, 0) * w, curve.points(r, 1) * w, curve.points(r, 2) * w,
                             w);
    for (int k = 0; k <= order; ++k) a[k] += nd[static_cast<size_t>(k * (p + 1) + j)] * pw;
  }
  // Quotient rule (The NURBS Book A4.2).
  CurveDerivatives out;
  const double w0 = a[0][3];
  out.point = a[0].head<3>() / w0;
  if (order >= 1) out.d1 = (a[1].head<3>() - a[1][3] * out.point) / w0;
  if (order >= 2) out.d2 = (a[2].head<3>() - 2.0 * a[1][3] * out.d1 - a[2][3] * out.point) / w0;
  return out;
}

Eigen::Vector3d evaluate(const BSplineCurve& curve, double t) {
  return derivatives(curve, t, 0).point;
}

SurfaceDerivatives derivatives(const BSplineSurface& surface, double u, double v, int order) {
  check_order(order);
  check_shape(surface);
  const int p = surface.u.degree, q = surface.v.degree;
  const int su = find_span(surface.u, u);
  const int sv = find_span(surface.v, v);
  std::array<double, 3 * max_width> nu, nv;
  if (order == 0) {  // the plain basis functions are cheaper than A2.3
    basis_functions(surface.u, su, u, nu);
    basis_functions(surface.v, sv, v, nv);
  } else {
    basis_derivatives(surface.u, su, u, order, nu);
    basis_derivatives(surface.v, sv, v, order, nv);
  }
  auto NU = [&](int k, int i) { return nu[static_cast<size_t>(k * (p + 1) + i)]; };
  auto NV = [&](int l, int j) { return nv[static_cast<size_t>(l * (q + 1) + j)]; };
  // Homogeneous derivatives A(k, l), k + l <= order (The NURBS Book A3.6).
  Eigen::Vector4d a[3][3];
  for (auto& row : a)
    for (auto& e : row) e.setZero();
  for (int i = 0; i <= p; ++i) {
    Eigen::Vector4d temp[3] = {Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero(),
                               Eigen::Vector4d::Zero()};
    for (int j = 0; j <= q; ++j) {
      const Eigen::Index r = surface.index(su - p + i, sv - q + j);
      const double w = surface.weights[r];
      const Eigen::Vector4d pw(surface.points(r, 0) * w, surface.points(r, 1) * w,
                               surface.points(r, 2) * w, w);
      for (int l = 0; l <= order; ++l) temp[l] += NV(l, j) * pw;
    }
    for (int k = 0; k <= order; ++k)
      for (int l = 0; k + l <= order; ++l) a[k][l] += NU(k, i) * temp[l];
  }
  // Rational quotient rule (The NURBS Book A4.4), binomials of order <= 2 written out.
  Eigen::Vector3d s[3][3];
  const double w00 = a[0][0][3];
  auto A = [&](int k, int l) { return Eigen::Vector3d(a[k][l].head<3>()); };
  auto W = [&](int k, int l) { return a[k][l][3]; };
  s[0][0] = A(0, 0) / w00;
  SurfaceDerivatives out;
  out.point = s[0][0];
  if (order >= 1) {
    s[1][0] = (A(1, 0) - W(1, 0) * s[0][0]) / w00;
    s[0][1] = (A(0, 1) - W(0, 1) * s[0][0]) / w00;
    out.du = s[1][0];
    out.dv = s[0][1];
  }
  if (order >= 2) {
    out.duu = (A(2, 0) - 2.0 * W(1, 0) * s[1][0] - W(2, 0) * s[0][0]) / w00;
    out.dvv = (A(0, 2) - 2.0 * W(0, 1) * s[0][1] - W(0, 2) * s[0][0]) / w00;
    out.duv = (A(1, 1) - W(1, 0) * s[0][1] - W(0, 1) * s[1][0] - W(1, 1) * s[0][0]) / w00;
  }
  return out;
}

Eigen::Vector3d evaluate(const BSplineSurface& surface, double u, double v) {
  return derivatives(surface, u, v, 0).point;
}

Eigen::Vector3d unit_normal(const BSplineSurface& surface, double u, double v) {
  const SurfaceDerivatives d = derivatives(surface, u, v, 1);
  const Eigen::Vector3d n = d.du.cross(d.dv);
  const double scale = d.du.norm() * d.dv.norm();
  const double len = n.norm();
  if (!(len > 1e-300 * std::max(scale, 1e-300)) || !(len > 0.0)) {
    throw Error(ErrorCategory::InvalidGeometry,
                "surface normal at (u, v) = (" + std::to_string(u) + ", " + std::to_string(v) +
                    ") is undefined: the partial derivatives are parallel or zero (a degenerate "
                    "point such as a pole); evaluate the normal nearby");
  }
  return n / len;
}

Points3 evaluate_many(const BSplineCurve& curve, std::span<const double> ts) {
  validate(curve);
  Points3 out(static_cast<Eigen::Index>(ts.size()), 3);
  for (size_t k = 0; k < ts.size(); ++k)
    out.row(static_cast<Eigen::Index>(k)) = evaluate(curve, ts[k]).transpose();
  return out;
}

namespace {

/// What one row of evaluate_grid needs: the homogeneous net by coordinate, the v basis by
/// function and the runs of v parameters sharing a knot span.
struct GridPlan {
  int p = 0, q = 0, cv = 0, coords = 3;
  size_t nvs = 0;
  const double* net[4] = {nullptr, nullptr, nullptr, nullptr};  // x w, y w, z w, w; row-major net
  const double* bv = nullptr;                   // bv[j * nvs + k] = N_{span-q+j}(v_k)
  const std::array<size_t, 3>* runs = nullptr;  // {first, end, span}
  size_t run_count = 0;
};

/// a[k] = sum_j N_{span-Q+j}(v_k) col[span-Q+j] over every run, for degree Q in v.
template <int Q>
inline void contract_runs(const GridPlan& g, const double* col, double* a) {
  const size_t nvs = g.nvs;
  for (size_t r = 0; r < g.run_count; ++r) {
    const size_t first = g.runs[r][0], end = g.runs[r][1], span = g.runs[r][2];
    double cj[Q + 1];
    for (int j = 0; j <= Q; ++j) cj[j] = col[span - Q + static_cast<size_t>(j)];
    for (size_t k = first; k < end; ++k) {
      double sum = g.bv[k] * cj[0];
      for (int j = 1; j <= Q; ++j) sum += g.bv[static_cast<size_t>(j) * nvs + k] * cj[j];
      a[k] = sum;
    }
  }
}

/// Grid row S(u, v_k) for all k into dst (3 per point): the net contracted in u with the basis
/// `bu` of span `su`, then in v run by run, each a loop over the parameters that vectorizes.
CLAY_SURFACE_CLONES
void grid_row(const GridPlan& g, int su, const double* bu, double* column, double* acc,
              double* dst) {
  const size_t nvs = g.nvs;
  for (int c = 0; c < g.coords; ++c) {
    double* col = column + static_cast<size_t>(c) * static_cast<size_t>(g.cv);
    for (int k = 0; k < g.cv; ++k) col[k] = 0.0;
    for (int i = 0; i <= g.p; ++i) {
      const double w = bu[i];
      const double* row = g.net[c] + static_cast<size_t>(su - g.p + i) * static_cast<size_t>(g.cv);
      for (int k = 0; k < g.cv; ++k) col[k] += w * row[k];
    }
    double* a = acc + static_cast<size_t>(c) * nvs;
    switch (g.q) {  // the usual degrees with the v sum unrolled: one store per point
      case 1:
        contract_runs<1>(g, col, a);
        break;
      case 2:
        contract_runs<2>(g, col, a);
        break;
      case 3:
        contract_runs<3>(g, col, a);
        break;
      default:
        for (size_t r = 0; r < g.run_count; ++r) {
          const size_t first = g.runs[r][0], end = g.runs[r][1], span = g.runs[r][2];
          for (size_t k = first; k < end; ++k) a[k] = 0.0;
          for (int j = 0; j <= g.q; ++j) {
            const double cj = col[span - static_cast<size_t>(g.q) + static_cast<size_t>(j)];
            const double* bj = g.bv + static_cast<size_t>(j) * nvs;
            for (size_t k = first; k < end; ++k) a[k] += bj[k] * cj;
          }
        }
    }
  }
  const double *x = acc, *y = acc + nvs, *z = acc + 2 * nvs, *w = acc + 3 * nvs;
  if (g.coords == 4) {
    for (size_t k = 0; k < nvs; ++k) {
      const double inv = 1.0 / w[k];
      dst[3 * k + 0] = x[k] * inv;
      dst[3 * k + 1] = y[k] * inv;
      dst[3 * k + 2] = z[k] * inv;
    }
  } else {
    for (size_t k = 0; k < nvs; ++k) {
      dst[3 * k + 0] = x[k];
      dst[3 * k + 1] = y[k];
      dst[3 * k + 2] = z[k];
    }
  }
}

}  // namespace

Points3 evaluate_grid(const BSplineSurface& surface, std::span<const double> us,
                      std::span<const double> vs) {
  validate(surface);
  GridPlan g;
  g.p = surface.u.degree;
  g.q = surface.v.degree;
  g.cv = surface.count_v();
  g.nvs = vs.size();
  g.coords = surface.is_rational() ? 4 : 3;  // polynomial: no division by sum N w = 1
  const size_t nus = us.size(), nvs = vs.size();
  // Basis functions of every v parameter, computed once and stored by function, and the runs of
  // consecutive parameters in the same knot span.
  std::vector<double> bv(static_cast<size_t>(g.q + 1) * nvs);
  std::vector<std::array<size_t, 3>> runs;
  std::array<double, max_width> b;
  for (size_t k = 0; k < nvs; ++k) {
    const int span = find_span(surface.v, vs[k]);
    basis_functions(surface.v, span, vs[k], b);
    for (int j = 0; j <= g.q; ++j) bv[static_cast<size_t>(j) * nvs + k] = b[static_cast<size_t>(j)];
    if (runs.empty() || runs.back()[2] != static_cast<size_t>(span))
      runs.push_back({k, k + 1, static_cast<size_t>(span)});
    else
      runs.back()[1] = k + 1;
  }
  // Homogeneous net by coordinate: x w, y w, z w, w.
  const Eigen::Index rows = surface.points.rows();
  std::vector<double> net(4 * static_cast<size_t>(rows));
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double w = surface.weights[r];
    for (int c = 0; c < 3; ++c) net[static_cast<size_t>(c * rows + r)] = surface.points(r, c) * w;
    net[static_cast<size_t>(3 * rows + r)] = w;
  }
  for (int c = 0; c < 4; ++c)
    g.net[c] = net.data() + static_cast<size_t>(c) * static_cast<size_t>(rows);
  g.bv = bv.data();
  g.runs = runs.data();
  g.run_count = runs.size();

  Points3 out(static_cast<Eigen::Index>(nus * nvs), 3);
  std::vector<double> column(4 * static_cast<size_t>(g.cv)), acc(4 * nvs);
  std::array<double, max_width> bu;
  for (size_t iu = 0; iu < nus; ++iu) {
    const int su = find_span(surface.u, us[iu]);
    basis_functions(surface.u, su, us[iu], bu);
    grid_row(g, su, bu.data(), column.data(), acc.data(), out.data() + iu * nvs * 3);
  }
  return out;
}

std::vector<double> linspace(double first, double last, int count) {
  if (count < 2 || !std::isfinite(first) || !std::isfinite(last))
    throw Error(ErrorCategory::InvalidArgument,
                "linspace: needs count >= 2 and finite ends, got count " + std::to_string(count));
  std::vector<double> out(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k)
    out[static_cast<size_t>(k)] = first + (last - first) * k / (count - 1);
  out.back() = last;
  return out;
}

/// S and its partial derivatives up to order 2 on the grid us x vs (index iu * vs.size() + iv):
/// the basis functions and their derivatives of each parameter computed once (The NURBS Book A2.3)
/// and the homogeneous net contracted in u first, row by row, so a point costs 6 (q+1) 4-vector
/// multiply-adds instead of (p+1)(q+1) (A3.6); then the rational quotient rule (A4.4).
std::vector<SurfaceDerivatives> derivatives_grid(const BSplineSurface& s,
                                                 std::span<const double> us,
                                                 std::span<const double> vs) {
  validate(s);
  const int p = s.u.degree, q = s.v.degree, cu = s.count_u(), cv = s.count_v();
  const std::size_t nv = vs.size(), wq = static_cast<std::size_t>(q + 1),
                    wp = static_cast<std::size_t>(p + 1);
  std::vector<int> span_v(nv);
  std::vector<double> bv(nv * 3 * wq);
  for (std::size_t k = 0; k < nv; ++k) {
    span_v[k] = find_span(s.v, vs[k]);
    basis_derivatives(s.v, span_v[k], vs[k], 2, std::span<double>(bv.data() + k * 3 * wq, 3 * wq));
  }
  std::vector<Eigen::Vector4d> net(static_cast<std::size_t>(cu) * static_cast<std::size_t>(cv));
  for (Eigen::Index r = 0; r < s.points.rows(); ++r) {
    const double w = s.weights[r];
    net[static_cast<std::size_t>(r)] =
        Eigen::Vector4d(s.points(r, 0) * w, s.points(r, 1) * w, s.points(r, 2) * w, w);
  }
  std::vector<SurfaceDerivatives> out(us.size() * nv);
  std::vector<double> bu(3 * wp);
  std::vector<Eigen::Vector4d> t(
      3 * static_cast<std::size_t>(cv));  // row contractions, u-derivative a at a * cv + j
  for (std::size_t iu = 0; iu < us.size(); ++iu) {
    const int su = find_span(s.u, us[iu]);
    basis_derivatives(s.u, su, us[iu], 2, bu);
    std::fill(t.begin(), t.end(), Eigen::Vector4d::Zero());
    for (int i = 0; i <= p; ++i)
      for (int j = 0; j < cv; ++j) {
        const Eigen::Vector4d& pw = net[static_cast<std::size_t>(s.index(su - p + i, j))];
        for (std::size_t a = 0; a < 3; ++a)
          t[a * static_cast<std::size_t>(cv) + static_cast<std::size_t>(j)] +=
              bu[a * wp + static_cast<std::size_t>(i)] * pw;
      }
    for (std::size_t iv = 0; iv < nv; ++iv) {
      const double* b = bv.data() + iv * 3 * wq;
      Eigen::Vector4d A[3][3];
      for (auto& row : A)
        for (auto& e : row) e.setZero();
      for (int j = 0; j <= q; ++j) {
        const std::size_t col = static_cast<std::size_t>(span_v[iv] - q + j);
        for (std::size_t a = 0; a < 3; ++a)
          for (std::size_t c = 0; a + c < 3; ++c)
            A[a][c] +=
                b[c * wq + static_cast<std::size_t>(j)] * t[a * static_cast<std::size_t>(cv) + col];
      }
      const auto P = [&](int a, int c) { return Eigen::Vector3d(A[a][c].head<3>()); };
      const auto W = [&](int a, int c) { return A[a][c][3]; };
      const double w = W(0, 0);
      auto& x = out[iu * nv + iv];
      x.point = P(0, 0) / w;
      x.du = (P(1, 0) - W(1, 0) * x.point) / w;
      x.dv = (P(0, 1) - W(0, 1) * x.point) / w;
      x.duu = (P(2, 0) - 2.0 * W(1, 0) * x.du - W(2, 0) * x.point) / w;
      x.dvv = (P(0, 2) - 2.0 * W(0, 1) * x.dv - W(0, 2) * x.point) / w;
      x.duv = (P(1, 1) - W(1, 0) * x.dv - W(0, 1) * x.du - W(1, 1) * x.point) / w;
    }
  }
  return out;
}

}  // namespace clay::surface
