// Converting OpenCASCADE faces, edges and pcurves into our NURBS: see model_convert.hpp.
#include "model_convert.hpp"

#include <clay/occt/model_exchange.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "convert.hpp"
#include "exchange_precheck.hpp"
#include "session.hpp"

#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2dAPI_Interpolate.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_Circle.hxx>
#include <Geom2d_Ellipse.hxx>
#include <Geom2d_Hyperbola.hxx>
#include <Geom2d_Parabola.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <GeomConvert.hxx>
#include <GeomConvert_ApproxSurface.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_Circle.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_ElementarySurface.hxx>
#include <Geom_Ellipse.hxx>
#include <Geom_Hyperbola.hxx>
#include <Geom_OffsetCurve.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_Parabola.hxx>
#include <Geom_Plane.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_HArray1OfPnt2d.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Trsf.hxx>

namespace clay::brep::detail {

namespace {
using surface::occt::extension_is;
using surface::occt::quoted;
}  // namespace

// ---- converted faces ------------------------------------------------------------------------

/// Reads the new surface; an all-negative weight set is negated first (the same surface).
surface::BSplineSurface checked_surface(Handle(Geom_BSplineSurface) s, const std::string& name) {
  if (s->IsURational() || s->IsVRational()) {
    bool all_negative = true;
    for (int i = 1; i <= s->NbUPoles(); ++i)
      for (int j = 1; j <= s->NbVPoles(); ++j) all_negative = all_negative && s->Weight(i, j) < 0;
    if (all_negative) {
      s = Handle(Geom_BSplineSurface)::DownCast(s->Copy());
      for (int i = 1; i <= s->NbUPoles(); ++i)
        for (int j = 1; j <= s->NbVPoles(); ++j) s->SetWeight(i, j, -s->Weight(i, j));
    }
  }
  return surface::occt::from_occt(s, name);
}

/// Removes trimmed and zero-offset wrappers.
Handle(Geom_Surface) unwrapped(Handle(Geom_Surface) s) {
  for (;;) {
    if (auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(s); !t.IsNull()) {
      s = t->BasisSurface();
      continue;
    }
    if (auto o = Handle(Geom_OffsetSurface)::DownCast(s); !o.IsNull()) {
      if (o->Offset() == 0.0) {
        s = o->BasisSurface();
        continue;
      }
      if (Handle(Geom_Surface) same = o->Surface(); !same.IsNull()) {
        s = same;  // an offset of an elementary surface is elementary
        continue;
      }
    }
    return s;
  }
}

/// The parameter box of `face` (its pcurves' extent) fitted to the surface's bounds: clamped to
/// a bounded direction, at most one period long in a periodic one.
std::array<double, 4> face_box(const TopoDS_Face& face, const Handle(Geom_Surface) & s,
                               const std::string& name, bool& encloses_nothing) {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  BRepTools::UVBounds(face, u0, u1, v0, v1);
  if (Precision::IsInfinite(u0) || Precision::IsInfinite(u1) || Precision::IsInfinite(v0) ||
      Precision::IsInfinite(v1) || !(u1 >= u0) || !(v1 >= v0) || (u1 == u0 && v1 == v0))
    throw Error(ErrorCategory::Exchange,
                name + ": the face has no bounded parameter box (no boundary loops?)");
  // A face whose loop runs along one line encloses no area (a PCB library's header pin, written
  // with 4-digit directions, has such a sliver between two planes): its box is flat in one
  // direction. The face is kept, on its surface widened across the line by 1e-3 of the box, so
  // its neighbours keep their shared edges and the shell stays closed.
  encloses_nothing = !(u1 > u0) || !(v1 > v0);
  if (!(u1 > u0)) {
    const double w = 1e-3 * (v1 - v0);
    u0 -= w;
    u1 += w;
  }
  if (!(v1 > v0)) {
    const double w = 1e-3 * (u1 - u0);
    v0 -= w;
    v1 += w;
  }
  double su0 = 0, su1 = 0, sv0 = 0, sv1 = 0;
  s->Bounds(su0, su1, sv0, sv1);
  // A full turn is taken as exactly one period from the multiple of the period nearest its start
  // when that is within 1e-9 of a period: files give bounds such as [-4e-13, 2 pi], and
  // GeomConvert then cuts a sliver span off its periodic B-spline, which fails
  // (NCollection_Array2::Allocate, one of the errors real files raised).
  auto full_turn = [](double& a, double& b, double period) {
    const double eps = 1e-9 * period;
    if (b - a < period - eps) return;
    const double start = std::round(a / period) * period;
    a = std::abs(a - start) <= eps ? start : a;
    b = a + period;
  };
  if (s->IsUPeriodic()) {
    full_turn(u0, u1, s->UPeriod());
    u1 = std::min(u1, u0 + s->UPeriod());
  } else {
    u0 = std::max(u0, su0);
    u1 = std::min(u1, su1);
  }
  if (s->IsVPeriodic()) {
    full_turn(v0, v1, s->VPeriod());
    v1 = std::min(v1, v0 + s->VPeriod());
  } else {
    v0 = std::max(v0, sv0);
    v1 = std::min(v1, sv1);
  }
  return {u0, u1, v0, v1};
}

/// A converted full turn ends where it starts only to rounding (a torus's last row of poles is
/// 1e-15 off its first). OpenCASCADE's readers make such a surface periodic and keep one row,
/// so a written model would not read back bit for bit: the last row is set to the first when
/// they agree within 1e-14 of the size (and their weights to 1e-15).
void close_exactly(const Handle(Geom_BSplineSurface) & s, double size) {
  const int nu = s->NbUPoles(), nv = s->NbVPoles();
  auto same = [&](int i0, int j0, int i1, int j1) {
    return s->Pole(i0, j0).Distance(s->Pole(i1, j1)) <= 1e-14 * size &&
           std::abs(s->Weight(i0, j0) - s->Weight(i1, j1)) <= 1e-15 * s->Weight(i0, j0);
  };
  bool u_closed = true, v_closed = true;
  for (int j = 1; j <= nv && u_closed; ++j) u_closed = same(1, j, nu, j);
  for (int i = 1; i <= nu && v_closed; ++i) v_closed = same(i, 1, i, nv);
  if (u_closed)
    for (int j = 1; j <= nv; ++j) s->SetPole(nu, j, s->Pole(1, j), s->Weight(1, j));
  if (v_closed)
    for (int i = 1; i <= nu; ++i) s->SetPole(i, nv, s->Pole(i, 1), s->Weight(i, 1));
}

/// The same for a converted closed curve (a full circle).
void close_exactly(const Handle(Geom_BSplineCurve) & c, double size) {
  const int n = c->NbPoles();
  if (c->Pole(1).Distance(c->Pole(n)) <= 1e-14 * size &&
      std::abs(c->Weight(1) - c->Weight(n)) <= 1e-15 * c->Weight(1))
    c->SetPole(n, c->Pole(1), c->Weight(1));
}

/// GeomConvert's B-spline of `s` on the box. OpenCASCADE 7.6 converts an elementary surface
/// trimmed to a full turn in u that starts off a multiple of the period wrongly: a cylinder of
/// radius 3.5 on [pi/2, 5 pi/2] comes back with the knots of [0, 2 pi] and 0.135 mm off at its
/// knots (a cone 0.20 mm, a torus of tube 3 0.50 mm; MicroStation's and HiCAD's holes, issue #39).
/// Such a surface is turned by the start about its axis, t(w) = s(w + u0), converted on
/// [0, period], and its u knots moved by u0: the same B-spline on the face's own seam.
Handle(Geom_BSplineSurface)
    to_bspline(const Handle(Geom_Surface) & s, const std::array<double, 4>& box) {
  const auto elementary = Handle(Geom_ElementarySurface)::DownCast(s);
  const double period = s->IsUPeriodic() ? s->UPeriod() : 0.0;
  const double u0 = box[0];
  // Only for a periodic u: u0 / 0 would raise the division-by-zero trap of the Debug tests.
  const bool full_turn = period > 0 && box[1] - box[0] >= period * (1 - 1e-12);
  const bool off_period =
      full_turn && std::abs(u0 - std::round(u0 / period) * period) > 1e-12 * period;
  if (elementary.IsNull() || !full_turn || !off_period)
    return GeomConvert::SurfaceToBSplineSurface(
        new Geom_RectangularTrimmedSurface(s, box[0], box[1], box[2], box[3]));
  const double v_mid = 0.5 * (box[2] + box[3]);
  const gp_Pnt start = s->Value(u0, v_mid);
  Handle(Geom_Surface) turned;
  for (const double angle : {u0, -u0}) {  // +u0 about a direct frame's axis, -u0 an indirect one
    gp_Trsf rotation;
    rotation.SetRotation(elementary->Position().Axis(), angle);
    turned = Handle(Geom_Surface)::DownCast(s->Transformed(rotation));
    if (turned->Value(0.0, v_mid).Distance(start) <= 1e-12 * (1 + start.XYZ().Modulus())) break;
    turned.Nullify();
  }
  if (turned.IsNull())  // not a surface of its axis: left to the checks of the conversion
    return GeomConvert::SurfaceToBSplineSurface(
        new Geom_RectangularTrimmedSurface(s, box[0], box[1], box[2], box[3]));
  Handle(Geom_BSplineSurface) b = GeomConvert::SurfaceToBSplineSurface(
      new Geom_RectangularTrimmedSurface(turned, 0.0, period, box[2], box[3]));
  TColStd_Array1OfReal knots(1, b->NbUKnots());
  for (int k = 1; k <= b->NbUKnots(); ++k) knots.SetValue(k, b->UKnot(k) + u0);
  b->SetUKnots(knots);
  return b;
}

FaceConversion convert_face(const TopoDS_Face& face, double size, const std::string& name) {
  FaceConversion c;
  c.size = size;
  c.name = name;
  const Handle(Geom_Surface) located = BRep_Tool::Surface(face);  // the location applied
  if (located.IsNull()) throw Error(ErrorCategory::Exchange, name + ": the face has no surface");
  c.old_surface = unwrapped(located);
  const auto box = face_box(face, c.old_surface, name, c.encloses_nothing);
  c.u_mid = 0.5 * (box[0] + box[1]);
  c.v_mid = 0.5 * (box[2] + box[3]);

  Handle(Geom_BSplineSurface) bspline = Handle(Geom_BSplineSurface)::DownCast(c.old_surface);
  const bool polynomial_kind =
      !bspline.IsNull() || !Handle(Geom_BezierSurface)::DownCast(c.old_surface).IsNull();
  if (!bspline.IsNull()) {
    double su0 = 0, su1 = 0, sv0 = 0, sv1 = 0;
    bspline->Bounds(su0, su1, sv0, sv1);
    const double slack = 1e-9 * (su1 - su0 + sv1 - sv0);
    const bool inside = box[0] >= su0 - slack && box[1] <= su1 + slack && box[2] >= sv0 - slack &&
                        box[3] <= sv1 + slack;
    if (inside) {
      c.nurbs = bspline;  // kept as it is (a periodic one is unperiodized exactly by from_occt)
    }
  }
  if (const auto offset = Handle(Geom_OffsetSurface)::DownCast(c.old_surface); !offset.IsNull()) {
    // An offset by d != 0 of a surface whose offset is not elementary: its NURBS form is not
    // exact, so it is approximated on the same (u, v), measured, and the pcurves are kept.
    const double tolerance = offset_relative * size;
    Handle(Geom_Surface) trimmed =
        new Geom_RectangularTrimmedSurface(c.old_surface, box[0], box[1], box[2], box[3]);
    GeomConvert_ApproxSurface approximation(trimmed, tolerance, GeomAbs_C2, GeomAbs_C2, 9, 9, 400,
                                            1);
    if (!approximation.HasResult() || approximation.Surface().IsNull())
      throw Error(ErrorCategory::Exchange, name + ": its offset surface (distance " +
                                               shortest(offset->Offset()) +
                                               " mm) could not be approximated by a NURBS within " +
                                               shortest(tolerance) + " mm");
    c.nurbs = approximation.Surface();
    c.nurbs->Bounds(c.nu0, c.nu1, c.nv0, c.nv1);
    constexpr int n = 48;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        const double a = box[0] + (box[1] - box[0]) * i / n, b = box[2] + (box[3] - box[2]) * j / n;
        c.approximation_error =
            std::max(c.approximation_error,
                     c.nurbs->Value(std::clamp(a, c.nu0, c.nu1), std::clamp(b, c.nv0, c.nv1))
                         .Distance(c.old_surface->Value(a, b)));
      }
    c.approximation_error = std::max(c.approximation_error, approximation.MaxError());
    if (!(c.approximation_error <= 10 * tolerance))
      throw Error(ErrorCategory::Exchange,
                  name + ": its offset surface (distance " + shortest(offset->Offset()) +
                      " mm) was approximated only within " + shortest(c.approximation_error) +
                      " mm (asked " + shortest(tolerance) + " mm)");
    c.kind = FaceKind::Approximated;
    return c;
  }
  if (c.nurbs.IsNull()) {
    try {
      c.nurbs = to_bspline(c.old_surface, box);
    } catch (const Standard_Failure& failure) {
      throw Error(
          ErrorCategory::Exchange,
          name + ": its " + c.old_surface->DynamicType()->Name() + " on [" + shortest(box[0]) +
              ", " + shortest(box[1]) + "] x [" + shortest(box[2]) + ", " + shortest(box[3]) +
              "] could not be converted to a B-spline: " + surface::occt::describe(failure));
    }
  }
  if (c.nurbs.IsNull())
    throw Error(ErrorCategory::Exchange, name + ": OpenCASCADE could not convert the surface");
  if (c.nurbs.get() != c.old_surface.get()) close_exactly(c.nurbs, size);
  c.nurbs->Bounds(c.nu0, c.nu1, c.nv0, c.nv1);
  auto whole_periods = [](double from, double to, bool periodic, double period) {
    return periodic ? std::round((to - from) / period) * period : 0.0;
  };
  c.u_shift = whole_periods(box[0], c.nu0, c.old_surface->IsUPeriodic(),
                            c.old_surface->IsUPeriodic() ? c.old_surface->UPeriod() : 1.0);
  c.v_shift = whole_periods(box[2], c.nv0, c.old_surface->IsVPeriodic(),
                            c.old_surface->IsVPeriodic() ? c.old_surface->VPeriod() : 1.0);

  // Which directions kept their parameter: S_new(a, b) = S_old(a, b) on a grid, per direction.
  auto differs = [&](double a, double b) {
    return c.nurbs->Value(a, b).Distance(c.old_surface->Value(a, b)) > exact_relative * size;
  };
  constexpr int n = 7;
  for (int i = 0; i <= n && (c.u_identity || c.v_identity); ++i) {
    const double a = box[0] + (box[1] - box[0]) * i / n;
    const double b = box[2] + (box[3] - box[2]) * i / n;
    if (c.u_identity && differs(a, c.v_mid)) c.u_identity = false;
    if (c.v_identity && differs(c.u_mid, b)) c.v_identity = false;
  }
  // A direction whose iso-line test failed may only look so because the other direction's map
  // moved the reference point: decide each by the solved parameters.
  if (!c.u_identity || !c.v_identity) {
    bool u_same = true, v_same = true;
    for (int i = 0; i <= n; ++i) {
      const double a = box[0] + (box[1] - box[0]) * i / n;
      const double b = box[2] + (box[3] - box[2]) * i / n;
      const double u = c.solve(a, c.v_mid).x(), v = c.solve(c.u_mid, b).y();
      u_same = u_same && std::abs(u - a) <= 1e-13 * (box[1] - box[0]);
      v_same = v_same && std::abs(v - b) <= 1e-13 * (box[3] - box[2]);
    }
    c.u_identity = u_same;
    c.v_identity = v_same;
  }
  c.kind = polynomial_kind                ? FaceKind::BSpline
           : c.u_identity && c.v_identity ? FaceKind::Affine
                                          : FaceKind::Angular;
  return c;
}

/// The analytic surface a face's (unwrapped, located) surface is, if it is one.
std::optional<Elementary> elementary_of(const Handle(Geom_Surface) & s) {
  const auto elementary = Handle(Geom_ElementarySurface)::DownCast(s);
  if (elementary.IsNull()) return std::nullopt;
  Elementary e;
  const gp_Ax3& frame = elementary->Position();
  auto vec = [](const auto& xyz) { return Eigen::Vector3d(xyz.X(), xyz.Y(), xyz.Z()); };
  e.origin = vec(frame.Location());
  e.x_axis = vec(frame.XDirection());
  e.y_axis = vec(frame.YDirection());
  e.z_axis = vec(frame.Direction());
  if (!Handle(Geom_Plane)::DownCast(s).IsNull()) {
    e.kind = ElementaryKind::Plane;
    // A plane's parameters depend on x and y only: its frame is taken right-handed (z = x × y),
    // as STEP's axis2_placement_3d can only hold it, so a written plane reads back the same.
    e.z_axis = e.x_axis.cross(e.y_axis);
  } else if (auto c = Handle(Geom_CylindricalSurface)::DownCast(s); !c.IsNull()) {
    e.kind = ElementaryKind::Cylinder;
    e.radius = c->Radius();
  } else if (auto k = Handle(Geom_ConicalSurface)::DownCast(s); !k.IsNull()) {
    e.kind = ElementaryKind::Cone;
    e.radius = k->RefRadius();
    e.semi_angle = k->SemiAngle();
  } else if (auto b = Handle(Geom_SphericalSurface)::DownCast(s); !b.IsNull()) {
    e.kind = ElementaryKind::Sphere;
    e.radius = b->Radius();
  } else if (auto t = Handle(Geom_ToroidalSurface)::DownCast(s); !t.IsNull()) {
    e.kind = ElementaryKind::Torus;
    e.radius = t->MajorRadius();
    e.minor_radius = t->MinorRadius();
  } else {
    return std::nullopt;
  }
  return e;
}

/// A plane face's NURBS: the plane, in its own parameters, over the box of its pcurves (32
/// samples per knot span of each, widened by 1e-3 of the box, which holds the arcs between the
/// samples, and rounded outward to 2^-20 of it). Not over BRepTools::UVBounds: that box depends on
/// how the file gave the pcurves (a circle, or the rational B-spline we write for it), and a
/// written plane must read back as the same NURBS bit for bit; nor over the pcurves' control
/// points, which reach far outside a circle (a lattice around the face would then not hold its
/// NURBS).
surface::BSplineSurface plane_over_pcurves(const Elementary& e, const std::vector<Loop>& loops,
                                           const std::vector<Edge>& edges) {
  double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
  for (const Loop& loop : loops)
    for (const Coedge& c : loop.coedges) {
      const Edge& edge = edges[static_cast<std::size_t>(c.edge)];
      const auto [d0, d1] = c.pcurve.basis.domain();
      std::vector<double> breaks{std::clamp(edge.t0, d0, d1), std::clamp(edge.t1, d0, d1)};
      for (double k : surface::breakpoints(c.pcurve.basis))
        if (k > breaks[0] && k < breaks[1]) breaks.push_back(k);
      std::sort(breaks.begin(), breaks.end());
      for (std::size_t k = 0; k + 1 < breaks.size(); ++k)
        for (int i = 0; i <= 32; ++i) {
          const Eigen::Vector3d p = surface::evaluate(
              c.pcurve, std::min(breaks[k + 1], breaks[k] + (breaks[k + 1] - breaks[k]) * i / 32));
          u0 = std::min(u0, p.x());
          u1 = std::max(u1, p.x());
          v0 = std::min(v0, p.y());
          v1 = std::max(v1, p.y());
        }
    }
  const double margin = 1e-3 * std::max(u1 - u0, v1 - v0);
  // Outward to a grid of 2^-20 of the box: OpenCASCADE's STEP reader re-derives some pcurves on
  // planes (circles of an Autodesk part, a CATIA hole), which then differ from ours by rounding,
  // and the box must not follow them for a written plane to read back bit for bit.
  const double step = std::exp2(std::floor(std::log2(std::max(u1 - u0, v1 - v0))) - 20);
  u0 = std::floor((u0 - margin) / step) * step;
  u1 = std::ceil((u1 + margin) / step) * step;
  v0 = std::floor((v0 - margin) / step) * step;
  v1 = std::ceil((v1 + margin) / step) * step;
  surface::Points3 corners(4, 3);
  int row = 0;
  for (double u : {u0, u1})
    for (double v : {v0, v1}) corners.row(row++) = point(e, u, v).transpose();
  return surface::make_surface(surface::BSplineBasis{1, {u0, u0, u1, u1}},
                               surface::BSplineBasis{1, {v0, v0, v1, v1}}, std::move(corners));
}

// ---- converted edges ------------------------------------------------------------------------

Handle(Geom_Curve) unwrapped(Handle(Geom_Curve) c) {
  for (;;) {
    if (auto t = Handle(Geom_TrimmedCurve)::DownCast(c); !t.IsNull()) {
      c = t->BasisCurve();
      continue;
    }
    if (auto o = Handle(Geom_OffsetCurve)::DownCast(c); !o.IsNull() && o->Offset() == 0.0) {
      c = o->BasisCurve();
      continue;
    }
    return c;
  }
}

EdgeConversion convert_edge(const TopoDS_Edge& edge, double size, const std::string& name) {
  EdgeConversion c;
  BRep_Tool::Range(edge, c.f, c.l);
  if (BRep_Tool::Degenerated(edge)) {
    c.s0 = c.f;
    c.s1 = c.l;
    return c;
  }
  double f = 0, l = 0;
  const Handle(Geom_Curve) located = BRep_Tool::Curve(edge, f, l);
  if (located.IsNull()) throw Error(ErrorCategory::Exchange, name + ": the edge has no 3D curve");
  c.old_curve = unwrapped(located);
  if (auto b = Handle(Geom_BSplineCurve)::DownCast(c.old_curve); !b.IsNull()) {
    const double slack = 1e-9 * (b->LastParameter() - b->FirstParameter());
    if (c.f >= b->FirstParameter() - slack && c.l <= b->LastParameter() + slack) c.nurbs = b;
  }
  if (c.nurbs.IsNull())
    c.nurbs = GeomConvert::CurveToBSplineCurve(new Geom_TrimmedCurve(c.old_curve, c.f, c.l));
  if (c.nurbs.IsNull())
    throw Error(ErrorCategory::Exchange, name + ": OpenCASCADE could not convert the curve");
  if (c.nurbs.get() != c.old_curve.get()) close_exactly(c.nurbs, size);
  if (c.nurbs.get() == c.old_curve.get()) {
    c.s0 = c.f;
    c.s1 = c.l;
    return c;
  }
  c.s0 = c.nurbs->FirstParameter();
  c.s1 = c.nurbs->LastParameter();
  c.identity = c.s0 == c.f && c.s1 == c.l;
  for (int i = 0; i <= 8 && c.identity; ++i) {
    const double t = c.f + (c.l - c.f) * i / 8;
    c.identity = c.nurbs->Value(t).Distance(c.old_curve->Value(t)) <= exact_relative * size;
  }
  return c;
}

/// Our curve of an OCCT one; all-negative weights negated first (the same curve).
surface::BSplineCurve checked_curve(Handle(Geom_BSplineCurve) b, const std::string& name) {
  if (b->IsRational()) {
    bool all_negative = true;
    for (int i = 1; i <= b->NbPoles(); ++i) all_negative = all_negative && b->Weight(i) < 0;
    if (all_negative) {
      b = Handle(Geom_BSplineCurve)::DownCast(b->Copy());
      for (int i = 1; i <= b->NbPoles(); ++i) b->SetWeight(i, -b->Weight(i));
    }
  }
  return surface::occt::from_occt(b, name);
}

/// Our pcurve (points (u, v, 0)) of a 2D OCCT B-spline, unperiodized exactly when periodic, and
/// closed exactly when it closes to rounding.
surface::BSplineCurve pcurve_of(const Handle(Geom2d_BSplineCurve) & b, const std::string& name) {
  const int n = b->NbPoles();
  TColgp_Array1OfPnt poles(1, n);
  for (int i = 1; i <= n; ++i) poles.SetValue(i, gp_Pnt(b->Pole(i).X(), b->Pole(i).Y(), 0.0));
  TColStd_Array1OfReal knots(1, b->NbKnots());
  TColStd_Array1OfInteger mults(1, b->NbKnots());
  b->Knots(knots);
  b->Multiplicities(mults);
  Handle(Geom_BSplineCurve) c;
  if (b->IsRational()) {
    TColStd_Array1OfReal weights(1, n);
    b->Weights(weights);
    c = new Geom_BSplineCurve(poles, weights, knots, mults, b->Degree(), b->IsPeriodic());
  } else {
    c = new Geom_BSplineCurve(poles, knots, mults, b->Degree(), b->IsPeriodic());
  }
  // A converted full circle ends where it starts only to rounding; OpenCASCADE's readers close
  // it exactly (a pcurve on a plane, rebuilt from its edge), so close it here too.
  Bnd_Box extent;
  for (int i = 1; i <= n; ++i) extent.Add(poles.Value(i));
  if (!c->IsPeriodic()) close_exactly(c, std::sqrt(extent.SquareExtent()));
  return checked_curve(c, name);
}

// ---- pcurves --------------------------------------------------------------------------------

/// The largest |S_new(q(s)) - S_old(p(t(s)))| at `samples` + 1 points of [s0, s1].
double rederivation_error(const FaceConversion& face, const EdgeConversion& edge,
                          const Handle(Geom2d_Curve) & old_pcurve,
                          const std::function<gp_Pnt2d(double)>& q, double s0, double s1,
                          int samples) {
  double worst = 0;
  for (int i = 0; i <= samples; ++i) {
    const double s = s0 + (s1 - s0) * i / samples;
    const gp_Pnt2d uv = q(s);
    const gp_Pnt2d old_uv = old_pcurve->Value(edge.old_parameter(s));
    worst = std::max(worst, face.nurbs->Value(uv.X(), uv.Y())
                                .Distance(face.old_surface->Value(old_uv.X(), old_uv.Y())));
  }
  return worst;
}

bool same_conic_kind(const Handle(Geom_Curve) & c3, const Handle(Geom2d_Curve) & c2) {
  if (c3.IsNull()) return false;
  return (!Handle(Geom_Circle)::DownCast(c3).IsNull() &&
          !Handle(Geom2d_Circle)::DownCast(c2).IsNull()) ||
         (!Handle(Geom_Ellipse)::DownCast(c3).IsNull() &&
          !Handle(Geom2d_Ellipse)::DownCast(c2).IsNull()) ||
         (!Handle(Geom_Parabola)::DownCast(c3).IsNull() &&
          !Handle(Geom2d_Parabola)::DownCast(c2).IsNull()) ||
         (!Handle(Geom_Hyperbola)::DownCast(c3).IsNull() &&
          !Handle(Geom2d_Hyperbola)::DownCast(c2).IsNull());
}

Handle(Geom2d_Curve) unwrapped(Handle(Geom2d_Curve) c) {
  for (auto t = Handle(Geom2d_TrimmedCurve)::DownCast(c); !t.IsNull();
       t = Handle(Geom2d_TrimmedCurve)::DownCast(c))
    c = t->BasisCurve();
  return c;
}

/// Joins cubic pieces on consecutive parameter intervals, each clamped, into one curve with C0
/// joins (knot multiplicity 3): the pieces' first and last poles are the shared sample points.
surface::BSplineCurve joined(const std::vector<Handle(Geom2d_BSplineCurve)>& pieces) {
  std::vector<double> knots;
  std::vector<gp_Pnt2d> poles;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const Handle(Geom2d_BSplineCurve)& b = pieces[k];
    TColStd_Array1OfReal flat(1, b->NbPoles() + b->Degree() + 1);
    b->KnotSequence(flat);
    for (int i = flat.Lower(); i <= flat.Upper(); ++i) {
      const bool leading = i<flat.Lower() + 4, trailing = i> flat.Upper() - 4;
      if (k > 0 && leading) continue;  // the join: 3 copies kept below
      if (k + 1 < pieces.size() && trailing && i == flat.Upper()) continue;  // 4 -> 3
      knots.push_back(flat.Value(i));
    }
    for (int i = 1; i <= b->NbPoles(); ++i)
      if (k == 0 || i > 1) poles.push_back(b->Pole(i));
  }
  surface::Points3 points(static_cast<Eigen::Index>(poles.size()), 3);
  for (std::size_t i = 0; i < poles.size(); ++i)
    points.row(static_cast<Eigen::Index>(i)) << poles[i].X(), poles[i].Y(), 0.0;
  return surface::make_curve(3, std::move(knots), std::move(points));
}

/// Where a parameter map crosses a knot line: `span_of(s)` names the knot spans (u, v) the map
/// is in at s; each change between 64 samples of [s0, s1] is bisected to rounding. The maps are
/// only C1 there, so the fitted pieces break at these parameters.
std::vector<double> span_changes(const std::function<std::pair<long, long>(double)>& span_of,
                                 double s0, double s1) {
  constexpr int scan = 64;
  std::vector<double> out;
  auto previous = span_of(s0);
  double previous_s = s0;
  for (int i = 1; i < scan; ++i) {
    const double s = s0 + (s1 - s0) * i / scan;
    const auto now = span_of(s);
    if (now != previous) {
      double lo = previous_s, hi = s;
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (span_of(mid) == previous ? lo : hi) = mid;
      }
      out.push_back(0.5 * (lo + hi));
    }
    previous = now;
    previous_s = s;
  }
  return out;
}

/// The new pcurve of one coedge: see the file comment for the four ways.
Rederived rederive(const FaceConversion& face, const EdgeConversion& edge,
                   const Handle(Geom2d_Curve) & old_pcurve, const std::string& name) {
  // An approximated face is within its approximation error of the original, not closer.
  const double exact_tol = exact_relative * face.size + face.approximation_error;
  const double s0 = edge.s0, s1 = edge.s1;
  auto target = [&](double s) {
    const gp_Pnt2d p = old_pcurve->Value(edge.old_parameter(s));
    return face.map(p.X(), p.Y());
  };
  const Handle(Geom2d_Curve) basis = unwrapped(old_pcurve);
  const bool face_kept = face.u_identity && face.v_identity;

  // 1 and 2: the old pcurve converted as it is.
  if (face_kept && (edge.identity || same_conic_kind(edge.old_curve, basis))) {
    Handle(Geom2d_BSplineCurve) b = Handle(Geom2d_BSplineCurve)::DownCast(basis);
    if (b.IsNull() || !edge.identity)
      b = Geom2dConvert::CurveToBSplineCurve(new Geom2d_TrimmedCurve(basis, edge.f, edge.l));
    if (!b.IsNull()) {
      auto q = [&](double s) { return b->Value(s); };
      const double error = rederivation_error(face, edge, old_pcurve, q, s0, s1, 64);
      if (error <= exact_tol &&
          (edge.identity || (b->FirstParameter() == s0 && b->LastParameter() == s1)))
        return {pcurve_of(b, name), edge.identity ? PcurveWay::Kept : PcurveWay::Exact, error};
    }
  }
  // 3: a line.
  {
    const Eigen::Vector2d a = target(s0), b = target(s1);
    auto q = [&](double s) {
      const double w = (s - s0) / (s1 - s0);
      return gp_Pnt2d(a.x() + (b.x() - a.x()) * w, a.y() + (b.y() - a.y()) * w);
    };
    const double error = rederivation_error(face, edge, old_pcurve, q, s0, s1, 64);
    if (error <= exact_tol) {
      surface::Points3 points(2, 3);
      points << a.x(), a.y(), 0.0, b.x(), b.y(), 0.0;
      return {surface::make_curve(1, {s0, s0, s1, s1}, std::move(points)), PcurveWay::Exact, error};
    }
  }
  // 4: fitted, piece by piece between breaks.
  std::vector<double> breaks{s0};
  {
    std::vector<double> candidates;
    if (!edge.nurbs.IsNull())
      for (int i = 1; i <= edge.nurbs->NbKnots(); ++i)
        if (edge.nurbs->Knot(i) > s0 && edge.nurbs->Knot(i) < s1)
          candidates.push_back(edge.nurbs->Knot(i));
    // Where the pcurve crosses a knot line of the new surface.
    const auto crossings = span_changes(
        [&](double s) {
          const Eigen::Vector2d uv = target(s);
          long iu = 0, iv = 0;
          for (int k = 1; k <= face.nurbs->NbUKnots(); ++k) iu += face.nurbs->UKnot(k) <= uv.x();
          for (int k = 1; k <= face.nurbs->NbVKnots(); ++k) iv += face.nurbs->VKnot(k) <= uv.y();
          return std::pair<long, long>(iu, iv);
        },
        s0, s1);
    candidates.insert(candidates.end(), crossings.begin(), crossings.end());
    std::sort(candidates.begin(), candidates.end());
    for (double b : candidates)
      if (b - breaks.back() > 1e-9 * (s1 - s0) && s1 - b > 1e-9 * (s1 - s0)) breaks.push_back(b);
    breaks.push_back(s1);
  }
  const double fit_tol = fit_relative * face.size + face.approximation_error;
  std::vector<Handle(Geom2d_BSplineCurve)> pieces;
  double worst = 0;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = breaks[k], b = breaks[k + 1];
    Handle(Geom2d_BSplineCurve) piece;
    double error = 0;
    for (int samples = 8;; samples *= 2) {
      if (samples > 4096)
        throw Error(ErrorCategory::Exchange,
                    name + ": the pcurve could not be re-derived on the converted surface within " +
                        shortest(fit_tol) + " mm (" + shortest(error) + " mm with 4096 samples)");
      Handle(TColgp_HArray1OfPnt2d) points = new TColgp_HArray1OfPnt2d(1, samples + 1);
      Handle(TColStd_HArray1OfReal) parameters = new TColStd_HArray1OfReal(1, samples + 1);
      for (int i = 0; i <= samples; ++i) {
        const double s = i == samples ? b : a + (b - a) * i / samples;
        const Eigen::Vector2d uv = target(s);
        points->SetValue(i + 1, gp_Pnt2d(uv.x(), uv.y()));
        parameters->SetValue(i + 1, s);
      }
      Geom2dAPI_Interpolate interpolate(points, parameters, false, 1e-15);
      interpolate.Perform();
      if (!interpolate.IsDone()) continue;
      piece = interpolate.Curve();
      auto q = [&](double s) { return piece->Value(s); };
      error = rederivation_error(face, edge, old_pcurve, q, a, b, 4 * samples);
      if (error <= fit_tol) break;
    }
    worst = std::max(worst, error);
    pieces.push_back(piece);
  }
  // Degree 3 throughout (the interpolant is cubic from 4 points on; 2 or 3 samples never occur).
  return {joined(pieces), PcurveWay::Fitted, worst};
}

}  // namespace clay::brep::detail
