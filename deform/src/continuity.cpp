#include <clay/deform/continuity.hpp>

#include <clay/error.hpp>
#include <clay/surface/basis.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace clay::deform {

namespace {

constexpr const char* face_name[6] = {"s_min", "s_max", "t_min", "t_max", "u_min", "u_max"};

int direction(Face f) { return static_cast<int>(f) / 2; }
bool at_max(Face f) { return static_cast<int>(f) % 2 == 1; }

void check_order(const FaceContinuity& fc, int degree) {
  if (fc.order < 0 || fc.order > degree)
    throw Error(ErrorCategory::InvalidArgument,
                std::string("FaceContinuity{") + face_name[static_cast<int>(fc.face)] +
                    "}.order = " + std::to_string(fc.order) +
                    " breaks the rule 0 <= order <= " + std::to_string(degree) +
                    " (the lattice degree across that face); ask for C^0 up to C^degree");
}

/// Marks every control point whose index along direction d is flagged in `planes`.
void mark(std::vector<bool>& locked, std::array<int, 3> counts, int d,
          const std::vector<bool>& planes) {
  for (int i = 0; i < counts[0]; ++i)
    for (int j = 0; j < counts[1]; ++j)
      for (int k = 0; k < counts[2]; ++k) {
        const int idx[3] = {i, j, k};
        if (planes[static_cast<size_t>(idx[d])])
          locked[static_cast<size_t>((i * counts[1] + j) * counts[2] + k)] = true;
      }
}

}  // namespace

std::vector<bool> locked_control_points(const BezierLattice& lattice,
                                        std::span<const FaceContinuity> faces) {
  validate(lattice);
  const auto counts = lattice.counts();
  std::vector<bool> locked(static_cast<size_t>(counts[0] * counts[1] * counts[2]), false);
  for (const FaceContinuity& fc : faces) {
    const int d = direction(fc.face);
    const int p = lattice.degrees[static_cast<size_t>(d)];
    check_order(fc, p);
    // Sederberg–Parry §3.1: C^k needs the face plane and the k planes next to it undisplaced.
    std::vector<bool> planes(static_cast<size_t>(p + 1), false);
    for (int r = 0; r <= fc.order; ++r)
      planes[static_cast<size_t>(at_max(fc.face) ? p - r : r)] = true;
    mark(locked, counts, d, planes);
  }
  return locked;
}

std::vector<bool> locked_control_points(const BSplineLattice& lattice,
                                        std::span<const FaceContinuity> faces) {
  validate(lattice);
  const auto counts = lattice.counts();
  std::vector<bool> locked(static_cast<size_t>(counts[0] * counts[1] * counts[2]), false);
  for (const FaceContinuity& fc : faces) {
    const int d = direction(fc.face);
    const surface::BSplineBasis& basis = lattice.bases[static_cast<size_t>(d)];
    const int p = basis.degree;
    check_order(fc, p);
    // A plane must stay when its basis function has a non-zero derivative of order <= k on the
    // face (the derivatives of the map across the face then equal the identity's).
    const double x = at_max(fc.face) ? 1.0 : 0.0;
    const int span = surface::find_span(basis, x);
    std::vector<double> ders(static_cast<size_t>((fc.order + 1) * (p + 1)));
    surface::basis_derivatives(basis, span, x, fc.order, ders);
    std::vector<bool> planes(static_cast<size_t>(basis.count()), false);
    for (int r = 0; r <= fc.order; ++r) {
      double largest = 0;
      for (int q = 0; q <= p; ++q)
        largest = std::max(largest, std::abs(ders[static_cast<size_t>(r * (p + 1) + q)]));
      for (int q = 0; q <= p; ++q)
        if (std::abs(ders[static_cast<size_t>(r * (p + 1) + q)]) > 1e-12 * largest)
          planes[static_cast<size_t>(span - p + q)] = true;
    }
    mark(locked, counts, d, planes);
  }
  return locked;
}

namespace {

template <class Lattice>
Lattice reset(Lattice lattice, std::span<const FaceContinuity> faces) {
  const std::vector<bool> locked = locked_control_points(lattice, faces);
  const Points3 rest = undisplaced_points(lattice);
  for (size_t r = 0; r < locked.size(); ++r)
    if (locked[r])
      lattice.points.row(static_cast<Eigen::Index>(r)) = rest.row(static_cast<Eigen::Index>(r));
  return lattice;
}

}  // namespace

BezierLattice with_continuity(BezierLattice lattice, std::span<const FaceContinuity> faces) {
  return reset(std::move(lattice), faces);
}

BSplineLattice with_continuity(BSplineLattice lattice, std::span<const FaceContinuity> faces) {
  return reset(std::move(lattice), faces);
}

}  // namespace clay::deform
