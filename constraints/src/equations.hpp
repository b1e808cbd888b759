#pragma once
// Internal: the constraint system as scalar unknowns and equations, with residuals templated on
// the scalar type so Ceres can differentiate them automatically (ceres::Jet) and plain doubles
// evaluate them for reports.
#include <clay/constraints/constraint.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace clay::constraints::detail {

/// A constraint flattened for the equation builder: the kind and the points, entities and ends it
/// refers to, in the order the kind's struct declares them, with its value (mm or degrees).
struct Lowered {
  ConstraintKind kind = ConstraintKind::Fixed;
  std::vector<PointId> points;
  std::vector<EntityId> entities;
  std::vector<CurveEnd> ends;
  double value = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< EndTangent only (world)
  std::string label;
};

/// The flat form of a typed constraint (constraint.cpp).
Lowered lower(const Constraint& constraint);

/// What an equation computes (one user constraint may give several equations).
enum class EqKind {
  EqualScalar,    // a - b                     (coincident, horizontal, vertical; substitutable)
  FixScalar,      // a - value                 (fixed; substitutable)
  PointsEqual,    // p - q (frame rows)        (coincident across planes / free points)
  Distance,       // (|p - q|^2 - L^2) / 2L
  PointLine,      // cross(b - a, p - a)/|b - a| - signed d (planar)
  PointOnLine,    // p - a - t (b - a)
  PointOnCircle,  // (|p - c|^2 - r^2) / 2 r0 [+ (p - c).n off-plane]
  PointOnArc,     // (|p - c|^2 - |s - c|^2) / 2 r0 [+ (p - c).n off-plane]
  PointOnCurve,   // C(t) - p
  Parallel,       // cross(d1, d2) / |d1||d2|
  Perpendicular,  // dot(d1, d2) / |d1||d2|
  Angle,          // wrap(atan2(s cross, dot) - theta)
  RadiusValue,    // circle: r - R ; arc: |s - c| - R
  EqualLength,    // |d1| - |d2|
  EqualRadius,    // radius(a) - radius(b)
  Midpoint,       // p - (a + b)/2
  Symmetric,      // cross(b - a, m - a)/|b - a| ; dot(q - p, b - a)/|b - a|
  ArcRadius,      // |e - c| - |s - c| (implicit for every arc)
  Joint,          // G1: away_b - alpha out_a ; G2 also: D2_b - alpha^2 D2_a - beta out_a
  EndTangent,     // D1 - alpha v
  Target,         // p - target (drag; in the point's own frame)
};

/// Where a point's coordinates sit among an equation's slots: dim 2 (plane coordinates of
/// `plane`) or 3 (world).
struct PointRef {
  int offset = 0;
  int dim = 3;
  int plane = -1;
};

/// One end of a curve in an equation: a B-spline-like end (lines count as degree 1) given by the
/// values of its basis functions and their first two derivatives at the end, or an arc end.
struct EndSpec {
  bool arc = false;
  std::vector<int> points;  // indices into Equation::points: B-spline end control points, or
                            // arc (center, start or end point)
  std::vector<double> n0, n1, n2, w;  // B-spline: basis values and derivatives, weights
  bool at_start = false;
};

/// One equation block: `rows` residuals over `scalars` (unreduced scalar indices, the slots).
struct Equation {
  EqKind kind = EqKind::EqualScalar;
  int constraint = -1;  // index into the user's list; -1 for implicit (arc radius)
  int entity = -1;      // implicit equations: the entity they belong to
  int rows = 1;
  std::vector<int> scalars;  // slot -> unreduced scalar
  std::vector<PointRef> points;
  bool planar = false;  // residuals in plane coordinates of `plane` (else world)
  int plane = -1;
  std::vector<double> data;   // kind-specific constants
  int extra = -1;             // slot of the first extra unknown (t, alpha, beta)
  std::vector<EndSpec> ends;  // Joint (2), EndTangent (1)
  bool substitutable = false;
};

/// A scalar unknown: its start value and whom it belongs to (for messages).
struct ScalarInfo {
  double value = 0;
  double lower = -INFINITY, upper = INFINITY;  // bounds (curve parameters)
};

/// The whole system before substitution.
struct Model {
  std::vector<ScalarInfo> scalars;
  std::vector<PointRef> point_vars;  // per sketch point: first scalar, dim, plane
  std::vector<int> radius_var;       // per entity: circle radius scalar, else -1
  std::vector<Equation> equations;
  std::vector<sketch::SketchPlane> planes;
  double size = 1;  // model size (mm)
};

/// Builds the model; throws clay::Error naming the constraint for bad references or values.
Model build_model(const sketch::Sketch& sketch, const std::vector<Constraint>& constraints);

/// Orientation sign of a constraint at the given unreduced values (+1/-1), or 0 when the
/// constraint has no orientation. Used to detect flips.
double orientation(const Model& model, const Equation& eq, const double* values);

// ---- residuals ----

/// Scalar part of a double or a ceres::Jet.
inline double ceres_scalar(double x) { return x; }
template <class J>
auto ceres_scalar(const J& x) -> decltype(x.a) {
  return x.a;
}

template <class T>
using V3 = Eigen::Matrix<T, 3, 1>;

template <class T>
T cross_z(const V3<T>& a, const V3<T>& b) {
  return a.x() * b.y() - a.y() * b.x();
}

template <class T>
T norm3(const V3<T>& a) {
  using std::sqrt;
  return sqrt(a.squaredNorm());
}

template <class T>
V3<T> point_at(const Model& m, const Equation& eq, const T* v, int k) {
  const PointRef& r = eq.points[static_cast<size_t>(k)];
  const T* p = v + r.offset;
  if (r.dim == 3) return {p[0], p[1], p[2]};
  if (eq.planar) return {p[0], p[1], T(0)};
  const sketch::SketchPlane& pl = m.planes[static_cast<size_t>(r.plane)];
  return pl.origin.cast<T>() + pl.x_axis.cast<T>() * p[0] + pl.y_axis.cast<T>() * p[1];
}

/// The normal of the equation's frame plane used for "perp" (planar: z; world: the plane normal).
inline Eigen::Vector3d frame_normal(const Model& m, const Equation& eq, int plane) {
  if (eq.planar) return Eigen::Vector3d::UnitZ();
  return m.planes[static_cast<size_t>(plane)].normal();
}

/// Point, first and second derivative (along increasing parameter) of a curve end.
template <class T>
void end_derivatives(const Model& m, const Equation& eq, const EndSpec& e, const T* v, V3<T>& c,
                     V3<T>& d1, V3<T>& d2) {
  if (e.arc) {
    const V3<T> center = point_at(m, eq, v, e.points[0]);
    const V3<T> r = point_at(m, eq, v, e.points[1]) - center;
    const int plane = eq.points[static_cast<size_t>(e.points[0])].plane;
    const V3<T> n = frame_normal(m, eq, plane).cast<T>();
    c = center + r;
    d1 = n.cross(r);  // counterclockwise about the plane normal, unit angular speed
    d2 = -r;
    return;
  }
  V3<T> a0 = V3<T>::Zero(), a1 = V3<T>::Zero(), a2 = V3<T>::Zero();
  double w0 = 0, w1 = 0, w2 = 0;
  for (size_t i = 0; i < e.points.size(); ++i) {
    const V3<T> p = point_at(m, eq, v, e.points[i]);
    a0 += p * (e.n0[i] * e.w[i]);
    a1 += p * (e.n1[i] * e.w[i]);
    a2 += p * (e.n2[i] * e.w[i]);
    w0 += e.n0[i] * e.w[i];
    w1 += e.n1[i] * e.w[i];
    w2 += e.n2[i] * e.w[i];
  }
  c = a0 / w0;
  d1 = (a1 - c * w1) / w0;
  d2 = (a2 - d1 * (2 * w1) - c * w2) / w0;
}

/// C(t) of a B-spline stored in eq.data as [degree, n_knots, knots..., weights...] with control
/// points eq.points[first .. first + count).
template <class T>
V3<T> curve_point(const Model& m, const Equation& eq, const T* v, const T& t, int first) {
  const int p = static_cast<int>(eq.data[0]);
  const int nk = static_cast<int>(eq.data[1]);
  const double* U = eq.data.data() + 2;
  const double* W = U + nk;
  const int count = nk - p - 1;
  // span from the scalar part of t (knots are constants)
  const double ts = ceres_scalar(t);
  int k = p;
  while (k < count - 1 && ts >= U[k + 1]) ++k;
  // Cox–de Boor (The NURBS Book A2.2) on T
  T N[32], left[32], right[32];
  N[0] = T(1);
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[k + 1 - j];
    right[j] = U[k + j] - t;
    T saved = T(0);
    for (int r = 0; r < j; ++r) {
      const T temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
  V3<T> a = V3<T>::Zero();
  T w = T(0);
  for (int i = 0; i <= p; ++i) {
    const int idx = k - p + i;
    a += point_at(m, eq, v, first + idx) * (N[i] * W[idx]);
    w += N[i] * W[idx];
  }
  return a / w;
}

template <class T>
T wrap_angle(const T& x) {
  const double s = ceres_scalar(x);
  if (s > std::numbers::pi) return x - 2 * std::numbers::pi;
  if (s <= -std::numbers::pi) return x + 2 * std::numbers::pi;
  return x;
}

/// The residuals of one equation from its slot values v.
template <class T>
void residuals(const Model& m, const Equation& eq, const T* v, T* r) {
  using std::atan2;
  using std::sqrt;
  switch (eq.kind) {
    case EqKind::EqualScalar:
      r[0] = v[0] - v[1];
      return;
    case EqKind::FixScalar:
      r[0] = v[0] - eq.data[0];
      return;
    case EqKind::PointsEqual: {
      const V3<T> d = point_at(m, eq, v, 0) - point_at(m, eq, v, 1);
      for (int i = 0; i < eq.rows; ++i) r[i] = d[i];
      return;
    }
    case EqKind::Distance: {
      const double L = eq.data[0];
      const V3<T> d = point_at(m, eq, v, 0) - point_at(m, eq, v, 1);
      r[0] = (d.squaredNorm() - L * L) / (2 * L);
      return;
    }
    case EqKind::PointLine: {
      const V3<T> p = point_at(m, eq, v, 0), a = point_at(m, eq, v, 1), b = point_at(m, eq, v, 2);
      r[0] = cross_z<T>(b - a, p - a) / norm3<T>(b - a) - eq.data[0];
      return;
    }
    case EqKind::PointOnLine: {
      const V3<T> p = point_at(m, eq, v, 0), a = point_at(m, eq, v, 1), b = point_at(m, eq, v, 2);
      const V3<T> d = p - a - (b - a) * v[eq.extra];
      for (int i = 0; i < eq.rows; ++i) r[i] = d[i];
      return;
    }
    case EqKind::PointOnCircle:
    case EqKind::PointOnArc: {
      const V3<T> p = point_at(m, eq, v, 0), c = point_at(m, eq, v, 1);
      T r2;
      if (eq.kind == EqKind::PointOnCircle) {
        r2 = v[eq.extra] * v[eq.extra];
      } else {
        r2 = (point_at(m, eq, v, 2) - c).squaredNorm();
      }
      r[0] = ((p - c).squaredNorm() - r2) / (2 * eq.data[0]);
      if (eq.rows == 2) {
        const Eigen::Vector3d n = m.planes[static_cast<size_t>(eq.plane)].normal();
        r[1] = (p - c).dot(n.cast<T>());
      }
      return;
    }
    case EqKind::PointOnCurve: {
      const V3<T> d = curve_point(m, eq, v, v[eq.extra], 1) - point_at(m, eq, v, 0);
      for (int i = 0; i < eq.rows; ++i) r[i] = d[i];
      return;
    }
    case EqKind::Parallel:
    case EqKind::Perpendicular:
    case EqKind::Angle: {
      const V3<T> d1 = point_at(m, eq, v, 1) - point_at(m, eq, v, 0);
      const V3<T> d2 = point_at(m, eq, v, 3) - point_at(m, eq, v, 2);
      const T cr = cross_z<T>(d1, d2), dt = d1.dot(d2);
      if (eq.kind == EqKind::Parallel)
        r[0] = cr / (norm3<T>(d1) * norm3<T>(d2));
      else if (eq.kind == EqKind::Perpendicular)
        r[0] = dt / (norm3<T>(d1) * norm3<T>(d2));
      else
        r[0] = wrap_angle<T>(atan2(cr * eq.data[1], dt) - eq.data[0]);
      return;
    }
    case EqKind::RadiusValue:
      if (eq.data[1] > 0)
        r[0] = v[0] - eq.data[0];  // circle radius unknown
      else
        r[0] = norm3<T>(point_at(m, eq, v, 1) - point_at(m, eq, v, 0)) - eq.data[0];
      return;
    case EqKind::EqualLength:
      r[0] = norm3<T>(point_at(m, eq, v, 1) - point_at(m, eq, v, 0)) -
             norm3<T>(point_at(m, eq, v, 3) - point_at(m, eq, v, 2));
      return;
    case EqKind::EqualRadius: {
      // data: [a is circle, b is circle]; circle radius at slot data[2]/data[3], arcs by points
      auto radius_of = [&](int which) -> T {
        if (eq.data[static_cast<size_t>(which)] > 0)
          return v[static_cast<int>(eq.data[static_cast<size_t>(2 + which)])];
        const int first = static_cast<int>(eq.data[static_cast<size_t>(2 + which)]);
        return norm3<T>(point_at(m, eq, v, first + 1) - point_at(m, eq, v, first));
      };
      r[0] = radius_of(0) - radius_of(1);
      return;
    }
    case EqKind::Midpoint: {
      const V3<T> d = point_at(m, eq, v, 0) - (point_at(m, eq, v, 1) + point_at(m, eq, v, 2)) * 0.5;
      for (int i = 0; i < eq.rows; ++i) r[i] = d[i];
      return;
    }
    case EqKind::Symmetric: {
      const V3<T> p = point_at(m, eq, v, 0), q = point_at(m, eq, v, 1);
      const V3<T> a = point_at(m, eq, v, 2), b = point_at(m, eq, v, 3);
      const T len = norm3<T>(b - a);
      r[0] = cross_z<T>(b - a, (p + q) * 0.5 - a) / len;
      r[1] = (q - p).dot(b - a) / len;
      return;
    }
    case EqKind::ArcRadius:
      r[0] = norm3<T>(point_at(m, eq, v, 2) - point_at(m, eq, v, 0)) -
             norm3<T>(point_at(m, eq, v, 1) - point_at(m, eq, v, 0));
      return;
    case EqKind::Joint: {
      V3<T> ca, a1, a2, cb, b1, b2;
      end_derivatives(m, eq, eq.ends[0], v, ca, a1, a2);
      end_derivatives(m, eq, eq.ends[1], v, cb, b1, b2);
      // out_a points out of curve a at the joint; away_b points from the joint into curve b.
      const V3<T> out_a = eq.ends[0].at_start ? V3<T>(-a1) : a1;
      const V3<T> away_b = eq.ends[1].at_start ? b1 : V3<T>(-b1);
      const T alpha = v[eq.extra];
      const int dim = eq.planar ? 2 : 3;
      const V3<T> g1 = away_b - out_a * alpha;
      for (int i = 0; i < dim; ++i) r[i] = g1[i];
      if (eq.rows > dim) {
        const V3<T> g2 = b2 - a2 * (alpha * alpha) - out_a * v[eq.extra + 1];
        for (int i = 0; i < dim; ++i) r[dim + i] = g2[i];
      }
      return;
    }
    case EqKind::Target: {
      const V3<T> d =
          point_at(m, eq, v, 0) - Eigen::Vector3d(eq.data[0], eq.data[1], eq.data[2]).cast<T>();
      for (int i = 0; i < eq.rows; ++i) r[i] = d[i];
      return;
    }
    case EqKind::EndTangent: {
      V3<T> c, d1, d2;
      end_derivatives(m, eq, eq.ends[0], v, c, d1, d2);
      const V3<T> dir(T(eq.data[0]), T(eq.data[1]), T(eq.data[2]));
      const V3<T> g = d1 - dir * v[eq.extra];
      for (int i = 0; i < eq.rows; ++i) r[i] = g[i];
      return;
    }
  }
}

}  // namespace clay::constraints::detail
