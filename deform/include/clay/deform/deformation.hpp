#pragma once
/// What every deformation of space offers, so that lattices, and later extended lattices,
/// regular deformations and deformation stacks, can be used alike: a one-off
/// `deform_point(d, x)` and a bulk `deform_points(d, points, options)` on an N x 3 row-major
/// matrix (and on structure-of-arrays columns). The PointDeformation concept checks both.
#include <clay/deform/export.hpp>
#include <clay/parallel.hpp>
#include <clay/surface/bspline_curve.hpp>

#include <Eigen/Core>

#include <concepts>
#include <span>
#include <string>
#include <vector>

namespace clay::deform {

/// Settings of deform_points().
struct CLAY_DEFORM_API DeformOptions {
  int threads = 0;  ///< parts the points are split into, 0..1024; 0 = one per hardware thread.
                    ///< Fewer are used when there are few points (at least 16,384 per part).
  /// Who runs the parts: empty = parts − 1 new std::threads plus the calling thread
  /// (clay::run_on_threads); an embedder hands in its own pool here (clay/parallel.hpp).
  Executor executor = {};

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// Read-only structure-of-arrays points: x[i], y[i], z[i] (mm), three spans of equal size.
struct PointColumns {
  std::span<const double> x, y, z;  ///< coordinates (mm), same size
};

/// Writable structure-of-arrays points, three spans of equal size. May be the very same buffers
/// as the input of deform_points (in-place), but must not overlap them otherwise.
struct MutablePointColumns {
  std::span<double> x, y, z;  ///< coordinates (mm), same size
};

/// A deformation of space: one point at a time and many at once.
template <class D>
concept PointDeformation = requires(const D& d, const Eigen::Vector3d& x,
                                    const surface::Points3& points, const DeformOptions& options) {
  { deform_point(d, x) } -> std::convertible_to<Eigen::Vector3d>;
  { deform_points(d, points, options) } -> std::convertible_to<surface::Points3>;
};

}  // namespace clay::deform
