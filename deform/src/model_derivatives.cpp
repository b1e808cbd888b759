// A model's exact Jacobian with respect to a lattice's points, its mass properties' gradients and
// moves that keep them (see clay/deform/model_derivatives.hpp).
#include <clay/deform/model_derivatives.hpp>

#include <clay/deform/derivatives.hpp>
#include <clay/deform/direct_manipulation.hpp>
#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "model_pieces.hpp"

namespace clay::deform {
namespace {

using namespace detail;

/// Rows `rows` of m, in that order.
SparseRows rows_of(const SparseRows& m, const std::vector<Eigen::Index>& rows) {
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (SparseRows::InnerIterator it(m, rows[r]); it; ++it)
      entries.emplace_back(static_cast<int>(r), static_cast<int>(it.col()), it.value());
  SparseRows out(static_cast<Eigen::Index>(rows.size()), m.cols());
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

/// composition_jacobian of a face, on the box of its trims when its surface leaves the lattice
/// though its trims do not (as deform_model composes it); errors name the face.
template <class Lattice>
CompositionJacobian compose_face(const Lattice& lattice, brep::Model& m, std::size_t f) {
  brep::Face& face = m.faces[f];
  try {
    return composition_jacobian(lattice, face.surface);
  } catch (const Error& e) {
    const auto box = e.category() == ErrorCategory::OutOfDomain ? trims_box(face) : std::nullopt;
    if (!box) throw Error(e.category(), "model_jacobian: " + face_name(m, f) + ": " + e.message());
    face.surface = surface::restricted(face.surface, (*box)[0], (*box)[1], (*box)[2], (*box)[3]);
    try {
      return composition_jacobian(lattice, face.surface);
    } catch (const Error& again) {
      throw Error(again.category(), "model_jacobian: " + face_name(m, f) +
                                        " (on the box of its trims): " + again.message());
    }
  }
}

template <class Lattice>
ModelJacobian jacobian_of(const Lattice& lattice, const brep::Model& input) {
  validate(lattice, "model_jacobian: lattice");
  brep::validate(input);
  ModelJacobian out;
  brep::Model& m = out.model;
  m = brep::flattened(input);
  if (m.faces.empty())
    throw Error(ErrorCategory::InvalidArgument,
                "model_jacobian: the model has no face; its Jacobian is taken over faces, edges "
                "and vertices (read a file with faces)");
  const Eigen::Index n = lattice.points.rows();
  out.lattice_points = n;
  out.faces.resize(m.faces.size());
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    brep::Face& face = m.faces[f];
    if (outside(lattice.frame, face.surface.points)) {
      out.faces[f] = SparseRows(face.surface.points.rows(), n);
      continue;
    }
    CompositionJacobian c = compose_face(lattice, m, f);
    face.surface = std::move(c.surface);
    face.elementary.reset();  // no longer a plane, cylinder, ...
    out.faces[f] = std::move(c.matrix);
  }
  out.edges.resize(m.edges.size());
  for (std::size_t e = 0; e < m.edges.size(); ++e) {
    brep::Edge& edge = m.edges[e];
    if (edge.degenerate || outside(lattice.frame, edge.curve.points)) {
      out.edges[e] = SparseRows(edge.curve.points.rows(), n);  // a pole: only its vertex moves
      continue;
    }
    CompositionJacobian c;
    try {
      c = composition_jacobian(lattice, ruled(edge.curve));
    } catch (const Error& error) {
      throw Error(error.category(),
                  "model_jacobian: edge " + std::to_string(e) + ": " + error.message());
    }
    std::vector<Eigen::Index> row0(static_cast<std::size_t>(c.surface.count_u()));
    for (std::size_t i = 0; i < row0.size(); ++i) row0[i] = c.surface.index(static_cast<int>(i), 0);
    edge.curve = row_zero(c.surface);
    out.edges[e] = rows_of(c.matrix, row0);
  }
  // Vertices inside the lattice's box move by the FFD; the others stay.
  std::vector<bool> moved(m.vertices.size(), false);
  std::vector<Eigen::Index> inside_rows;
  Points3 inside_points(0, 3);
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    if (inside(local_coordinates(lattice.frame, m.vertices[v].point))) {
      moved[v] = true;
      inside_rows.push_back(static_cast<Eigen::Index>(v));
    }
  inside_points.resize(static_cast<Eigen::Index>(inside_rows.size()), 3);
  for (std::size_t k = 0; k < inside_rows.size(); ++k)
    inside_points.row(static_cast<Eigen::Index>(k)) =
        m.vertices[static_cast<std::size_t>(inside_rows[k])].point.transpose();
  const SparseRows b = influence_matrix(lattice, inside_points);
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t k = 0; k < inside_rows.size(); ++k)
    for (SparseRows::InnerIterator it(b, static_cast<Eigen::Index>(k)); it; ++it)
      entries.emplace_back(static_cast<int>(inside_rows[k]), static_cast<int>(it.col()),
                           it.value());
  out.vertices.resize(static_cast<Eigen::Index>(m.vertices.size()), n);
  out.vertices.setFromTriplets(entries.begin(), entries.end());
  const Points3 at = out.vertices * lattice.points;
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    if (moved[v]) m.vertices[v].point = at.row(static_cast<Eigen::Index>(v)).transpose();
  widen_stretched_tolerances(m, moved, size_of(m));
  return out;
}

/// The lattice gradient Σ_f C_fᵀ G_f + Vᵀ G_v of a property whose gradients with respect to the
/// faces' control points and the vertices are `g`.
Points3 to_lattice(const ModelJacobian& j, const brep::PointGradients& g) {
  Points3 out = Points3(j.vertices.transpose() * g.vertices);
  for (std::size_t f = 0; f < g.faces.size(); ++f)
    if (g.faces[f].rows() > 0 && j.faces[f].nonZeros() > 0)
      out += Points3(j.faces[f].transpose() * g.faces[f]);
  return out;
}

/// mass_property_gradients of `m`, jacobian.model at other lattice points (deformed_model; or
/// moved_geometry, unchecked).
LatticeMassGradients gradients_at(const ModelJacobian& jacobian, const brep::Model& m,
                                  bool check = true) {
  brep::MassPropertyOptions options;
  options.validate = check;
  const brep::MassPropertyGradients g = brep::mass_property_gradients(m, options);
  LatticeMassGradients out;
  out.value = g.value;
  out.volume = to_lattice(jacobian, g.volume);
  for (std::size_t i = 0; i < 3; ++i) out.centroid[i] = to_lattice(jacobian, g.centroid[i]);
  for (std::size_t i = 0; i < 6; ++i) out.inertia[i] = to_lattice(jacobian, g.inertia[i]);
  return out;
}

/// Refuses lattice points of another shape than the Jacobian's, or not finite.
void check_points(const ModelJacobian& jacobian, const Points3& points, const std::string& where) {
  if (points.rows() != jacobian.lattice_points)
    throw Error(ErrorCategory::InvalidArgument,
                where + ": " + std::to_string(points.rows()) +
                    " lattice points given, but the Jacobian was taken for " +
                    std::to_string(jacobian.lattice_points) +
                    "; give the points of a lattice of the same shape");
  if (!points.allFinite())
    throw Error(ErrorCategory::InvalidArgument,
                where + ": a lattice point is not finite; give finite coordinates");
}

/// The model's faces and vertices at other lattice points, edges and tolerances as they are: what
/// the mass properties read (the faces, and the vertices for their reference point). A Newton
/// step's model: its topology is jacobian.model's, already checked.
brep::Model moved_geometry(const ModelJacobian& jacobian, const Points3& points) {
  brep::Model m = jacobian.model;
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    if (jacobian.faces[f].nonZeros() > 0) m.faces[f].surface.points = jacobian.faces[f] * points;
  const Points3 at = jacobian.vertices * points;
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    if (jacobian.vertices.outerIndexPtr()[v + 1] > jacobian.vertices.outerIndexPtr()[v])
      m.vertices[v].point = at.row(static_cast<Eigen::Index>(v)).transpose();
  return m;
}

}  // namespace

ModelJacobian model_jacobian(const BezierLattice& lattice, const brep::Model& model) {
  return jacobian_of(lattice, model);
}

ModelJacobian model_jacobian(const BSplineLattice& lattice, const brep::Model& model) {
  return jacobian_of(lattice, model);
}

brep::Model deformed_model(const ModelJacobian& jacobian, const Points3& points) {
  check_points(jacobian, points, "deformed_model");
  brep::Model m = moved_geometry(jacobian, points);
  for (std::size_t e = 0; e < m.edges.size(); ++e)
    if (jacobian.edges[e].nonZeros() > 0) m.edges[e].curve.points = jacobian.edges[e] * points;
  std::vector<bool> moved(m.vertices.size(), false);
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    moved[v] = jacobian.vertices.outerIndexPtr()[v + 1] > jacobian.vertices.outerIndexPtr()[v];
  widen_stretched_tolerances(m, moved, size_of(m));
  return m;
}

SparseRows face_point_jacobian(const ModelJacobian& jacobian, int face,
                               const std::vector<Eigen::Vector2d>& uv) {
  if (face < 0 || static_cast<std::size_t>(face) >= jacobian.model.faces.size())
    throw Error(ErrorCategory::InvalidArgument,
                "face_point_jacobian: face " + std::to_string(face) +
                    " does not exist; the model has " +
                    std::to_string(jacobian.model.faces.size()) + " faces");
  const surface::BSplineSurface& s = jacobian.model.faces[static_cast<std::size_t>(face)].surface;
  const SparseRows& c = jacobian.faces[static_cast<std::size_t>(face)];
  const auto [u0, u1] = s.u.domain();
  const auto [v0, v1] = s.v.domain();
  const int p = s.u.degree, q = s.v.degree;
  std::vector<Eigen::Triplet<double>> entries;
  std::array<double, 2 * (surface::max_kernel_degree + 1)> nu{}, nv{};
  for (std::size_t i = 0; i < uv.size(); ++i) {
    const double u = uv[i].x(), v = uv[i].y();
    if (!(u >= u0 && u <= u1 && v >= v0 && v <= v1))
      throw Error(ErrorCategory::InvalidArgument,
                  "face_point_jacobian: (u, v) #" + std::to_string(i) + " (" +
                      internal::shortest(u) + ", " + internal::shortest(v) + ") is outside face " +
                      std::to_string(face) + "'s domain [" + internal::shortest(u0) + ", " +
                      internal::shortest(u1) + "] x [" + internal::shortest(v0) + ", " +
                      internal::shortest(v1) + "]");
    const int su = surface::find_span(s.u, u), sv = surface::find_span(s.v, v);
    surface::basis_derivatives(s.u, su, u, 0, nu);
    surface::basis_derivatives(s.v, sv, v, 0, nv);
    double weight = 0;
    for (int a = 0; a <= p; ++a)
      for (int b = 0; b <= q; ++b)
        weight += nu[static_cast<std::size_t>(a)] * nv[static_cast<std::size_t>(b)] *
                  s.weights[s.index(su - p + a, sv - q + b)];
    for (int a = 0; a <= p; ++a)
      for (int b = 0; b <= q; ++b) {
        const Eigen::Index k = s.index(su - p + a, sv - q + b);
        const double r = nu[static_cast<std::size_t>(a)] * nv[static_cast<std::size_t>(b)] *
                         s.weights[k] / weight;
        if (r == 0) continue;
        for (SparseRows::InnerIterator it(c, k); it; ++it)
          entries.emplace_back(static_cast<int>(i), static_cast<int>(it.col()), r * it.value());
      }
  }
  SparseRows out(static_cast<Eigen::Index>(uv.size()), jacobian.lattice_points);
  out.setFromTriplets(entries.begin(), entries.end());  // duplicates summed
  return out;
}

LatticeMassGradients mass_property_gradients(const ModelJacobian& jacobian) {
  return gradients_at(jacobian, jacobian.model);
}

LatticeMassGradients mass_property_gradients(const ModelJacobian& jacobian, const Points3& points) {
  return gradients_at(jacobian, deformed_model(jacobian, points));
}

LatticeAreaGradient surface_area_gradient(const ModelJacobian& jacobian) {
  const brep::SurfaceAreaGradient g = brep::surface_area_gradient(jacobian.model);
  return {g.value, to_lattice(jacobian, g.area)};
}

LatticeAreaGradient surface_area_gradient(const ModelJacobian& jacobian, const Points3& points) {
  const brep::SurfaceAreaGradient g = brep::surface_area_gradient(deformed_model(jacobian, points));
  return {g.value, to_lattice(jacobian, g.area)};
}

KeptMove keep_properties(const ModelJacobian& jacobian, const Points3& moved,
                         const KeptProperties& keep) {
  const std::string name = "keep_properties";
  if (!keep.volume_mm3 && !keep.centroid_mm)
    throw Error(ErrorCategory::InvalidArgument,
                name + ": nothing to keep; give a volume, a centroid or both");
  if (!(keep.tolerance > 0 && keep.tolerance < 1e-3))
    throw Error(ErrorCategory::InvalidArgument,
                name + ": tolerance " + internal::shortest(keep.tolerance) +
                    " must lie in (0, 1e-3) (relative; 1e-13 by default)");
  std::vector<bool> held(static_cast<std::size_t>(jacobian.lattice_points), false);
  for (int h : keep.held) {
    if (h < 0 || h >= jacobian.lattice_points)
      throw Error(ErrorCategory::InvalidArgument,
                  name + ": held point " + std::to_string(h) + " does not exist; the lattice has " +
                      std::to_string(jacobian.lattice_points) + " points");
    held[static_cast<std::size_t>(h)] = true;
  }
  if (keep.volume_mm3 && !(std::isfinite(*keep.volume_mm3) && *keep.volume_mm3 != 0))
    throw Error(ErrorCategory::InvalidArgument,
                name + ": the volume to keep is " + internal::shortest(*keep.volume_mm3) +
                    " mm^3; give the solid's own volume (finite, not 0)");
  if (keep.centroid_mm && !keep.centroid_mm->allFinite())
    throw Error(ErrorCategory::InvalidArgument,
                name + ": the centroid to keep is not finite; give the solid's own centroid");
  check_points(jacobian, moved, name);
  const double size = size_of(jacobian.model);
  // The constraints: residuals and gradients (free rows only) at lattice points L, each divided
  // by its scale (the volume by the target's, the centroid by the model's size), so the Newton
  // matrix mixes no units: a volume row ~ L^4 next to centroid rows ~ 1 fell below FullPivLU's
  // rank threshold for a part of a few metres in mm.
  const double volume_scale = keep.volume_mm3 ? std::abs(*keep.volume_mm3) : 1.0;
  auto constraints = [&](const Points3& l, brep::MassProperties& value,
                         std::vector<Points3>& gradients) {
    const LatticeMassGradients g = gradients_at(jacobian, moved_geometry(jacobian, l), false);
    value = g.value;
    std::vector<double> residual;
    gradients.clear();
    if (keep.volume_mm3) {
      residual.push_back((g.value.volume_mm3 - *keep.volume_mm3) / volume_scale);
      gradients.push_back(g.volume / volume_scale);
    }
    if (keep.centroid_mm)
      for (int i = 0; i < 3; ++i) {
        residual.push_back((g.value.centroid_mm[i] - (*keep.centroid_mm)[i]) / size);
        gradients.push_back(g.centroid[static_cast<std::size_t>(i)] / size);
      }
    for (Points3& d : gradients)
      for (std::size_t r = 0; r < held.size(); ++r)
        if (held[r]) d.row(static_cast<Eigen::Index>(r)).setZero();
    return Eigen::VectorXd(
        Eigen::Map<Eigen::VectorXd>(residual.data(), static_cast<Eigen::Index>(residual.size())));
  };
  auto met = [&](const Eigen::VectorXd& r, KeptMove& out) {
    int k = 0;
    out.volume_error = out.centroid_error_mm = 0;
    if (keep.volume_mm3) out.volume_error = std::abs(r[k++]);
    if (keep.centroid_mm) out.centroid_error_mm = r.segment(k, 3).norm() * size;
    return out.volume_error <= keep.tolerance && out.centroid_error_mm <= keep.tolerance * size;
  };
  KeptMove out;
  out.points = moved;
  std::vector<Points3> directions, gradients;
  Eigen::VectorXd r = constraints(moved, out.properties, directions);
  const auto m = static_cast<Eigen::Index>(directions.size());
  gradients = directions;
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  for (; !met(r, out); ++out.iterations) {
    if (out.iterations == 20)
      throw Error(ErrorCategory::ToleranceNotMet,
                  name + ": 20 Newton steps left the volume " +
                      internal::shortest(out.volume_error) + " (relative) and the centroid " +
                      internal::shortest(out.centroid_error_mm) +
                      " mm off their targets; the move folds the lattice or is too large to "
                      "correct: move in smaller steps");
    Eigen::MatrixXd j(m, m);  // ∂q_i/∂λ_k = ∇q_i · direction_k
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index k = 0; k < m; ++k)
        j(i, k) = gradients[static_cast<std::size_t>(i)]
                      .cwiseProduct(directions[static_cast<std::size_t>(k)])
                      .sum();
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(j);
    if (lu.rank() < m)
      throw Error(ErrorCategory::InvalidArgument,
                  name +
                      ": the free lattice points cannot change the kept properties "
                      "independently (every point that moves them is held); hold fewer points");
    lambda -= lu.solve(r);
    out.points = moved;
    for (Eigen::Index k = 0; k < m; ++k)
      out.points += lambda[k] * directions[static_cast<std::size_t>(k)];
    r = constraints(out.points, out.properties, gradients);
  }
  return out;
}

}  // namespace clay::deform
