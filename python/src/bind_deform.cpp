// Lattices (Bézier, B-spline) as value classes with zero-copy control points, bulk point
// deformation on NumPy arrays, exact composition with surfaces, and the style deformation.
#include "common.hpp"

#include <clay/deform/compose.hpp>
#include <clay/deform/derivatives.hpp>
#include <clay/deform/direct_manipulation.hpp>
#include <clay/deform/frozen_lattice.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/style.hpp>

#include <cmath>

namespace clay::python {

using deform::BezierLattice;
using deform::BSplineLattice;
using deform::Frame;
using deform::FrozenLattice;
using surface::BSplineCurve;
using surface::BSplineSurface;

namespace {

Frame frame_in(const py::handle& origin, const py::handle& s, const py::handle& t,
               const py::handle& u) {
  Frame f;
  f.origin = vec3(origin, "origin");
  f.s = vec3(s, "s");
  f.t = vec3(t, "t");
  f.u = vec3(u, "u");
  return f;
}

py::tuple frame_out(const Frame& f) {
  return py::make_tuple(tuple_of(f.origin), tuple_of(f.s), tuple_of(f.t), tuple_of(f.u));
}

/// deform_points on an (n, 3) array: into `out` (in place when it is `points`) or a new array.
py::object deform_array(const FrozenLattice& lattice, const py::handle& points,
                        const py::object& out, int threads) {
  const auto in = points_in(points, "points");
  require_finite(in, "points");
  deform::DeformOptions o;
  o.threads = threads;
  const std::span<const double> from(in.data(), static_cast<std::size_t>(in.size()));
  if (out.is_none()) {
    Points3 result(in.rows(), 3);
    {
      py::gil_scoped_release free;
      deform::deform_points(
          lattice, from, std::span<double>(result.data(), static_cast<std::size_t>(result.size())),
          o);
    }
    return owned(std::move(result));
  }
  auto to = points_out_arg(out, "out");
  if (to.rows() != in.rows())
    throw py::value_error("out: expected " + std::to_string(in.rows()) + " rows, got " +
                          std::to_string(to.rows()));
  // In place is fine (each row is read before it is written); a partial overlap would read rows
  // already written over (issue #36: silently wrong).
  const double *a = in.data(), *b = to.data();
  if (a != b && b < a + in.size() && a < b + to.size())
    throw py::value_error(
        "out: it overlaps points without being points itself, so rows would be read after they "
        "were written; give points itself (in place) or an array of its own");
  {
    py::gil_scoped_release free;
    deform::deform_points(lattice, from,
                          std::span<double>(to.data(), static_cast<std::size_t>(to.size())), o);
  }
  return out;
}

py::dict compose_report(const deform::ComposeReport& r) {
  py::dict d;
  d["degree_u"] = r.degree_u;
  d["degree_v"] = r.degree_v;
  d["patches"] = r.patches;
  d["control_points"] = r.control_points;
  d["knots_removed"] = r.knots_removed;
  d["splits"] = r.splits;
  d["max_relative_deviation"] = r.max_relative_deviation;
  d["size_mm"] = r.size;
  d["exact"] = r.exact;
  d["message"] = r.brief();
  return d;
}

py::dict style_report(const deform::StyleReport& r) {
  py::dict d;
  d["mode"] = r.mode == deform::StyleMode::Exact ? "exact" : "paper";
  d["constraint_class"] = std::string(deform::to_string(r.constraint_class));
  d["key_points"] = r.key_points.size();
  d["influenced_vertices"] = r.influenced_vertices;
  d["moved_vertices"] = r.moved_vertices;
  d["max_displacement"] = r.max_displacement;
  d["target_deviation"] = r.target_deviation;
  d["target_curve_deviation"] = r.target_curve_deviation;
  d["target_curve_distance"] = r.target_curve_distance;
  d["locality"] = r.locality;
  d["boundary_position_jump"] = r.boundary_position_jump;
  d["boundary_tangent_angle"] = r.boundary_tangent_angle;
  d["knots_inserted"] = r.knots_inserted;
  d["added_key_points"] = r.added_key_points;
  d["net_change"] = std::isnan(r.net_change) ? py::object(py::none()) : py::float_(r.net_change);
  d["mean_curvature_min"] = r.mean_curvature_min;
  d["mean_curvature_max"] = r.mean_curvature_max;
  d["curvature_waves"] = r.curvature_waves;
  d["fairness_energy"] = r.fairness_energy;
  d["converged"] = r.summary.converged();
  d["message"] = r.message;
  return d;
}

/// A scipy.sparse CSR matrix copied from a row-major sparse matrix's own arrays (Debian's
/// python3-scipy).
template <class Lattice>
void lattice_common(py::class_<Lattice>& c) {
  c.def_property(
       "points",
       [](py::object self) {
         auto& l = self.cast<Lattice&>();
         return view(l.points.data(), l.points.rows(), self);
       },
       [](Lattice& l, const py::handle& points) {
         const auto p = points_in(points, "points");
         if (p.rows() != l.points.rows())
           throw py::value_error("points: expected " + std::to_string(l.points.rows()) +
                                 " rows, got " + std::to_string(p.rows()));
         l.points = p;
       },
       "The control points P_ijk, row (i * count_t + j) * count_u + k: a writable view.")
      .def_property_readonly(
          "frame", [](const Lattice& l) { return frame_out(l.frame); },
          "(origin, s, t, u) of the parallelepiped, mm.")
      .def_property_readonly("counts", [](const Lattice& l) { return tuple_of(l.counts()); })
      .def(
          "index",
          [](const Lattice& l, int i, int j, int k) {
            // The kernel's index() is unchecked (inner loops); here a wrong index moved another
            // point (issue #36).
            const auto n = l.counts();
            if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2])
              throw py::index_error("index (" + std::to_string(i) + ", " + std::to_string(j) +
                                    ", " + std::to_string(k) + ") is outside the lattice's " +
                                    std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " +
                                    std::to_string(n[2]) + " points (0-based)");
            return l.index(i, j, k);
          },
          py::arg("i"), py::arg("j"), py::arg("k"),
          "The row of P_ijk in points; IndexError outside the lattice.")
      .def(
          "deform_points",
          [](const Lattice& l, const py::handle& points, const py::object& out, int threads) {
            std::optional<FrozenLattice> frozen;
            {
              py::gil_scoped_release free;
              frozen.emplace(l);
            }
            return deform_array(*frozen, points, out, threads);
          },
          py::arg("points"), py::arg("out") = py::none(), py::arg("threads") = 0,
          "The points (n, 3) float64, C order, read in place, deformed: a new array, or into "
          "out (which may be points itself). For many calls, freeze() once.")
      .def(
          "deform_point",
          [](const Lattice& l, const py::handle& x) {
            return tuple_of(deform::deform_point(l, vec3(x, "x")));
          },
          py::arg("x"), "One point deformed (a small call).")
      .def(
          "freeze",
          [](const Lattice& l) {
            py::gil_scoped_release free;
            return FrozenLattice(l);
          },
          "The lattice prepared for fast evaluation (power-basis cells).")
      .def(
          "compose",
          [](const Lattice& l, const BSplineSurface& s, int check_samples, int max_degree,
             long max_control_points) {
            deform::ComposeOptions o;
            o.check_samples = check_samples;
            o.max_degree = max_degree;
            o.max_control_points = max_control_points;
            deform::ComposeResult r;
            {
              py::gil_scoped_release free;
              r = deform::compose_exact(l, s, o);
            }
            return py::make_tuple(std::move(r.surface), compose_report(r.report));
          },
          py::arg("surface"), py::arg("check_samples") = 4, py::arg("max_degree") = 25,
          py::arg("max_control_points") = 0,
          "The surface deformed by the lattice exactly (compose_exact): (surface, report). "
          "DegreeLimitError, before anything is composed, when the result would be above "
          "max_degree or max_control_points (> 0; the net predicted from the degrees).")
      .def(
          "composition_jacobian",
          [](const Lattice& l, const BSplineSurface& s) {
            deform::CompositionJacobian j;
            {
              py::gil_scoped_release free;
              j = deform::composition_jacobian(l, s);
            }
            return py::make_tuple(std::move(j.surface), scipy_csr(j.matrix));
          },
          py::arg("surface"),
          "(composed, C): the surface composed exactly in a fixed form (Bezier patches at their "
          "tensor degrees, joined C0; split at a B-spline lattice's knot planes as compose "
          "splits it) and its control points' Jacobian, a scipy.sparse CSR matrix (control "
          "points x lattice points): composed.points == C @ lattice.points, exact and constant "
          "(docs/optimisation.md).")
      .def(
          "influence_matrix",
          [](const Lattice& l, const py::handle& points) {
            const Points3 p = points_in(points, "points");
            Eigen::SparseMatrix<double, Eigen::RowMajor> b;
            {
              py::gil_scoped_release free;
              b = deform::influence_matrix(l, p);
            }
            return scipy_csr(std::move(b));
          },
          py::arg("points"),
          "The Jacobian of the deformed points with respect to the lattice points, a "
          "scipy.sparse CSR matrix B (points x lattice points): deform_points(points) == B @ "
          "points of the lattice, exact and constant (eq. (2) is linear in them; a mesh's nodes, "
          "or a surface's points at given (u, v)). OutOfDomainError for a point outside.")
      .def(
          "influence_transpose_product",
          [](const Lattice& l, const py::handle& points, const py::handle& g) {
            const Points3 p = points_in(points, "points");
            const Points3 gradient = points_in(g, "g");
            Points3 out;
            {
              py::gil_scoped_release free;
              out = deform::influence_transpose_product(l, p, gradient);
            }
            return owned(std::move(out));
          },
          py::arg("points"), py::arg("g"),
          "B.T @ g without forming B (influence_matrix): the gradient with respect to the "
          "lattice points (lattice points x 3) of a function whose gradient with respect to the "
          "deformed points is g (points x 3), for adjoint users.")
      .def("validate", [](const Lattice& l) { deform::validate(l); })
      .def("__copy__", [](const Lattice& l) { return l; })
      .def("__deepcopy__", [](const Lattice& l, py::dict) { return l; });
}

}  // namespace

void bind_deform(py::module_& m) {
  py::class_<BezierLattice> bezier(
      m, "BezierLattice",
      "A trivariate Bernstein FFD (Sederberg-Parry eq. (2)) on a parallelepiped: "
      "BezierLattice(origin, s, t, u, degrees) is the undisplaced lattice.");
  bezier
      .def(py::init([](const py::handle& origin, const py::handle& s, const py::handle& t,
                       const py::handle& u, std::array<int, 3> degrees) {
             return deform::make_bezier_lattice(frame_in(origin, s, t, u), degrees);
           }),
           py::arg("origin"), py::arg("s"), py::arg("t"), py::arg("u"),
           py::arg("degrees") = std::array<int, 3>{3, 3, 3})
      .def_property_readonly("degrees", [](const BezierLattice& l) { return tuple_of(l.degrees); })
      .def("__repr__",
           [](const BezierLattice& l) {
             return "<clayform.BezierLattice degrees (" + std::to_string(l.degrees[0]) + ", " +
                    std::to_string(l.degrees[1]) + ", " + std::to_string(l.degrees[2]) + ")>";
           })
      .def(py::pickle(
          [](const BezierLattice& l) {
            return py::make_tuple(frame_out(l.frame), l.degrees, owned(Points3(l.points)));
          },
          [](const py::tuple& t) {
            const auto f = t[0].cast<py::tuple>();
            BezierLattice l = deform::make_bezier_lattice(frame_in(f[0], f[1], f[2], f[3]),
                                                          t[1].cast<std::array<int, 3>>());
            l.points = points_in(t[2], "points");
            deform::validate(l);
            return l;
          }));
  lattice_common(bezier);

  py::class_<BSplineLattice> bspline(
      m, "BSplineLattice",
      "A trivariate B-spline FFD (Hsu-Hughes-Kaufman eq. (1)) with clamped knots: "
      "BSplineLattice(origin, s, t, u, degrees, cells) is the undisplaced lattice.");
  bspline
      .def(py::init([](const py::handle& origin, const py::handle& s, const py::handle& t,
                       const py::handle& u, std::array<int, 3> degrees, std::array<int, 3> cells) {
             return deform::make_bspline_lattice(frame_in(origin, s, t, u), degrees, cells);
           }),
           py::arg("origin"), py::arg("s"), py::arg("t"), py::arg("u"),
           py::arg("degrees") = std::array<int, 3>{3, 3, 3},
           py::arg("cells") = std::array<int, 3>{4, 4, 4})
      .def_property_readonly(
          "degrees",
          [](const BSplineLattice& l) {
            return std::array<int, 3>{l.bases[0].degree, l.bases[1].degree, l.bases[2].degree};
          })
      .def("__repr__",
           [](const BSplineLattice& l) {
             const auto c = l.counts();
             return "<clayform.BSplineLattice " + std::to_string(c[0]) + " x " +
                    std::to_string(c[1]) + " x " + std::to_string(c[2]) + " control points>";
           })
      .def(py::pickle(
          [](const BSplineLattice& l) {
            py::list bases;
            for (const auto& b : l.bases) bases.append(py::make_tuple(b.degree, b.knots));
            return py::make_tuple(frame_out(l.frame), bases, owned(Points3(l.points)));
          },
          [](const py::tuple& t) {
            const auto f = t[0].cast<py::tuple>();
            std::array<surface::BSplineBasis, 3> bases;
            const auto list = t[1].cast<py::list>();
            for (int k = 0; k < 3; ++k) {
              const auto b = list[static_cast<std::size_t>(k)].cast<py::tuple>();
              bases[static_cast<std::size_t>(k)] = {b[0].cast<int>(),
                                                    b[1].cast<std::vector<double>>()};
            }
            BSplineLattice l =
                deform::make_bspline_lattice(frame_in(f[0], f[1], f[2], f[3]), bases);
            l.points = points_in(t[2], "points");
            deform::validate(l);
            return l;
          }));
  lattice_common(bspline);

  py::class_<FrozenLattice>(m, "FrozenLattice",
                            "A lattice prepared for fast evaluation (lattice.freeze()); immutable.")
      .def_property_readonly("degrees",
                             [](const FrozenLattice& l) { return tuple_of(l.degrees()); })
      .def_property_readonly("cells", [](const FrozenLattice& l) { return tuple_of(l.cells()); })
      .def(
          "deform_points",
          [](const FrozenLattice& l, const py::handle& points, const py::object& out, int threads) {
            return deform_array(l, points, out, threads);
          },
          py::arg("points"), py::arg("out") = py::none(), py::arg("threads") = 0,
          "The points (n, 3) float64, C order, deformed without copies: a new array, or into "
          "out (which may be points itself). The GIL is released.")
      .def(
          "deform_point",
          [](const FrozenLattice& l, const py::handle& x) {
            return tuple_of(deform::deform_point(l, vec3(x, "x")));
          },
          py::arg("x"));

  m.def(
      "style_deform",
      [](const BSplineSurface& parent, const py::object& bound, const BSplineCurve& target,
         const std::string& mode, double lam, double curve_tolerance, double net_convergence,
         const std::string& continuity, bool net_convergence_best_effort) {
        deform::StyleOptions o;
        if (mode == "exact")
          o.mode = deform::StyleMode::Exact;
        else if (mode != "paper")
          throw Error(ErrorCategory::InvalidArgument,
                      "style_deform: mode \"" + mode + "\" is not \"paper\" or \"exact\"");
        if (continuity == "G2")
          o.continuity = deform::BoundContinuity::G2;
        else if (continuity != "G1")
          throw Error(ErrorCategory::InvalidArgument,
                      "style_deform: continuity \"" + continuity + "\" is not \"G1\" or \"G2\"");
        o.lambda = lam;
        o.curve_tolerance = curve_tolerance;
        o.net_convergence = net_convergence;
        o.net_convergence_best_effort = net_convergence_best_effort;
        const std::optional<BSplineCurve> b =
            bound.is_none() ? std::nullopt : std::optional(bound.cast<BSplineCurve>());
        deform::StyleResult r;
        {
          py::gil_scoped_release free;
          r = b ? deform::style_deform(parent, *b, target, o)
                : deform::style_deform(parent, target, o);
        }
        if (!r.report.summary.converged())
          throw Error(ErrorCategory::ToleranceNotMet,
                      "style_deform: " + r.report.summary.message +
                          "; loosen curve_tolerance or net_convergence, or widen the bound");
        return py::make_tuple(std::move(r.surface), style_report(r.report));
      },
      py::arg("parent"), py::arg("bound"), py::arg("target"), py::arg("mode") = "exact",
      py::arg("lam") = 1.0, py::arg("curve_tolerance") = 1e-4, py::arg("net_convergence") = 0.0,
      py::arg("continuity") = "G1", py::arg("net_convergence_best_effort") = false,
      "Han-De Amicis-Conti style deformation of parent by a closed bound curve (None: the "
      "target's support band) and a target curve: (surface, report). A result that misses its "
      "tolerance raises ToleranceNotMetError; with net_convergence_best_effort, a net that "
      "stops short of net_convergence keeps its finest result (report['net_change']).");
}

}  // namespace clay::python
