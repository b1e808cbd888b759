#pragma once
/// Fast deformation of many points (Güdükbay–Özgüç 1990 §3.2): the lattice's Bernstein form is
/// converted once to power-basis (monomial) coefficients per Bézier cell, and each point is
/// deformed by nested Horner evaluation in u, t, s.
///
/// How (docs/deform.md): points are processed in blocks of 8 as structure-of-arrays with the
/// coefficients broadcast, in a kernel compiled for AVX-512, AVX2+FMA and baseline x86-64 and
/// chosen at run time (GCC target_clones), on std::thread workers over contiguous ranges. For a
/// B-spline lattice each worker sorts a chunk of points by cell (a counting sort; uniform breaks
/// are found by arithmetic, others by binary search) so that every block shares one cell's
/// coefficients. Nothing is allocated per point.
#include <clay/deform/deformation.hpp>
#include <clay/deform/export.hpp>
#include <clay/deform/lattice.hpp>

#include <Eigen/Core>

#include <array>
#include <span>
#include <vector>

namespace clay::deform {

/// A lattice prepared for fast evaluation: the frame's dual vectors and the power-basis
/// coefficients of every Bézier cell. Build it once and deform many point sets with it; it is an
/// immutable value (copyable, safe to share between threads).
class CLAY_DEFORM_API FrozenLattice {
 public:
  /// Freezes a Bézier lattice (one cell). Throws clay::Error(InvalidGeometry) for an invalid one.
  explicit FrozenLattice(const BezierLattice& lattice);
  /// Freezes a B-spline lattice (its Bézier cells). Throws clay::Error(InvalidGeometry) for an
  /// invalid one.
  explicit FrozenLattice(const BSplineLattice& lattice);

  /// Degrees along S, T, U.
  const std::array<int, 3>& degrees() const noexcept { return degrees_; }
  /// Number of cells along S, T, U (1, 1, 1 for a Bézier lattice).
  std::array<int, 3> cells() const noexcept {
    return {static_cast<int>(breaks_[0].size()) - 1, static_cast<int>(breaks_[1].size()) - 1,
            static_cast<int>(breaks_[2].size()) - 1};
  }
  /// The frame of the lattice.
  const Frame& frame() const noexcept { return frame_; }

 private:
  friend struct FrozenLatticeAccess;  // the kernels in frozen_lattice.cpp
  Frame frame_;
  std::array<Eigen::Vector3d, 3> dual_{};  // (T×U)/(T×U·S), (U×S)/(U×S·T), (S×T)/(S×T·U)
  std::array<int, 3> degrees_{};
  std::array<std::vector<double>, 3> breaks_;  // cell boundaries in [0, 1] per direction
  std::array<std::vector<double>, 3> inverse_width_;
  std::array<bool, 3> uniform_{};  // breaks equally spaced: arithmetic cell lookup
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();  // coefficients are relative to this point
  std::vector<double> coefficients_;  // per cell, per coordinate, power coefficients, s-major
};

/// Deformed position of x by the frozen power form (one point; the bulk functions are faster).
CLAY_DEFORM_API Eigen::Vector3d deform_point(const FrozenLattice& lattice,
                                             const Eigen::Vector3d& x);

/// Deforms every row of `points` (N x 3, row-major, mm); rows outside the lattice are copied
/// unchanged. Throws clay::Error(InvalidArgument) for bad options.
CLAY_DEFORM_API Points3 deform_points(const FrozenLattice& lattice, const Points3& points,
                                      const DeformOptions& options = {});

/// Same into `out` (resized to points.rows() x 3 when needed, so a reused buffer costs no
/// allocation). `out` may be `points` itself.
CLAY_DEFORM_API void deform_points(const FrozenLattice& lattice, const Points3& points,
                                   Points3& out, const DeformOptions& options = {});

/// Structure-of-arrays form: writes the deformed in[i] to out[i]. `out` may be `in` itself.
/// Throws clay::Error(InvalidArgument) for columns of different sizes or bad options.
CLAY_DEFORM_API void deform_points(const FrozenLattice& lattice, PointColumns in,
                                   MutablePointColumns out, const DeformOptions& options = {});

/// Interleaved form, no copy: `in` and `out` hold x, y, z of each point in turn (3 N doubles,
/// an N x 3 row-major buffer such as a NumPy (N, 3) float64 array). `out` may be `in` itself.
/// Throws clay::Error(InvalidArgument) for sizes that differ or are not a multiple of 3.
CLAY_DEFORM_API void deform_points(const FrozenLattice& lattice, std::span<const double> in,
                                   std::span<double> out, const DeformOptions& options = {});

/// One-off: freezes the lattice and deforms the points (Sederberg–Parry eq. (2)).
CLAY_DEFORM_API Points3 deform_points(const BezierLattice& lattice, const Points3& points,
                                      const DeformOptions& options = {});
/// One-off: freezes the lattice and deforms the points (Hsu–Hughes–Kaufman eq. (1)).
CLAY_DEFORM_API Points3 deform_points(const BSplineLattice& lattice, const Points3& points,
                                      const DeformOptions& options = {});

}  // namespace clay::deform
