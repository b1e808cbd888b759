// Strokes fitted to curves, and planar or 3D sketches with geometric constraints solved on them.
#include "common.hpp"

#include <clay/constraints/constraint.hpp>
#include <clay/constraints/solve.hpp>
#include <clay/sketch/entities.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/plane.hpp>

#include <array>

namespace clay::python {

namespace {

using sketch::EntityId;
using sketch::PlaneId;
using sketch::PointId;

/// A sketch and the constraints on it: what Python builds with add_* and the constraint methods,
/// then solves. Points, entities and planes are named by their indices.
struct PySketch {
  sketch::Sketch sketch;
  std::vector<constraints::Constraint> constraints;

  PointId point(int k) const {
    if (k < 0 || k >= static_cast<int>(sketch.points.size()))
      throw Error(ErrorCategory::InvalidArgument,
                  "sketch: no point " + std::to_string(k) + "; it has " +
                      std::to_string(sketch.points.size()) + " (0-based)");
    return PointId{k};
  }
  EntityId entity(int k) const {
    if (k < 0 || k >= static_cast<int>(sketch.entities.size()))
      throw Error(ErrorCategory::InvalidArgument,
                  "sketch: no entity " + std::to_string(k) + "; it has " +
                      std::to_string(sketch.entities.size()) + " (0-based)");
    return EntityId{k};
  }
  PlaneId plane(int k) const {
    if (k >= static_cast<int>(sketch.planes.size()))
      throw Error(ErrorCategory::InvalidArgument,
                  "sketch: no plane " + std::to_string(k) + "; it has " +
                      std::to_string(sketch.planes.size()) + " (-1: free in 3D)");
    return PlaneId{k};
  }
  int add(constraints::Constraint c) {
    constraints.push_back(std::move(c));
    return static_cast<int>(constraints.size()) - 1;
  }
};

constraints::CurveEnd end_in(const PySketch& s, int entity, const std::string& end) {
  if (end != "start" && end != "end")
    throw Error(ErrorCategory::InvalidArgument,
                "sketch: curve end \"" + end + "\" is not \"start\" or \"end\"");
  return {s.entity(entity), end == "start"};
}

py::dict fit_report(const sketch::StrokeFit& f) {
  py::dict d;
  d["curves"] = f.curves.size();
  d["corners"] = std::vector<long long>(f.corners.begin(), f.corners.end());
  d["closed"] = f.closed;
  d["max_deviation_mm"] = f.max_deviation_mm;
  d["plane_offset_mm"] = f.plane_offset;
  d["converged"] = f.summary.converged();
  d["message"] = f.summary.message;
  return d;
}

py::dict solve_report(const constraints::SolveReport& r) {
  py::dict d;
  d["converged"] = r.summary.converged();
  d["max_residual"] = r.max_residual;
  d["unknowns"] = r.unknowns;
  d["equations"] = r.equations;
  d["degrees_of_freedom"] = r.degrees_of_freedom;
  py::list redundant, conflicting;
  for (const auto& x : r.redundant) redundant.append(x.message);
  for (const auto& x : r.conflicting) conflicting.append(x.message);
  d["redundant"] = redundant;
  d["conflicting"] = conflicting;
  d["flipped"] = r.flipped;
  d["message"] = r.brief();
  return d;
}

}  // namespace

void bind_sketch(py::module_& m) {
  m.def(
      "fit_stroke",
      [](const py::handle& points, double tolerance_mm, int degree, double corner_angle,
         double closing_ratio) {
        sketch::Stroke stroke;
        stroke.points = points_in(points, "points");
        sketch::FitOptions o;
        o.tolerance_mm = tolerance_mm;
        o.degree = degree;
        o.corner_angle = corner_angle;
        o.closing_ratio = closing_ratio;
        sketch::StrokeFit fit;
        {
          py::gil_scoped_release free;
          fit = sketch::fit_stroke(stroke, o);
        }
        std::vector<surface::BSplineCurve> curves;
        for (auto& c : fit.curves) curves.push_back(std::move(c.curve));
        return py::make_tuple(curves, fit_report(fit));
      },
      py::arg("points"), py::arg("tolerance_mm") = 0.1, py::arg("degree") = 3,
      py::arg("corner_angle") = 50.0, py::arg("closing_ratio") = 0.03,
      "A drawn polyline (n, 3) fitted with B-spline curves within tolerance_mm, split at "
      "corners, closed when its ends meet: (curves, report).");

  py::class_<PySketch>(m, "Sketch",
                       "Points, lines, arcs, circles and B-spline curves with constraints; "
                       "add_* return indices, solve() moves the points.")
      .def(py::init<>())
      .def(
          "add_plane",
          [](PySketch& s, const py::handle& origin, const py::handle& normal) {
            return s.sketch
                .add_plane(sketch::make_plane(vec3(origin, "origin"), vec3(normal, "normal")))
                .index;
          },
          py::arg("origin"), py::arg("normal"), "A sketch plane; returns its index.")
      .def(
          "add_point",
          [](PySketch& s, const py::handle& position, int plane) {
            if (plane < 0) return s.sketch.add_point(vec3(position, "position")).index;
            const auto& p = s.sketch.planes[static_cast<std::size_t>(s.plane(plane).index)];
            return s.sketch
                .add_point(PlaneId{plane}, sketch::to_plane(p, vec3(position, "position")))
                .index;
          },
          py::arg("position"), py::arg("plane") = -1,
          "A point (world mm; on a plane it is projected onto it); returns its index.")
      .def(
          "add_line",
          [](PySketch& s, int a, int b) { return s.sketch.add_line(s.point(a), s.point(b)).index; },
          py::arg("start"), py::arg("end"))
      .def(
          "add_arc",
          [](PySketch& s, int center, int start, int end, int plane) {
            return s.sketch.add_arc(s.point(center), s.point(start), s.point(end), s.plane(plane))
                .index;
          },
          py::arg("center"), py::arg("start"), py::arg("end"), py::arg("plane"))
      .def(
          "add_circle",
          [](PySketch& s, int center, double radius, int plane) {
            return s.sketch.add_circle(s.point(center), radius, s.plane(plane)).index;
          },
          py::arg("center"), py::arg("radius"), py::arg("plane"))
      .def(
          "add_curve",
          [](PySketch& s, const surface::BSplineCurve& c, int plane) {
            return s.sketch.add_curve(c, s.plane(plane)).index;
          },
          py::arg("curve"), py::arg("plane") = -1,
          "A B-spline curve whose control points become sketch points; returns its index.")
      .def("position", [](const PySketch& s,
                          int k) { return tuple_of(sketch::position(s.sketch, s.point(k))); })
      .def(
          "curve", [](const PySketch& s, int k) { return sketch::curve_of(s.sketch, s.entity(k)); },
          "The entity as a B-spline curve (exact: arcs and circles rational).")
      .def_property_readonly("point_count",
                             [](const PySketch& s) { return s.sketch.points.size(); })
      .def_property_readonly("constraint_count",
                             [](const PySketch& s) { return s.constraints.size(); })
      // Constraints: each returns its index in the constraint list.
      .def("fixed", [](PySketch& s, int p) { return s.add(constraints::fixed(s.point(p))); })
      .def("coincident",
           [](PySketch& s, int a, int b) {
             return s.add(constraints::coincident(s.point(a), s.point(b)));
           })
      .def("point_on", [](PySketch& s, int p,
                          int e) { return s.add(constraints::point_on(s.point(p), s.entity(e))); })
      .def("horizontal",
           [](PySketch& s, int e) { return s.add(constraints::horizontal(s.entity(e))); })
      .def("vertical", [](PySketch& s, int e) { return s.add(constraints::vertical(s.entity(e))); })
      .def("parallel", [](PySketch& s, int a,
                          int b) { return s.add(constraints::parallel(s.entity(a), s.entity(b))); })
      .def("perpendicular",
           [](PySketch& s, int a, int b) {
             return s.add(constraints::perpendicular(s.entity(a), s.entity(b)));
           })
      .def(
          "distance",
          [](PySketch& s, int a, int b, double mm) {
            return s.add(constraints::distance(s.point(a), s.point(b), mm));
          },
          py::arg("a"), py::arg("b"), py::arg("mm"))
      .def(
          "distance_to_line",
          [](PySketch& s, int p, int line, double mm) {
            return s.add(constraints::distance(s.point(p), s.entity(line), mm));
          },
          py::arg("point"), py::arg("line"), py::arg("mm"))
      .def(
          "angle",
          [](PySketch& s, int a, int b, double degrees) {
            return s.add(constraints::angle(s.entity(a), s.entity(b), degrees));
          },
          py::arg("a"), py::arg("b"), py::arg("degrees"))
      .def(
          "radius",
          [](PySketch& s, int e, double mm) { return s.add(constraints::radius(s.entity(e), mm)); },
          py::arg("entity"), py::arg("mm"))
      .def("equal_length",
           [](PySketch& s, int a, int b) {
             return s.add(constraints::equal_length(s.entity(a), s.entity(b)));
           })
      .def("equal_radius",
           [](PySketch& s, int a, int b) {
             return s.add(constraints::equal_radius(s.entity(a), s.entity(b)));
           })
      .def("midpoint",
           [](PySketch& s, int p, int line) {
             return s.add(constraints::midpoint(s.point(p), s.entity(line)));
           })
      .def("symmetric",
           [](PySketch& s, int a, int b, int line) {
             return s.add(constraints::symmetric(s.point(a), s.point(b), s.entity(line)));
           })
      .def(
          "tangent",
          [](PySketch& s, int a, const std::string& end_a, int b, const std::string& end_b) {
            return s.add(constraints::tangent(end_in(s, a, end_a), end_in(s, b, end_b)));
          },
          py::arg("a"), py::arg("end_a"), py::arg("b"), py::arg("end_b"),
          "G1 where end_a (\"start\" or \"end\") of a meets end_b of b.")
      .def(
          "curvature",
          [](PySketch& s, int a, const std::string& end_a, int b, const std::string& end_b) {
            return s.add(constraints::curvature(end_in(s, a, end_a), end_in(s, b, end_b)));
          },
          py::arg("a"), py::arg("end_a"), py::arg("b"), py::arg("end_b"))
      .def(
          "end_tangent",
          [](PySketch& s, int e, const std::string& end, const py::handle& direction) {
            return s.add(constraints::end_tangent(end_in(s, e, end), vec3(direction, "direction")));
          },
          py::arg("entity"), py::arg("end"), py::arg("direction"))
      .def(
          "solve",
          [](PySketch& s, double residual_tolerance) {
            constraints::SolveOptions o;
            o.residual_tolerance = residual_tolerance;
            // The solve runs without the GIL on a copy: another thread adding points meanwhile
            // reallocated the vectors it read and crashed the interpreter (issue #36). Adding
            // only grows the sketch, so its sizes tell whether it changed.
            const sketch::Sketch copy = s.sketch;
            const std::vector<constraints::Constraint> constraints = s.constraints;
            const auto sizes = [&] {
              return std::array<std::size_t, 4>{s.sketch.points.size(), s.sketch.entities.size(),
                                                s.sketch.planes.size(), s.constraints.size()};
            };
            const auto before = sizes();
            constraints::SolveResult r;
            {
              py::gil_scoped_release free;
              r = constraints::solve(copy, constraints, o);
            }
            if (sizes() != before)
              throw Error(ErrorCategory::InvalidArgument,
                          "sketch: points, curves or constraints were added while solve() ran "
                          "in another thread, so its result was not applied; solve again (or "
                          "lock the sketch while one thread builds it)");
            s.sketch = std::move(r.sketch);
            return solve_report(r.report);
          },
          py::arg("residual_tolerance") = 1e-10,
          "Solves the constraints in place: the report (converged, max_residual, "
          "degrees_of_freedom, redundant and conflicting sets).");
}

}  // namespace clay::python
