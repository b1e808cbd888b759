// Deformation stacks (lattices, extended lattices, taper, twist, bend in order; their JSON form,
// docs/deform.md) and the certified refit of surfaces.
#include "common.hpp"

#include <clay/deform/receiver.hpp>
#include <clay/deform/refit.hpp>
#include <clay/deform/stack.hpp>

#include <cmath>
#include <limits>

namespace clay::python {

namespace {

py::dict refit_report(const deform::RefitReport& r) {
  py::dict d;
  d["converged"] = r.summary.converged();
  d["certified"] = r.certified;
  d["certified_bound_mm"] = std::isfinite(r.certified_bound_mm)
                                ? py::object(py::float_(r.certified_bound_mm))
                                : py::object(py::none());
  d["sampled_max_mm"] = r.sampled_max;
  d["tolerance_mm"] = r.tolerance_mm;
  d["degree_u"] = r.degree_u;
  d["degree_v"] = r.degree_v;
  d["message"] = r.brief();
  return d;
}

deform::RefitOptions refit_options(double relative_tolerance, double tolerance_mm, int degree,
                                   int max_control_points) {
  deform::RefitOptions o;
  // A tolerance in mm replaces the default relative one (as a recipe's composition reads them).
  o.relative_tolerance = tolerance_mm > 0 ? 0.0 : relative_tolerance;
  o.tolerance_mm = tolerance_mm;
  o.degree = degree;
  o.max_control_points = max_control_points;
  return o;
}

/// A refit that misses its tolerance is a failure, not a result (DESIGN.md).
py::tuple refit_result(deform::RefitResult&& r) {
  if (!r.report.summary.converged())
    throw Error(ErrorCategory::ToleranceNotMet,
                "refit: " + r.report.brief() +
                    "; loosen the tolerance, raise max_control_points or the degree");
  return py::make_tuple(std::move(r.surface), refit_report(r.report));
}

}  // namespace

void bind_stack(py::module_& m) {
  py::class_<deform::DeformationStack>(
      m, "DeformationStack",
      "Deformations of space applied in order (Bezier, B-spline and extended lattices, taper, "
      "twist, bend), from their JSON form (docs/deform.md); pickles as that JSON, bit for bit.")
      .def_static(
          "from_json", [](const std::string& text) { return deform::stack_from_json(text); },
          py::arg("text"), "Parses a stack (DocumentError names the JSON path and the fix).")
      .def("to_json", [](const deform::DeformationStack& s) { return deform::to_json(s); })
      .def_property_readonly("kinds",
                             [](const deform::DeformationStack& s) {
                               std::vector<std::string> out;
                               for (const auto& step : s.steps)
                                 out.emplace_back(deform::kind_name(step.deformation));
                               return out;
                             })
      .def(
          "deform_points",
          [](const deform::DeformationStack& s, const py::handle& points, int threads) {
            // The stack's bulk function works on its own matrix: one copy in, none out.
            Points3 p = points_in(points, "points");
            require_finite(p, "points");
            deform::DeformOptions o;
            o.threads = threads;
            deform::StackReport report;
            Points3 out;
            {
              py::gil_scoped_release free;
              deform::deform_points(s, p, out, report, o);
            }
            if (!report.converged())
              throw Error(ErrorCategory::ToleranceNotMet,
                          "deform_points: " + report.brief() +
                              " (points an extended lattice cannot place are left unchanged)");
            return owned(std::move(out));
          },
          py::arg("points"), py::arg("threads") = 0,
          "The points (n, 3) float64 deformed by every enabled step in order (a new array).")
      .def(
          "deform_point",
          [](const deform::DeformationStack& s, const py::handle& x) {
            return tuple_of(deform::deform_point(s, vec3(x, "x")));
          },
          py::arg("x"))
      .def(
          "refit",
          [](const deform::DeformationStack& s, const surface::BSplineSurface& surface,
             double relative_tolerance, double tolerance_mm, int degree, int max_control_points) {
            deform::RefitResult r;
            {
              py::gil_scoped_release free;
              r = deform::refit_deformed(
                  s, surface,
                  refit_options(relative_tolerance, tolerance_mm, degree, max_control_points));
            }
            return refit_result(std::move(r));
          },
          py::arg("surface"), py::arg("relative_tolerance") = 1e-4, py::arg("tolerance_mm") = 0.0,
          py::arg("degree") = 3, py::arg("max_control_points") = 40000,
          "The deformed surface refitted on its own (u, v), with a certified bound: (surface, "
          "report). ToleranceNotMetError when the bound misses the tolerance.")
      .def(py::pickle([](const deform::DeformationStack& s) { return deform::to_json(s); },
                      [](const std::string& text) { return deform::stack_from_json(text); }))
      .def("__repr__", [](const deform::DeformationStack& s) {
        return "<clayform.DeformationStack " + std::to_string(s.steps.size()) + " steps>";
      });

  m.def(
      "refit_surface",
      [](const surface::BSplineSurface& surface, double relative_tolerance, double tolerance_mm,
         int degree, int max_control_points) {
        deform::RefitResult r;
        {
          py::gil_scoped_release free;
          deform::RefitOptions o =
              refit_options(relative_tolerance, tolerance_mm, degree, max_control_points);
          o.keep_breakpoints = false;  // an editable copy: knots only where the tolerance needs
          r = deform::refit_surface(surface, o);
        }
        return refit_result(std::move(r));
      },
      py::arg("surface"), py::arg("relative_tolerance") = 1e-4, py::arg("tolerance_mm") = 0.0,
      py::arg("degree") = 3, py::arg("max_control_points") = 40000,
      "A light, certified copy of a surface (the recipes' rebuild without counts): (surface, "
      "report).");

  m.def(
      "fit_to_profile",
      [](const surface::BSplineSurface& surface, const std::string& profile,
         double relative_tolerance, double tolerance_mm, const std::string& name) {
        const deform::ReceiverProfile& p = deform::receiver_profile(profile);
        deform::ProfileFit f;
        {
          py::gil_scoped_release free;
          f = deform::fit_to_profile(
              surface, p, refit_options(relative_tolerance, tolerance_mm, 3, 40000), name);
        }
        py::dict d = f.refitted ? refit_report(f.report) : py::dict();
        d["profile"] = profile;
        d["refitted"] = f.refitted;
        d["elevated"] = f.elevated;
        d["bound_mm"] = f.bound_mm;
        return py::make_tuple(std::move(f.surface), d);
      },
      py::arg("surface"), py::arg("profile"), py::arg("relative_tolerance") = 1e-4,
      py::arg("tolerance_mm") = 0.0, py::arg("name") = "surface",
      "The surface as a receiver takes it (docs/deform.md, Receiver profiles): profile 'exact', "
      "'opencascade', 'catia', 'class_a' or 'bicubic'; unchanged when it conforms, raised "
      "exactly, or refitted within the tolerance with a certified bound: (surface, report with "
      "refitted, elevated, bound_mm). ToleranceNotMetError or DegreeLimitError when it cannot "
      "conform.");
}

}  // namespace clay::python
