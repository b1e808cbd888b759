#pragma once
// Adapter between Clayform's B-spline value types and OpenCASCADE's Geom_BSplineCurve /
// Geom_BSplineSurface (internal: only files in surface/src/occt/ include OCCT headers).
//
// The translation is bit-exact both ways: our flat knot vector becomes OCCT's distinct knots and
// multiplicities by exact (==) comparison, 0-based rows become 1-based arrays, and coordinates,
// knots and weights are copied, never recomputed. Polynomial objects (every weight exactly 1) are
// built without weights, rational ones with them.
//
// One documented loss: OCCT itself decides a curve or surface is polynomial when its weights are
// all equal (to within one unit in the last place between neighbours), and then drops them. Such an
// object is polynomial in disguise; from_occt returns it with weights 1 (the same geometry).
#include <clay/error.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <string_view>
#include <utility>

#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Standard_Failure.hxx>
#include <Standard_Handle.hxx>
#include <string>

namespace clay::surface::occt {

/// An OpenCASCADE exception in words: its type and, when it has one, its message.
std::string describe(const Standard_Failure& failure);

/// Runs `body`, turning an OpenCASCADE exception into clay::Error(category) that names `what`.
template <class Body>
auto guarded(ErrorCategory category, std::string_view what, Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const Standard_Failure& failure) {
    throw Error(category, std::string(what) + ": OpenCASCADE failed: " + describe(failure));
  }
}

/// Builds the OCCT curve. Throws clay::Error: InvalidGeometry when validate(curve, name) fails,
/// DegreeLimit above Geom_BSplineCurve::MaxDegree() (25), Exchange when OCCT refuses the data
/// (e.g. two knots one unit in the last place apart). `name` names the object in messages.
Handle(Geom_BSplineCurve) to_occt(const BSplineCurve& curve, std::string_view name = "curve");

/// Reads an OCCT curve. A periodic one is made non-periodic on a copy (SetNotPeriodic) and then
/// clamped to its domain: exactly (control points copied) when its end knots have multiplicity
/// >= degree, which is the case for a closed clamped curve that OCCT made periodic, so such a
/// curve comes back as it was written; otherwise after OCCT knot insertion (not bit-exact).
/// Throws clay::Error(Exchange) for a null handle; the result is validated (InvalidGeometry).
BSplineCurve from_occt(const Handle(Geom_BSplineCurve) & curve, std::string_view name = "curve");

/// Builds the OCCT surface; control point (i, j) becomes pole (i + 1, j + 1). Throws as the curve
/// overload (DegreeLimit when either degree exceeds 25).
Handle(Geom_BSplineSurface)
    to_occt(const BSplineSurface& surface, std::string_view name = "surface");

/// Reads an OCCT surface: periodic directions are made non-periodic and clamped as for curves
/// (the STEP and IGES readers make every closed clamped surface periodic; this undoes it
/// exactly); weights are read when IsURational() || IsVRational(), else all 1. Throws as the
/// curve overload.
BSplineSurface from_occt(const Handle(Geom_BSplineSurface) & surface,
                         std::string_view name = "surface");

}  // namespace clay::surface::occt
