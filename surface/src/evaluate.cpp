#include <clay/surface/evaluate.hpp>

#include <clay/error.hpp>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace clay::surface {
namespace {

void check_order(int order) {
  if (order < 0 || order > 2)
    throw Error(ErrorCategory::InvalidArgument,
                "derivative order " + std::to_string(order) + " is outside [0, 2]; ask for 0, 1 or 2");
}

void check_shape(const BSplineCurve& c) {
  if (c.basis.degree < 1 || c.basis.degree > max_kernel_degree || c.basis.count() < c.basis.degree + 1 ||
      c.points.rows() != c.basis.count() || c.weights.size() != c.points.rows())
    throw Error(ErrorCategory::InvalidGeometry,
                "curve: degree, knot count, control point count and weight count disagree; "
                "call validate(curve) for details");
}

void check_shape(const BSplineSurface& s) {
  const auto ok = [](const BSplineBasis& b) {
    return b.degree >= 1 && b.degree <= max_kernel_degree && b.count() >= b.degree + 1;
  };
  if (!ok(s.u) || !ok(s.v) || s.points.rows() != static_cast<Eigen::Index>(s.u.count()) * s.v.count() ||
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
  Eigen::Vector4d a[3] = {Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero()};
  for (int j = 0; j <= p; ++j) {
    const Eigen::Index r = span - p + j;
    const double w = curve.weights[r];
    const Eigen::Vector4d pw(curve.points(r, 0) * w, curve.points(r, 1) * w, curve.points(r, 2) * w, w);
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

Eigen::Vector3d evaluate(const BSplineCurve& curve, double t) { return derivatives(curve, t, 0).point; }

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
    Eigen::Vector4d temp[3] = {Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero()};
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
  for (size_t k = 0; k < ts.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = evaluate(curve, ts[k]).transpose();
  return out;
}

Points3 evaluate_grid(const BSplineSurface& surface, std::span<const double> us,
                      std::span<const double> vs) {
  validate(surface);
  const int p = surface.u.degree, q = surface.v.degree;
  const int cv = surface.count_v();
  const size_t nus = us.size(), nvs = vs.size();
  // Basis functions of every v parameter, computed once.
  std::vector<int> span_v(nvs);
  std::vector<double> basis_v(nvs * static_cast<size_t>(q + 1));
  for (size_t k = 0; k < nvs; ++k) {
    span_v[k] = find_span(surface.v, vs[k]);
    basis_functions(surface.v, span_v[k], vs[k],
                    std::span<double>(basis_v.data() + k * static_cast<size_t>(q + 1), static_cast<size_t>(q + 1)));
  }
  // Homogeneous net, 4 doubles per control point.
  const Eigen::Index rows = surface.points.rows();
  std::vector<double> net(static_cast<size_t>(rows) * 4);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double w = surface.weights[r];
    net[static_cast<size_t>(r) * 4 + 0] = surface.points(r, 0) * w;
    net[static_cast<size_t>(r) * 4 + 1] = surface.points(r, 1) * w;
    net[static_cast<size_t>(r) * 4 + 2] = surface.points(r, 2) * w;
    net[static_cast<size_t>(r) * 4 + 3] = w;
  }
  Points3 out(static_cast<Eigen::Index>(nus * nvs), 3);
  std::vector<double> column(static_cast<size_t>(cv) * 4);  // the net contracted in u at one u
  std::array<double, max_width> bu;
  for (size_t iu = 0; iu < nus; ++iu) {
    const int su = find_span(surface.u, us[iu]);
    basis_functions(surface.u, su, us[iu], bu);
    std::fill(column.begin(), column.end(), 0.0);
    for (int i = 0; i <= p; ++i) {
      const double b = bu[static_cast<size_t>(i)];
      const double* row = net.data() + static_cast<size_t>(su - p + i) * static_cast<size_t>(cv) * 4;
      for (size_t c = 0; c < column.size(); ++c) column[c] += b * row[c];
    }
    for (size_t iv = 0; iv < nvs; ++iv) {
      const double* bv = basis_v.data() + iv * static_cast<size_t>(q + 1);
      const double* base = column.data() + static_cast<size_t>(span_v[iv] - q) * 4;
      double x = 0, y = 0, z = 0, w = 0;
      for (int j = 0; j <= q; ++j) {
        const double b = bv[j];
        x += b * base[4 * j + 0];
        y += b * base[4 * j + 1];
        z += b * base[4 * j + 2];
        w += b * base[4 * j + 3];
      }
      const Eigen::Index r = static_cast<Eigen::Index>(iu * nvs + iv);
      const double inv = 1.0 / w;
      out(r, 0) = x * inv;
      out(r, 1) = y * inv;
      out(r, 2) = z * inv;
    }
  }
  return out;
}

std::vector<double> linspace(double first, double last, int count) {
  if (count < 2 || !std::isfinite(first) || !std::isfinite(last))
    throw Error(ErrorCategory::InvalidArgument,
                "linspace: needs count >= 2 and finite ends, got count " + std::to_string(count));
  std::vector<double> out(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) out[static_cast<size_t>(k)] = first + (last - first) * k / (count - 1);
  out.back() = last;
  return out;
}

}  // namespace clay::surface
