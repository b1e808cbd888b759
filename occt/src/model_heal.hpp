#pragma once
// Healing steps of the model reader that work on the model alone (model_heal.cpp), as
// OpenCASCADE's Shape Healing does for the files real exporters write. Internal to the OCCT
// library; each step returns what it did, for the read report.
#include <clay/brep/model.hpp>

#include <string>

namespace clay::brep::detail {

/// Pcurves that leave their surface's (u, v) domain by at most this fraction of the domain's
/// width are pulled in (the 8 files of issue #39 leave it by 1e-10 to 3.2e-5; an Alias pcurve
/// that leaves by 3.2e-5 has control points 3.2e-4 out). The gaps are measured after.
inline constexpr double pull_in_relative = 1e-3;

/// Gaps between faces and edges still there once pcurves are re-derived, up to this fraction of
/// the model size, are the file's own: NX 9 gives 0.0157 mm where its faces are 0.026 mm from
/// their edges, Onshape 0.00055 mm for 0.0076 mm. The reader sets the tolerance to the gap, as
/// OpenCASCADE's FixSameParameter sets it, and reports it; a wider gap is a defect problems()
/// names.
inline constexpr double healed_gap_relative = 1e-3;

/// What pull_pcurves_into_domains did: how many pcurves it changed and the farthest any of their
/// control points lay outside, as a fraction of the domain's width in that direction.
struct PulledPcurves {
  int count = 0;
  double farthest = 0;
};

/// Every pcurve whose curve leaves its face's surface domain (sampled as problems() samples it,
/// beyond its rounding slack of 1e-9) while all its control points lie within pull_in_relative
/// of the domain has its control points clamped into the domain: by the convex hull property of
/// B-splines (positive weights) the curve then lies inside. The face along it moves by about
/// |S_u| du + |S_v| dv; the caller measures the gaps again. Pcurves farther out are left for
/// problems() to name.
PulledPcurves pull_pcurves_into_domains(Model& model);

/// The report's words for `pulled` ("" when nothing was pulled).
std::string describe(const PulledPcurves& pulled);

}  // namespace clay::brep::detail
