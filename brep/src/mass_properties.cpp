// Mass properties and their gradients by the divergence, Green and Hadamard theorems (see
// clay/brep/mass_properties.hpp).
#include <clay/brep/mass_properties.hpp>

#include <clay/error.hpp>
#include <clay/parallel.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include "integration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace clay::brep {
namespace {

using detail::breaks;
using detail::Budget;
using detail::rule;

/// The ten moments about c: ∭ 1, y_x, y_y, y_z, y_x², y_y², y_z², y_x y_y, y_x y_z, y_y y_z dV.
using Moments = Eigen::Matrix<double, 10, 1>;

/// Each moment's field Φ_m(y) (div Φ_m = φ_m) and (∇Φ_m)ᵀ n, the derivative of Φ_m·n along a
/// move of the point: e·(∇Φ_mᵀ n) for a move e.
struct Fields {
  std::array<Eigen::Vector3d, 10> phi, a;
};

Fields fields(const Eigen::Vector3d& y, const Eigen::Vector3d& n) {
  Fields f;
  f.phi[0] = y / 3;
  f.a[0] = n / 3;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(i);
    f.phi[1 + k] = e * y[i] * y[i] / 2;
    f.a[1 + k] = e * y[i] * n[i];
    f.phi[4 + k] = e * y[i] * y[i] * y[i] / 3;
    f.a[4 + k] = e * y[i] * y[i] * n[i];
  }
  const double x = y.x(), yy = y.y(), z = y.z();
  f.phi[7] = Eigen::Vector3d(x * x * yy / 2, 0, 0);
  f.a[7] = n.x() * Eigen::Vector3d(x * yy, x * x / 2, 0);
  f.phi[8] = Eigen::Vector3d(x * x * z / 2, 0, 0);
  f.a[8] = n.x() * Eigen::Vector3d(x * z, 0, x * x / 2);
  f.phi[9] = Eigen::Vector3d(0, yy * yy * z / 2, 0);
  f.a[9] = n.y() * Eigen::Vector3d(0, yy * z, yy * yy / 2);
  return f;
}

/// Φ·n of each moment's field (div Φ = φ) at y, n = X_u × X_v.
Moments fluxes(const Eigen::Vector3d& y, const Eigen::Vector3d& n) {
  Moments f;
  f << y.dot(n) / 3,  //
      y.x() * y.x() * n.x() / 2, y.y() * y.y() * n.y() / 2, y.z() * y.z() * n.z() / 2,
      y.x() * y.x() * y.x() * n.x() / 3, y.y() * y.y() * y.y() * n.y() / 3,
      y.z() * y.z() * y.z() * n.z() / 3, y.x() * y.x() * y.y() * n.x() / 2,
      y.x() * y.x() * y.z() * n.x() / 2, y.y() * y.y() * y.z() * n.y() / 2;
  return f;
}

using detail::Node;

/// adaptive_vector on the ten moments.
template <class F>
Moments adaptive_moments(double a, double b, F&& f, const Moments& tol, Budget& budget,
                         std::vector<Node>& record) {
  return detail::adaptive_vector(a, b, std::forward<F>(f), tol, budget, record);
}

/// ∫_a^u Φ·n ds at v (F of Green's theorem for every moment), appending its nodes to rec: Gauss
/// with ceil(5p / 2) points per knot span of u on a polynomial surface (exact: the second
/// moments' integrand has degree 5p − 1 in u), adaptive on a rational one.
Moments inner(const surface::BSplineSurface& s, const Eigen::Vector3d& c, double a, double u,
              double v, const Moments& tol, Budget& budget, std::vector<Node>* rec) {
  u = std::clamp(u, s.u.domain().first, s.u.domain().second);
  v = std::clamp(v, s.v.domain().first, s.v.domain().second);
  const double lo = std::min(a, u), hi = std::max(a, u);
  if (hi == lo) return Moments::Zero();
  const double sign = u >= a ? 1 : -1;
  const auto spans = breaks(s.u, lo, hi);
  const detail::Isocurve iso(s, v, lo, hi);  // v is fixed along the integral
  auto integrand = [&](double x, std::vector<Node>* r) -> Moments {
    if (r) r->push_back({x, v, 1});
    Eigen::Vector3d point, du, dv;
    iso.at(x, point, du, dv);
    return fluxes(point - c, du.cross(dv));
  };
  Moments sum = Moments::Zero();
  std::vector<Node> nodes;
  for (std::size_t k = 0; k + 1 < spans.size(); ++k) {
    if (s.is_rational()) {
      sum += adaptive_moments(spans[k], spans[k + 1], integrand, tol, budget, nodes);
    } else {
      const auto& g = rule(std::clamp((5 * s.u.degree + 1) / 2, 1, 64));
      const double half = 0.5 * (spans[k + 1] - spans[k]), mid = 0.5 * (spans[k] + spans[k + 1]);
      for (std::size_t i = 0; i < g.nodes.size(); ++i) {
        const std::size_t first = nodes.size();
        sum += g.weights[i] * half * integrand(mid + half * g.nodes[i], &nodes);
        nodes[first].w = g.weights[i] * half;
      }
    }
  }
  if (rec)
    for (Node n : nodes) rec->push_back({n.u, n.v, sign * n.w});
  return sign * sum;
}

/// One face's quadrature nodes (their weights carry the loop's orientation and the face's), and
/// whether its integration converged.
struct FaceRule {
  std::vector<Node> nodes;
  Moments value = Moments::Zero();  // the moments the nodes integrate (their accepted sums)
  Budget budget;
};

FaceRule face_rule(const Model& m, const Face& face, const Eigen::Vector3d& centre,
                   const Moments& tol) {
  FaceRule out;
  out.budget.intervals = detail::face_budget(face.surface);
  const surface::BSplineSurface& s = face.surface;
  const double u0 = s.u.domain().first, u1 = s.u.domain().second;
  const double v0 = s.v.domain().first, v1 = s.v.domain().second;
  const Moments tol_inner = tol / std::max(v1 - v0, 1e-300);
  if (face.loops.empty()) {
    // The whole domain: along its right side (the left one has F = 0, the others dv = 0).
    const auto spans = breaks(s.v, v0, v1);
    for (std::size_t k = 0; k + 1 < spans.size(); ++k)
      out.value += adaptive_moments(
          spans[k], spans[k + 1],
          [&](double v, std::vector<Node>* rec) {
            return inner(s, centre, u0, u1, v, tol_inner, out.budget, rec);
          },
          tol, out.budget, out.nodes);
  } else {
    for (const Loop& loop : face.loops)
      for (const Coedge& co : loop.coedges) {
        const Edge& e = m.edges[static_cast<std::size_t>(co.edge)];
        const double d0 = co.pcurve.basis.domain().first, d1 = co.pcurve.basis.domain().second;
        auto integrand = [&](double t, std::vector<Node>* rec) -> Moments {
          const surface::CurveDerivatives q =
              surface::derivatives(co.pcurve, std::clamp(t, d0, d1), 1);
          if (q.d1.y() == 0.0) return Moments::Zero();
          const std::size_t first = rec ? rec->size() : 0;
          const Moments f =
              inner(s, centre, u0, q.point.x(), q.point.y(), tol_inner, out.budget, rec);
          if (rec)
            for (std::size_t k = first; k < rec->size(); ++k) (*rec)[k].w *= q.d1.y();
          return f * q.d1.y();
        };
        const auto pieces = detail::with_knot_crossings(
            co.pcurve, breaks(co.pcurve.basis, e.t0, e.t1), s.v, d0, d1);
        const std::size_t first = out.nodes.size();
        Moments along = Moments::Zero();
        for (std::size_t k = 0; k + 1 < pieces.size(); ++k)
          along +=
              adaptive_moments(pieces[k], pieces[k + 1], integrand, tol, out.budget, out.nodes);
        out.value += co.same_sense ? along : Moments(-along);
        if (!co.same_sense)
          for (std::size_t k = first; k < out.nodes.size(); ++k) out.nodes[k].w = -out.nodes[k].w;
      }
  }
  if (face.reversed) {
    out.value = -out.value;
    for (Node& n : out.nodes) n.w = -n.w;
  }
  return out;
}

/// A face's moments and, when asked, their gradients with respect to its control points (one
/// n x 3 matrix per moment) and to the reference point c.
struct FaceMoments {
  Moments value = Moments::Zero();
  std::array<Eigen::MatrixX3d, 10> gradient;
  Eigen::Matrix<double, 10, 3> centre = Eigen::Matrix<double, 10, 3>::Zero();
  Budget budget;
};

FaceMoments face_moments(const Model& m, const Face& face, const Eigen::Vector3d& centre,
                         const Moments& tol, bool gradients) {
  const FaceRule r = face_rule(m, face, centre, tol);
  const surface::BSplineSurface& s = face.surface;
  FaceMoments out;
  out.budget = r.budget;
  out.value = r.value;
  if (!gradients) return out;
  // P_k -> P_k + e moves the flux ∬ Φ(y)·(X_u × X_v) by
  // ∬ R_k e·(∇Φᵀ n) + R_k,u e·(X_v × Φ) + R_k,v e·(Φ × X_u), and c -> c + e by −∬ e·(∇Φᵀ n).
  using Block = Eigen::Matrix<double, 10, 3>;
  out.gradient = detail::control_point_gradients<10>(
      s, r.nodes, [&](const detail::Isocurve::Point& at, double w, Block& a, Block& b, Block& c) {
        const Fields f = fields(at.point - centre, at.du.cross(at.dv));
        for (int m2 = 0; m2 < 10; ++m2) {
          const auto i2 = static_cast<std::size_t>(m2);
          a.row(m2) = w * f.a[i2].transpose();
          b.row(m2) = w * at.dv.cross(f.phi[i2]).transpose();
          c.row(m2) = w * f.phi[i2].cross(at.du).transpose();
        }
        out.centre -= a;
      });
  return out;
}

/// The moments of the solids `bodies` about their common centre c, their gradients, and the
/// gradient of c itself (what its points' rows of `unit_centre` times a vector give).
struct Totals {
  Eigen::Vector3d centre;
  Moments value = Moments::Zero();
  std::array<PointGradients, 10> gradient;
  detail::CentrePoints centre_points;
  long centre_count = 0;           // how many points c is the mean of
  std::vector<Eigen::Index> rows;  // per face: its control points when measured, else 0
};

/// A gradient that is `d` at c, spread over the points c is the mean of (d / count each).
PointGradients through_centre(const Model& m, const Totals& t, const Eigen::Vector3d& d) {
  PointGradients out;
  for (Eigen::Index n : t.rows) out.faces.push_back(Eigen::MatrixX3d::Zero(n, 3));
  out.vertices = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(m.vertices.size()), 3);
  if (t.centre_count == 0) return out;
  const Eigen::RowVector3d share = d.transpose() / static_cast<double>(t.centre_count);
  for (int v : t.centre_points.vertices) out.vertices.row(v) += share;
  for (int f : t.centre_points.faces) out.faces[static_cast<std::size_t>(f)].rowwise() += share;
  return out;
}

Totals totals(const Model& m, const std::vector<int>& bodies, const std::vector<int>& shape,
              bool gradients) {
  Totals out;
  out.centre = detail::body_centre(m, bodies);
  out.centre_points = detail::centre_points(m, bodies);
  out.centre_count = static_cast<long>(out.centre_points.vertices.size());
  for (int f : out.centre_points.faces)
    out.centre_count +=
        static_cast<long>(m.faces[static_cast<std::size_t>(f)].surface.points.rows());
  const double d = std::cbrt(detail::size_cubed(m));
  Moments tol;
  tol << std::pow(d, 3), Eigen::Matrix<double, 3, 1>::Constant(std::pow(d, 4)),
      Eigen::Matrix<double, 6, 1>::Constant(std::pow(d, 5));
  tol *= 1e-14;
  std::vector<bool> measured(m.faces.size(), false);
  for (int b : bodies)
    for (const Shell& shell : m.bodies[static_cast<std::size_t>(b)].shells)
      for (int f : shell.faces) measured[static_cast<std::size_t>(f)] = true;
  // The gradients' rows: every face of the `shape` solids (those measured together), so the
  // solids' own gradients add up.
  std::vector<bool> shaped(m.faces.size(), false);
  for (int b : shape)
    for (const Shell& shell : m.bodies[static_cast<std::size_t>(b)].shells)
      for (int f : shell.faces) shaped[static_cast<std::size_t>(f)] = true;
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    out.rows.push_back(shaped[f] ? m.faces[f].surface.points.rows() : 0);
  std::vector<FaceMoments> face(m.faces.size());
  const std::size_t parts = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1,
                                                    std::max<std::size_t>(1, m.faces.size()));
  run_on_threads(parts, [&](std::size_t part) {
    for (std::size_t f = part; f < m.faces.size(); f += parts)
      if (measured[f]) face[f] = face_moments(m, m.faces[f], out.centre, tol, gradients);
  });
  std::string failed;
  int count = 0;
  for (std::size_t f = 0; f < face.size(); ++f) {
    if (!face[f].budget.converged && ++count <= 5)
      failed += (failed.empty() ? "" : ", ") + std::to_string(f);
    out.value += face[f].value;
  }
  if (count > 0)
    throw Error(
        ErrorCategory::ToleranceNotMet,
        "mass_properties: the integration did not converge on " + std::to_string(count) +
            " face(s) (" + failed + (count > 5 ? ", ..." : "") +
            ") within its budget of quadrature intervals: a surface with extreme weights "
            "or a near-singular parametrization; rebuild those faces with moderate weights");
  if (gradients) {
    Eigen::Matrix<double, 10, 3> centre = Eigen::Matrix<double, 10, 3>::Zero();
    for (const FaceMoments& f : face) centre += f.centre;
    for (std::size_t k = 0; k < 10; ++k) {
      // c's own gradient, spread over its points, then the faces' control points' own
      PointGradients g =
          through_centre(m, out, centre.row(static_cast<Eigen::Index>(k)).transpose());
      for (std::size_t f = 0; f < m.faces.size(); ++f)
        if (measured[f]) g.faces[f] += face[f].gradient[k];
      out.gradient[k] = std::move(g);
    }
  }
  return out;
}

/// The sum a0 g0 + a1 g1 + ... of gradients with the same shapes.
PointGradients combine(std::initializer_list<std::pair<double, const PointGradients*>> terms) {
  PointGradients out = *terms.begin()->second;
  for (auto& g : out.faces) g *= terms.begin()->first;
  out.vertices *= terms.begin()->first;
  for (auto it = terms.begin() + 1; it != terms.end(); ++it) {
    for (std::size_t f = 0; f < out.faces.size(); ++f)
      out.faces[f] += it->first * it->second->faces[f];
    out.vertices += it->first * it->second->vertices;
  }
  return out;
}

/// Volume, centroid and inertia from the moments about c: centroid g = c + M1 / V, second
/// moments about it S' = S − M1 M1ᵀ / V, inertia tr(S') 1 − S'; their gradients by the chain rule
/// when the moments have them.
MassPropertyGradients assemble(const Model& m, const Totals& t, bool gradients) {
  MassPropertyGradients out;
  const double volume = t.value[0];
  if (!(std::isfinite(volume) && volume != 0))
    throw Error(ErrorCategory::InvalidGeometry,
                "mass_properties: the solids enclose a volume of " + std::to_string(volume) +
                    " mm^3, so their centroid and inertia are undefined; measure closed solids "
                    "with volume (brep::problems names open shells)");
  const Eigen::Vector3d first = t.value.segment<3>(1);
  Eigen::Matrix3d second;
  second << t.value[4], t.value[7], t.value[8],  //
      t.value[7], t.value[5], t.value[9],        //
      t.value[8], t.value[9], t.value[6];
  const Eigen::Matrix3d about = second - first * first.transpose() / volume;
  out.value.volume_mm3 = volume;
  out.value.centroid_mm = t.centre + first / volume;
  out.value.inertia_mm5 = about.trace() * Eigen::Matrix3d::Identity() - about;
  if (!gradients) return out;
  out.volume = t.gradient[0];
  for (int i = 0; i < 3; ++i) {  // d(c_i + M1_i / V) = dc_i + dM1_i / V − M1_i dV / V²
    const PointGradients own = through_centre(m, t, Eigen::Vector3d::Unit(i));
    out.centroid[static_cast<std::size_t>(i)] =
        combine({{1.0, &own},
                 {1 / volume, &t.gradient[static_cast<std::size_t>(1 + i)]},
                 {-first[i] / (volume * volume), &t.gradient[0]}});
  }
  // dS'_ij = dS_ij − (dM1_i M1_j + M1_i dM1_j) / V + M1_i M1_j dV / V²
  const std::array<std::array<int, 3>, 3> slot{{{4, 7, 8}, {7, 5, 9}, {8, 9, 6}}};
  auto d_about = [&](int i, int j) {
    return combine({{1.0, &t.gradient[static_cast<std::size_t>(slot[i][j])]},
                    {-first[j] / volume, &t.gradient[static_cast<std::size_t>(1 + i)]},
                    {-first[i] / volume, &t.gradient[static_cast<std::size_t>(1 + j)]},
                    {first[i] * first[j] / (volume * volume), &t.gradient[0]}});
  };
  const PointGradients sxx = d_about(0, 0), syy = d_about(1, 1), szz = d_about(2, 2);
  out.inertia[0] = combine({{1.0, &syy}, {1.0, &szz}});
  out.inertia[1] = combine({{1.0, &sxx}, {1.0, &szz}});
  out.inertia[2] = combine({{1.0, &sxx}, {1.0, &syy}});
  const PointGradients sxy = d_about(0, 1), sxz = d_about(0, 2), syz = d_about(1, 2);
  out.inertia[3] = combine({{-1.0, &sxy}});
  out.inertia[4] = combine({{-1.0, &sxz}});
  out.inertia[5] = combine({{-1.0, &syz}});
  return out;
}

/// The solids a call measures, checked: `body` alone, or every solid when body < 0.
std::vector<int> measured_bodies(const Model& model, int body, const char* function,
                                 bool check = true) {
  if (check) validate(model);
  const std::string name = function;
  if (model.is_assembly())
    throw Error(ErrorCategory::InvalidArgument,
                name +
                    ": the model is an assembly; measure brep::flattened(model), whose bodies "
                    "are its placed instances");
  std::vector<int> out;
  if (body >= 0) {
    if (body >= static_cast<int>(model.bodies.size()))
      throw Error(ErrorCategory::InvalidArgument,
                  name + ": body " + std::to_string(body) + " does not exist; the model has " +
                      std::to_string(model.bodies.size()) + " bodies");
    if (model.bodies[static_cast<std::size_t>(body)].kind != BodyKind::Solid)
      throw Error(ErrorCategory::InvalidArgument,
                  name + ": body " + std::to_string(body) +
                      " is not a solid (a sheet or wire body encloses no volume); choose a solid");
    out.push_back(body);
  } else {
    for (std::size_t b = 0; b < model.bodies.size(); ++b)
      if (model.bodies[b].kind == BodyKind::Solid) out.push_back(static_cast<int>(b));
    if (out.empty())
      throw Error(ErrorCategory::InvalidArgument,
                  name + ": the model has no solid (" + std::to_string(model.bodies.size()) +
                      " sheet or wire bodies): mass properties need a closed shell");
  }
  return out;
}

/// into += a g (into empty: a g).
void add_to(PointGradients& into, double a, const PointGradients& g) {
  if (into.faces.empty()) {
    into = combine({{a, &g}});
    return;
  }
  for (std::size_t f = 0; f < into.faces.size(); ++f) into.faces[f] += a * g.faces[f];
  into.vertices += a * g.vertices;
}

/// The solids `bodies` measured each about its own reference point (as volume_mm3 measures each
/// body: on a real file's shell with gaps the figure is the flux through its faces, and a common
/// point for several solids changed it, 1e-5 of AutoCAD's solid with voids), then put together:
/// V = Σ V_b, g = Σ V_b g_b / V, I = Σ I_b + V_b (|d_b|² 1 − d_b d_bᵀ), d_b = g_b − g (the
/// parallel-axis theorem), their gradients by the chain rule.
MassPropertyGradients measure(const Model& m, const std::vector<int>& bodies, bool gradients) {
  if (bodies.size() == 1) return assemble(m, totals(m, bodies, bodies, gradients), gradients);
  std::vector<MassPropertyGradients> parts;
  for (int b : bodies) parts.push_back(assemble(m, totals(m, {b}, bodies, gradients), gradients));
  MassPropertyGradients out;
  double volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const auto& p : parts) {
    volume += p.value.volume_mm3;
    moment += p.value.volume_mm3 * p.value.centroid_mm;
  }
  if (!(std::isfinite(volume) && volume != 0))
    throw Error(ErrorCategory::InvalidGeometry,
                "mass_properties: the solids enclose a volume of " + std::to_string(volume) +
                    " mm^3 together, so their centroid and inertia are undefined; measure them "
                    "one by one (a body index)");
  const Eigen::Vector3d g = moment / volume;
  out.value.volume_mm3 = volume;
  out.value.centroid_mm = g;
  for (const auto& p : parts) {
    const Eigen::Vector3d d = p.value.centroid_mm - g;
    out.value.inertia_mm5 +=
        p.value.inertia_mm5 +
        p.value.volume_mm3 * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  if (!gradients) return out;
  for (const auto& p : parts) add_to(out.volume, 1.0, p.volume);
  for (int i = 0; i < 3; ++i) {  // dg_i = Σ (dV_b g_b,i + V_b dg_b,i) / V − g_i dV / V
    PointGradients& dg = out.centroid[static_cast<std::size_t>(i)];
    for (const auto& p : parts) {
      add_to(dg, p.value.centroid_mm[i] / volume, p.volume);
      add_to(dg, p.value.volume_mm3 / volume, p.centroid[static_cast<std::size_t>(i)]);
    }
    add_to(dg, -g[i] / volume, out.volume);
  }
  // dI_ij = Σ dI_b,ij + dV_b E_b,ij + V_b dE_b,ij, E = |d|² δ_ij − d_i d_j, dd = dg_b − dg:
  // dE_ij = 2 Σ_k d_k dd_k δ_ij − dd_i d_j − d_i dd_j.
  const std::array<std::pair<int, int>, 6> entry{{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};
  for (const auto& p : parts) {
    const Eigen::Vector3d d = p.value.centroid_mm - g;
    const double v = p.value.volume_mm3;
    std::array<PointGradients, 3> dd;
    for (std::size_t k = 0; k < 3; ++k)
      dd[k] = combine({{1.0, &p.centroid[k]}, {-1.0, &out.centroid[k]}});
    for (std::size_t e = 0; e < 6; ++e) {
      const auto [i, j] = entry[e];
      const double delta = i == j ? 1.0 : 0.0;
      PointGradients& di = out.inertia[e];
      add_to(di, 1.0, p.inertia[e]);
      add_to(di, delta * d.squaredNorm() - d[i] * d[j], p.volume);
      for (int k = 0; k < 3; ++k) add_to(di, v * 2 * delta * d[k], dd[static_cast<std::size_t>(k)]);
      add_to(di, -v * d[j], dd[static_cast<std::size_t>(i)]);
      add_to(di, -v * d[i], dd[static_cast<std::size_t>(j)]);
    }
  }
  return out;
}

}  // namespace

MassProperties mass_properties(const Model& model) {
  return measure(model, measured_bodies(model, -1, "mass_properties"), false).value;
}

MassProperties mass_properties(const Model& model, int body) {
  if (body < 0)
    throw Error(ErrorCategory::InvalidArgument,
                "mass_properties: body " + std::to_string(body) + " does not exist (negative)");
  return measure(model, measured_bodies(model, body, "mass_properties"), false).value;
}

MassPropertyGradients mass_property_gradients(const Model& model) {
  return measure(model, measured_bodies(model, -1, "mass_property_gradients"), true);
}

MassPropertyGradients mass_property_gradients(const Model& model, int body) {
  if (body < 0)
    throw Error(
        ErrorCategory::InvalidArgument,
        "mass_property_gradients: body " + std::to_string(body) + " does not exist (negative)");
  return measure(model, measured_bodies(model, body, "mass_property_gradients"), true);
}

MassPropertyGradients mass_property_gradients(const Model& model,
                                              const MassPropertyOptions& options) {
  if (options.body && *options.body < 0)
    throw Error(ErrorCategory::InvalidArgument, "mass_property_gradients: body " +
                                                    std::to_string(*options.body) +
                                                    " does not exist (negative)");
  return measure(model,
                 measured_bodies(model, options.body.value_or(-1), "mass_property_gradients",
                                 options.validate),
                 true);
}

}  // namespace clay::brep
