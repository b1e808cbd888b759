// OpenCASCADE as an independent reference (internal; tests and benchmarks only).
#include "occt_reference.hpp"

#include "convert.hpp"

#include <IGESControl_Controller.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Controller.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

namespace clay::surface::occt_reference {
namespace {

Eigen::Vector3d to_eigen(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

}  // namespace

SurfaceDerivatives surface_d2(const BSplineSurface& surface, double u, double v) {
  const Handle(Geom_BSplineSurface) s = occt::to_occt(surface);
  gp_Pnt p;
  gp_Vec du, dv, duu, dvv, duv;
  s->D2(u, v, p, du, dv, duu, dvv, duv);
  SurfaceDerivatives out;
  out.point = to_eigen(p.XYZ());
  out.du = to_eigen(du.XYZ());
  out.dv = to_eigen(dv.XYZ());
  out.duu = to_eigen(duu.XYZ());
  out.duv = to_eigen(duv.XYZ());
  out.dvv = to_eigen(dvv.XYZ());
  return out;
}

CurveDerivatives curve_d2(const BSplineCurve& curve, double t) {
  const Handle(Geom_BSplineCurve) c = occt::to_occt(curve);
  gp_Pnt p;
  gp_Vec d1, d2;
  c->D2(t, p, d1, d2);
  CurveDerivatives out;
  out.point = to_eigen(p.XYZ());
  out.d1 = to_eigen(d1.XYZ());
  out.d2 = to_eigen(d2.XYZ());
  return out;
}

BSplineSurface round_trip(const BSplineSurface& surface) {
  return occt::from_occt(occt::to_occt(surface));
}

BSplineCurve round_trip(const BSplineCurve& curve) { return occt::from_occt(occt::to_occt(curve)); }

struct GridEvaluator::Impl {
  Handle(Geom_BSplineSurface) surface;
};

GridEvaluator::GridEvaluator(const BSplineSurface& surface)
    : impl_(std::make_unique<Impl>(Impl{occt::to_occt(surface)})) {}

GridEvaluator::~GridEvaluator() = default;

Points3 GridEvaluator::evaluate_grid(std::span<const double> us, std::span<const double> vs) const {
  Points3 out(static_cast<Eigen::Index>(us.size() * vs.size()), 3);
  Eigen::Index row = 0;
  gp_Pnt p;
  for (double u : us)
    for (double v : vs) {
      impl_->surface->D0(u, v, p);
      out.row(row++) << p.X(), p.Y(), p.Z();
    }
  return out;
}

Eigen::Vector3d GridEvaluator::evaluate(double u, double v) const {
  gp_Pnt p;
  impl_->surface->D0(u, v, p);
  return {p.X(), p.Y(), p.Z()};
}

namespace {
void init_controllers() {
  STEPControl_Controller::Init();
  IGESControl_Controller::Init();
}
}  // namespace

int exchange_setting_int(const char* name) {
  init_controllers();
  return Interface_Static::IVal(name);
}

std::string exchange_setting_text(const char* name) {
  init_controllers();
  const char* text = Interface_Static::CVal(name);
  return text ? text : "";
}

bool set_exchange_setting(const char* name, int value) {
  init_controllers();
  return Interface_Static::SetIVal(name, value);
}

bool set_exchange_setting(const char* name, const char* value) {
  init_controllers();
  return Interface_Static::SetCVal(name, value);
}

}  // namespace clay::surface::occt_reference
