// Bit-exact translation between Clayform's B-spline value types and OCCT's Geom_BSpline*.
#include "convert.hpp"

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

constexpr int occt_max_degree =
    25;  // Geom_BSplineSurface::MaxDegree() == Geom_BSplineCurve::MaxDegree()

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

/// Flat knots of one direction and, for each of our control points, the 0-based index of the
/// OCCT pole it copies.
struct DirectionPlan {
  std::vector<double> knots;
  std::vector<int> source;
};

DirectionPlan keep_all(const TColStd_Array1OfReal& knots, const TColStd_Array1OfInteger& mults,
                       int poles) {
  DirectionPlan plan{flat_knots(knots, mults), {}};
  for (int i = 0; i < poles; ++i) plan.source.push_back(i);
  return plan;
}

/// A periodic direction whose end knots have multiplicity p (what OCCT's SetUPeriodic makes of a
/// closed clamped direction, and what the STEP and IGES readers do to every closed surface):
/// its clamped form repeats the end knots p + 1 times and closes the poles with the first one.
/// Only copies, so a closed clamped surface comes back exactly as written. (OCCT's own
/// SetNotPeriodic goes through homogeneous coordinates and changes rational poles in the last
/// bit.)
DirectionPlan unperiodize_exact(const TColStd_Array1OfReal& knots,
                                const TColStd_Array1OfInteger& mults, int p, int poles) {
  DirectionPlan plan;
  plan.knots.assign(static_cast<size_t>(p + 1), knots.First());
  for (int k = knots.Lower() + 1; k < knots.Upper(); ++k)
    plan.knots.insert(plan.knots.end(), static_cast<size_t>(mults(k)), knots(k));
  plan.knots.insert(plan.knots.end(), static_cast<size_t>(p + 1), knots.Last());
  for (int i = 0; i < poles; ++i) plan.source.push_back(i);
  plan.source.push_back(0);
  return plan;
}

/// Clamps a direction made non-periodic by SetNotPeriodic whose domain ends [K[p], K[n]] have
/// multiplicity >= p (raised by knot insertion first): inserting an end knot once more at a
/// p-fold knot only duplicates a pole (Boehm's rule with s = p blends nothing), and the poles
/// whose basis functions vanish on the domain are dropped.
DirectionPlan clamp_ends(const TColStd_Array1OfReal& knots, const TColStd_Array1OfInteger& mults,
                         int p) {
  const std::vector<double> k = flat_knots(knots, mults);
  const int n = static_cast<int>(k.size()) - p - 1;
  const double a = k[static_cast<size_t>(p)], b = k[static_cast<size_t>(n)];
  int e = p;  // last index of the run of a
  while (k[static_cast<size_t>(e + 1)] == a) ++e;
  int s2 = n;  // first index of the run of b
  while (k[static_cast<size_t>(s2 - 1)] == b) --s2;
  DirectionPlan plan;
  plan.knots.assign(static_cast<size_t>(p + 1), a);
  plan.knots.insert(plan.knots.end(), k.begin() + e + 1, k.begin() + s2);
  plan.knots.insert(plan.knots.end(), static_cast<size_t>(p + 1), b);
  for (int i = e - p; i <= s2 - 1; ++i) plan.source.push_back(i);
  return plan;
}

[[noreturn]] void refused(std::string_view name, const Standard_Failure& failure) {
  throw Error(ErrorCategory::Exchange,
              std::string(name) + ": OpenCASCADE refused the B-spline data: " + describe(failure) +
                  "; check for knots closer than one unit in the last place or weights near 0");
}

void check_degree(std::string_view name, int degree_u, int degree_v, bool surface) {
  if (degree_u <= occt_max_degree && degree_v <= occt_max_degree) return;
  std::string degrees = surface
                            ? "(" + std::to_string(degree_u) + ", " + std::to_string(degree_v) + ")"
                            : std::to_string(degree_u);
  throw Error(
      ErrorCategory::DegreeLimit,
      std::string(name) + ": degree " + degrees + " exceeds " + std::to_string(occt_max_degree) +
          ", the largest degree OpenCASCADE (and so STEP/IGES export) accepts; reduce "
          "the degree or refit the " +
          (surface ? "surface" : "curve") + " with degree <= " + std::to_string(occt_max_degree));
}

}  // namespace

std::string describe(const Standard_Failure& failure) {
  const char* text = failure.GetMessageString();
  std::string out = failure.DynamicType()->Name();
  if (text != nullptr && *text != '\0') out += std::string(" (") + text + ")";
  return out;
}

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

BSplineCurve from_occt(const Handle(Geom_BSplineCurve) & input, std::string_view name) {
  if (input.IsNull())
    throw Error(ErrorCategory::Exchange,
                std::string(name) + ": no OpenCASCADE curve (null handle)");
  BSplineCurve curve;
  try {
    Handle(Geom_BSplineCurve) c = input;
    const int p = c->Degree();
    DirectionPlan plan;
    if (c->IsPeriodic() && c->Multiplicity(1) < p) {
      // No exact clamped form: unperiodize and raise the end multiplicities with OCCT.
      c = Handle(Geom_BSplineCurve)::DownCast(input->Copy());
      c->SetNotPeriodic();
      c->InsertKnot(c->Knot(c->FirstUKnotIndex()), p, 0.0, false);
      c->InsertKnot(c->Knot(c->LastUKnotIndex()), p, 0.0, false);
      plan = clamp_ends(c->Knots(), c->Multiplicities(), p);
    } else if (c->IsPeriodic()) {
      plan = unperiodize_exact(c->Knots(), c->Multiplicities(), p, c->NbPoles());
    } else {
      plan = keep_all(c->Knots(), c->Multiplicities(), c->NbPoles());
    }
    const int n = static_cast<int>(plan.source.size());
    curve.basis.degree = p;
    curve.basis.knots = std::move(plan.knots);
    curve.points.resize(n, 3);
    curve.weights = Eigen::VectorXd::Ones(n);
    const TColgp_Array1OfPnt& poles = c->Poles();
    const TColStd_Array1OfReal* weights = c->IsRational() ? c->Weights() : nullptr;
    for (int i = 0; i < n; ++i) {
      const int from = plan.source[static_cast<size_t>(i)];
      const gp_Pnt& pt = poles.Value(poles.Lower() + from);
      curve.points.row(i) << pt.X(), pt.Y(), pt.Z();
      if (weights != nullptr) curve.weights[i] = weights->Value(weights->Lower() + from);
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
      for (int j = 0; j < nv; ++j)
        weights.SetValue(i + 1, j + 1, surface.weights[surface.index(i, j)]);
    return new Geom_BSplineSurface(poles, weights, ku.knots, kv.knots, ku.mults, kv.mults,
                                   surface.u.degree, surface.v.degree, false, false);
  } catch (const Standard_Failure& failure) {
    refused(name, failure);
  }
}

BSplineSurface from_occt(const Handle(Geom_BSplineSurface) & input, std::string_view name) {
  if (input.IsNull())
    throw Error(ErrorCategory::Exchange,
                std::string(name) + ": no OpenCASCADE surface (null handle)");
  BSplineSurface surface;
  try {
    Handle(Geom_BSplineSurface) s = input;
    const int p = s->UDegree(), q = s->VDegree();
    // Periodic directions without an exact clamped form: unperiodize and raise the end
    // multiplicities with OCCT on a copy (see the curve overload).
    const bool u_inexact = s->IsUPeriodic() && s->UMultiplicity(1) < p;
    const bool v_inexact = s->IsVPeriodic() && s->VMultiplicity(1) < q;
    if (u_inexact || v_inexact) {
      s = Handle(Geom_BSplineSurface)::DownCast(input->Copy());
      if (u_inexact) {
        s->SetUNotPeriodic();
        s->InsertUKnot(s->UKnot(s->FirstUKnotIndex()), p, 0.0, false);
        s->InsertUKnot(s->UKnot(s->LastUKnotIndex()), p, 0.0, false);
      }
      if (v_inexact) {
        s->SetVNotPeriodic();
        s->InsertVKnot(s->VKnot(s->FirstVKnotIndex()), q, 0.0, false);
        s->InsertVKnot(s->VKnot(s->LastVKnotIndex()), q, 0.0, false);
      }
    }
    const DirectionPlan pu =
        u_inexact          ? clamp_ends(s->UKnots(), s->UMultiplicities(), p)
        : s->IsUPeriodic() ? unperiodize_exact(s->UKnots(), s->UMultiplicities(), p, s->NbUPoles())
                           : keep_all(s->UKnots(), s->UMultiplicities(), s->NbUPoles());
    const DirectionPlan pv =
        v_inexact          ? clamp_ends(s->VKnots(), s->VMultiplicities(), q)
        : s->IsVPeriodic() ? unperiodize_exact(s->VKnots(), s->VMultiplicities(), q, s->NbVPoles())
                           : keep_all(s->VKnots(), s->VMultiplicities(), s->NbVPoles());
    const int nu = static_cast<int>(pu.source.size()), nv = static_cast<int>(pv.source.size());
    surface.u.degree = p;
    surface.v.degree = q;
    surface.u.knots = pu.knots;
    surface.v.knots = pv.knots;
    surface.points.resize(static_cast<Eigen::Index>(nu) * nv, 3);
    surface.weights = Eigen::VectorXd::Ones(surface.points.rows());
    const TColgp_Array2OfPnt& poles = s->Poles();
    // IsURational() says whether weights vary along V (and the reverse): test both.
    const TColStd_Array2OfReal* weights =
        (s->IsURational() || s->IsVRational()) ? s->Weights() : nullptr;
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const int ui = pu.source[static_cast<size_t>(i)], vj = pv.source[static_cast<size_t>(j)];
        const gp_Pnt& pt = poles.Value(poles.LowerRow() + ui, poles.LowerCol() + vj);
        surface.points.row(surface.index(i, j)) << pt.X(), pt.Y(), pt.Z();
        if (weights != nullptr)
          surface.weights[surface.index(i, j)] =
              weights->Value(weights->LowerRow() + ui, weights->LowerCol() + vj);
      }
  } catch (const Standard_Failure& failure) {
    refused(name, failure);
  }
  validate(surface, name);
  return surface;
}

}  // namespace clay::surface::occt
