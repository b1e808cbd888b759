#pragma once
/// Receiver profiles (issue #38 item 2): what the CAD system receiving an export takes, and the
/// certified fit of a surface that it would not take. A surface that conforms is written as it
/// is; one that does not is refitted (refit_surface: certified, knots where the error needs
/// them) to the profile's fit degree and net cap within a tolerance, or refused naming the
/// surface, the figure and the way out. Never widened silently.
///
/// | profile | degree | net | receivers |
/// |---|---|---|---|
/// | exact | any up to 25 | any | the exact result (what OpenCASCADE's STEP/IGES writer takes) |
/// | opencascade | ≤ 25 | any | OpenCASCADE, FreeCAD, most readers |
/// | catia | ≤ 15 | any | CATIA's converter (order 16) |
/// | class_a | ≤ 5 | ≤ 32 control points per direction | a net a stylist edits (Alias, ICEM) |
/// | bicubic | exactly 3 | any | Alias's IGES receivers, rebuilt to bicubic |
#include <clay/deform/export.hpp>
#include <clay/deform/refit.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace clay::deform {

/// A receiver's limits and how a surface beyond them is refitted.
struct ReceiverProfile {
  std::string_view name;            ///< "exact", "opencascade", "catia", "class_a", "bicubic"
  int max_degree = 25;              ///< highest degree it takes
  int min_degree = 1;               ///< lowest (3 for bicubic: lower ones are elevated exactly)
  int max_count_per_direction = 0;  ///< > 0: most control points per direction (class A: 32)
  int fit_degree = 3;               ///< the degree of a refit; 0: never refitted (exact)
};

/// Every profile, in the table's order.
CLAY_DEFORM_API const std::vector<ReceiverProfile>& receiver_profiles();

/// The profile named `name`; throws clay::Error(InvalidArgument) listing the names otherwise.
CLAY_DEFORM_API const ReceiverProfile& receiver_profile(std::string_view name);

/// Why `surface` is not what `profile` takes, one line per limit broken; empty when it conforms.
CLAY_DEFORM_API std::vector<std::string> conformance_problems(
    const surface::BSplineSurface& surface, const ReceiverProfile& profile);

/// A surface made to conform.
struct ProfileFit {
  surface::BSplineSurface surface;  ///< conforming: the input, elevated, or refitted
  bool refitted = false;            ///< refitted (report holds the certificate)
  bool elevated = false;            ///< degree raised exactly to min_degree
  /// Certified deviation from the input (mm): 0 when unchanged or elevated; the refit's bound.
  double bound_mm = 0;
  RefitReport report;  ///< when refitted
};

/// `surface` made to conform to `profile`: unchanged when it conforms; a degree below
/// min_degree raised exactly; otherwise refit_surface at the profile's fit degree (capped by its
/// net) within `fit` (its tolerance; degree and caps are the profile's). Throws
/// clay::Error: DegreeLimit for the exact profile when the surface is above degree 25 (no
/// conforming exact form exists), ToleranceNotMet naming `name`, the bound and the tolerance when
/// the refit misses it (the class-A net cap is the usual reason), InvalidGeometry for an invalid
/// surface.
CLAY_DEFORM_API ProfileFit fit_to_profile(const surface::BSplineSurface& surface,
                                          const ReceiverProfile& profile, RefitOptions fit,
                                          std::string_view name = "surface");

}  // namespace clay::deform
