#pragma once
/// Projection of a point onto a surface: the local foot point from a start (normal projection)
/// and the global closest point.
///
/// Both minimize |S(u,v) - P|^2 over the parameter domain by Newton's method on the gradient
/// (S_u.r, S_v.r) with the full Hessian (S_u.S_u + S_uu.r, ...), a backtracking line search and
/// bound constraints, so a foot point on a domain edge is found as such (a Karush–Kuhn–Tucker
/// point), not by silently clamping the answer.
#include <clay/summary.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace clay::surface {

/// Settings of project_normal and closest_point.
struct CLAY_SURFACE_API ProjectionOptions {
  int max_iterations = 50;              ///< Newton iterations per start, >= 1
  double parametric_tolerance = 1e-14;  ///< step size below which Newton stops (relative to domain)
  double cosine_tolerance = 1e-12;  ///< |cos| between S_u or S_v and S - P that counts as normal
  int samples_per_span = 4;         ///< closest_point: start grid density per knot span, >= 1
  int starts = 4;                   ///< closest_point: Newton runs from the best grid samples, >= 1

  /// Field by field (the recipe's cache of style editors compares settings).
  bool operator==(const ProjectionOptions&) const = default;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// A projected point: its parameters, the surface point, the distance and how Newton ended.
struct SurfaceProjection {
  double u = 0, v = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance = 0;
  bool on_boundary = false;  ///< the foot point lies on the domain edge (gradient points outside)
  Summary summary;
};

/// The foot point of `point` reached by Newton from (u0, v0): a point where S - P is normal to the
/// surface (or a constrained minimum on the domain edge). Throws clay::Error: OutOfDomain for a
/// start outside the domain, InvalidGeometry for an invalid surface or a non-finite point.
CLAY_SURFACE_API SurfaceProjection project_normal(const BSplineSurface& surface,
                                                  const Eigen::Vector3d& point, double u0,
                                                  double v0, const ProjectionOptions& options = {});

/// The closest point of the surface to `point`: Newton from the best samples of a grid of
/// samples_per_span points per knot span, the nearest result kept. Throws as project_normal.
CLAY_SURFACE_API SurfaceProjection closest_point(const BSplineSurface& surface,
                                                 const Eigen::Vector3d& point,
                                                 const ProjectionOptions& options = {});

/// A surface prepared for many projections: validated once, with the start grid of
/// closest_point evaluated once, on the first closest_point (so a projector used only for
/// project_normal costs no grid). Same results as the free functions (bit for bit). An immutable
/// value: copyable (copies share the grid) and safe to share between threads. A moved-from
/// projector throws InvalidArgument from closest_point until a projector is assigned to it.
class CLAY_SURFACE_API SurfaceProjector {
 public:
  /// Copies and validates the surface. Throws clay::Error: InvalidGeometry for an invalid
  /// surface, InvalidArgument for bad options.
  explicit SurfaceProjector(BSplineSurface surface, const ProjectionOptions& options = {});

  /// The surface projected onto.
  const BSplineSurface& surface() const noexcept { return surface_; }
  /// The options in use.
  const ProjectionOptions& options() const noexcept { return options_; }

  /// As the free project_normal(surface, point, u0, v0, options).
  SurfaceProjection project_normal(const Eigen::Vector3d& point, double u0, double v0) const;
  /// As the free closest_point(surface, point, options).
  SurfaceProjection closest_point(const Eigen::Vector3d& point) const;

 private:
  struct StartGrid;
  const StartGrid& start_grid() const;

  BSplineSurface surface_;
  ProjectionOptions options_;
  double size_ = 0;                  // diagonal of the control box
  std::shared_ptr<StartGrid> grid_;  // evaluated once, on first use
};

// ---- curves ---------------------------------------------------------------------------------

/// A point projected onto a curve: its parameter, the curve point and the distance.
struct CurveProjection {
  double t = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance = 0;
};

/// The foot point of `point` on the curve by Newton's method on (C − P) · C' = 0 from t0 (the
/// full second-order step where the Hessian is safely positive, Gauss–Newton elsewhere), with a
/// backtracking line search, so the distance never increases from t0's. An open curve keeps t in
/// its domain (a foot beyond an end is the end); `periodic` wraps t around the domain (a closed,
/// periodic curve). Throws clay::Error(InvalidGeometry) for an invalid curve or a non-finite point.
CLAY_SURFACE_API CurveProjection project_normal(const BSplineCurve& curve,
                                                const Eigen::Vector3d& point, double t0,
                                                bool periodic = false);

/// The closest point of the curve to `point`: Newton (project_normal) from the three best of
/// `samples_per_span` samples per knot span (>= 1), the nearest foot kept. Throws as
/// project_normal, and InvalidArgument for samples_per_span < 1.
CLAY_SURFACE_API CurveProjection closest_point(const BSplineCurve& curve,
                                               const Eigen::Vector3d& point,
                                               int samples_per_span = 8);

}  // namespace clay::surface
