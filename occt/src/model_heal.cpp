// Healing steps of the model reader on the model alone (model_heal.hpp).
#include "model_heal.hpp"

#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <algorithm>
#include <cmath>

#include "model_convert.hpp"

#include <Geom2dAPI_Interpolate.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_HArray1OfPnt2d.hxx>
#include <gp_Pnt2d.hxx>

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

int outer_loops_first(Model& model) {
  int changed = 0;
  for (std::size_t f = 0; f < model.faces.size(); ++f) {
    Face& face = model.faces[f];
    if (face.loops.size() < 2) continue;
    std::vector<double> area(face.loops.size());
    try {
      for (std::size_t l = 0; l < face.loops.size(); ++l)
        area[l] = loop_area(model, static_cast<int>(f), static_cast<int>(l));
    } catch (const Error&) {
      continue;  // problems() names it
    }
    if (!(area[0] < 0)) continue;
    const auto counter_clockwise =
        std::count_if(area.begin(), area.end(), [](double a) { return a > 0; });
    if (counter_clockwise != 1) continue;
    const auto outer = std::find_if(area.begin(), area.end(), [](double a) { return a > 0; });
    const auto k = static_cast<std::ptrdiff_t>(outer - area.begin());
    std::rotate(face.loops.begin(), face.loops.begin() + k, face.loops.begin() + k + 1);
    ++changed;
  }
  return changed;
}

std::optional<std::pair<surface::BSplineCurve, double>> pcurve_from_edge(
    const surface::BSplineSurface& surface, const Edge& edge, const surface::BSplineCurve& old,
    double accepted, double fit_tol) {
  std::vector<double> breaks{edge.t0};
  for (double k : edge.curve.basis.knots)
    if (k - breaks.back() > 1e-9 * (edge.t1 - edge.t0) && edge.t1 - k > 1e-9 * (edge.t1 - edge.t0))
      breaks.push_back(k);
  breaks.push_back(edge.t1);
  bool off_face = false;
  // Plain copies: Clang 14 refuses structured bindings captured by lambdas.
  const double u0 = surface.u.domain().first, u1 = surface.u.domain().second;
  const double v0 = surface.v.domain().first, v1 = surface.v.domain().second;
  const surface::SurfaceProjector projector(surface);  // validated once, not per point
  auto projection = [&](double t) {
    const Eigen::Vector3d point = surface::evaluate(edge.curve, t);
    const Eigen::Vector3d start = surface::evaluate(old, t);
    // Pcurves reach rounding outside the domain (v = -1e-20 on the I-DEAS cone).
    auto p = projector.project_normal(point, std::clamp(start.x(), u0, u1),
                                      std::clamp(start.y(), v0, v1));
    // Newton from a pcurve 0.1 rad off near a sphere's pole (where S_u nearly vanishes) stops
    // short: the closest point over the whole face then.
    if (!(p.distance <= accepted)) p = projector.closest_point(point);
    off_face = off_face || !(p.distance <= accepted);
    return p;
  };
  auto foot = [&](double t) {
    const surface::SurfaceProjection p = projection(t);
    return gp_Pnt2d(p.u, p.v);
  };
  std::vector<Handle(Geom2d_BSplineCurve)> pieces;
  double worst = 0;
  try {
    // Breaks also where the foot crosses a knot line of the surface (span_changes).
    const auto crossings = span_changes(
        [&](double t) {
          const gp_Pnt2d uv = foot(t);
          const auto& ku = surface.u.knots;
          const auto& kv = surface.v.knots;
          return std::pair<long, long>(std::upper_bound(ku.begin(), ku.end(), uv.X()) - ku.begin(),
                                       std::upper_bound(kv.begin(), kv.end(), uv.Y()) - kv.begin());
        },
        edge.t0, edge.t1);
    breaks.insert(breaks.end() - 1, crossings.begin(), crossings.end());
    std::sort(breaks.begin(), breaks.end());
    breaks.erase(
        std::unique(breaks.begin(), breaks.end(),
                    [&](double x, double y) { return y - x <= 1e-9 * (edge.t1 - edge.t0); }),
        breaks.end());
    breaks.back() = edge.t1;
    // Each piece is interpolated with 8 to 64 samples; a piece that still misses fit_tol is
    // halved. Where the edge passes near a pole of its face (Alibre's meridian circle, 0.024 mm
    // from a sphere's axis, turns u by pi within 1e-3 of its parameter) only the pieces there
    // are refined: uniform sampling would need 1e5 samples per piece.
    std::vector<std::pair<double, double>> todo;  // a stack, the next piece at the back
    for (std::size_t k = breaks.size() - 1; k > 0; --k) todo.emplace_back(breaks[k - 1], breaks[k]);
    const double shortest_piece = 1e-9 * (edge.t1 - edge.t0);
    while (!todo.empty()) {
      const auto [a, b] = todo.back();
      todo.pop_back();
      Handle(Geom2d_BSplineCurve) piece;
      double error = 0;
      bool met = false;
      for (int samples = 8; samples <= 64 && !met; samples *= 2) {
        if (off_face) return std::nullopt;
        Handle(TColgp_HArray1OfPnt2d) points = new TColgp_HArray1OfPnt2d(1, samples + 1);
        Handle(TColStd_HArray1OfReal) parameters = new TColStd_HArray1OfReal(1, samples + 1);
        for (int i = 0; i <= samples; ++i) {
          const double t = i == samples ? b : a + (b - a) * i / samples;
          points->SetValue(i + 1, foot(t));
          parameters->SetValue(i + 1, t);
        }
        Geom2dAPI_Interpolate interpolate(points, parameters, false, 1e-15);
        interpolate.Perform();
        if (!interpolate.IsDone()) continue;
        piece = interpolate.Curve();
        // The feet lie in the domain, but a cubic through them can overshoot it between them
        // (Onshape's pcurve along v = 0 came out at v = -3.2e-9): its poles are clamped into
        // the domain, so the curve is inside (convex hull), and the fit is measured after.
        for (int i = 1; i <= piece->NbPoles(); ++i) {
          const gp_Pnt2d pole = piece->Pole(i);
          piece->SetPole(i, gp_Pnt2d(std::clamp(pole.X(), u0, u1), std::clamp(pole.Y(), v0, v1)));
        }
        // The fit against the projection (an edge 1.6e-6 mm off its face, within its
        // tolerance, can never come within fit_tol of it), the gap against the edge.
        error = 0;
        double fit_error = 0;
        for (int i = 0; i <= 4 * samples; ++i) {
          const double t = a + (b - a) * i / (4 * samples);
          const gp_Pnt2d uv = piece->Value(t);  // within rounding of the domain
          const Eigen::Vector3d on_face =
              surface::evaluate(surface, std::clamp(uv.X(), u0, u1), std::clamp(uv.Y(), v0, v1));
          error = std::max(error, (on_face - surface::evaluate(edge.curve, t)).norm());
          fit_error = std::max(fit_error, (on_face - projection(t).point).norm());
        }
        met = fit_error <= fit_tol;
      }
      if (off_face) return std::nullopt;
      if (!met) {
        if (b - a < 2 * shortest_piece || pieces.size() + todo.size() >= 4096) return std::nullopt;
        const double m = 0.5 * (a + b);
        todo.emplace_back(m, b);
        todo.emplace_back(a, m);
        continue;
      }
      worst = std::max(worst, error);
      pieces.push_back(piece);
    }
  } catch (const Error&) {
    return std::nullopt;  // a projection outside the domain: left for problems() to name
  }
  return std::pair{joined(pieces), worst};
}

}  // namespace clay::brep::detail
