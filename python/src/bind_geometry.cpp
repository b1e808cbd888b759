// Curves and surfaces as NumPy-first value classes, their evaluation and tessellation, the
// builders (fill, loft, revolve), exchange (STEP, IGES, glTF) and pictures.
#include "common.hpp"

#include <clay/occt/fill.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/render/render.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/skin.hpp>
#include <clay/surface/tessellate.hpp>

#include <pybind11/stl/filesystem.h>

#include <cstring>

namespace clay::python {

using surface::BSplineCurve;
using surface::BSplineSurface;

namespace {

Eigen::VectorXd weights_in(const py::object& w, Eigen::Index count, const std::string& what) {
  if (w.is_none()) return {};
  const auto a = py::cast<py::array>(w);
  const auto v = values_in(a, what);
  if (static_cast<Eigen::Index>(v.size()) != count)
    throw py::value_error(what + ": expected " + std::to_string(count) + " weights, got " +
                          std::to_string(v.size()));
  return Eigen::Map<const Eigen::VectorXd>(v.data(), count);
}

py::dict build_report(const surface::BuildReport& r) {
  py::dict d;
  d["method"] = r.method;
  d["degree_u"] = r.degree_u;
  d["degree_v"] = r.degree_v;
  d["control_points"] = static_cast<long long>(r.count_u) * r.count_v;
  d["rational"] = r.rational;
  d["exact"] = r.exact;
  d["max_deviation_mm"] = r.max_deviation_mm;
  d["samples"] = r.samples;
  d["message"] = r.brief();
  return d;
}

py::dict exchange_report(const surface::ExchangeReport& r) {
  py::dict d;
  d["faces"] = r.faces;
  d["max_degree"] = r.max_degree;
  d["control_points"] = r.control_points;
  d["valid"] = r.valid;
  d["tolerance_mm"] = r.tolerance_mm;
  d["message"] = r.brief();
  return d;
}

/// Evaluates `f(u, v)` or `f(t)` on parameter arrays of one shape: shape + (3,).
template <class F>
py::array_t<double> on_parameters(const std::vector<py::array>& params, F&& f) {
  std::vector<std::span<const double>> spans;
  const char* names[] = {"u", "v"};
  for (std::size_t k = 0; k < params.size(); ++k) {
    spans.push_back(values_in(params[k], params.size() == 1 ? "t" : names[k]));
    if (k && spans[k].size() != spans[0].size())
      throw py::value_error("u and v: expected arrays of the same shape, got " +
                            std::string(py::str(params[0].attr("shape"))) + " and " +
                            std::string(py::str(params[k].attr("shape"))));
  }
  const std::size_t n = spans[0].size();
  std::vector<py::ssize_t> shape(params[0].shape(), params[0].shape() + params[0].ndim());
  shape.push_back(3);
  py::array_t<double> out(shape);
  double* o = out.mutable_data();
  {
    py::gil_scoped_release free;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d p = f(spans, i);
      o[3 * i] = p.x();
      o[3 * i + 1] = p.y();
      o[3 * i + 2] = p.z();
    }
  }
  return out;
}

std::vector<BSplineSurface> surfaces_in(const py::object& obj) {
  if (py::isinstance<BSplineSurface>(obj)) return {obj.cast<BSplineSurface>()};
  return obj.cast<std::vector<BSplineSurface>>();
}

py::bytes png_of(const std::vector<BSplineSurface>& surfaces,
                 const std::vector<BSplineCurve>& curves, int width, int height) {
  std::vector<unsigned char> png;
  {
    py::gil_scoped_release free;
    render::RenderOptions o;
    o.width = width;
    o.height = height;
    png = render::encode_png(render::render(surfaces, o, curves));
  }
  return py::bytes(reinterpret_cast<const char*>(png.data()), png.size());
}

surface::FillStyle fill_style(const std::string& s) {
  if (s == "coons") return surface::FillStyle::Coons;
  if (s == "stretch") return surface::FillStyle::Stretch;
  if (s == "curved") return surface::FillStyle::Curved;
  throw Error(ErrorCategory::InvalidArgument,
              "fill: style \"" + s + "\" is not one of \"coons\", \"stretch\", \"curved\"");
}

}  // namespace

void bind_geometry(py::module_& m) {
  py::class_<BSplineCurve>(m, "Curve",
                           "A (rational) B-spline curve: degree, knots, control points (n, 3) and "
                           "weights (n). Value type: copy with copy.copy, compare with identical.")
      .def(py::init([](int degree, std::vector<double> knots, const py::handle& points,
                       const py::object& weights) {
             const auto p = points_in(points, "points");
             return surface::make_curve(degree, std::move(knots), Points3(p),
                                        weights_in(weights, p.rows(), "weights"));
           }),
           py::arg("degree"), py::arg("knots"), py::arg("points"), py::arg("weights") = py::none(),
           "Builds and validates a curve (the points and weights are copied into it); "
           "InvalidGeometryError names every broken invariant.")
      .def_property_readonly("degree", [](const BSplineCurve& c) { return c.basis.degree; })
      .def_property_readonly(
          "knots", [](const BSplineCurve& c) { return frozen_copy(c.basis.knots); },
          "The knot vector (a read-only copy).")
      .def_property(
          "points",
          [](py::object self) {
            auto& c = self.cast<BSplineCurve&>();
            return view(c.points.data(), c.points.rows(), self);
          },
          [](BSplineCurve& c, const py::handle& points) {
            const auto p = points_in(points, "points");
            if (p.rows() != c.points.rows())
              throw py::value_error("points: expected " + std::to_string(c.points.rows()) +
                                    " rows, got " + std::to_string(p.rows()));
            c.points = p;
          },
          "The control points, (n, 3): a writable view into the curve (no copy).")
      .def_property_readonly(
          "weights",
          [](py::object self) {
            auto& c = self.cast<BSplineCurve&>();
            return py::array_t<double>({c.weights.size()}, {sizeof(double)}, c.weights.data(),
                                       self);
          },
          "The weights, (n,): a writable view into the curve (all 1 when polynomial).")
      .def_property_readonly("domain", [](const BSplineCurve& c) { return c.basis.domain(); })
      .def_property_readonly("rational", &BSplineCurve::is_rational)
      .def(
          "evaluate",
          [](const BSplineCurve& c, double t) {
            const Eigen::Vector3d p = surface::evaluate(c, t);
            return owned(Points3(p.transpose())).attr("reshape")(3);
          },
          py::arg("t"), "The point at parameter t, (3,).")
      .def(
          "evaluate",
          [](const BSplineCurve& c, const py::array& t) {
            // The curve's batch evaluation (one basis per span, not per point).
            const auto ts = values_in(t, "t");
            Points3 p;
            {
              py::gil_scoped_release free;
              p = surface::evaluate_many(c, ts);
            }
            std::vector<py::ssize_t> shape(t.shape(), t.shape() + t.ndim());
            shape.push_back(3);
            return owned(std::move(p)).attr("reshape")(shape);
          },
          py::arg("t"), "The points at the parameters of an array t: shape t.shape + (3,).")
      .def(
          "validate", [](const BSplineCurve& c) { surface::validate(c); },
          "Raises InvalidGeometryError when the curve breaks an invariant (after edits).")
      .def(
          "identical",
          [](const BSplineCurve& a, const BSplineCurve& b) { return surface::identical(a, b); },
          "True when degree, knots, points and weights are equal bit for bit.")
      .def("reversed", [](const BSplineCurve& c) { return surface::reversed(c); })
      .def(
          "mirrored",
          [](const BSplineCurve& c, const py::handle& origin, const py::handle& normal) {
            return surface::mirrored(c, vec3(origin, "origin"), vec3(normal, "normal"));
          },
          py::arg("origin"), py::arg("normal"), "The curve reflected in a plane.")
      .def("__copy__", [](const BSplineCurve& c) { return c; })
      .def("__deepcopy__", [](const BSplineCurve& c, py::dict) { return c; })
      .def("__repr__",
           [](const BSplineCurve& c) {
             return "<clayform.Curve degree " + std::to_string(c.basis.degree) + ", " +
                    std::to_string(c.points.rows()) + " control points" +
                    (c.is_rational() ? ", rational" : "") + ">";
           })
      .def("_repr_png_", [](const BSplineCurve& c) { return png_of({}, {c}, 480, 320); })
      .def(py::pickle(
          [](const BSplineCurve& c) {
            return py::make_tuple(
                c.basis.degree, c.basis.knots, owned(Points3(c.points)),
                owned(std::vector<double>(c.weights.data(), c.weights.data() + c.weights.size())));
          },
          [](const py::tuple& t) {
            const auto p = points_in(t[2], "points");
            return surface::make_curve(t[0].cast<int>(), t[1].cast<std::vector<double>>(),
                                       Points3(p), weights_in(t[3], p.rows(), "weights"));
          }));

  py::class_<BSplineSurface>(
      m, "Surface",
      "A (rational) tensor-product B-spline surface. Control point (i, j) is row i * count_v + "
      "j of points (u-major).")
      .def(py::init([](std::array<int, 2> degrees, std::vector<double> knots_u,
                       std::vector<double> knots_v, const py::handle& points,
                       const py::object& weights) {
             const auto p = points_in(points, "points");
             return surface::make_surface({degrees[0], std::move(knots_u)},
                                          {degrees[1], std::move(knots_v)}, Points3(p),
                                          weights_in(weights, p.rows(), "weights"));
           }),
           py::arg("degrees"), py::arg("knots_u"), py::arg("knots_v"), py::arg("points"),
           py::arg("weights") = py::none(),
           "Builds and validates a surface (points (count_u * count_v, 3), u-major; copied in).")
      .def_property_readonly(
          "degrees", [](const BSplineSurface& s) { return py::make_tuple(s.u.degree, s.v.degree); })
      .def_property_readonly(
          "counts",
          [](const BSplineSurface& s) { return py::make_tuple(s.u.count(), s.v.count()); })
      .def_property_readonly("knots_u",
                             [](const BSplineSurface& s) { return frozen_copy(s.u.knots); })
      .def_property_readonly("knots_v",
                             [](const BSplineSurface& s) { return frozen_copy(s.v.knots); })
      .def_property(
          "points",
          [](py::object self) {
            auto& s = self.cast<BSplineSurface&>();
            return view(s.points.data(), s.points.rows(), self);
          },
          [](BSplineSurface& s, const py::handle& points) {
            const auto p = points_in(points, "points");
            if (p.rows() != s.points.rows())
              throw py::value_error("points: expected " + std::to_string(s.points.rows()) +
                                    " rows, got " + std::to_string(p.rows()));
            s.points = p;
          },
          "The control points, (count_u * count_v, 3): a writable view (no copy).")
      .def_property_readonly(
          "weights",
          [](py::object self) {
            auto& s = self.cast<BSplineSurface&>();
            return py::array_t<double>({s.weights.size()}, {sizeof(double)}, s.weights.data(),
                                       self);
          },
          "The weights: a writable view (all 1 when polynomial).")
      .def_property_readonly(
          "domain",
          [](const BSplineSurface& s) { return std::make_pair(s.u.domain(), s.v.domain()); })
      .def_property_readonly("rational", &BSplineSurface::is_rational)
      .def(
          "evaluate",
          [](const BSplineSurface& s, double u, double v) {
            const Eigen::Vector3d p = surface::evaluate(s, u, v);
            return owned(Points3(p.transpose())).attr("reshape")(3);
          },
          py::arg("u"), py::arg("v"), "The point at (u, v), (3,).")
      .def(
          "evaluate",
          [](const BSplineSurface& s, const py::array& u, const py::array& v) {
            return on_parameters({u, v}, [&](const auto& p, std::size_t i) {
              return surface::evaluate(s, p[0][i], p[1][i]);
            });
          },
          py::arg("u"), py::arg("v"),
          "The points at the parameters of arrays u and v of one shape: shape + (3,).")
      .def(
          "normal",
          [](const BSplineSurface& s, const py::array& u, const py::array& v) {
            return on_parameters({u, v}, [&](const auto& p, std::size_t i) {
              return surface::unit_normal(s, p[0][i], p[1][i]);
            });
          },
          py::arg("u"), py::arg("v"), "Unit normals at arrays u and v: shape + (3,).")
      .def(
          "evaluate_grid",
          [](const BSplineSurface& s, const py::array& u, const py::array& v) {
            const auto us = values_in(u, "u"), vs = values_in(v, "v");
            Points3 grid;
            {
              py::gil_scoped_release free;
              grid = surface::evaluate_grid(s, us, vs);
            }
            return owned(std::move(grid)).attr("reshape")(py::make_tuple(us.size(), vs.size(), 3));
          },
          py::arg("u"), py::arg("v"), "The grid u x v: (len(u), len(v), 3).")
      .def(
          "tessellate",
          [](const BSplineSurface& s, int per_span, int max_samples) {
            surface::GridMesh mesh;
            {
              py::gil_scoped_release free;
              mesh = surface::tessellate(s, per_span, max_samples);
            }
            std::vector<std::array<int, 3>> triangles;
            for (int i = 0; i + 1 < mesh.rows; ++i)
              for (int j = 0; j + 1 < mesh.cols; ++j)
                for (const auto& t : surface::cell_triangles(mesh, i, j)) triangles.push_back(t);
            py::array_t<std::int32_t> faces(
                {static_cast<py::ssize_t>(triangles.size()), py::ssize_t{3}});
            std::memcpy(faces.mutable_data(), triangles.data(), triangles.size() * 12);
            return py::make_tuple(owned(std::move(mesh.positions)), faces,
                                  owned(std::move(mesh.normals)));
          },
          py::arg("per_span") = 8, py::arg("max_samples") = 161,
          "A triangle mesh: (vertices (n, 3), faces (m, 3) int32, normals (n, 3)), as "
          "trimesh.Trimesh(vertices, faces) and matplotlib's plot_trisurf take it.")
      .def("validate", [](const BSplineSurface& s) { surface::validate(s); })
      .def(
          "identical",
          [](const BSplineSurface& a, const BSplineSurface& b) { return surface::identical(a, b); },
          "True when degrees, knots, points and weights are equal bit for bit.")
      .def(
          "mirrored",
          [](const BSplineSurface& s, const py::handle& origin, const py::handle& normal) {
            return surface::mirrored(s, vec3(origin, "origin"), vec3(normal, "normal"));
          },
          py::arg("origin"), py::arg("normal"))
      .def("__copy__", [](const BSplineSurface& s) { return s; })
      .def("__deepcopy__", [](const BSplineSurface& s, py::dict) { return s; })
      .def("__repr__",
           [](const BSplineSurface& s) {
             return "<clayform.Surface degrees (" + std::to_string(s.u.degree) + ", " +
                    std::to_string(s.v.degree) + "), " + std::to_string(s.u.count()) + " x " +
                    std::to_string(s.v.count()) + " control points" +
                    (s.is_rational() ? ", rational" : "") + ">";
           })
      .def("_repr_png_", [](const BSplineSurface& s) { return png_of({s}, {}, 480, 320); })
      .def(py::pickle(
          [](const BSplineSurface& s) {
            return py::make_tuple(
                s.u.degree, s.u.knots, s.v.degree, s.v.knots, owned(Points3(s.points)),
                owned(std::vector<double>(s.weights.data(), s.weights.data() + s.weights.size())));
          },
          [](const py::tuple& t) {
            const auto p = points_in(t[4], "points");
            return surface::make_surface({t[0].cast<int>(), t[1].cast<std::vector<double>>()},
                                         {t[2].cast<int>(), t[3].cast<std::vector<double>>()},
                                         Points3(p), weights_in(t[5], p.rows(), "weights"));
          }));

  m.def(
      "render_png",
      [](const py::object& surfaces, const std::vector<BSplineCurve>& curves, int width,
         int height) { return png_of(surfaces_in(surfaces), curves, width, height); },
      py::arg("surfaces"), py::arg("curves") = std::vector<BSplineCurve>{}, py::arg("width") = 960,
      py::arg("height") = 640,
      "A shaded picture (PNG bytes) of surfaces and curves, by the software renderer.");

  // Builders: (surface, report dict).
  m.def(
      "fill",
      [](const std::vector<BSplineCurve>& curves, const std::string& style, double gap_tolerance,
         double min_span_ratio) {
        surface::FillOptions o;
        o.style = fill_style(style);
        o.gap_tolerance = gap_tolerance;
        o.min_span_ratio = min_span_ratio;
        surface::BuiltSurface b;
        {
          py::gil_scoped_release free;
          b = surface::fill(curves, o);
        }
        return py::make_tuple(b.surface, build_report(b.report));
      },
      py::arg("curves"), py::arg("style") = "coons", py::arg("gap_tolerance") = 1e-7,
      py::arg("min_span_ratio") = 0.05,
      "The surface bounded by 2-4 curves (surface::fill): (surface, report).");
  m.def(
      "loft",
      [](const std::vector<BSplineCurve>& sections, int degree) {
        surface::LoftOptions o;
        o.degree = degree;
        surface::BuiltSurface b;
        {
          py::gil_scoped_release free;
          b = surface::loft(sections, o);
        }
        return py::make_tuple(b.surface, build_report(b.report));
      },
      py::arg("sections"), py::arg("degree") = 3,
      "The surface through the sections, in order (skinning, surface::loft): (surface, report).");
  m.def(
      "revolve",
      [](const BSplineCurve& profile, const py::handle& point, const py::handle& direction,
         double angle_degrees) {
        const surface::Axis axis{vec3(point, "point"), vec3(direction, "direction")};
        surface::BuiltSurface b;
        {
          py::gil_scoped_release free;
          b = surface::revolve(profile, axis, angle_degrees);
        }
        return py::make_tuple(b.surface, build_report(b.report));
      },
      py::arg("profile"), py::arg("point"), py::arg("direction"), py::arg("angle_degrees") = 360.0,
      "The profile revolved about an axis (exact, rational): (surface, report).");

  // Exchange. OpenCASCADE's translators are serialized inside the kernel; the GIL is released.
  m.def(
      "write_step",
      [](const py::object& surfaces, const std::filesystem::path& path, const std::string& schema) {
        surface::StepWriteOptions o;
        if (schema == "AP242")
          o.schema = surface::StepSchema::AP242;
        else if (schema != "AP214")
          throw Error(ErrorCategory::InvalidArgument,
                      "write_step: schema \"" + schema + "\" is not \"AP214\" or \"AP242\"");
        const auto list = surfaces_in(surfaces);
        surface::ExchangeReport r;
        {
          py::gil_scoped_release free;
          r = surface::write_step(list, path, o);
        }
        return exchange_report(r);
      },
      py::arg("surfaces"), py::arg("path"), py::arg("schema") = "AP214",
      "Writes surfaces as faces of a STEP file (atomic); returns the exchange report.");
  m.def(
      "write_iges",
      [](const py::object& surfaces, const std::filesystem::path& path) {
        const auto list = surfaces_in(surfaces);
        surface::ExchangeReport r;
        {
          py::gil_scoped_release free;
          r = surface::write_iges(list, path);
        }
        return exchange_report(r);
      },
      py::arg("surfaces"), py::arg("path"), "Writes surfaces to an IGES file (atomic).");
  m.def(
      "write_gltf",
      [](const py::object& surfaces, const std::filesystem::path& path) {
        const auto list = surfaces_in(surfaces);
        py::gil_scoped_release free;
        surface::write_gltf(list, path);
      },
      py::arg("surfaces"), py::arg("path"), "Writes a binary glTF (.glb) preview mesh.");
  for (const char* name : {"read_step", "read_iges"}) {
    const bool step = std::string(name) == "read_step";
    m.def(
        name,
        [step](const std::filesystem::path& path, bool precheck, bool isolate) {
          surface::ReadOptions o;
          o.precheck = precheck;
          o.isolate = isolate;
          py::gil_scoped_release free;
          return step ? surface::read_step(path, o) : surface::read_iges(path, o);
        },
        py::arg("path"), py::arg("precheck") = true, py::arg("isolate") = true,
        step ? "The surface of every face of a STEP file, as Surfaces. Read in a child process "
               "(isolate=True, the default: a file that crashes OpenCASCADE raises ExchangeError "
               "instead of killing the interpreter); isolate=False reads in this process."
             : "Every B-spline surface of an IGES file, as Surfaces. Read in a child process "
               "(isolate=True, the default: a file that crashes OpenCASCADE raises ExchangeError "
               "instead of killing the interpreter); isolate=False reads in this process.");
  }
}

}  // namespace clay::python
