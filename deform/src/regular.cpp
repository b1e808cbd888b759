// Barr's regular deformations (Güdükbay–Özgüç 1990 §3.1, after Barr 1984) about any axis.
// The paper's §3.1 numbers no equations; comments cite the subsection and the equation line.
// Every map is: local = R (X − origin), Barr's formula on local, X' = origin + R^T local'.
#include <clay/deform/regular.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <Eigen/Geometry>  // cross products

#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>

#include "messages.hpp"
#include "parallel.hpp"

namespace clay::deform {

namespace {

using detail::format;
using internal::all_finite;

/// Which of Barr's local axes `axis` and `reference` are.
enum class Layout {
  axial_z,  // taper, twist: axis = z, reference = x, y = z × x
  axial_y,  // bend: axis = y, reference = z, x = y × z
};

/// The orthonormal local basis: rows ex, ey, ez (Barr's x, y, z in world coordinates).
struct Basis {
  double o[3];
  double r[3][3];

  Eigen::Vector3d to_local(const double* p) const noexcept {
    const double dx = p[0] - o[0], dy = p[1] - o[1], dz = p[2] - o[2];
    return {r[0][0] * dx + r[0][1] * dy + r[0][2] * dz, r[1][0] * dx + r[1][1] * dy + r[1][2] * dz,
            r[2][0] * dx + r[2][1] * dy + r[2][2] * dz};
  }
  void to_world(const Eigen::Vector3d& l, double* p) const noexcept {
    for (int c = 0; c < 3; ++c) p[c] = o[c] + (r[0][c] * l.x() + r[1][c] * l.y() + r[2][c] * l.z());
  }
  Eigen::Matrix3d rotation() const {
    Eigen::Matrix3d m;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) m(a, b) = r[a][b];
    return m;
  }
};

Basis basis_of(const AxisFrame& f, Layout layout) {
  const Eigen::Vector3d a = f.axis / f.axis.norm();
  const Eigen::Vector3d perpendicular = f.reference - f.reference.dot(a) * a;
  const Eigen::Vector3d ref = perpendicular / perpendicular.norm();
  const Eigen::Vector3d third = a.cross(ref);
  Eigen::Vector3d e[3];
  if (layout == Layout::axial_z) {
    e[0] = ref, e[1] = third, e[2] = a;
  } else {
    e[0] = third, e[1] = a, e[2] = ref;
  }
  Basis b{};
  for (int c = 0; c < 3; ++c) {
    b.o[c] = f.origin[c];
    for (int d = 0; d < 3; ++d) b.r[c][d] = e[c][d];
  }
  return b;
}

/// Σ c_i z^i by Horner's rule, and its derivative.
double polynomial(const std::vector<double>& c, double z) noexcept {
  double v = c.back();
  for (std::size_t i = c.size() - 1; i-- > 0;) v = v * z + c[i];
  return v;
}
double polynomial_derivative(const std::vector<double>& c, double z) noexcept {
  if (c.size() < 2) return 0;
  double v = static_cast<double>(c.size() - 1) * c.back();
  for (std::size_t i = c.size() - 1; i-- > 1;) v = v * z + static_cast<double>(i) * c[i];
  return v;
}

/// The bend angle's sine and cosine and q = sin(θ/2) / k for θ = k h, from one sin/cos pair of
/// θ/2: cos θ = 1 − 2 sin²(θ/2), sin θ = 2 sin(θ/2) cos(θ/2). Then sin θ / k = 2 cos(θ/2) q and
/// (1 − cos θ) / k = 2 sin(θ/2) q, with no cancellation for small θ (q = h/2 sinc(θ/2) there).
struct BendAngle {
  double c, s, half_sin, half_cos, q;
};
BendAngle bend_angle(double k, double h) noexcept {
  const double half = 0.5 * k * h;
  BendAngle a;
  a.half_sin = std::sin(half);
  a.half_cos = std::cos(half);
  a.c = 1 - 2 * a.half_sin * a.half_sin;
  a.s = 2 * a.half_sin * a.half_cos;
  const double t2 = half * half;
  a.q = std::abs(half) < 1e-4 ? 0.5 * h * (1 - t2 / 6 * (1 - t2 / 20)) : a.half_sin / k;
  return a;
}

// ---- the three maps in local coordinates --------------------------------------------------

/// §3.1.1: r = f(z), X = r x, Y = r y, Z = z.
Eigen::Vector3d taper_local(const Taper& d, const Eigen::Vector3d& l) noexcept {
  const double r = polynomial(d.profile, l.z());
  return {r * l.x(), r * l.y(), l.z()};
}

/// §3.1.2: θ = f(z), X = x Cθ − y Sθ, Y = x Sθ + y Cθ, Z = z.
Eigen::Vector3d twist_local(const Twist& d, const Eigen::Vector3d& l) noexcept {
  const double theta = polynomial(d.angle, l.z());
  const double c = std::cos(theta), s = std::sin(theta);
  return {l.x() * c - l.y() * s, l.x() * s + l.y() * c, l.z()};
}

/// The clamped ŷ of §3.1.3: y_min below the region, y inside, y_max above.
double clamp_y(const Bend& d, double y) noexcept {
  return y <= d.y_min ? d.y_min : (y >= d.y_max ? d.y_max : y);
}

/// §3.1.3: θ = k (ŷ − y0), X = x,
///   Y = −Sθ (z − 1/k) + y0 + Cθ (y − ŷ),   Z = Cθ (z − 1/k) + 1/k + Sθ (y − ŷ)
/// (y − ŷ is 0 inside the region, y − y_min below, y − y_max above), written without 1/k:
/// Y = −Sθ z + Sθ/k + y0 + Cθ (y − ŷ), Z = Cθ z + (1 − Cθ)/k + Sθ (y − ŷ) (see bend_angle).
Eigen::Vector3d bend_local(const Bend& d, const Eigen::Vector3d& l) noexcept {
  const double yh = clamp_y(d, l.y());
  const BendAngle a = bend_angle(d.rate, yh - d.center);
  const double outside = l.y() - yh;
  return {l.x(), -a.s * l.z() + 2 * a.half_cos * a.q + d.center + a.c * outside,
          a.c * l.z() + 2 * a.half_sin * a.q + a.s * outside};
}

// ---- Jacobians in local coordinates --------------------------------------------------------

Eigen::Matrix3d taper_jacobian_local(const Taper& d, const Eigen::Vector3d& l) {
  const double r = polynomial(d.profile, l.z()), dr = polynomial_derivative(d.profile, l.z());
  Eigen::Matrix3d j;
  j << r, 0, dr * l.x(),  //
      0, r, dr * l.y(),   //
      0, 0, 1;
  return j;
}

Eigen::Matrix3d twist_jacobian_local(const Twist& d, const Eigen::Vector3d& l) {
  const double theta = polynomial(d.angle, l.z()), dtheta = polynomial_derivative(d.angle, l.z());
  const double c = std::cos(theta), s = std::sin(theta);
  const double X = l.x() * c - l.y() * s, Y = l.x() * s + l.y() * c;
  Eigen::Matrix3d j;
  j << c, -s, -dtheta * Y,  //
      s, c, dtheta * X,     //
      0, 0, 1;
  return j;
}

Eigen::Matrix3d bend_jacobian_local(const Bend& d, const Eigen::Vector3d& l) {
  const BendAngle a = bend_angle(d.rate, clamp_y(d, l.y()) - d.center);
  const double c = a.c, s = a.s;
  // Inside (and on the ends of) the region dθ/dy = k: ∂Y/∂y = Cθ (1 − k z), ∂Z/∂y = Sθ (1 − k z);
  // outside the parts are rigid: ∂Y/∂y = Cθ, ∂Z/∂y = Sθ.
  const bool inside = l.y() >= d.y_min && l.y() <= d.y_max;
  const double stretch = inside ? 1 - d.rate * l.z() : 1.0;
  Eigen::Matrix3d j;
  j << 1, 0, 0,            //
      0, c * stretch, -s,  //
      0, s * stretch, c;
  return j;
}

template <class D, class Map>
Eigen::Vector3d deform_one(const D& d, const Basis& b, const Eigen::Vector3d& x, Map map) {
  Eigen::Vector3d out;
  b.to_world(map(d, b.to_local(x.data())), out.data());
  return out;
}

template <class D, class Map>
void deform_many(const D& d, Layout layout, const Points3& points, Points3& out,
                 const DeformOptions& options, Map map) {
  validate(d);
  options.validate();
  if (&out != &points && out.rows() != points.rows()) out.resize(points.rows(), 3);
  const Basis b = basis_of(d.frame, layout);
  const double* in = points.data();
  double* o = out.data();
  detail::parallel_ranges(static_cast<std::size_t>(points.rows()), options,
                          [&](std::size_t begin, std::size_t end) {
                            for (std::size_t i = begin; i < end; ++i)
                              b.to_world(map(d, b.to_local(in + 3 * i)), o + 3 * i);
                          });
}

Eigen::Matrix3d jacobian_world(const Basis& b, const Eigen::Matrix3d& local) {
  const Eigen::Matrix3d r = b.rotation();
  return r.transpose() * local * r;
}

void polynomial_problems(const std::vector<double>& c, std::string_view name, const char* field,
                         const char* meaning, std::vector<std::string>& out) {
  if (c.empty()) {
    out.push_back(std::string(name) + ": " + field + " is empty; give at least the constant " +
                  meaning);
    return;
  }
  if (c.size() > static_cast<std::size_t>(max_profile_coefficients))
    out.push_back(std::string(name) + ": " + field + " has " + std::to_string(c.size()) +
                  " coefficients, more than " + std::to_string(max_profile_coefficients) +
                  " (degree 63); give a polynomial of lower degree");
  for (std::size_t i = 0; i < c.size(); ++i)
    if (!std::isfinite(c[i])) {
      out.push_back(std::string(name) + ": " + field + "[" + std::to_string(i) +
                    "] = " + format(c[i]) + " is not finite; give finite coefficients");
      return;
    }
}

}  // namespace

// ---- validation -------------------------------------------------------------------------------

std::vector<std::string> problems(const AxisFrame& frame, std::string_view name) {
  std::vector<std::string> out;
  const std::string n(name);
  const std::pair<const char*, const Eigen::Vector3d*> vectors[3] = {
      {"origin", &frame.origin}, {"axis", &frame.axis}, {"reference", &frame.reference}};
  for (const auto& [what, v] : vectors)
    if (!all_finite(*v))
      out.push_back(n + ": " + what + " " + format(*v) + " is not finite; give finite coordinates");
  if (!out.empty()) return out;
  if (frame.axis.norm() == 0)
    out.push_back(n +
                  ": axis (0, 0, 0) has zero length; give a non-zero direction for the "
                  "deformation axis");
  if (frame.reference.norm() == 0)
    out.push_back(n +
                  ": reference (0, 0, 0) has zero length; give a non-zero direction not "
                  "parallel to the axis");
  if (!out.empty()) return out;
  const Eigen::Vector3d a = frame.axis.normalized();
  const double perpendicular = (frame.reference - frame.reference.dot(a) * a).norm();
  if (!(perpendicular > 1e-9 * frame.reference.norm()))
    out.push_back(n + ": reference " + format(frame.reference) + " is parallel to the axis " +
                  format(frame.axis) + " (relative perpendicular part " +
                  format(perpendicular / frame.reference.norm()) +
                  "), so it fixes no other axis; give a reference direction across the axis");
  return out;
}

void validate(const AxisFrame& frame, std::string_view name) {
  const auto list = problems(frame, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}

std::vector<std::string> problems(const Taper& taper, std::string_view name) {
  auto out = problems(taper.frame, std::string(name) + " frame");
  polynomial_problems(taper.profile, name, "profile", "radius factor r(z) (1 = unchanged)", out);
  return out;
}

std::vector<std::string> problems(const Twist& twist, std::string_view name) {
  auto out = problems(twist.frame, std::string(name) + " frame");
  polynomial_problems(twist.angle, name, "angle", "angle θ(z) in radians (0 = unchanged)", out);
  return out;
}

std::vector<std::string> problems(const Bend& bend, std::string_view name) {
  auto out = problems(bend.frame, std::string(name) + " frame");
  const std::string n(name);
  const std::pair<const char*, double> values[4] = {
      {"y_min", bend.y_min}, {"y_max", bend.y_max}, {"center", bend.center}, {"rate", bend.rate}};
  bool all_finite = true;
  for (const auto& [what, v] : values)
    if (!std::isfinite(v)) {
      out.push_back(n + ": " + what + " = " + format(v) + " is not finite; give a finite value" +
                    (std::string_view(what) == "rate" ? " in rad/mm (0 = no bend)" : " in mm"));
      all_finite = false;
    }
  if (all_finite && bend.y_min > bend.y_max)
    out.push_back(n + ": y_min = " + format(bend.y_min) + " > y_max = " + format(bend.y_max) +
                  "; give y_min <= y_max (the bent region along the axis)");
  return out;
}

void validate(const Taper& taper, std::string_view name) {
  const auto list = problems(taper, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}
void validate(const Twist& twist, std::string_view name) {
  const auto list = problems(twist, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}
void validate(const Bend& bend, std::string_view name) {
  const auto list = problems(bend, name);
  internal::throw_if(ErrorCategory::InvalidGeometry, list);
}

// ---- one point --------------------------------------------------------------------------------

Eigen::Vector3d deform_point(const Taper& taper, const Eigen::Vector3d& x) {
  return deform_one(taper, basis_of(taper.frame, Layout::axial_z), x, taper_local);
}

Eigen::Vector3d deform_point(const Twist& twist, const Eigen::Vector3d& x) {
  return deform_one(twist, basis_of(twist.frame, Layout::axial_z), x, twist_local);
}

Eigen::Vector3d deform_point(const Bend& bend, const Eigen::Vector3d& x) {
  if (bend.rate == 0) return x;  // the identity, exactly
  return deform_one(bend, basis_of(bend.frame, Layout::axial_y), x, bend_local);
}

// ---- Jacobians --------------------------------------------------------------------------------

Eigen::Matrix3d jacobian_matrix(const Taper& taper, const Eigen::Vector3d& x) {
  const Basis b = basis_of(taper.frame, Layout::axial_z);
  return jacobian_world(b, taper_jacobian_local(taper, b.to_local(x.data())));
}

Eigen::Matrix3d jacobian_matrix(const Twist& twist, const Eigen::Vector3d& x) {
  const Basis b = basis_of(twist.frame, Layout::axial_z);
  return jacobian_world(b, twist_jacobian_local(twist, b.to_local(x.data())));
}

Eigen::Matrix3d jacobian_matrix(const Bend& bend, const Eigen::Vector3d& x) {
  if (bend.rate == 0) return Eigen::Matrix3d::Identity();
  const Basis b = basis_of(bend.frame, Layout::axial_y);
  return jacobian_world(b, bend_jacobian_local(bend, b.to_local(x.data())));
}

// ---- many points ------------------------------------------------------------------------------

void deform_points(const Taper& taper, const Points3& points, Points3& out,
                   const DeformOptions& options) {
  deform_many(taper, Layout::axial_z, points, out, options, taper_local);
}

void deform_points(const Twist& twist, const Points3& points, Points3& out,
                   const DeformOptions& options) {
  deform_many(twist, Layout::axial_z, points, out, options, twist_local);
}

void deform_points(const Bend& bend, const Points3& points, Points3& out,
                   const DeformOptions& options) {
  if (bend.rate == 0) {  // the identity, exactly (as deform_point)
    validate(bend);
    options.validate();
    if (&out != &points) out = points;
    return;
  }
  deform_many(bend, Layout::axial_y, points, out, options, bend_local);
}

Points3 deform_points(const Taper& taper, const Points3& points, const DeformOptions& options) {
  Points3 out(points.rows(), 3);
  deform_points(taper, points, out, options);
  return out;
}

Points3 deform_points(const Twist& twist, const Points3& points, const DeformOptions& options) {
  Points3 out(points.rows(), 3);
  deform_points(twist, points, out, options);
  return out;
}

Points3 deform_points(const Bend& bend, const Points3& points, const DeformOptions& options) {
  Points3 out(points.rows(), 3);
  deform_points(bend, points, out, options);
  return out;
}

}  // namespace clay::deform
