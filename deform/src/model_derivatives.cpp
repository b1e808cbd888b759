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
  out.points = lattice.points;
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

namespace {

/// The free coordinates' feasible set of keep_properties' linear constraints, K y = 0 on the
/// displacement y = L − jacobian.points (coordinate 3J + c), held coordinates fixed at moved's.
struct LinearSet {
  std::vector<Eigen::Index> free;  // the free coordinates
  Eigen::MatrixXd null;            // orthonormal basis of K's null space on them (free × dim)
  Points3 projected;               // moved, its free coordinates moved least onto the set
  bool any = false;                // any linear constraint
};

Eigen::Vector3d row3(const Points3& p, Eigen::Index r) { return p.row(r).transpose(); }

/// The rows of K: per fixed face, an orthonormal basis of C_f's row space (C_f y = 0 per
/// coordinate), per symmetry plane y_m(J) − S y_J = 0.
Eigen::MatrixXd linear_rows(const ModelJacobian& j, const KeptProperties& keep,
                            const std::string& name) {
  const Eigen::Index n = j.lattice_points;
  std::vector<Eigen::RowVectorXd> rows;
  for (int f : keep.fixed_faces) {
    if (f < 0 || f >= static_cast<int>(j.faces.size()))
      throw Error(ErrorCategory::InvalidArgument, name + ": fixed face " + std::to_string(f) +
                                                      " does not exist; the model has " +
                                                      std::to_string(j.faces.size()) + " faces");
    const SparseRows& c = j.faces[static_cast<std::size_t>(f)];
    if (c.nonZeros() == 0) continue;  // outside the lattice: it never moves
    std::vector<Eigen::Index> touched;
    std::vector<Eigen::Index> column(static_cast<std::size_t>(n), -1);
    for (Eigen::Index r = 0; r < c.rows(); ++r)
      for (SparseRows::InnerIterator it(c, r); it; ++it)
        if (column[static_cast<std::size_t>(it.col())] < 0) {
          column[static_cast<std::size_t>(it.col())] = static_cast<Eigen::Index>(touched.size());
          touched.push_back(it.col());
        }
    Eigen::MatrixXd dt = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(touched.size()), c.rows());
    for (Eigen::Index r = 0; r < c.rows(); ++r)
      for (SparseRows::InnerIterator it(c, r); it; ++it)
        dt(column[static_cast<std::size_t>(it.col())], r) = it.value();
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(dt);
    qr.setThreshold(1e-10);
    const Eigen::MatrixXd q = qr.householderQ();
    for (Eigen::Index k = 0; k < qr.rank(); ++k)
      for (int coord = 0; coord < 3; ++coord) {
        Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(3 * n);
        for (std::size_t t = 0; t < touched.size(); ++t)
          row[3 * touched[t] + coord] = q(static_cast<Eigen::Index>(t), k);
        rows.push_back(std::move(row));
      }
  }
  const Eigen::Vector3d lo = j.points.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = j.points.colwise().maxCoeff().transpose();
  const double size = std::max((hi - lo).norm(), 1e-300);
  for (std::size_t k = 0; k < keep.symmetry_planes.size(); ++k) {
    const SymmetryPlane& plane = keep.symmetry_planes[k];
    const std::string which = "symmetry plane " + std::to_string(k);
    if (!plane.point.allFinite() || !plane.normal.allFinite() || plane.normal.norm() == 0)
      throw Error(ErrorCategory::InvalidArgument,
                  name + ": " + which +
                      " has a zero or non-finite normal or point; give a point "
                      "on the plane and its normal");
    const Eigen::Vector3d u = plane.normal.normalized();
    const Eigen::Matrix3d reflect = Eigen::Matrix3d::Identity() - 2 * u * u.transpose();
    for (Eigen::Index a = 0; a < n; ++a) {
      const Eigen::Vector3d x = row3(j.points, a);
      const Eigen::Vector3d image = x - 2 * (x - plane.point).dot(u) * u;
      Eigen::Index b = -1;
      for (Eigen::Index c = 0; c < n && b < 0; ++c)
        if ((row3(j.points, c) - image).norm() <= 1e-9 * size) b = c;
      if (b < 0)
        throw Error(ErrorCategory::InvalidArgument,
                    name + ": lattice point " + std::to_string(a) + " has no mirror image across " +
                        which +
                        ", so the lattice's moves cannot mirror across it; make the "
                        "lattice symmetric about the plane (a frame centred on it)");
      if (b < a) continue;  // the pair's rows are already there
      for (int coord = 0; coord < 3; ++coord) {
        Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(3 * n);
        row[3 * b + coord] += 1;
        for (int d = 0; d < 3; ++d) row[3 * a + d] -= reflect(coord, d);
        rows.push_back(std::move(row));
      }
    }
  }
  Eigen::MatrixXd k(static_cast<Eigen::Index>(rows.size()), 3 * n);
  for (std::size_t r = 0; r < rows.size(); ++r) k.row(static_cast<Eigen::Index>(r)) = rows[r];
  return k;
}

LinearSet linear_set(const ModelJacobian& j, const KeptProperties& keep,
                     const std::vector<bool>& held, const Points3& moved, const std::string& name) {
  LinearSet out;
  out.projected = moved;
  const Eigen::Index n = j.lattice_points;
  for (Eigen::Index i = 0; i < 3 * n; ++i)
    if (!held[static_cast<std::size_t>(i / 3)]) out.free.push_back(i);
  const auto nf = static_cast<Eigen::Index>(out.free.size());
  const Eigen::MatrixXd k = linear_rows(j, keep, name);
  out.any = k.rows() > 0;
  if (!out.any) {
    out.null = Eigen::MatrixXd::Identity(nf, nf);
    return out;
  }
  Eigen::VectorXd y(3 * n);  // the displacement asked for
  for (Eigen::Index i = 0; i < 3 * n; ++i) y[i] = moved(i / 3, i % 3) - j.points(i / 3, i % 3);
  Eigen::MatrixXd kf(k.rows(), nf);
  Eigen::VectorXd yf(nf);
  for (Eigen::Index i = 0; i < nf; ++i) {
    kf.col(i) = k.col(out.free[static_cast<std::size_t>(i)]);
    yf[i] = y[out.free[static_cast<std::size_t>(i)]];
  }
  const Eigen::VectorXd rhs = kf * yf - k * y;  // = −K_H y_H
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(kf.transpose());
  qr.setThreshold(1e-10);
  const Eigen::MatrixXd q = qr.householderQ();
  const Eigen::Index rank = qr.rank();
  out.null = q.rightCols(nf - rank);
  const Eigen::MatrixXd range = q.leftCols(rank);
  Eigen::VectorXd solution = out.null * (out.null.transpose() * yf);
  if (rank > 0) solution += range * (kf * range).colPivHouseholderQr().solve(rhs);
  const double lattice_size =
      std::max((j.points.colwise().maxCoeff() - j.points.colwise().minCoeff()).norm(), 1e-300);
  if ((kf * solution - rhs).cwiseAbs().maxCoeff() > 1e-9 * lattice_size)
    throw Error(ErrorCategory::InvalidArgument,
                name +
                    ": the held lattice points move a fixed face or break a symmetry plane, "
                    "and the free points cannot restore it; hold no point that moves a fixed face "
                    "(or release the face), and drag points so their mirrors may follow");
  for (Eigen::Index i = 0; i < nf; ++i) {
    const Eigen::Index c = out.free[static_cast<std::size_t>(i)];
    out.projected(c / 3, c % 3) = j.points(c / 3, c % 3) + solution[i];
  }
  return out;
}

/// The largest residual of the linear constraints at lattice points l, mm.
double linear_residual(const ModelJacobian& j, const KeptProperties& keep, const Points3& l) {
  double worst = 0;
  for (int f : keep.fixed_faces) {
    const SparseRows& c = j.faces[static_cast<std::size_t>(f)];
    if (c.nonZeros() == 0) continue;
    const Points3 at = c * l;
    worst = std::max(
        worst,
        (at - j.model.faces[static_cast<std::size_t>(f)].surface.points).cwiseAbs().maxCoeff());
  }
  if (!keep.symmetry_planes.empty()) {
    const Eigen::MatrixXd k = linear_rows(j, keep, "keep_properties");
    Eigen::VectorXd y(3 * j.lattice_points);
    for (Eigen::Index i = 0; i < y.size(); ++i) y[i] = l(i / 3, i % 3) - j.points(i / 3, i % 3);
    if (k.rows() > 0) worst = std::max(worst, (k * y).cwiseAbs().maxCoeff());
  }
  return worst;
}

}  // namespace

KeptMove keep_properties(const ModelJacobian& jacobian, const Points3& moved,
                         const KeptProperties& keep) {
  const std::string name = "keep_properties";
  const bool mass = keep.volume_mm3 || keep.centroid_mm;
  if (!mass && !keep.area_mm2 && keep.fixed_faces.empty() && keep.symmetry_planes.empty())
    throw Error(ErrorCategory::InvalidArgument,
                name +
                    ": nothing to keep; give a volume, a centroid, an area, fixed faces or "
                    "symmetry planes");
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
  if (keep.area_mm2 && !(std::isfinite(*keep.area_mm2) && *keep.area_mm2 > 0))
    throw Error(ErrorCategory::InvalidArgument,
                name + ": the area to keep is " + internal::shortest(*keep.area_mm2) +
                    " mm^2; give the faces' own area (finite, positive)");
  if (keep.centroid_mm && !keep.centroid_mm->allFinite())
    throw Error(ErrorCategory::InvalidArgument,
                name + ": the centroid to keep is not finite; give the solid's own centroid");
  check_points(jacobian, moved, name);
  if (jacobian.points.rows() != jacobian.lattice_points)
    throw Error(ErrorCategory::InvalidArgument,
                name +
                    ": the Jacobian has no rest points (ModelJacobian::points); take it with "
                    "model_jacobian");
  const double size = size_of(jacobian.model);
  const LinearSet linear = linear_set(jacobian, keep, held, moved, name);
  // A gradient (lattice points × 3) restricted to the linear set's tangent space: its free
  // coordinates projected onto K's null space (Z Zᵀ), the held ones zero.
  auto tangent = [&](const Points3& g) {
    Eigen::VectorXd gf(static_cast<Eigen::Index>(linear.free.size()));
    for (std::size_t i = 0; i < linear.free.size(); ++i)
      gf[static_cast<Eigen::Index>(i)] = g(linear.free[i] / 3, linear.free[i] % 3);
    if (linear.any) gf = linear.null * (linear.null.transpose() * gf);
    Points3 out = Points3::Zero(g.rows(), 3);
    for (std::size_t i = 0; i < linear.free.size(); ++i)
      out(linear.free[i] / 3, linear.free[i] % 3) = gf[static_cast<Eigen::Index>(i)];
    return out;
  };
  // The constraints: residuals and gradients (tangent) at lattice points L, each divided by its
  // scale (the volume by the target's, the centroid by the model's size), so the Newton matrix
  // mixes no units: a volume row ~ L^4 next to centroid rows ~ 1 fell below FullPivLU's rank
  // threshold for a part of a few metres in mm.
  const double volume_scale = keep.volume_mm3 ? std::abs(*keep.volume_mm3) : 1.0;
  const double area_scale = keep.area_mm2 ? *keep.area_mm2 : 1.0;
  std::vector<double> raw;  // each row's gradient norm before the projection
  auto project = [&](const Points3& g) {
    raw.push_back(g.norm());
    return tangent(g);
  };
  auto constraints = [&](const Points3& l, KeptMove& report, std::vector<Points3>& gradients) {
    const brep::Model m = moved_geometry(jacobian, l);
    std::vector<double> residual;
    gradients.clear();
    raw.clear();
    if (mass) {
      const LatticeMassGradients g = gradients_at(jacobian, m, false);
      report.properties = g.value;
      if (keep.volume_mm3) {
        residual.push_back((g.value.volume_mm3 - *keep.volume_mm3) / volume_scale);
        gradients.push_back(project(g.volume / volume_scale));
      }
      if (keep.centroid_mm)
        for (int i = 0; i < 3; ++i) {
          residual.push_back((g.value.centroid_mm[i] - (*keep.centroid_mm)[i]) / size);
          gradients.push_back(project(g.centroid[static_cast<std::size_t>(i)] / size));
        }
    }
    if (keep.area_mm2) {
      brep::MassPropertyOptions unchecked;
      unchecked.validate = false;
      const brep::SurfaceAreaGradient g = brep::surface_area_gradient(m, unchecked);
      report.area_mm2 = g.value.area_mm2;
      residual.push_back((g.value.area_mm2 - *keep.area_mm2) / area_scale);
      gradients.push_back(project(to_lattice(jacobian, g.area) / area_scale));
    }
    return Eigen::VectorXd(
        Eigen::Map<Eigen::VectorXd>(residual.data(), static_cast<Eigen::Index>(residual.size())));
  };
  auto met = [&](const Eigen::VectorXd& r, KeptMove& out) {
    int k = 0;
    out.volume_error = out.centroid_error_mm = out.area_error = 0;
    if (keep.volume_mm3) out.volume_error = std::abs(r[k++]);
    if (keep.centroid_mm) {
      out.centroid_error_mm = r.segment(k, 3).norm() * size;
      k += 3;
    }
    if (keep.area_mm2) out.area_error = std::abs(r[k++]);
    return out.volume_error <= keep.tolerance && out.centroid_error_mm <= keep.tolerance * size &&
           out.area_error <= keep.tolerance;
  };
  KeptMove out;
  out.points = linear.projected;
  std::vector<Points3> directions, gradients;
  Eigen::VectorXd r = constraints(out.points, out, directions);
  // A property the linear constraints freeze (the centroid's component across a symmetry plane
  // of a symmetric part: its projected gradient vanishes) has no Newton direction: met already,
  // it leaves the system (met() still checks it); not met, no allowed move reaches its target.
  static const char* const row_names[] = {"volume", "centroid x", "centroid y", "centroid z",
                                          "area"};
  std::vector<std::string> names;
  if (keep.volume_mm3) names.push_back(row_names[0]);
  if (keep.centroid_mm)
    for (int i = 1; i <= 3; ++i) names.push_back(row_names[i]);
  if (keep.area_mm2) names.push_back(row_names[4]);
  std::vector<std::size_t> active;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    if (directions[i].norm() > 1e-8 * raw[i]) {
      active.push_back(i);
      continue;
    }
    // every residual is relative: the volume and area by their targets, the centroid by the size
    const double tolerance = keep.tolerance;
    if (std::abs(r[static_cast<Eigen::Index>(i)]) > tolerance)
      throw Error(ErrorCategory::InvalidArgument,
                  name + ": the held points, fixed faces and symmetry planes hold the " + names[i] +
                      " where it is, so no allowed move reaches its target (" +
                      internal::shortest(std::abs(r[static_cast<Eigen::Index>(i)])) +
                      " off, relative); hold fewer points, give a target the constraints allow "
                      "(a centroid on the symmetry plane), or drop a constraint");
  }
  auto pick = [&](std::vector<Points3>& all) {
    std::vector<Points3> kept_rows;
    for (std::size_t i : active) kept_rows.push_back(all[i]);
    all = std::move(kept_rows);
  };
  auto picked = [&](const Eigen::VectorXd& all) {
    Eigen::VectorXd out_rows(static_cast<Eigen::Index>(active.size()));
    for (std::size_t k = 0; k < active.size(); ++k)
      out_rows[static_cast<Eigen::Index>(k)] = all[static_cast<Eigen::Index>(active[k])];
    return out_rows;
  };
  pick(directions);
  const auto m = static_cast<Eigen::Index>(directions.size());
  gradients = directions;
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  for (; !met(r, out); ++out.iterations) {
    if (out.iterations == 20)
      throw Error(ErrorCategory::ToleranceNotMet,
                  name + ": 20 Newton steps left the volume " +
                      internal::shortest(out.volume_error) + " (relative), the centroid " +
                      internal::shortest(out.centroid_error_mm) + " mm and the area " +
                      internal::shortest(out.area_error) +
                      " (relative) off their targets; the move folds the lattice or is too large "
                      "to correct: move in smaller steps");
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
                      "independently (every point that moves them is held, fixed or mirrored); "
                      "hold fewer points");
    lambda -= lu.solve(picked(r));
    out.points = linear.projected;
    for (Eigen::Index k = 0; k < m; ++k)
      out.points += lambda[k] * directions[static_cast<std::size_t>(k)];
    r = constraints(out.points, out, gradients);
    pick(gradients);
  }
  if (linear.any) out.linear_error_mm = linear_residual(jacobian, keep, out.points);
  return out;
}

}  // namespace clay::deform
