// Surface area of trimmed faces with an error bound, and its exact gradient (see
// clay/brep/mass_properties.hpp).
#include <clay/brep/mass_properties.hpp>

#include <clay/error.hpp>
#include <clay/parallel.hpp>
#include <clay/surface/evaluate.hpp>

#include "integration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace clay::brep {
namespace {

using detail::breaks;
using detail::Budget;
using detail::Node;
using One = Eigen::Matrix<double, 1, 1>;

/// ∫_a^u |X_u × X_v| ds at v (Green's F for the area) and its error bound, appending its nodes to
/// rec: adaptive per knot span of u (|n| is not polynomial, not even on a polynomial face).
std::pair<double, double> inner(const surface::BSplineSurface& s, double a, double u, double v,
                                double tol, Budget& budget, std::vector<Node>* rec) {
  u = std::clamp(u, s.u.domain().first, s.u.domain().second);
  v = std::clamp(v, s.v.domain().first, s.v.domain().second);
  const double lo = std::min(a, u), hi = std::max(a, u);
  if (hi == lo) return {0.0, 0.0};
  const double sign = u >= a ? 1 : -1;
  const auto spans = breaks(s.u, lo, hi);
  const detail::Isocurve iso(s, v, lo, hi);  // v is fixed along the integral
  auto integrand = [&](double x, std::vector<Node>* r) -> One {
    if (r) r->push_back({x, v, 1});
    Eigen::Vector3d point, du, dv;
    iso.at(x, point, du, dv);
    return One(du.cross(dv).norm());
  };
  One sum = One::Zero(), gaps = One::Zero();
  std::vector<Node> nodes;
  for (std::size_t k = 0; k + 1 < spans.size(); ++k)
    sum +=
        detail::adaptive_vector(spans[k], spans[k + 1], integrand, One(tol), budget, nodes, &gaps);
  if (rec)
    for (Node n : nodes) rec->push_back({n.u, n.v, sign * n.w});
  return {sign * sum[0], gaps[0]};
}

/// One face's area, its error bound and the nodes that integrate it (their weights carry the
/// loops' orientation), and whether the integration converged. The bound: the sum over the
/// accepted intervals along the loops of |Q16 − Q10| (the coarser rule's error; the area is the
/// finer's) plus three times the outer rule applied to the inner integrals' own bounds e (each
/// the same sum along u) times |v'|: the gap is measured on the inexact G̃, so
/// |Q16[G] − Q10[G]| ≤ gap + Q16[e] + Q10[e], and |Q16[G̃] − ∫G| ≤ Q16[e] + |Q16[G] − ∫G|
/// (Q10[e] taken as Q16[e]: both rules integrate the same smooth bound).
struct FaceArea {
  double area = 0, bound = 0;
  std::vector<Node> nodes;
  Budget budget;
};

FaceArea face_area(const Model& m, const Face& face, double tol) {
  FaceArea out;
  out.budget.intervals = detail::face_budget(face.surface);
  const surface::BSplineSurface& s = face.surface;
  const double u0 = s.u.domain().first, u1 = s.u.domain().second;
  const double v0 = s.v.domain().first, v1 = s.v.domain().second;
  const double tol_inner = tol / std::max(v1 - v0, 1e-300);
  // (G v', bound of G |v'|): the second entry is integrated alongside, never refined on.
  const Eigen::Vector2d tols(tol, std::numeric_limits<double>::infinity());
  if (face.loops.empty()) {
    // The whole domain: along its right side (the left one has F = 0, the others dv = 0).
    const auto spans = breaks(s.v, v0, v1);
    for (std::size_t k = 0; k + 1 < spans.size(); ++k) {
      Eigen::Vector2d gaps = Eigen::Vector2d::Zero();
      const Eigen::Vector2d along = detail::adaptive_vector(
          spans[k], spans[k + 1],
          [&](double v, std::vector<Node>* rec) {
            const auto [g, e] = inner(s, u0, u1, v, tol_inner, out.budget, rec);
            return Eigen::Vector2d(g, e);
          },
          tols, out.budget, out.nodes, &gaps);
      out.area += along[0];
      out.bound += gaps[0] + 3 * std::abs(along[1]);
    }
    return out;
  }
  for (const Loop& loop : face.loops)
    for (const Coedge& co : loop.coedges) {
      const Edge& e = m.edges[static_cast<std::size_t>(co.edge)];
      const double d0 = co.pcurve.basis.domain().first, d1 = co.pcurve.basis.domain().second;
      auto integrand = [&](double t, std::vector<Node>* rec) -> Eigen::Vector2d {
        const surface::CurveDerivatives q =
            surface::derivatives(co.pcurve, std::clamp(t, d0, d1), 1);
        if (q.d1.y() == 0.0) return Eigen::Vector2d::Zero();
        const std::size_t first = rec ? rec->size() : 0;
        const auto [g, bound] = inner(s, u0, q.point.x(), q.point.y(), tol_inner, out.budget, rec);
        if (rec)
          for (std::size_t k = first; k < rec->size(); ++k) (*rec)[k].w *= q.d1.y();
        return Eigen::Vector2d(g * q.d1.y(), bound * std::abs(q.d1.y()));
      };
      const auto pieces =
          detail::with_knot_crossings(co.pcurve, breaks(co.pcurve.basis, e.t0, e.t1), s.v, d0, d1);
      const std::size_t first = out.nodes.size();
      Eigen::Vector2d along = Eigen::Vector2d::Zero(), gaps = Eigen::Vector2d::Zero();
      for (std::size_t k = 0; k + 1 < pieces.size(); ++k)
        along += detail::adaptive_vector(pieces[k], pieces[k + 1], integrand, tols, out.budget,
                                         out.nodes, &gaps);
      out.area += co.same_sense ? along[0] : -along[0];
      out.bound += gaps[0] + 3 * std::abs(along[1]);
      if (!co.same_sense)
        for (std::size_t k = first; k < out.nodes.size(); ++k) out.nodes[k].w = -out.nodes[k].w;
    }
  return out;
}

/// The faces a call measures: those of `body`, or of every body when body < 0 (each once),
/// checked.
std::vector<bool> measured_faces(const Model& model, int body, const char* function, bool check) {
  const std::string name = function;
  if (body < -1 || body >= static_cast<int>(model.bodies.size()))
    throw Error(ErrorCategory::InvalidArgument,
                name + ": body " + std::to_string(body) + " does not exist; the model has " +
                    std::to_string(model.bodies.size()) + " bodies");
  if (check) validate(model);
  if (model.is_assembly())
    throw Error(ErrorCategory::InvalidArgument,
                name +
                    ": the model is an assembly; measure brep::flattened(model), whose bodies "
                    "are its placed instances");
  std::vector<bool> out(model.faces.size(), false);
  bool any = false;
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
    if (body < 0 || static_cast<int>(b) == body)
      for (const Shell& shell : model.bodies[b].shells)
        for (int f : shell.faces) any = out[static_cast<std::size_t>(f)] = true;
  if (!any)
    throw Error(ErrorCategory::InvalidArgument,
                name + ": " +
                    (body < 0 ? std::string("no body of the model has a face")
                              : "body " + std::to_string(body) + " has no face (a wire body)") +
                    ": the area is that of faces; measure a solid, shell or sheet");
  return out;
}

SurfaceAreaGradient measure_area(const Model& m, const std::vector<bool>& measured,
                                 bool gradients) {
  // 1e-14 of the size squared, as the volume's 1e-14 of its cube: the bound comes out near it.
  const double tol = 1e-14 * std::pow(detail::size_cubed(m), 2.0 / 3.0);
  std::vector<FaceArea> face(m.faces.size());
  const std::size_t parts = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1,
                                                    std::max<std::size_t>(1, m.faces.size()));
  SurfaceAreaGradient out;
  out.area.faces.resize(m.faces.size());
  out.area.vertices = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(m.vertices.size()), 3);
  run_on_threads(parts, [&](std::size_t part) {
    for (std::size_t f = part; f < m.faces.size(); f += parts) {
      const surface::BSplineSurface& s = m.faces[f].surface;
      if (!measured[f]) {
        out.area.faces[f] = Eigen::MatrixX3d::Zero(0, 3);
        continue;
      }
      face[f] = face_area(m, m.faces[f], tol);
      if (!gradients || !face[f].budget.converged) continue;
      // A = ∬ |X_u × X_v|: P_k -> P_k + e moves it by ∬ ν·(R_k,u e × X_v + X_u × R_k,v e)
      // = ∬ R_k,u e·(X_v × ν) + R_k,v e·(ν × X_u), ν = n / |n| (zero where n vanishes).
      using Block = Eigen::Matrix<double, 1, 3>;
      out.area.faces[f] = detail::control_point_gradients<1>(
          s, face[f].nodes,
          [](const detail::Isocurve::Point& at, double w, Block& a, Block& b, Block& c) {
            const Eigen::Vector3d n = at.du.cross(at.dv);
            const double length = n.norm();
            const Eigen::Vector3d nu =
                length > 0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
            a.setZero();
            b = w * at.dv.cross(nu).transpose();
            c = w * nu.cross(at.du).transpose();
          })[0];
    }
  });
  std::string failed;
  int count = 0;
  out.value.faces_mm2.assign(m.faces.size(), 0.0);
  for (std::size_t f = 0; f < face.size(); ++f) {
    if (!measured[f]) continue;
    if (!face[f].budget.converged && ++count <= 5)
      failed += (failed.empty() ? "" : ", ") + std::to_string(f);
    out.value.faces_mm2[f] = face[f].area;
    out.value.area_mm2 += face[f].area;
    out.value.bound_mm2 += face[f].bound;
  }
  if (count > 0)
    throw Error(ErrorCategory::ToleranceNotMet,
                "surface_area: the integration did not converge on " + std::to_string(count) +
                    " face(s) (" + failed + (count > 5 ? ", ..." : "") +
                    ") within its budget of quadrature intervals: a surface with extreme "
                    "weights or a near-singular parametrization; rebuild those faces with "
                    "moderate weights");
  // The rounding of the sum itself, so the bound holds for the total too.
  out.value.bound_mm2 += 4 * std::numeric_limits<double>::epsilon() *
                         static_cast<double>(face.size()) * std::abs(out.value.area_mm2);
  return out;
}

}  // namespace

SurfaceArea surface_area(const Model& model) {
  return measure_area(model, measured_faces(model, -1, "surface_area", true), false).value;
}

SurfaceArea surface_area(const Model& model, int body) {
  if (body < 0)
    throw Error(ErrorCategory::InvalidArgument,
                "surface_area: body " + std::to_string(body) + " does not exist (negative)");
  return measure_area(model, measured_faces(model, body, "surface_area", true), false).value;
}

SurfaceAreaGradient surface_area_gradient(const Model& model, const MassPropertyOptions& options) {
  if (options.body && *options.body < 0)
    throw Error(ErrorCategory::InvalidArgument, "surface_area_gradient: body " +
                                                    std::to_string(*options.body) +
                                                    " does not exist (negative)");
  return measure_area(
      model,
      measured_faces(model, options.body.value_or(-1), "surface_area_gradient", options.validate),
      true);
}

}  // namespace clay::brep
