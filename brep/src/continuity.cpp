// How the faces of a model meet along their shared edges (continuity.hpp).
#include <clay/brep/continuity.hpp>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/evaluate.hpp>

#include "sampling.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace clay::brep {

namespace {

/// One use of an edge: face, loop and coedge.
struct Use {
  int face = -1, loop = -1, coedge = -1;
};

/// A face at one sample of an edge: its point, outward unit normal, and normal curvature across
/// the edge (NaN where the face is singular or the edge's tangent vanishes there).
struct Side {
  Eigen::Vector3d point, normal;
  bool has_normal = false;
  double curvature = std::numeric_limits<double>::quiet_NaN();
};

Side side_at(const Face& face, const Coedge& co, double t) {
  Side s;
  const Eigen::Vector2d uv = detail::uv_at(face.surface, co.pcurve, t);
  const surface::SurfaceDerivatives d = surface::derivatives(face.surface, uv.x(), uv.y(), 2);
  s.point = d.point;
  const Eigen::Vector3d cross = d.du.cross(d.dv);
  const double scale = d.du.norm() * d.dv.norm();
  if (!(cross.norm() > 1e-12 * scale)) return s;  // a pole or a collapsed side: no tangent plane
  s.normal = (face.reversed ? -1.0 : 1.0) * cross.normalized();
  s.has_normal = true;
  // The edge's tangent from the face's own derivatives (chain rule through the pcurve).
  const Eigen::Vector3d dp = surface::derivatives(co.pcurve, detail::within(co.pcurve, t), 1).d1;
  const Eigen::Vector3d tangent = d.du * dp.x() + d.dv * dp.y();
  if (!(tangent.norm() > 1e-12 * std::sqrt(scale))) return s;
  // w across the edge, in the tangent plane; (a, b) its (u, v) components (first fundamental
  // form), then the normal curvature II(w) / I(w) (do Carmo §3-2).
  const Eigen::Vector3d w = s.normal.cross(tangent.normalized());
  const double E = d.du.dot(d.du), F = d.du.dot(d.dv), G = d.dv.dot(d.dv);
  const double det = E * G - F * F;
  const double a = (G * w.dot(d.du) - F * w.dot(d.dv)) / det;
  const double b = (E * w.dot(d.dv) - F * w.dot(d.du)) / det;
  const double L = d.duu.dot(s.normal), M = d.duv.dot(s.normal), N = d.dvv.dot(s.normal);
  const double first = E * a * a + 2 * F * a * b + G * b * b;
  s.curvature = (L * a * a + 2 * M * a * b + N * b * b) / first;
  return s;
}

const Coedge& coedge_of(const Model& m, const Use& u) {
  return m.faces[static_cast<size_t>(u.face)]
      .loops[static_cast<size_t>(u.loop)]
      .coedges[static_cast<size_t>(u.coedge)];
}

EdgeContinuity measure(const Model& m, int edge, const Use& ua, const Use& ub,
                       const ContinuityOptions& o) {
  const Edge& e = m.edges[static_cast<size_t>(edge)];
  const Coedge& ca = coedge_of(m, ua);
  const Coedge& cb = coedge_of(m, ub);
  std::vector<double> ts = detail::coedge_samples(e, ca, o.samples_per_span);
  for (double t : detail::coedge_samples(e, cb, o.samples_per_span)) ts.push_back(t);
  std::sort(ts.begin(), ts.end());
  ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
  EdgeContinuity r;
  r.edge = edge;
  r.face_a = ua.face;
  r.face_b = ub.face;
  r.samples = static_cast<int>(ts.size());
  r.t_gap = r.t_angle = r.t_curvature = e.t0;
  const Face& fa = m.faces[static_cast<size_t>(ua.face)];
  const Face& fb = m.faces[static_cast<size_t>(ub.face)];
  for (double t : ts) {
    const Side a = side_at(fa, ca, t), b = side_at(fb, cb, t);
    const double gap = (a.point - b.point).norm();
    if (gap > r.gap_mm || std::isnan(gap)) {
      r.gap_mm = gap;
      r.t_gap = t;
    }
    if (a.has_normal && b.has_normal) {
      // atan2 of |a x b| and a.b: accurate near 0 and 180 degrees, where acos is not
      const double angle = std::atan2(a.normal.cross(b.normal).norm(), a.normal.dot(b.normal)) *
                           180 / std::numbers::pi;
      if (angle > r.angle_deg) {
        r.angle_deg = angle;
        r.t_angle = t;
      }
    }
    if (!std::isnan(a.curvature) && !std::isnan(b.curvature)) {
      const double jump = std::abs(a.curvature - b.curvature);
      const double relative =
          jump / std::max({std::abs(a.curvature), std::abs(b.curvature), o.curvature_floor});
      if (relative > r.relative_curvature_jump) {
        r.relative_curvature_jump = relative;
        r.t_curvature = t;
      }
      r.curvature_jump = std::max(r.curvature_jump, jump);
    }
  }
  return r;
}

}  // namespace

std::vector<std::string> ContinuityOptions::problems() const {
  std::vector<std::string> out;
  if (samples_per_span < 1 || samples_per_span > 4096)
    out.push_back("ContinuityOptions::samples_per_span = " + std::to_string(samples_per_span) +
                  " must be in [1, 4096] (16 by default)");
  if (!(std::isfinite(curvature_floor) && curvature_floor > 0))
    out.push_back("ContinuityOptions::curvature_floor = " + internal::shortest(curvature_floor) +
                  " must be finite and > 0 (1/mm; 1e-6 by default: a radius of 1 km)");
  return out;
}

void ContinuityOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::string ContinuityReport::brief() const {
  char line[256];
  std::snprintf(line, sizeof line,
                "%zu shared edge%s: gap <= %.2g mm, angle <= %.3g deg, relative curvature jump "
                "<= %.3g (%d boundary, %d degenerate edge%s)",
                edges.size(), edges.size() == 1 ? "" : "s", max_gap_mm, max_angle_deg,
                max_relative_curvature_jump, boundary_edges, degenerate_edges,
                degenerate_edges == 1 ? "" : "s");
  return non_manifold_edges == 0
             ? std::string(line)
             : line + ("; " + std::to_string(non_manifold_edges) + " non-manifold, not measured");
}

ContinuityReport edge_continuity(const Model& model, const ContinuityOptions& options) {
  options.validate();
  // What sampling needs (indices in range; surfaces, curves and pcurves valid) is what edge_gaps
  // checks and throws for: one sample per span is enough for that.
  edge_gaps(model, 1);
  std::vector<std::vector<Use>> uses(model.edges.size());
  for (size_t f = 0; f < model.faces.size(); ++f)
    for (size_t l = 0; l < model.faces[f].loops.size(); ++l)
      for (size_t c = 0; c < model.faces[f].loops[l].coedges.size(); ++c)
        uses[static_cast<size_t>(model.faces[f].loops[l].coedges[c].edge)].push_back(
            {static_cast<int>(f), static_cast<int>(l), static_cast<int>(c)});
  ContinuityReport report;
  for (size_t e = 0; e < uses.size(); ++e) {
    if (model.edges[e].degenerate) {
      report.degenerate_edges += !uses[e].empty();
      continue;
    }
    if (uses[e].size() > 2) {  // which two faces meet there is not defined
      ++report.non_manifold_edges;
      continue;
    }
    if (uses[e].size() < 2) {
      report.boundary_edges += uses[e].size() == 1;
      continue;
    }
    const EdgeContinuity c = measure(model, static_cast<int>(e), uses[e][0], uses[e][1], options);
    report.max_gap_mm = std::max(report.max_gap_mm, c.gap_mm);
    report.max_angle_deg = std::max(report.max_angle_deg, c.angle_deg);
    report.max_relative_curvature_jump =
        std::max(report.max_relative_curvature_jump, c.relative_curvature_jump);
    report.edges.push_back(c);
  }
  return report;
}

}  // namespace clay::brep
