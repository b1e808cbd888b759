#pragma once
// Healing steps of the model reader that work on the model alone (model_heal.cpp), as
// OpenCASCADE's Shape Healing does for the files real exporters write. Internal to the OCCT
// library; each step returns what it did, for the read report.
#include <clay/brep/model.hpp>

#include <optional>
#include <string>
#include <utility>

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

/// Puts each face's outer loop first where the reader's order has a hole there: a face whose
/// first loop runs clockwise in (u, v) while exactly one other loop runs counter-clockwise has
/// that loop moved to the front (the others keep their order). OpenCASCADE's
/// BRepTools::OuterWire picks the outer wire by its pcurves' boxes, and a pcurve 0.1 rad off near
/// a sphere's pole (Alibre's s1) made it pick a hole. Faces whose loops cannot be measured are
/// left for problems() to name. Returns how many faces were changed.
int outer_loops_first(Model& model);

/// The pcurve of `edge` on `surface` re-derived from the edge: its points projected onto the
/// surface (Newton from `old` at the same parameter, else the closest point), interpolated by
/// cubics piece by piece between the edge's knots and where the projection crosses the surface's
/// knot lines, a piece halved until the face along it is within `fit_tol` of the projection.
/// Returns the pcurve and the largest gap between the face along it and the edge; nullopt when
/// the edge leaves the face by more than `accepted` or no fit is found.
std::optional<std::pair<surface::BSplineCurve, double>> pcurve_from_edge(
    const surface::BSplineSurface& surface, const Edge& edge, const surface::BSplineCurve& old,
    double accepted, double fit_tol);

}  // namespace clay::brep::detail
