// composition_jacobian (derivatives.hpp, issue #41): Sederberg–Parry eq. (2) composed with each
// Bézier patch of a surface as compose_exact's tensor route does (compose_factors.hpp), with the
// lattice's points replaced by unit vectors, one channel per lattice point.
#include <clay/deform/derivatives.hpp>
#include <clay/error.hpp>
#include <clay/surface/knots.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "bernstein_poly.hpp"
#include "cell_extraction.hpp"
#include "compose_factors.hpp"
#include "patch_containment.hpp"

namespace clay::deform {

namespace {

using detail::Poly;

/// Eq. (2) on one patch for every lattice point at once: channel j of the result holds the
/// homogeneous Bernstein coefficients of B_j(s, t, u) · W^(l+m+n) (u innermost, then t, then s,
/// as compose_exact). Unscaled.
Poly compose_channels(const BezierLattice& lattice, const std::array<detail::Factor, 3>& f) {
  const auto n = lattice.counts();
  const int channels = n[0] * n[1] * n[2];
  std::vector<Poly> along_s;
  for (int i = 0; i < n[0]; ++i) {
    std::vector<Poly> along_t;
    for (int j = 0; j < n[1]; ++j) {
      std::vector<Poly> along_u;
      for (int k = 0; k < n[2]; ++k) {
        Poly unit(0, 0, channels);
        unit.c[static_cast<std::size_t>(lattice.index(i, j, k))] = 1;
        along_u.push_back(std::move(unit));
      }
      along_t.push_back(detail::casteljau(std::move(along_u), f[2]));
    }
    along_s.push_back(detail::casteljau(std::move(along_t), f[1]));
  }
  Poly h = detail::casteljau(std::move(along_s), f[0]);
  detail::scale(h, true);
  return h;
}

/// One composed patch: channel c of `h` is the coefficient of lattice point columns[c].
struct PatchColumns {
  Poly h;
  std::vector<int> columns;
};

/// The patches joined as join_bezier_patches joins them: each elevated to the largest degrees,
/// the homogeneous points that neighbours share summed. A composed point's weight is the sum of
/// its channels (the B_j sum to 1, so eq. (2) with every point's weight 1 gives W^(l+m+n)), and
/// its control point is H_r / W_r: row r of C is the summed channels over the summed weights.
CompositionJacobian join_columns(const surface::BezierPatches& bp,
                                 const std::vector<PatchColumns>& patches, const Points3& points,
                                 bool rational) {
  int pu = 1, pv = 1;
  for (const PatchColumns& p : patches) {
    pu = std::max(pu, p.h.du);
    pv = std::max(pv, p.h.dv);
  }
  const int cu = bp.count_u(), cv = bp.count_v();
  const int nu = cu * pu + 1, nv = cv * pv + 1;
  const Eigen::Index rows = static_cast<Eigen::Index>(nu) * nv;
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(rows);
  Eigen::VectorXi shared = Eigen::VectorXi::Zero(rows);
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b) {
      const PatchColumns& p = patches[static_cast<std::size_t>(a * cv + b)];
      const Poly h = detail::to_degree(detail::to_degree(p.h, pu, 0), pv, 1);
      for (int i = 0; i <= pu; ++i)
        for (int j = 0; j <= pv; ++j) {
          const Eigen::Index r = static_cast<Eigen::Index>(a * pu + i) * nv + (b * pv + j);
          ++shared(r);
          for (int c = 0; c < h.dim; ++c) {
            const double x = h.at(i, j, c);
            weight(r) += x;
            if (x != 0)
              entries.emplace_back(static_cast<int>(r), p.columns[static_cast<std::size_t>(c)], x);
          }
        }
    }
  CompositionJacobian out;
  out.matrix.resize(rows, points.rows());
  out.matrix.setFromTriplets(entries.begin(), entries.end());
  out.matrix = weight.cwiseInverse().asDiagonal() * out.matrix;
  out.surface.u = {pu, surface::c0_knots(bp.breaks_u, pu)};
  out.surface.v = {pv, surface::c0_knots(bp.breaks_v, pv)};
  out.surface.points = out.matrix * points;
  out.surface.weights = rational ? Eigen::VectorXd(weight.cwiseQuotient(shared.cast<double>()))
                                 : Eigen::VectorXd::Ones(rows);
  return out;
}

}  // namespace

CompositionJacobian composition_jacobian(const BezierLattice& lattice,
                                         const surface::BSplineSurface& surface) {
  validate(lattice, "composition_jacobian: Bézier lattice");
  surface::validate(surface, "composition_jacobian: surface");
  const auto bp = surface::extract_bezier(surface);
  const auto dual = detail::dual_vectors(lattice.frame);
  const int cu = bp.count_u(), cv = bp.count_v();
  std::vector<int> every(static_cast<std::size_t>(lattice.points.rows()));
  for (std::size_t j = 0; j < every.size(); ++j) every[j] = static_cast<int>(j);
  std::vector<PatchColumns> patches(bp.patches.size());
  for (int a = 0; a < cu; ++a)
    for (int b = 0; b < cv; ++b) {
      const auto pc = detail::patch_coordinates(bp.patch(a, b), lattice.frame.origin, dual);
      for (int d = 0; d < 3; ++d)
        if (const auto v = detail::leaves(detail::ratio_poly(pc, d), 0, 1, face_tolerance))
          detail::throw_leaves_lattice(bp, a, b, d, *v, "Bézier lattice", "composition_jacobian");
      patches[static_cast<std::size_t>(a * cv + b)] = {
          compose_channels(lattice, detail::cell_factors(pc, {0, 0, 0}, {1, 1, 1})), every};
    }
  return join_columns(bp, patches, lattice.points, surface.is_rational());
}

CompositionJacobian composition_jacobian(const BSplineLattice& lattice,
                                         const surface::BSplineSurface& surface) {
  validate(lattice, "composition_jacobian: B-spline lattice");
  surface::validate(surface, "composition_jacobian: surface");
  const BezierCells cells = bezier_cells(lattice);
  const detail::LatticePatches located =
      detail::locate_patches(lattice, cells, surface, "composition_jacobian");
  std::array<std::vector<surface::SpanExtraction>, 3> spans;
  for (std::size_t d = 0; d < 3; ++d) spans[d] = surface::bezier_extraction(lattice.bases[d]);
  std::vector<PatchColumns> patches(located.bp.patches.size());
  for (std::size_t k = 0; k < patches.size(); ++k) {
    const auto [ci, cj, ck] = located.cells[k];
    const BezierLattice& cell = cells.cell(ci, cj, ck);
    const Poly local = compose_channels(cell, located.factors[k]);
    // The cell's channels map to the lattice points of its support through its extraction.
    const detail::CellExtraction e = detail::cell_extraction(lattice, cell, spans, ci, cj, ck);
    const auto m = static_cast<int>(cell.points.rows());
    PatchColumns out{Poly(local.du, local.dv, m), e.points};
    using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const Eigen::Index coefficients = static_cast<Eigen::Index>(local.du + 1) * (local.dv + 1);
    Eigen::Map<Rows>(out.h.c.data(), coefficients, m) =
        Eigen::Map<const Rows>(local.c.data(), coefficients, m) * e.matrix;
    patches[k] = std::move(out);
  }
  return join_columns(located.bp, patches, lattice.points, located.split.is_rational());
}

}  // namespace clay::deform
