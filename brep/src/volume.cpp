// The volume of solids by the divergence and Green theorems (see clay/brep/volume.hpp).
#include <clay/brep/volume.hpp>

#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/internal/math.hpp>
#include <clay/parallel.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include "integration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace clay::brep {
namespace {

using detail::adaptive;
using detail::body_centre;
using detail::breaks;
using detail::Budget;
using detail::face_budget;
using detail::gauss;
using detail::size_cubed;
using detail::with_knot_crossings;

/// F(u, v) = ∫_a^u (S − c)·(S_u × S_v) / 3 ds, per knot span of u. On a polynomial surface of
/// degree p in u the integrand has degree 3p - 1 there, so ceil(3p / 2) points are exact. A
/// rational one is integrated adaptively to `tol` (F's units: volume per unit of v) within the
/// face's budget: a fixed 16-point rule was 30 % off where a weight of 1e3 crowds the
/// parametrization (issue #36).
double inner(const surface::BSplineSurface& s, const Eigen::Vector3d& c, double a, double u,
             double v, double tol, Budget& budget) {
  // A pcurve may stand a rounding error outside the surface's domain (problems() allows it):
  // evaluate on its boundary there.
  u = std::clamp(u, s.u.domain().first, s.u.domain().second);
  v = std::clamp(v, s.v.domain().first, s.v.domain().second);
  const double lo = std::min(a, u), hi = std::max(a, u);
  if (hi == lo) return 0;
  const auto spans = breaks(s.u, lo, hi);
  const detail::Isocurve iso(s, v, lo, hi);  // v is fixed along the integral
  auto integrand = [&](double x) {
    Eigen::Vector3d point, du, dv;
    iso.at(x, point, du, dv);
    return (point - c).dot(du.cross(dv)) / 3.0;
  };
  double sum = 0;
  for (std::size_t k = 0; k + 1 < spans.size(); ++k)
    sum += s.is_rational() ? adaptive(spans[k], spans[k + 1], integrand, tol, budget)
                           : gauss(std::clamp((3 * s.u.degree + 1) / 2, 1, 16), spans[k],
                                   spans[k + 1], integrand);
  return u >= a ? sum : -sum;
}

/// One face's contribution and how its integration went.
struct FaceVolume {
  double mm3 = 0;
  Budget budget;
};

FaceVolume face_volume(const Model& m, const Face& face, const Eigen::Vector3d& centre,
                       double tol) {
  FaceVolume out;
  out.budget.intervals = face_budget(face.surface);
  const surface::BSplineSurface& s = face.surface;
  // Plain copies, not structured bindings: lambdas below capture them (Clang 14 refuses).
  const double u0 = s.u.domain().first, u1 = s.u.domain().second;
  const double v0 = s.v.domain().first, v1 = s.v.domain().second;
  // F's tolerance: an error δ in F moves the loop integral by at most δ times the v extent.
  const double tol_inner = tol / std::max(v1 - v0, 1e-300);
  double sum = 0;
  if (face.loops.empty()) {
    // The whole domain: along its right side (the left one has F = 0, the others dv = 0).
    const auto spans = breaks(s.v, v0, v1);
    for (std::size_t k = 0; k + 1 < spans.size(); ++k)
      sum += adaptive(
          spans[k], spans[k + 1],
          [&](double v) { return inner(s, centre, u0, u1, v, tol_inner, out.budget); }, tol,
          out.budget);
  } else {
    const double a = u0;  // any reference works: ∂F/∂u is the integrand for every choice
    for (const Loop& loop : face.loops)
      for (const Coedge& c : loop.coedges) {
        const Edge& e = m.edges[static_cast<std::size_t>(c.edge)];
        // problems() lets an edge range end a rounding error past its pcurve's domain (a range
        // read from a file, 30.773502691896002 against 30.773502691895999): evaluate inside.
        const double d0 = c.pcurve.basis.domain().first, d1 = c.pcurve.basis.domain().second;
        auto integrand = [&](double t) {
          const surface::CurveDerivatives q =
              surface::derivatives(c.pcurve, std::clamp(t, d0, d1), 1);
          return q.d1.y() == 0.0
                     ? 0.0
                     : inner(s, centre, a, q.point.x(), q.point.y(), tol_inner, out.budget) *
                           q.d1.y();
        };
        const auto pieces =
            with_knot_crossings(c.pcurve, breaks(c.pcurve.basis, e.t0, e.t1), s.v, d0, d1);
        double along = 0;
        for (std::size_t k = 0; k + 1 < pieces.size(); ++k)
          along += adaptive(pieces[k], pieces[k + 1], integrand, tol, out.budget);
        sum += c.same_sense ? along : -along;
      }
  }
  out.mm3 = face.reversed ? -sum : sum;
  return out;
}

/// The signed volume of the bodies `wanted` says (0 for the others): the faces' contributions
/// integrated on the hardware's threads (each face on its own), then summed per body in shell
/// order, so the result does not depend on the threads. Only the wanted bodies' faces are
/// integrated: a sheet's faces (a surface model's large trimmed B-splines) may not converge, and
/// their figure means nothing. Precondition: the model is valid.
std::vector<double> body_volumes(const Model& m, const std::vector<bool>& wanted) {
  const double tol = 1e-14 * size_cubed(m);
  std::vector<FaceVolume> face(m.faces.size());
  std::vector<bool> integrate(m.faces.size(), false);
  std::vector<Eigen::Vector3d> centre(m.faces.size(), Eigen::Vector3d::Zero());
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    if (wanted[b]) {
      const Eigen::Vector3d c = body_centre(m, {static_cast<int>(b)});
      for (const Shell& shell : m.bodies[b].shells)
        for (int f : shell.faces) {
          integrate[static_cast<std::size_t>(f)] = true;
          centre[static_cast<std::size_t>(f)] = c;
        }
    }
  const std::size_t parts = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1,
                                                    std::max<std::size_t>(1, m.faces.size()));
  run_on_threads(parts, [&](std::size_t part) {
    for (std::size_t f = part; f < m.faces.size(); f += parts)
      if (integrate[f]) face[f] = face_volume(m, m.faces[f], centre[f], tol);
  });
  std::vector<double> out(m.bodies.size(), 0.0);
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    if (wanted[b])
      for (const Shell& shell : m.bodies[b].shells)
        for (int f : shell.faces) out[b] += face[static_cast<std::size_t>(f)].mm3;
  // A volume that did not converge is a failure, not a figure: name the faces and the estimate.
  std::string faces;
  int count = 0;
  for (std::size_t f = 0; f < face.size(); ++f)
    if (!face[f].budget.converged && ++count <= 5)
      faces += (faces.empty() ? "" : ", ") + std::to_string(f);
  if (count > 0)
    throw Error(ErrorCategory::ToleranceNotMet,
                "the volume did not converge on " + std::to_string(count) + " face(s) (" + faces +
                    (count > 5 ? ", ..." : "") +
                    ") within its budget of quadrature intervals: a surface with extreme weights "
                    "(their ratio "
                    "far above 1e3) or a near-singular parametrization; rebuild those faces with "
                    "moderate weights");
  return out;
}

}  // namespace

double volume_mm3(const Model& model, int body) {
  if (body < 0 || body >= static_cast<int>(model.bodies.size()))
    throw Error(ErrorCategory::InvalidArgument,
                "volume_mm3: body " + std::to_string(body) + " does not exist; the model has " +
                    std::to_string(model.bodies.size()) + " bodies");
  validate(model);
  std::vector<bool> wanted(model.bodies.size(), false);
  wanted[static_cast<std::size_t>(body)] = true;
  return body_volumes(model, wanted)[static_cast<std::size_t>(body)];
}

std::vector<double> body_volumes_mm3(const Model& model) {
  validate(model);
  std::vector<bool> solids(model.bodies.size());
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
    solids[b] = model.bodies[b].kind == BodyKind::Solid;
  return body_volumes(model, solids);
}

double volume_mm3(const Model& model) {
  const std::vector<double> bodies = body_volumes_mm3(model);
  if (!model.is_assembly()) {
    double sum = 0;
    for (double v : bodies) sum += v;
    return sum;
  }
  // Each placed instance once (validate refused cycles).
  std::function<double(int)> part = [&](int p) {
    const Part& node = model.parts[static_cast<std::size_t>(p)];
    double v = 0;
    for (int b : node.bodies) v += bodies[static_cast<std::size_t>(b)];
    for (const Instance& c : node.components) v += part(c.part);
    return v;
  };
  double sum = 0;
  for (const Instance& root : model.roots) sum += part(root.part);
  return sum;
}

}  // namespace clay::brep
