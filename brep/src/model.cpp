// The B-rep model's counts, edge gaps and invariants (clay/brep/model.hpp).
#include <clay/brep/model.hpp>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <utility>

#include <vector>
#include "sampling.hpp"

namespace clay::brep {

namespace {

using internal::shortest;

std::string face_name(const Model& m, int f) {
  const std::string& name = m.faces[static_cast<size_t>(f)].name;
  return "face " + std::to_string(f) + (name.empty() ? "" : " (\"" + name + "\")");
}

std::string coedge_name(const Model& m, int f, int l, int c) {
  return face_name(m, f) + " loop " + std::to_string(l) + " coedge " + std::to_string(c);
}

bool in_range(int index, size_t size) { return index >= 0 && static_cast<size_t>(index) < size; }

/// Slack for parameter comparisons: rounding of knot values, relative to the range.
double parameter_slack(double a, double b) {
  return 1e-12 * std::max({1.0, std::abs(a), std::abs(b)});
}

using detail::coedge_samples;
using detail::uv_at;
using detail::within;

/// Largest |surface(pcurve(t)) - edge(t)| over the samples. Preconditions: indices and curves
/// valid, the edge range inside both curves' domains.
EdgeGap gap_of(const Model& m, int f, int l, int c, int per_span) {
  const Face& face = m.faces[static_cast<size_t>(f)];
  const Coedge& co = face.loops[static_cast<size_t>(l)].coedges[static_cast<size_t>(c)];
  const Edge& e = m.edges[static_cast<size_t>(co.edge)];
  EdgeGap g{f, l, c, co.edge, e.t0, 0.0};
  auto distance = [&](double t) {
    const Eigen::Vector2d uv = uv_at(face.surface, co.pcurve, t);
    const Eigen::Vector3d on_face = surface::evaluate(face.surface, uv.x(), uv.y());
    const Eigen::Vector3d on_edge = e.degenerate ? m.vertices[static_cast<size_t>(e.start)].point
                                                 : surface::evaluate(e.curve, within(e.curve, t));
    return (on_face - on_edge).norm();
  };
  const std::vector<double> ts = coedge_samples(e, co, per_span);
  std::vector<double> d(ts.size());
  for (size_t k = 0; k < ts.size(); ++k) {
    d[k] = distance(ts[k]);
    if (d[k] > g.gap_mm || std::isnan(d[k])) {
      g.gap_mm = d[k];
      g.t = ts[k];
    }
  }
  if (std::isnan(g.gap_mm)) return g;
  // The samples miss the peak between them: OpenCASCADE's BRepCheck maximizes the distance and
  // found NX 9's deformed edge 0.2 % farther than 16 samples per span said, past a tolerance set
  // to the sampled gap. Each local maximum within half the largest is refined by golden section
  // between its neighbours (a peak narrower than the spacing, far below the others, is not).
  const double sampled = g.gap_mm;
  for (size_t k = 1; k + 1 < ts.size(); ++k) {
    if (!(d[k] >= d[k - 1] && d[k] >= d[k + 1] && d[k] >= 0.5 * sampled && d[k] > 0)) continue;
    constexpr double ratio = 0.6180339887498949;
    double a = ts[k - 1], b = ts[k + 1];
    double x1 = b - ratio * (b - a), x2 = a + ratio * (b - a);
    double f1 = distance(x1), f2 = distance(x2);
    for (int it = 0; it < 60 && b - a > 1e-13 * std::max({1.0, std::abs(a), std::abs(b)}); ++it) {
      if (f1 >= f2) {
        b = x2, x2 = x1, f2 = f1;
        x1 = b - ratio * (b - a), f1 = distance(x1);
      } else {
        a = x1, x1 = x2, f1 = f2;
        x2 = a + ratio * (b - a), f2 = distance(x2);
      }
    }
    const double best_t = f1 >= f2 ? x1 : x2, best = std::max(f1, f2);
    if (best > g.gap_mm) {
      g.gap_mm = best;
      g.t = best_t;
    }
  }
  return g;
}

/// Problems of one coedge's own data; empty when edge_gaps may measure it.
std::vector<std::string> coedge_problems(const Model& m, int f, int l, int c) {
  std::vector<std::string> out;
  const Face& face = m.faces[static_cast<size_t>(f)];
  const Coedge& co = face.loops[static_cast<size_t>(l)].coedges[static_cast<size_t>(c)];
  const std::string name = coedge_name(m, f, l, c);
  if (!in_range(co.edge, m.edges.size())) {
    out.push_back(name + ": edge index " + std::to_string(co.edge) + " is not one of the " +
                  std::to_string(m.edges.size()) + " edges");
    return out;
  }
  const auto pcurve = surface::problems(co.pcurve, name + "'s pcurve");
  if (!pcurve.empty()) {
    internal::append(out, pcurve);
    return out;
  }
  if ((co.pcurve.points.col(2).array() != 0.0).any())
    out.push_back(name +
                  ": the pcurve leaves the plane z = 0; give its control points as (u, v, 0)");
  const Edge& e = m.edges[static_cast<size_t>(co.edge)];
  const auto [a, b] = co.pcurve.basis.domain();
  const double slack = parameter_slack(e.t0, e.t1);
  if (e.t0 < a - slack || e.t1 > b + slack)
    out.push_back(name + ": the edge range [" + shortest(e.t0) + ", " + shortest(e.t1) +
                  "] of edge " + std::to_string(co.edge) + " is not inside the pcurve's domain [" +
                  shortest(a) + ", " + shortest(b) +
                  "]; a pcurve is parametrized like its edge (same parameter)");
  return out;
}

/// Signed area in (u, v) of the polygon through the loop's samples, in loop order.
double signed_area(const Model& m, const Loop& loop) {
  std::vector<Eigen::Vector2d> poly;
  for (const Coedge& co : loop.coedges) {
    const Edge& e = m.edges[static_cast<size_t>(co.edge)];
    std::vector<double> ts = coedge_samples(e, co, 8);
    if (!co.same_sense) std::reverse(ts.begin(), ts.end());
    for (double t : ts) {
      const Eigen::Vector3d p = surface::evaluate(co.pcurve, within(co.pcurve, t));
      poly.emplace_back(p.x(), p.y());
    }
  }
  double twice = 0;
  for (size_t k = 0; k < poly.size(); ++k) {
    const Eigen::Vector2d& p = poly[k];
    const Eigen::Vector2d& q = poly[(k + 1) % poly.size()];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return twice / 2;
}

/// The vertex a coedge starts (or ends) at, in loop order.
int first_vertex(const Edge& e, const Coedge& c) { return c.same_sense ? e.start : e.end; }
int last_vertex(const Edge& e, const Coedge& c) { return c.same_sense ? e.end : e.start; }

bool colour_ok(const std::optional<Colour>& c) {
  if (!c) return true;
  for (double x : {c->r, c->g, c->b})
    if (!(x >= 0 && x <= 1)) return false;
  return true;
}

std::string colour_text(const Colour& c) {
  return "(" + shortest(c.r) + ", " + shortest(c.g) + ", " + shortest(c.b) + ")";
}

void vertex_and_edge_problems(const Model& m, std::vector<std::string>& out) {
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const Vertex& v = m.vertices[i];
    if (!internal::all_finite(v.point))
      out.push_back("vertex " + std::to_string(i) + ": its point has a non-finite coordinate");
    if (!(std::isfinite(v.tolerance_mm) && v.tolerance_mm >= 0))
      out.push_back("vertex " + std::to_string(i) + ": tolerance_mm = " + shortest(v.tolerance_mm) +
                    " must be finite and >= 0");
  }
  for (size_t i = 0; i < m.edges.size(); ++i) {
    const Edge& e = m.edges[i];
    const std::string name = "edge " + std::to_string(i);
    if (!(std::isfinite(e.tolerance_mm) && e.tolerance_mm >= 0))
      out.push_back(name + ": tolerance_mm = " + shortest(e.tolerance_mm) +
                    " must be finite and >= 0");
    const bool ends_ok = in_range(e.start, m.vertices.size()) && in_range(e.end, m.vertices.size());
    if (!ends_ok)
      out.push_back(name + ": vertex indices (" + std::to_string(e.start) + ", " +
                    std::to_string(e.end) + ") are not both among the " +
                    std::to_string(m.vertices.size()) + " vertices");
    if (!(std::isfinite(e.t0) && std::isfinite(e.t1) && e.t0 < e.t1))
      out.push_back(name + ": its range [" + shortest(e.t0) + ", " + shortest(e.t1) +
                    "] must be finite with t0 < t1");
    if (e.degenerate) {
      if (e.start != e.end)
        out.push_back(name + ": a degenerate edge (a pole) starts and ends at one vertex, not at " +
                      std::to_string(e.start) + " and " + std::to_string(e.end));
      continue;
    }
    const auto curve = surface::problems(e.curve, name + "'s curve");
    if (!curve.empty()) {
      internal::append(out, curve);
      continue;
    }
    const auto [a, b] = e.curve.basis.domain();
    const double slack = parameter_slack(a, b);
    if (e.t0 < a - slack || e.t1 > b + slack) {
      out.push_back(name + ": its range [" + shortest(e.t0) + ", " + shortest(e.t1) +
                    "] is not inside its curve's domain [" + shortest(a) + ", " + shortest(b) +
                    "]");
      continue;
    }
    if (!ends_ok || !(e.t0 < e.t1)) continue;
    for (const auto& [t, vi, which] :
         {std::tuple{e.t0, e.start, "start"}, std::tuple{e.t1, e.end, "end"}}) {
      const Vertex& v = m.vertices[static_cast<size_t>(vi)];
      const double d = (surface::evaluate(e.curve, within(e.curve, t)) - v.point).norm();
      if (!(d <= e.tolerance_mm + v.tolerance_mm))
        out.push_back(name + ": its " + which + " is " + shortest(d) + " mm from vertex " +
                      std::to_string(vi) + ", more than the tolerances allow (" +
                      shortest(e.tolerance_mm) + " + " + shortest(v.tolerance_mm) + " mm)");
    }
  }
}

/// Whether a face's analytic surface is well formed and is the surface its NURBS represents:
/// every control net node's point of the NURBS (a 9 x 9 grid of its domain) lies on it, and for a
/// plane at the same (u, v), within 1e-9 of the face's size (or 1e-12 mm).
void elementary_problems(const Model& m, int f, std::vector<std::string>& out) {
  const Face& face = m.faces[static_cast<size_t>(f)];
  const Elementary& e = *face.elementary;
  const std::string name = face_name(m, f) + "'s " + std::string(to_string(e.kind));
  const size_t before = out.size();
  if (!internal::all_finite(e.origin) || !internal::all_finite(e.x_axis) ||
      !internal::all_finite(e.y_axis) || !internal::all_finite(e.z_axis))
    out.push_back(name + ": its frame has a non-finite coordinate");
  const Eigen::Matrix3d frame = (Eigen::Matrix3d() << e.x_axis, e.y_axis, e.z_axis).finished();
  if (!((frame.transpose() * frame - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-12))
    out.push_back(name + ": its axes are not orthonormal (give unit x, y, z at right angles)");
  const bool round = e.kind != ElementaryKind::Plane;
  if (round && !(std::isfinite(e.radius) && e.radius >= 0 &&
                 (e.radius > 0 || e.kind == ElementaryKind::Cone)))
    out.push_back(name + ": radius = " + shortest(e.radius) + " must be finite and " +
                  (e.kind == ElementaryKind::Cone ? ">= 0" : "> 0"));
  if (e.kind == ElementaryKind::Torus && !(std::isfinite(e.minor_radius) && e.minor_radius > 0))
    out.push_back(name + ": minor_radius = " + shortest(e.minor_radius) +
                  " must be finite and > 0");
  if (e.kind == ElementaryKind::Cone &&
      !(std::abs(e.semi_angle) < std::acos(0.0) && e.semi_angle != 0))
    out.push_back(name + ": semi_angle = " + shortest(e.semi_angle) +
                  " must be in (-pi/2, pi/2) and not 0");
  if (out.size() != before) return;
  const auto [u0, u1] = face.surface.u.domain();
  const auto [v0, v1] = face.surface.v.domain();
  Eigen::AlignedBox3d box;
  for (Eigen::Index r = 0; r < face.surface.points.rows(); ++r)
    box.extend(Eigen::Vector3d(face.surface.points.row(r).transpose()));
  const double tolerance = std::max(1e-12, 1e-9 * box.diagonal().norm());
  double worst = 0;
  constexpr int n = 8;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double u = std::min(u1, u0 + (u1 - u0) * i / n),
                   v = std::min(v1, v0 + (v1 - v0) * j / n);
      const Eigen::Vector3d p = surface::evaluate(face.surface, u, v);
      const double d =
          e.kind == ElementaryKind::Plane ? (p - point(e, u, v)).norm() : distance(e, p);
      worst = std::max(worst, std::isnan(d) ? INFINITY : d);
    }
  if (!(worst <= tolerance))
    out.push_back(name + ": the face's NURBS surface is " + shortest(worst) + " mm off it (" +
                  (e.kind == ElementaryKind::Plane ? "at the same (u, v), " : "") + "more than " +
                  shortest(tolerance) + " mm); drop `elementary` when the surface is changed");
}

/// Face, loop and coedge problems.
void face_problems(const Model& m, std::vector<std::string>& out) {
  for (size_t fi = 0; fi < m.faces.size(); ++fi) {
    const int f = static_cast<int>(fi);
    const Face& face = m.faces[fi];
    const auto surface = surface::problems(face.surface, face_name(m, f) + "'s surface");
    if (!surface.empty()) {
      internal::append(out, surface);
      continue;
    }
    if (!colour_ok(face.colour))
      out.push_back(face_name(m, f) + ": colour " + colour_text(*face.colour) +
                    " has a component outside [0, 1]");
    if (face.elementary) elementary_problems(m, f, out);
    const auto [u0, u1] = face.surface.u.domain();
    const auto [v0, v1] = face.surface.v.domain();
    const double uv_slack = 1e-9 * std::max(u1 - u0, v1 - v0);
    for (size_t li = 0; li < face.loops.size(); ++li) {
      const Loop& loop = face.loops[li];
      const int l = static_cast<int>(li);
      const std::string loop_name = face_name(m, f) + " loop " + std::to_string(l);
      if (loop.coedges.empty()) {
        out.push_back(loop_name + ": has no coedges");
        continue;
      }
      bool loop_ok = true;
      for (size_t ci = 0; ci < loop.coedges.size(); ++ci) {
        const int c = static_cast<int>(ci);
        const auto own = coedge_problems(m, f, l, c);
        if (!own.empty()) {
          internal::append(out, own);
          loop_ok = false;
          continue;
        }
        const Coedge& co = loop.coedges[ci];
        const Edge& e = m.edges[static_cast<size_t>(co.edge)];
        if (!e.degenerate && !surface::problems(e.curve).empty()) {
          loop_ok = false;  // reported with the edge
          continue;
        }
        if (!in_range(e.start, m.vertices.size()) || !in_range(e.end, m.vertices.size())) {
          loop_ok = false;
          continue;
        }
        // Inside the surface's domain, at the samples.
        for (double t : coedge_samples(e, co, 4)) {
          const Eigen::Vector3d p = surface::evaluate(co.pcurve, within(co.pcurve, t));
          if (p.x() < u0 - uv_slack || p.x() > u1 + uv_slack || p.y() < v0 - uv_slack ||
              p.y() > v1 + uv_slack) {
            out.push_back(coedge_name(m, f, l, c) + ": the pcurve leaves the surface's domain [" +
                          shortest(u0) + ", " + shortest(u1) + "] x [" + shortest(v0) + ", " +
                          shortest(v1) + "] at t = " + shortest(t) + " (u, v) = (" +
                          shortest(p.x()) + ", " + shortest(p.y()) + ")");
            break;
          }
        }
        const EdgeGap g = gap_of(m, f, l, c, 16);
        if (!(g.gap_mm <= e.tolerance_mm))
          out.push_back(coedge_name(m, f, l, c) + ": the face is " + shortest(g.gap_mm) +
                        " mm from edge " + std::to_string(co.edge) + " at t = " + shortest(g.t) +
                        ", more than the edge's tolerance " + shortest(e.tolerance_mm) + " mm");
      }
      if (!loop_ok) continue;
      // Closed: each coedge ends where the next one starts.
      for (size_t ci = 0; ci < loop.coedges.size(); ++ci) {
        const Coedge& a = loop.coedges[ci];
        const Coedge& b = loop.coedges[(ci + 1) % loop.coedges.size()];
        const int end = last_vertex(m.edges[static_cast<size_t>(a.edge)], a);
        const int start = first_vertex(m.edges[static_cast<size_t>(b.edge)], b);
        if (end != start)
          out.push_back(loop_name + " is open: coedge " + std::to_string(ci) + " ends at vertex " +
                        std::to_string(end) + " but coedge " +
                        std::to_string((ci + 1) % loop.coedges.size()) + " starts at vertex " +
                        std::to_string(start));
      }
      const double area = signed_area(m, loop);
      if (l == 0 && !(area > 0))
        out.push_back(loop_name + " (the outer loop) runs clockwise in (u, v) (signed area " +
                      shortest(area) +
                      "); the outer loop runs counter-clockwise, face on its left");
      if (l > 0 && !(area < 0))
        out.push_back(loop_name + " (a hole) runs counter-clockwise in (u, v) (signed area " +
                      shortest(area) + "); holes run clockwise, face on their left");
    }
  }
}

void shell_problems(const Model& m, std::vector<std::string>& out) {
  std::vector<int> shell_of_face(m.faces.size(), -1);
  std::vector<int> uses(m.edges.size(), 0);
  std::vector<int> wire_of_edge(m.edges.size(), -1);  // the wire body holding each edge
  int shell_index = 0;
  for (size_t bi = 0; bi < m.bodies.size(); ++bi) {
    const Body& body = m.bodies[bi];
    const std::string body_name =
        "body " + std::to_string(bi) + (body.name.empty() ? "" : " (\"" + body.name + "\")");
    if (!colour_ok(body.colour))
      out.push_back(body_name + ": colour " + colour_text(*body.colour) +
                    " has a component outside [0, 1]");
    if (body.kind == BodyKind::Wire) {
      if (!body.shells.empty())
        out.push_back(body_name + ": a wire body holds edges, not shells (it has " +
                      std::to_string(body.shells.size()) + "); make it a sheet or a shell");
      if (body.edges.empty()) out.push_back(body_name + ": a wire body has no edges");
      for (int e : body.edges) {
        if (!in_range(e, m.edges.size())) {
          out.push_back(body_name + ": edge index " + std::to_string(e) + " is not one of the " +
                        std::to_string(m.edges.size()) + " edges");
          continue;
        }
        if (m.edges[static_cast<size_t>(e)].degenerate)
          out.push_back(body_name + ": edge " + std::to_string(e) +
                        " is degenerate (a pole); a wire body's edges are curves");
        if (wire_of_edge[static_cast<size_t>(e)] >= 0)
          out.push_back(body_name + ": edge " + std::to_string(e) + " is already in body " +
                        std::to_string(wire_of_edge[static_cast<size_t>(e)]) +
                        "; an edge belongs to one wire body");
        else
          wire_of_edge[static_cast<size_t>(e)] = static_cast<int>(bi);
      }
      continue;
    }
    if (!body.edges.empty())
      out.push_back(body_name + ": a " + std::string(to_string(body.kind)) + " lists " +
                    std::to_string(body.edges.size()) +
                    " free edges; only a wire body holds edges (its faces hold theirs)");
    if (body.shells.empty()) out.push_back(body_name + ": has no shells");
    for (size_t si = 0; si < body.shells.size(); ++si, ++shell_index) {
      const Shell& shell = body.shells[si];
      const std::string shell_name = body_name + " shell " + std::to_string(si);
      if (shell.faces.empty()) out.push_back(shell_name + ": has no faces");
      // Each use of an edge in this shell: the face and its direction around the outward normal.
      std::map<int, std::vector<std::pair<int, bool>>> used;
      for (int f : shell.faces) {
        if (!in_range(f, m.faces.size())) {
          out.push_back(shell_name + ": face index " + std::to_string(f) + " is not one of the " +
                        std::to_string(m.faces.size()) + " faces");
          continue;
        }
        int& owner = shell_of_face[static_cast<size_t>(f)];
        if (owner >= 0)
          out.push_back(shell_name + ": " + face_name(m, f) + " is already in another shell");
        owner = shell_index;
        const Face& face = m.faces[static_cast<size_t>(f)];
        if (body.kind == BodyKind::Solid && face.loops.empty())
          out.push_back(shell_name + ": " + face_name(m, f) +
                        " has no loops; a solid's faces are bounded by edges it shares");
        for (const Loop& loop : face.loops)
          for (const Coedge& co : loop.coedges) {
            if (!in_range(co.edge, m.edges.size())) continue;  // reported with the face
            if (m.edges[static_cast<size_t>(co.edge)].degenerate) continue;
            used[co.edge].emplace_back(f, co.same_sense != face.reversed);
          }
      }
      for (const auto& [edge, list] : used) {
        if (list.size() > 2) {
          out.push_back(shell_name + ": edge " + std::to_string(edge) + " is used by " +
                        std::to_string(list.size()) +
                        " coedges; a shell is a manifold: at most two faces meet along an edge");
        } else if (list.size() == 2 && list[0].second == list[1].second) {
          out.push_back(shell_name + ": " + face_name(m, list[0].first) + " and " +
                        face_name(m, list[1].first) + " both run along edge " +
                        std::to_string(edge) +
                        " in the same direction: their orientations disagree (reverse one face)");
        } else if (list.size() == 1) {
          if (body.kind == BodyKind::Solid)
            out.push_back(shell_name + " does not close: edge " + std::to_string(edge) +
                          " is used by " + face_name(m, list[0].first) +
                          " only; a solid's shells are closed");
        }
      }
    }
  }
  for (size_t f = 0; f < m.faces.size(); ++f) {
    if (shell_of_face[f] < 0)
      out.push_back(face_name(m, static_cast<int>(f)) + " belongs to no body; put it in a shell");
    for (const Loop& loop : m.faces[f].loops)
      for (const Coedge& co : loop.coedges)
        if (in_range(co.edge, m.edges.size())) ++uses[static_cast<size_t>(co.edge)];
  }
  for (size_t e = 0; e < m.edges.size(); ++e) {
    if (uses[e] > 0 && wire_of_edge[e] >= 0)
      out.push_back("edge " + std::to_string(e) + " is in wire body " +
                    std::to_string(wire_of_edge[e]) +
                    " and used by a face; a wire body's edges are free (copy the edge)");
    if (uses[e] == 0 && wire_of_edge[e] < 0)
      out.push_back("edge " + std::to_string(e) + " is dangling: no face and no wire body uses it");
  }
}

void assembly_problems(const Model& m, std::vector<std::string>& out) {
  auto check_instance = [&](const Instance& in, const std::string& where) {
    if (!in_range(in.part, m.parts.size()))
      out.push_back(where + ": part index " + std::to_string(in.part) + " is not one of the " +
                    std::to_string(m.parts.size()) + " parts");
    if (!internal::all_finite(in.placement.matrix()))
      out.push_back(where + ": its placement has a non-finite entry");
  };
  for (size_t r = 0; r < m.roots.size(); ++r)
    check_instance(m.roots[r], "root instance " + std::to_string(r));
  for (size_t p = 0; p < m.parts.size(); ++p) {
    const Part& part = m.parts[p];
    const std::string name =
        "part " + std::to_string(p) + (part.name.empty() ? "" : " (\"" + part.name + "\")");
    for (int b : part.bodies)
      if (!in_range(b, m.bodies.size()))
        out.push_back(name + ": body index " + std::to_string(b) + " is not one of the " +
                      std::to_string(m.bodies.size()) + " bodies");
    for (size_t k = 0; k < part.components.size(); ++k)
      check_instance(part.components[k], name + " component " + std::to_string(k));
    if (!colour_ok(part.colour))
      out.push_back(name + ": colour " + colour_text(*part.colour) +
                    " has a component outside [0, 1]");
  }
  // No cycle: depth-first, 0 unvisited, 1 on the path, 2 done.
  std::vector<int> state(m.parts.size(), 0);
  auto visit = [&](auto& self, int p) -> void {
    state[static_cast<size_t>(p)] = 1;
    for (const Instance& in : m.parts[static_cast<size_t>(p)].components) {
      if (!in_range(in.part, m.parts.size())) continue;
      const int s = state[static_cast<size_t>(in.part)];
      if (s == 1)
        out.push_back("part " + std::to_string(in.part) +
                      " contains itself (an assembly cycle through part " + std::to_string(p) +
                      ")");
      else if (s == 0)
        self(self, in.part);
    }
    state[static_cast<size_t>(p)] = 2;
  };
  for (size_t p = 0; p < m.parts.size(); ++p)
    if (state[p] == 0) visit(visit, static_cast<int>(p));
}

}  // namespace

Eigen::Vector3d point(const Elementary& e, double u, double v) {
  const Eigen::Vector3d radial = std::cos(u) * e.x_axis + std::sin(u) * e.y_axis;
  switch (e.kind) {
    case ElementaryKind::Plane:
      return e.origin + u * e.x_axis + v * e.y_axis;
    case ElementaryKind::Cylinder:
      return e.origin + e.radius * radial + v * e.z_axis;
    case ElementaryKind::Cone:
      return e.origin + (e.radius + v * std::sin(e.semi_angle)) * radial +
             v * std::cos(e.semi_angle) * e.z_axis;
    case ElementaryKind::Sphere:
      return e.origin + e.radius * (std::cos(v) * radial + std::sin(v) * e.z_axis);
    case ElementaryKind::Torus:
      return e.origin + (e.radius + e.minor_radius * std::cos(v)) * radial +
             e.minor_radius * std::sin(v) * e.z_axis;
  }
  return e.origin;
}

double distance(const Elementary& e, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - e.origin;
  const double axial = d.dot(e.z_axis);
  const double radial = (d - axial * e.z_axis).norm();  // distance from the axis
  switch (e.kind) {
    case ElementaryKind::Plane:
      return std::abs(axial);
    case ElementaryKind::Cylinder:
      return std::abs(radial - e.radius);
    case ElementaryKind::Cone: {
      // In the half-plane through the axis and p, the cone (both nappes: the radius changes sign
      // at the apex) is two rays from the apex, mirror images across the axis.
      const double s = std::sin(e.semi_angle), c = std::cos(e.semi_angle);
      const Eigen::Vector2d apex(0.0, -e.radius * c / s), q(radial, axial);
      double nearest = INFINITY;
      for (double side : {1.0, -1.0}) {
        const Eigen::Vector2d ray(std::abs(s), side * c);
        const double t = std::max(0.0, (q - apex).dot(ray));
        nearest = std::min(nearest, (q - apex - t * ray).norm());
      }
      return nearest;
    }
    case ElementaryKind::Sphere:
      return std::abs(d.norm() - e.radius);
    case ElementaryKind::Torus: {
      // A spindle torus (minor radius above the major: EUCLID's screw threads) also holds the
      // points whose tube circle is across the axis, R + r cos v < 0.
      const double near = std::abs(std::hypot(radial - e.radius, axial) - e.minor_radius);
      if (!(e.minor_radius > e.radius)) return near;
      return std::min(near, std::abs(std::hypot(radial + e.radius, axial) - e.minor_radius));
    }
  }
  return INFINITY;
}

Counts counts(const Model& model) {
  Counts c;
  c.bodies = static_cast<int>(model.bodies.size());
  for (const Body& b : model.bodies) {
    c.solids += b.kind == BodyKind::Solid;
    c.shells += static_cast<int>(b.shells.size());
    c.wires += b.kind == BodyKind::Wire;
    c.wire_edges += static_cast<int>(b.edges.size());
  }
  c.faces = static_cast<int>(model.faces.size());
  for (const Face& f : model.faces) {
    c.trimmed_faces += !f.loops.empty();
    c.loops += static_cast<int>(f.loops.size());
    c.inner_loops += f.loops.empty() ? 0 : static_cast<int>(f.loops.size()) - 1;
    for (const Loop& l : f.loops) c.coedges += static_cast<int>(l.coedges.size());
  }
  c.edges = static_cast<int>(model.edges.size());
  for (const Edge& e : model.edges) c.degenerate_edges += e.degenerate;
  c.vertices = static_cast<int>(model.vertices.size());
  c.parts = static_cast<int>(model.parts.size());
  c.instances = static_cast<int>(model.roots.size());
  for (const Part& p : model.parts) c.instances += static_cast<int>(p.components.size());
  return c;
}

std::vector<EdgeGap> edge_gaps(const Model& model, int samples_per_span) {
  if (samples_per_span < 1)
    throw Error(ErrorCategory::InvalidArgument,
                "edge_gaps: samples_per_span = " + std::to_string(samples_per_span) +
                    " must be >= 1 (16 samples each knot span by default)");
  std::vector<EdgeGap> out;
  for (size_t f = 0; f < model.faces.size(); ++f) {
    const Face& face = model.faces[f];
    const int fi = static_cast<int>(f);
    if (auto bad = surface::problems(face.surface, face_name(model, fi) + "'s surface");
        !bad.empty())
      internal::throw_problems(ErrorCategory::InvalidGeometry, bad);
    for (size_t l = 0; l < face.loops.size(); ++l)
      for (size_t c = 0; c < face.loops[l].coedges.size(); ++c) {
        const int li = static_cast<int>(l), ci = static_cast<int>(c);
        // What gap_of needs: the coedge's own data, then its edge's curve or pole vertex.
        std::vector<std::string> bad = coedge_problems(model, fi, li, ci);
        if (bad.empty()) {
          const int ei = face.loops[l].coedges[c].edge;
          const Edge& e = model.edges[static_cast<size_t>(ei)];
          if (e.degenerate && !in_range(e.start, model.vertices.size()))
            bad.push_back("edge " + std::to_string(ei) + ": a pole without a vertex");
          if (!e.degenerate)
            bad = surface::problems(e.curve, "edge " + std::to_string(ei) + "'s curve");
        }
        if (!bad.empty()) internal::throw_problems(ErrorCategory::InvalidGeometry, bad);
        out.push_back(gap_of(model, fi, li, ci, samples_per_span));
      }
  }
  return out;
}

double loop_area(const Model& model, int face, int loop) {
  if (face < 0 || static_cast<size_t>(face) >= model.faces.size())
    throw Error(ErrorCategory::InvalidArgument, "loop_area: face " + std::to_string(face) +
                                                    " does not exist; the model has " +
                                                    std::to_string(model.faces.size()) + " faces");
  const Face& f = model.faces[static_cast<size_t>(face)];
  if (loop < 0 || static_cast<size_t>(loop) >= f.loops.size())
    throw Error(ErrorCategory::InvalidArgument, "loop_area: " + face_name(model, face) +
                                                    " has no loop " + std::to_string(loop) +
                                                    "; it has " + std::to_string(f.loops.size()));
  for (size_t c = 0; c < f.loops[static_cast<size_t>(loop)].coedges.size(); ++c)
    if (auto bad = coedge_problems(model, face, loop, static_cast<int>(c)); !bad.empty())
      internal::throw_problems(ErrorCategory::InvalidGeometry, bad);
  return signed_area(model, f.loops[static_cast<size_t>(loop)]);
}

std::vector<std::string> problems(const Model& model) {
  std::vector<std::string> out;
  vertex_and_edge_problems(model, out);
  face_problems(model, out);
  shell_problems(model, out);
  assembly_problems(model, out);
  return out;
}

Box control_box(const Model& model, const std::vector<int>& faces) {
  const Model flat = flattened(model);
  const int wire_edges = counts(flat).wire_edges;
  if (flat.faces.empty() && wire_edges == 0)
    throw Error(ErrorCategory::InvalidArgument,
                "control_box: the model has no face and no wire edge; read or build one with "
                "faces or curves first");
  Box box{Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
          Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity())};
  auto add = [&](const surface::Points3& p) {
    for (Eigen::Index r = 0; r < p.rows(); ++r) {
      box.lo = box.lo.cwiseMin(p.row(r).transpose());
      box.hi = box.hi.cwiseMax(p.row(r).transpose());
    }
  };
  std::vector<int> chosen = faces;
  if (chosen.empty()) {
    for (size_t f = 0; f < flat.faces.size(); ++f) chosen.push_back(static_cast<int>(f));
    for (const Body& body : flat.bodies)
      for (int e : body.edges)
        if (in_range(e, flat.edges.size())) add(flat.edges[static_cast<size_t>(e)].curve.points);
  }
  for (int f : chosen) {
    if (f < 0 || static_cast<size_t>(f) >= flat.faces.size())
      throw Error(ErrorCategory::InvalidArgument,
                  "control_box: face " + std::to_string(f) + " does not exist; the model has " +
                      std::to_string(flat.faces.size()) +
                      " faces (indices into the flattened model, from 0)");
    add(flat.faces[static_cast<size_t>(f)].surface.points);
  }
  return box;
}

Model flattened(const Model& model) {
  if (!model.is_assembly()) return model;
  {
    std::vector<std::string> tree;
    assembly_problems(model, tree);
    if (!tree.empty()) internal::throw_problems(ErrorCategory::InvalidGeometry, tree);
  }
  Model out;
  // One copy of a body: its faces, their edges and vertices, moved by `place`.
  auto copy_body = [&](int b, const Eigen::Isometry3d& place, const Part& part,
                       const std::optional<Colour>& inherited) {
    std::map<int, int> vertex_copy, edge_copy;
    auto vertex = [&](int v) {
      if (auto it = vertex_copy.find(v); it != vertex_copy.end()) return it->second;
      Vertex copy = model.vertices[static_cast<size_t>(v)];
      copy.point = place * copy.point;
      out.vertices.push_back(copy);
      return vertex_copy[v] = static_cast<int>(out.vertices.size()) - 1;
    };
    auto moved = [&](surface::Points3 points) {
      for (Eigen::Index r = 0; r < points.rows(); ++r)
        points.row(r) = (place * Eigen::Vector3d(points.row(r).transpose())).transpose();
      return points;
    };
    auto edge = [&](int e) {
      if (auto it = edge_copy.find(e); it != edge_copy.end()) return it->second;
      Edge copy = model.edges[static_cast<size_t>(e)];
      if (!copy.degenerate) copy.curve.points = moved(copy.curve.points);
      copy.start = vertex(copy.start);
      copy.end = vertex(copy.end);
      out.edges.push_back(std::move(copy));
      return edge_copy[e] = static_cast<int>(out.edges.size()) - 1;
    };
    const Body& body = model.bodies[static_cast<size_t>(b)];
    Body copy;
    copy.kind = body.kind;
    copy.name = body.name.empty() ? part.name : body.name;
    copy.colour = body.colour ? body.colour : inherited;
    for (const Shell& shell : body.shells) {
      Shell moved_shell;
      for (int f : shell.faces) {
        Face face = model.faces[static_cast<size_t>(f)];
        face.surface.points = moved(face.surface.points);
        if (face.elementary) {
          Elementary& e = *face.elementary;
          e.origin = place * e.origin;
          e.x_axis = place.linear() * e.x_axis;
          e.y_axis = place.linear() * e.y_axis;
          e.z_axis = place.linear() * e.z_axis;
        }
        for (Loop& loop : face.loops)
          for (Coedge& co : loop.coedges) co.edge = edge(co.edge);
        out.faces.push_back(std::move(face));
        moved_shell.faces.push_back(static_cast<int>(out.faces.size()) - 1);
      }
      copy.shells.push_back(std::move(moved_shell));
    }
    for (int e : body.edges) copy.edges.push_back(edge(e));
    out.bodies.push_back(std::move(copy));
  };
  auto walk = [&](auto& self, int p, const Eigen::Isometry3d& place,
                  std::optional<Colour> inherited) -> void {
    const Part& part = model.parts[static_cast<size_t>(p)];
    if (part.colour) inherited = part.colour;
    for (int b : part.bodies) copy_body(b, place, part, inherited);
    for (const Instance& in : part.components) self(self, in.part, place * in.placement, inherited);
  };
  for (const Instance& root : model.roots) walk(walk, root.part, root.placement, std::nullopt);
  return out;
}

void validate(const Model& model) {
  const auto list = problems(model);
  if (!list.empty()) internal::throw_problems(ErrorCategory::InvalidGeometry, list);
}

std::string_view to_string(ElementaryKind kind) noexcept {
  switch (kind) {
    case ElementaryKind::Plane:
      return "plane";
    case ElementaryKind::Cylinder:
      return "cylinder";
    case ElementaryKind::Cone:
      return "cone";
    case ElementaryKind::Sphere:
      return "sphere";
    case ElementaryKind::Torus:
      return "torus";
  }
  return "unknown";
}

std::string_view to_string(BodyKind kind) noexcept {
  switch (kind) {
    case BodyKind::Solid:
      return "solid";
    case BodyKind::Shell:
      return "shell";
    case BodyKind::Sheet:
      return "sheet";
    case BodyKind::Wire:
      return "wire";
  }
  return "unknown";
}

}  // namespace clay::brep
