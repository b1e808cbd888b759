#pragma once
// Models built by hand from planar quadrilateral faces, whose edges, pcurves, gaps and angles have
// closed forms: the B-rep tests' fixtures (model_test.cpp, continuity_test.cpp), and `mapped`, a
// model's points moved by a function (the mass property and area tests).
#include <clay/brep/model.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <functional>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace clay::test {

using brep::Body;
using brep::BodyKind;
using brep::Coedge;
using brep::Edge;
using brep::Face;
using brep::Loop;
using brep::Model;
using Eigen::Vector2d;
using Eigen::Vector3d;

inline clay::surface::BSplineCurve line(const Vector3d& a, const Vector3d& b) {
  clay::surface::Points3 p(2, 3);
  p.row(0) = a;
  p.row(1) = b;
  return clay::surface::make_curve(1, {0, 0, 1, 1}, p);
}

/// Builds models from planar quadrilateral faces S(u, v) = o + u e1 + v e2 on [0, 1]^2, sharing
/// vertices by position and edges by their pair of vertices.
struct Builder {
  Model m;
  std::map<std::tuple<double, double, double>, int> vertex_at;
  std::map<std::pair<int, int>, int> edge_between;

  int vertex(const Vector3d& p) {
    const auto key = std::tuple{p.x(), p.y(), p.z()};
    if (auto it = vertex_at.find(key); it != vertex_at.end()) return it->second;
    m.vertices.push_back({p, 1e-9});
    return vertex_at[key] = static_cast<int>(m.vertices.size()) - 1;
  }

  /// The coedge from corner a to corner b of a face (3D points pa, pb; (u, v) at ua, ub): the edge
  /// runs from its lower vertex index to its higher one, the pcurve with the same parameter.
  Coedge coedge(const Vector3d& pa, const Vector3d& pb, const Vector2d& ua, const Vector2d& ub) {
    const int a = vertex(pa), b = vertex(pb);
    const bool forward = a < b;
    const auto key = std::pair{std::min(a, b), std::max(a, b)};
    int e;
    if (auto it = edge_between.find(key); it != edge_between.end()) {
      e = it->second;
    } else {
      Edge edge;
      edge.curve = forward ? line(pa, pb) : line(pb, pa);
      edge.start = key.first;
      edge.end = key.second;
      edge.tolerance_mm = 1e-9;
      m.edges.push_back(edge);
      e = edge_between[key] = static_cast<int>(m.edges.size()) - 1;
    }
    const Vector2d s = forward ? ua : ub, t = forward ? ub : ua;
    return {e, forward, line({s.x(), s.y(), 0}, {t.x(), t.y(), 0})};
  }

  /// A loop through the given (u, v) corners of a face, in order.
  Loop loop(const Face& f, const std::vector<Vector2d>& uv) {
    Loop l;
    for (size_t k = 0; k < uv.size(); ++k) {
      const Vector2d& a = uv[k];
      const Vector2d& b = uv[(k + 1) % uv.size()];
      l.coedges.push_back(coedge(at(f, a), at(f, b), a, b));
    }
    return l;
  }

  static Vector3d at(const Face& f, const Vector2d& uv) {
    const auto& p = f.surface.points;  // bilinear: rows (0,0), (0,1), (1,0), (1,1)
    return (1 - uv.x()) * (1 - uv.y()) * Vector3d(p.row(0)) +
           (1 - uv.x()) * uv.y() * Vector3d(p.row(1)) + uv.x() * (1 - uv.y()) * Vector3d(p.row(2)) +
           uv.x() * uv.y() * Vector3d(p.row(3));
  }

  /// A planar face o + u e1 + v e2 bounded by its four sides, counter-clockwise in (u, v).
  int quad(const Vector3d& o, const Vector3d& e1, const Vector3d& e2, std::string name = "") {
    Face f;
    clay::surface::Points3 p(4, 3);
    p.row(0) = o;
    p.row(1) = o + e2;
    p.row(2) = o + e1;
    p.row(3) = o + e1 + e2;
    f.surface = clay::surface::make_surface({1, {0, 0, 1, 1}}, {1, {0, 0, 1, 1}}, p);
    f.name = std::move(name);
    f.loops.push_back(loop(f, {{0, 0}, {1, 0}, {1, 1}, {0, 1}}));
    m.faces.push_back(std::move(f));
    return static_cast<int>(m.faces.size()) - 1;
  }
};

/// The cube [0, a]^3 as a solid: six faces with outward normals e1 × e2, 12 shared edges.
inline Model cube(double a = 10) {
  Builder b;
  const Vector3d x(a, 0, 0), y(0, a, 0), z(0, 0, a), o = Vector3d::Zero();
  b.quad(o, y, x, "bottom");  // y × x = -z
  b.quad(z, x, y, "top");
  b.quad(o, z, y, "x0");  // z × y = -x
  b.quad(x, y, z, "x1");
  b.quad(o, x, z, "y0");  // x × z = -y
  b.quad(y, z, x, "y1");
  Body body;
  body.kind = BodyKind::Solid;
  body.name = "cube";
  body.shells.push_back({{0, 1, 2, 3, 4, 5}});
  b.m.bodies.push_back(body);
  return b.m;
}

/// Every control point, edge point and vertex x moved to f(x), edge and vertex tolerances widened
/// to `tolerance` (a nonlinear f opens the edges by its curvature).
inline Model mapped(Model m, const std::function<Vector3d(const Vector3d&)>& f,
                    double tolerance = 0) {
  auto move = [&](clay::surface::Points3& p) {
    for (Eigen::Index r = 0; r < p.rows(); ++r) p.row(r) = f(p.row(r).transpose()).transpose();
  };
  for (auto& face : m.faces) {
    move(face.surface.points);
    face.elementary.reset();  // no longer a plane, cylinder, ...
  }
  for (auto& edge : m.edges) {
    move(edge.curve.points);
    edge.tolerance_mm = std::max(edge.tolerance_mm, tolerance);
  }
  for (auto& v : m.vertices) {
    v.point = f(v.point);
    v.tolerance_mm = std::max(v.tolerance_mm, tolerance);
  }
  return m;
}

}  // namespace clay::test
