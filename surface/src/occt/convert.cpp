// Bit-exact translation between Clayform's B-spline value types and OCCT's Geom_BSpline*.
#include "occt/convert.hpp"

#include <clay/error.hpp>

#include <string>

#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array2OfPnt.hxx>

namespace clay::surface::occt {
namespace {

constexpr int occt_max_degree = 25;  // Geom_BSplineSurface::MaxDegree() == Geom_BSplineCurve::MaxDegree()

/// OCCT's distinct knots and multiplicities (1-based) of a flat knot vector, by exact equality.
struct KnotsAndMults {
  TColStd_Array1OfReal knots;
  TColStd_Array1OfInteger mults;
};

KnotsAndMults split_knots(const std::vector<double>& flat) {
  int distinct = 0;
  for (size_t i = 0; i < flat.size(); ++i)
    if (i == 0 || flat[i] != flat[i - 1]) ++distinct;
  KnotsAndMults out{TColStd_Array1OfReal(1, distinct), TColStd_Array1OfInteger(1, distinct)};
  int k = 0;
  for (size_t i = 0; i < flat.size(); ++i) {
    if (i == 0 || flat[i] != flat[i - 1]) {
      ++k;
      out.knots.SetValue(k, flat[i]);
      out.mults.SetValue(k, 1);
    } else {
      out.mults.ChangeValue(k) += 1;
    }
  }
  return out;
}

std::vector<double> flat_knots(const TColStd_Array1OfReal& knots,
                               const TColStd_Array1OfInteger& mults) {
  std::vector<double> flat;
  for (int k = knots.Lower(); k <= knots.Upper(); ++k)
    flat.insert(flat.end(), static_cast<size_t>(mults.Value(k)), knots.Value(k));
  return flat;
}

std::string occt_message(const Standard_Failure& failure) {
  const char* text = failure.GetMessageString();
  std::string out = failure.DynamicType()->Name();
  if (text != nullptr && *text != '\0') out += std::string(" (") + text + ")";
  return out;
}

[[noreturn]] void refused(std::string_view name, const Standard_Failure& failure) {
  throw Error(ErrorCategory::Exchange,
              std::string(name) + ": OpenCASCADE refused the B-spline data: " +
                  occt_message(failure) +
                  "; check for knots closer than one unit in the last place or weights near 0");
}

void check_degree(std::string_view name, int degree_u, int degree_v, bool surface) {
  if (degree_u <= occt_max_degree && degree_v <= occt_max_degree) return;
  std::string degrees = surface ? "(" + std::to_string(degree_u) + ", " +
                                      std::to_string(degree_v) + ")"
                                : std::to_string(degree_u);
  throw Error(ErrorCategory::DegreeLimit,
              std::string(name) + ": degree " + degrees + " exceeds " +
                  std::to_string(occt_max_degree) +
                  ", the largest degree OpenCASCADE (and so STEP/IGES export) accepts; reduce "
                  "the degree or refit the " +
                  (surface ? "surface" : "curve") + " with degree <= " +
                  std::to_string(occt_max_degree));
}

}  // namespace

Handle(Geom_BSplineCurve) to_occt(const BSplineCurve& curve, std::string_view name) {
  validate(curve, name);
  check_degree(name, curve.basis.degree, 0, false);
  const KnotsAndMults km = split_knots(curve.basis.knots);
  const int n = curve.basis.count();
  TColgp_Array1OfPnt poles(1, n);
  for (int i = 0; i < n; ++i)
    poles.SetValue(i + 1, gp_Pnt(curve.points(i, 0), curve.points(i, 1), curve.points(i, 2)));
  try {
    if (!curve.is_rational())
      return new Geom_BSplineCurve(poles, km.knots, km.mults, curve.basis.degree, false);
    TColStd_Array1OfReal weights(1, n);
    for (int i = 0; i < n; ++i) weights.SetValue(i + 1, curve.weights[i]);
    // CheckRational = false keeps the weights even when they are all equal (but not 1).
    return new Geom_BSplineCurve(poles, weights, km.knots, km.mults, curve.basis.degree, false,
                                 false);
  } catch (const Standard_Failure& failure) {
    refused(name, failure);
  }
}

BSplineCurve from_occt(const Handle(Geom_BSplineCurve)& input, std::string_view name) {
  if (input.IsNull())
    throw Error(ErrorCategory::Exchange, std::string(name) + ": no OpenCASCADE curve (null handle)");
  BSplineCurve curve;
  try {
    Handle(Geom_BSplineCurve) c = input;
    if (c->IsPeriodic()) {
      c = Handle(Geom_BSplineCurve)::DownCast(input->Copy());
      c->SetNotPeriodic();
    }
    const int n = c->NbPoles();
    curve.basis.degree = c->Degree();
    curve.basis.knots = flat_knots(c->Knots(), c->Multiplicities());
    curve.points.resize(n, 3);
    curve.weights = Eigen::VectorXd::Ones(n);
    const TColgp_Array1OfPnt& poles = c->Poles();
    for (int i = 0; i < n; ++i) {
      const gp_Pnt& p = poles.Value(poles.Lower() + i);
      curve.points.row(i) << p.X(), p.Y(), p.Z();
    }
    if (c->IsRational()) {
      const TColStd_Array1OfReal* weights = c->Weights();
      for (int i = 0; i < n; ++i) curve.weights[i] = weights->Value(weights->Lower() + i);
    }
  } catch (const Standard_Failure& failure) {
    refused(name, failure);
  }
  validate(curve, name);
  return curve;
}

Handle(Geom_BSplineSurface) to_occt(const BSplineSurface& surface, std::string_view name) {
  validate(surface, name);
  check_degree(name, surface.u.degree, surface.v.degree, true);
  const KnotsAndMults ku = split_knots(surface.u.knots);
  const KnotsAndMults kv = split_knots(surface.v.knots);
  const int nu = surface.count_u(), nv = surface.count_v();
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Eigen::Index r = surface.index(i, j);
      poles.SetValue(i + 1, j + 1,
                     gp_Pnt(surface.points(r, 0), surface.points(r, 1), surface.points(r, 2)));
    }
  try {
    if (!surface.is_rational())
      return new Geom_BSplineSurface(poles, ku.knots, kv.knots, ku.mults, kv.mults,
                                     surface.u.degree, surface.v.degree, false, false);
    TColStd_Array2OfReal weights(1, nu, 1, nv);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) weights.SetValue(i + 1, j + 1, surface.weights[surface.index(i, j)]);
    return new Geom_BSplineSurface(poles, weights, ku.knots, kv.knots, ku.mults, kv.mults,
                                   surface.u.degree, surface.v.degree, false, false);
  } catch (const Standard_Failure& failure) {
    refused(name, failure);
  }
}

BSplineSurface from_occt(const Handle(Geom_BSplineSurface)& input, std::string_view name) {
  if (input.IsNull())
    throw Error(ErrorCategory::Exchange,
                std::string(name) + ": no OpenCASCADE surface (null handle)");
  BSplineSurface surface;
  try {
    Handle(Geom_BSplineSurface) s = input;
    if (s->IsUPeriodic() || s->IsVPeriodic()) {
      s = Handle(Geom_BSplineSurface)::DownCast(input->Copy());
      if (s->IsUPeriodic()) s->SetUNotPeriodic();
      if (s->IsVPeriodic()) s->SetVNotPeriodic();
    }
    const int nu = s->NbUPoles(), nv = s->NbVPoles();
    surface.u.degree = s->UDegree();
    surface.v.degree = s->VDegree();
    surface.u.knots = flat_knots(s->UKnots(), s->UMultiplicities());
    surface.v.knots = flat_knots(s->VKnots(), s->VMultiplicities());
    surface.points.resize(static_cast<Eigen::Index>(nu) * nv, 3);
    surface.weights = Eigen::VectorXd::Ones(surface.points.rows());
    const TColgp_Array2OfPnt& poles = s->Poles();
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const gp_Pnt& p = poles.Value(poles.LowerRow() + i, poles.LowerCol() + j);
        surface.points.row(surface.index(i, j)) << p.X(), p.Y(), p.Z();
      }
    // IsURational() says whether weights vary along V (and the reverse): test both.
    if (s->IsURational() || s->IsVRational()) {
      const TColStd_Array2OfReal* weights = s->Weights();
      for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j)
          surface.weights[surface.index(i, j)] =
              weights->Value(weights->LowerRow() + i, weights->LowerCol() + j);
    }
  } catch (const Standard_Failure& failure) {
    refused(name, failure);
  }
  validate(surface, name);
  return surface;
}

}  // namespace clay::surface::occt
