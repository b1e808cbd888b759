// Pieces of a model's deformation (see model_pieces.hpp).
#include "model_pieces.hpp"

#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

namespace clay::deform::detail {

bool outside(const Frame& frame, const surface::Points3& points) {
  for (int axis = 0; axis < 3; ++axis) {
    bool below = true, above = true;
    for (Eigen::Index r = 0; r < points.rows() && (below || above); ++r) {
      const double c = local_coordinates(frame, points.row(r).transpose())[axis];
      below = below && c < 0;
      above = above && c > 1;
    }
    if (below || above) return true;
  }
  return false;
}

surface::BSplineSurface ruled(const surface::BSplineCurve& c) {
  const Eigen::Index n = c.points.rows();
  surface::Points3 points(2 * n, 3);
  Eigen::VectorXd weights(2 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    points.row(2 * i) = c.points.row(i);
    points.row(2 * i + 1) = c.points.row(i);
    weights[2 * i] = weights[2 * i + 1] = c.weights[i];
  }
  return surface::make_surface(c.basis, {1, {0, 0, 1, 1}}, std::move(points), std::move(weights));
}

surface::BSplineCurve row_zero(const surface::BSplineSurface& s) {
  const int nu = s.count_u();
  surface::Points3 points(nu, 3);
  Eigen::VectorXd weights(nu);
  for (int i = 0; i < nu; ++i) {
    points.row(i) = s.points.row(s.index(i, 0));
    weights[i] = s.weights[s.index(i, 0)];
  }
  return surface::make_curve(s.u.degree, s.u.knots, std::move(points), std::move(weights));
}

std::optional<std::array<double, 4>> trims_box(const brep::Face& face) {
  if (face.loops.empty()) return std::nullopt;
  const auto [a, b] = face.surface.u.domain();
  const auto [c, d] = face.surface.v.domain();
  std::array<double, 4> box{b, a, d, c};
  for (const brep::Loop& loop : face.loops)
    for (const brep::Coedge& co : loop.coedges)
      for (Eigen::Index r = 0; r < co.pcurve.points.rows(); ++r) {
        box[0] = std::min(box[0], co.pcurve.points(r, 0));
        box[1] = std::max(box[1], co.pcurve.points(r, 0));
        box[2] = std::min(box[2], co.pcurve.points(r, 1));
        box[3] = std::max(box[3], co.pcurve.points(r, 1));
      }
  box = {std::max(box[0], a), std::min(box[1], b), std::max(box[2], c), std::min(box[3], d)};
  if (!(box[0] < box[1] && box[2] < box[3])) return std::nullopt;
  if (box[0] == a && box[1] == b && box[2] == c && box[3] == d) return std::nullopt;
  return box;
}

double size_of(const brep::Model& m) {
  const brep::Box box = brep::control_box(m);  // faces and free edges
  return std::max((box.hi - box.lo).norm(), 1e-300);
}

std::string face_name(const brep::Model& m, std::size_t f) {
  const std::string& name = m.faces[f].name;
  return "face " + std::to_string(f) + (name.empty() ? "" : " (\"" + name + "\")");
}

double widen_stretched_tolerances(brep::Model& m, const std::vector<bool>& vertex_touched,
                                  double size) {
  double largest = 0;
  // A deformation stretches the file's own gaps with the geometry: where an exact edge's gap now
  // exceeds its tolerance by no more than the stretch allows (10 x, or 1e-9 of the size), the
  // tolerance follows the measured gap, as OpenCASCADE's GTransform scales tolerances.
  // The gaps measured once: widening tolerances and reversing faces below do not move them.
  // The tolerance covers the gap with 0.1 % to spare: BRepCheck measures the same gap by its own
  // sampling and rounding, and found Alibre's bulged annulus (a constant 5.5e-7 mm gap along a
  // circle) above a tolerance of the gap x (1 + 1e-9).
  constexpr double spare = 1e-3;
  for (const brep::EdgeGap& g : brep::edge_gaps(m)) {
    largest = std::max(largest, g.gap_mm);
    brep::Edge& edge = m.edges[static_cast<std::size_t>(g.edge)];
    const double allowed = std::max(10 * edge.tolerance_mm, 1e-9 * size);
    if (g.gap_mm * (1 + spare) > edge.tolerance_mm && g.gap_mm <= allowed) {
      edge.tolerance_mm = g.gap_mm * (1 + spare);
      for (int v : {edge.start, edge.end}) {
        brep::Vertex& vertex = m.vertices[static_cast<std::size_t>(v)];
        vertex.tolerance_mm = std::max(vertex.tolerance_mm, edge.tolerance_mm);
      }
    }
  }
  // The same for the vertices: the file's distance from a vertex to the ends of its edges (3D,
  // and each face along its pcurve) is stretched too, and OpenCASCADE's BRepCheck then finds the
  // vertex off its curve (CATIA's as1 assembly, 10 % stretch: BRepCheck_InvalidPointOnCurve).
  auto widen_vertex = [&](int v, const Eigen::Vector3d& end) {
    if (!vertex_touched[static_cast<std::size_t>(v)]) return;
    brep::Vertex& vertex = m.vertices[static_cast<std::size_t>(v)];
    const double distance = (vertex.point - end).norm();
    if (distance * (1 + spare) > vertex.tolerance_mm &&
        distance <= std::max(10 * vertex.tolerance_mm, 1e-9 * size))
      vertex.tolerance_mm = distance * (1 + spare);
  };
  for (const brep::Edge& edge : m.edges) {
    if (edge.degenerate) continue;
    widen_vertex(edge.start, surface::evaluate(edge.curve, edge.t0));
    widen_vertex(edge.end, surface::evaluate(edge.curve, edge.t1));
  }
  for (const brep::Face& face : m.faces)
    for (const brep::Loop& loop : face.loops)
      for (const brep::Coedge& c : loop.coedges) {
        const brep::Edge& edge = m.edges[static_cast<std::size_t>(c.edge)];
        const auto [d0, d1] = c.pcurve.basis.domain();
        for (const auto& [v, t] : {std::pair{edge.start, edge.t0}, std::pair{edge.end, edge.t1}}) {
          const Eigen::Vector3d uv = surface::evaluate(c.pcurve, std::clamp(t, d0, d1));
          const auto [u0, u1] = face.surface.u.domain();
          const auto [v0, v1] = face.surface.v.domain();
          widen_vertex(v, surface::evaluate(face.surface, std::clamp(uv.x(), u0, u1),
                                            std::clamp(uv.y(), v0, v1)));
        }
      }
  return largest;
}

}  // namespace clay::deform::detail
