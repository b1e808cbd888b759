#pragma once
// OpenCASCADE as an independent reference, behind an OCCT-free interface (internal; used by tests
// and benchmarks only, not installed). Each function converts through the adapter in convert.hpp.
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <memory>
#include <span>
#include <string>

namespace clay::surface::occt_reference {

/// Point and derivatives up to order 2 from Geom_BSplineSurface::D2 (du, dv, duu, duv, dvv).
SurfaceDerivatives surface_d2(const BSplineSurface& surface, double u, double v);

/// Point and derivatives up to order 2 from Geom_BSplineCurve::D2.
CurveDerivatives curve_d2(const BSplineCurve& curve, double t);

/// Ours -> Geom_BSplineSurface -> ours (checks the adapter is bit-exact both ways).
BSplineSurface round_trip(const BSplineSurface& surface);
/// Ours -> Geom_BSplineCurve -> ours.
BSplineCurve round_trip(const BSplineCurve& curve);

/// OpenCASCADE's exchange settings (Interface_Static), as a host application in the same process
/// sets and reads them, after the STEP and IGES controllers' Init: an integer or enumerated one
/// by its number, a text one by its text. The setters return false when OpenCASCADE refuses.
int exchange_setting_int(const char* name);
std::string exchange_setting_text(const char* name);
bool set_exchange_setting(const char* name, int value);
bool set_exchange_setting(const char* name, const char* value);

/// Holds one Geom_BSplineSurface and evaluates grids with its D0 (the benchmark's baseline).
class GridEvaluator {
 public:
  explicit GridEvaluator(const BSplineSurface& surface);
  ~GridEvaluator();
  GridEvaluator(const GridEvaluator&) = delete;
  GridEvaluator& operator=(const GridEvaluator&) = delete;
  /// Same layout as clay::surface::evaluate_grid.
  Points3 evaluate_grid(std::span<const double> us, std::span<const double> vs) const;
  /// One point by Geom_BSplineSurface::D0.
  Eigen::Vector3d evaluate(double u, double v) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clay::surface::occt_reference
