// Healing steps of the model reader on the model alone (model_heal.hpp).
#include "model_heal.hpp"

#include <clay/internal/format.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>

namespace clay::brep::detail {

namespace {

/// The parameters problems() samples a coedge at, over the part of [t0, t1] in the pcurve's
/// domain: both ends, each breakpoint, and 8 points in each span.
std::vector<double> pcurve_samples(const Edge& e, const surface::BSplineCurve& pcurve) {
  const auto [a, b] = pcurve.basis.domain();
  const double t0 = std::clamp(std::min(e.t0, e.t1), a, b);
  const double t1 = std::clamp(std::max(e.t0, e.t1), a, b);
  std::vector<double> breaks{t0};
  for (const double k : pcurve.basis.knots)
    if (k > t0 && k < t1 && k > breaks.back()) breaks.push_back(k);
  breaks.push_back(t1);
  std::vector<double> ts;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k)
    for (int s = 0; s < 8; ++s) ts.push_back(breaks[k] + (breaks[k + 1] - breaks[k]) * s / 8);
  ts.push_back(t1);
  return ts;
}

}  // namespace

PulledPcurves pull_pcurves_into_domains(Model& model) {
  PulledPcurves out;
  for (Face& face : model.faces) {
    // Plain copies: Clang 14 refuses structured bindings captured by lambdas.
    const double u0 = face.surface.u.domain().first, u1 = face.surface.u.domain().second;
    const double v0 = face.surface.v.domain().first, v1 = face.surface.v.domain().second;
    const double du = u1 - u0, dv = v1 - v0;
    const double slack = 1e-9 * std::max(du, dv);  // problems()'s rounding slack
    // How far outside the domain (u, v) is, as fractions of the widths (0 inside).
    auto outside = [&](double u, double v) {
      const double ou = std::max({u0 - u, u - u1, 0.0}) / du;
      const double ov = std::max({v0 - v, v - v1, 0.0}) / dv;
      return std::max(ou, ov);
    };
    for (Loop& loop : face.loops)
      for (Coedge& coedge : loop.coedges) {
        if (coedge.edge < 0 || static_cast<std::size_t>(coedge.edge) >= model.edges.size())
          continue;  // problems() names it
        const Edge& edge = model.edges[static_cast<std::size_t>(coedge.edge)];
        surface::BSplineCurve& pcurve = coedge.pcurve;
        if (pcurve.points.rows() == 0 || pcurve.basis.knots.empty()) continue;
        bool leaves = false;
        for (const double t : pcurve_samples(edge, pcurve)) {
          const Eigen::Vector3d p = surface::evaluate(pcurve, t);
          if (p.x() < u0 - slack || p.x() > u1 + slack || p.y() < v0 - slack ||
              p.y() > v1 + slack) {
            leaves = true;
            break;
          }
        }
        if (!leaves) continue;
        double farthest = 0;
        for (Eigen::Index r = 0; r < pcurve.points.rows(); ++r)
          farthest = std::max(farthest, outside(pcurve.points(r, 0), pcurve.points(r, 1)));
        if (!(farthest <= pull_in_relative)) continue;
        for (Eigen::Index r = 0; r < pcurve.points.rows(); ++r) {
          pcurve.points(r, 0) = std::clamp(pcurve.points(r, 0), u0, u1);
          pcurve.points(r, 1) = std::clamp(pcurve.points(r, 1), v0, v1);
        }
        ++out.count;
        out.farthest = std::max(out.farthest, farthest);
      }
  }
  return out;
}

std::string describe(const PulledPcurves& pulled) {
  if (pulled.count == 0) return {};
  return "pulled " + std::to_string(pulled.count) + (pulled.count == 1 ? " pcurve" : " pcurves") +
         " into their surfaces' domains (control points up to " +
         internal::shortest(pulled.farthest) + " of the domain's width outside)";
}

}  // namespace clay::brep::detail
