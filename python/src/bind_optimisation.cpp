// Shape optimisation on exact CAD (issue #41): a model's Jacobian with respect to a lattice's
// points as SciPy sparse matrices, the model at other points, mass properties and their
// gradients, moves that keep them, and the lattice's Jacobian coefficients as validity
// constraints with their gradients.
#include "common.hpp"

#include <clay/brep/mass_properties.hpp>
#include <clay/deform/jacobian.hpp>
#include <clay/deform/model_derivatives.hpp>

namespace clay::python {

using deform::BezierLattice;
using deform::BSplineLattice;
using deform::ModelJacobian;

namespace {

py::dict properties_dict(const brep::MassProperties& p) {
  py::dict d;
  d["volume_mm3"] = p.volume_mm3;
  d["centroid_mm"] = py::array_t<double>(3, p.centroid_mm.data());
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> inertia = p.inertia_mm5;
  d["inertia_mm5"] = py::array_t<double>({3, 3}, inertia.data());
  return d;
}

/// Gradients (lattice points x 3 each) stacked: (k, points, 3).
py::array_t<double> stacked(const Points3* first, std::size_t count) {
  const auto n = static_cast<py::ssize_t>(first->rows());
  py::array_t<double> out({static_cast<py::ssize_t>(count), n, py::ssize_t{3}});
  double* data = out.mutable_data();
  for (std::size_t k = 0; k < count; ++k)
    std::copy(first[k].data(), first[k].data() + first[k].size(), data + k * n * 3);
  return out;
}

py::dict gradients_dict(deform::LatticeMassGradients&& g) {
  py::dict d = properties_dict(g.value);
  d["volume_gradient"] = owned(std::move(g.volume));
  d["centroid_gradient"] = stacked(g.centroid.data(), 3);
  d["inertia_gradient"] = stacked(g.inertia.data(), 6);
  return d;
}

py::dict area_dict(const brep::SurfaceArea& a) {
  py::dict d;
  d["area_mm2"] = a.area_mm2;
  d["bound_mm2"] = a.bound_mm2;
  d["faces_mm2"] =
      py::array_t<double>(static_cast<py::ssize_t>(a.faces_mm2.size()), a.faces_mm2.data());
  return d;
}

/// Refuses a lattice its Jacobian's coefficients do not prove fold-free, unless allowed.
template <class Lattice>
void refuse_fold(const Lattice& lattice, bool allow_fold) {
  const deform::JacobianBounds b = deform::jacobian_bounds(lattice);
  if (b.fold_free || allow_fold) return;
  throw Error(ErrorCategory::InvalidGeometry,
              "model_jacobian: the lattice may fold space (the smallest Bernstein coefficient of "
              "its Jacobian is " +
                  std::to_string(b.min) +
                  " <= 0, Sederberg-Parry section 4), so the deformed solid may intersect itself; "
                  "start from a fold-free lattice (keep jacobian_constraints() > 0 while "
                  "optimising), or allow it with allow_fold=True");
}

template <class Lattice>
py::tuple constraints_of(const Lattice& lattice) {
  deform::JacobianConstraints c;
  {
    py::gil_scoped_release free;
    c = deform::jacobian_constraints(lattice);
  }
  py::array_t<double> values(c.values.size(), c.values.data());
  return py::make_tuple(values, scipy_csr(std::move(c.gradient)));
}

template <class Lattice>
void lattice_methods(py::class_<Lattice> c) {
  c.def(
       "model_jacobian",
       [](const Lattice& l, const brep::Model& model, bool allow_fold) {
         refuse_fold(l, allow_fold);
         py::gil_scoped_release free;
         return deform::model_jacobian(l, model);
       },
       py::arg("model"), py::kw_only(), py::arg("allow_fold") = false,
       "The model's exact Jacobian with respect to the lattice's points (ModelJacobian): every "
       "face, edge and vertex linear in them, in one fixed form (docs/optimisation.md). "
       "OutOfDomainError naming a face that crosses the lattice's boundary; "
       "InvalidGeometryError for a lattice not proven fold-free unless allow_fold=True.")
      .def("jacobian_constraints", &constraints_of<Lattice>,
           "(values, gradient): every Bernstein coefficient of the lattice's Jacobian (the "
           "volume ratio det DF; all > 0 proves it fold-free, Sederberg-Parry section 4) and "
           "their exact gradient, a scipy.sparse CSR matrix (coefficients x 3 * lattice "
           "points; column 3 j + c: coordinate c of point j), for an optimiser's inequality "
           "constraints values >= a floor.");
}

}  // namespace

void bind_optimisation(py::module_& m) {
  py::class_<ModelJacobian>(
      m, "ModelJacobian",
      "A model composed with a lattice in the fixed form of its derivatives, and the sparse "
      "maps from the lattice points to its geometry (lattice.model_jacobian(model)).")
      .def_property_readonly(
          "model", [](const ModelJacobian& j) { return j.model; },
          "The model at the lattice's points, in the fixed form (a copy).")
      .def_property_readonly("lattice_points",
                             [](const ModelJacobian& j) { return j.lattice_points; })
      .def_property_readonly(
          "faces",
          [](const ModelJacobian& j) {
            py::list out;
            for (const auto& f : j.faces) out.append(scipy_csr(f));
            return out;
          },
          "Per face, a scipy.sparse CSR matrix C (control points x lattice points): the face's "
          "control points == C @ lattice points. No entries: the face lies outside the lattice "
          "and keeps its points.")
      .def_property_readonly(
          "edges",
          [](const ModelJacobian& j) {
            py::list out;
            for (const auto& e : j.edges) out.append(scipy_csr(e));
            return out;
          },
          "Per edge, the same for its curve's control points.")
      .def_property_readonly(
          "vertices", [](const ModelJacobian& j) { return scipy_csr(j.vertices); },
          "One row per vertex: its point == row @ lattice points (no entries: outside).")
      .def(
          "deformed",
          [](const ModelJacobian& j, const py::handle& points) {
            const Points3 p = points_in(points, "points");
            py::gil_scoped_release free;
            return deform::deformed_model(j, p);
          },
          py::arg("points"),
          "The model at other lattice points (same shape), in the same form, by sparse "
          "products: much cheaper than composing again.")
      .def(
          "face_point_jacobian",
          [](const ModelJacobian& j, int face, const py::handle& uv) {
            const py::array_t<double> a = py::array_t<double>::ensure(uv);
            if (!a || a.ndim() != 2 || a.shape(1) != 2)
              throw py::value_error("uv: expected an (n, 2) array of (u, v)");
            std::vector<Eigen::Vector2d> at(static_cast<std::size_t>(a.shape(0)));
            auto r = a.unchecked<2>();
            for (py::ssize_t i = 0; i < a.shape(0); ++i)
              at[static_cast<std::size_t>(i)] = {r(i, 0), r(i, 1)};
            return scipy_csr(deform::face_point_jacobian(j, face, at));
          },
          py::arg("face"), py::arg("uv"),
          "The Jacobian of the face's points at (u, v) (an (n, 2) array) with respect to the "
          "lattice points, a scipy.sparse CSR matrix (n x lattice points).")
      .def(
          "mass_properties",
          [](const ModelJacobian& j, const py::object& points) {
            brep::MassProperties p;
            if (points.is_none()) {
              py::gil_scoped_release free;
              p = brep::mass_properties(j.model);
            } else {
              const Points3 l = points_in(points, "points");
              py::gil_scoped_release free;
              p = brep::mass_properties(deform::deformed_model(j, l));
            }
            return properties_dict(p);
          },
          py::arg("points") = py::none(),
          "{volume_mm3, centroid_mm (3,), inertia_mm5 (3, 3) about the centroid, unit "
          "density} of the solids at the lattice points given (None: the Jacobian's own).")
      .def(
          "mass_property_gradients",
          [](const ModelJacobian& j, const py::object& points) {
            deform::LatticeMassGradients g;
            if (points.is_none()) {
              py::gil_scoped_release free;
              g = deform::mass_property_gradients(j);
            } else {
              const Points3 l = points_in(points, "points");
              py::gil_scoped_release free;
              g = deform::mass_property_gradients(j, l);
            }
            return gradients_dict(std::move(g));
          },
          py::arg("points") = py::none(),
          "mass_properties and their exact gradients with respect to the lattice points: "
          "volume_gradient (points, 3), centroid_gradient (3, points, 3), inertia_gradient "
          "(6, points, 3) of xx, yy, zz, xy, xz, yz.")
      .def(
          "surface_area",
          [](const ModelJacobian& j, const py::object& points) {
            deform::LatticeAreaGradient g;
            if (points.is_none()) {
              py::gil_scoped_release free;
              g = deform::surface_area_gradient(j);
            } else {
              const Points3 l = points_in(points, "points");
              py::gil_scoped_release free;
              g = deform::surface_area_gradient(j, l);
            }
            py::dict d = area_dict(g.value);
            d["area_gradient"] = owned(std::move(g.area));
            return d;
          },
          py::arg("points") = py::none(),
          "{area_mm2, bound_mm2 (|error| <= it), faces_mm2 (per face), area_gradient (points, "
          "3)}: the faces' area at the lattice points given (None: the Jacobian's own) and its "
          "exact gradient with respect to the lattice points.")
      .def(
          "keep_properties",
          [](const ModelJacobian& j, const py::handle& moved, const py::object& volume,
             const py::object& centroid, const py::object& area, const std::vector<int>& held,
             const std::vector<int>& fixed_faces, const py::list& symmetry_planes,
             double tolerance) {
            deform::KeptProperties keep;
            if (!volume.is_none()) keep.volume_mm3 = volume.cast<double>();
            if (!centroid.is_none()) keep.centroid_mm = vec3(centroid, "centroid_mm");
            if (!area.is_none()) keep.area_mm2 = area.cast<double>();
            keep.held = held;
            keep.fixed_faces = fixed_faces;
            for (std::size_t i = 0; i < symmetry_planes.size(); ++i) {
              const py::handle plane = symmetry_planes[i];
              if (!py::isinstance<py::sequence>(plane) || py::isinstance<py::str>(plane) ||
                  py::len(plane) != 2)
                throw Error(ErrorCategory::InvalidArgument,
                            "keep_properties: symmetry_planes[" + std::to_string(i) +
                                "]: expected a (point, normal) pair of 3-vectors");
              const auto pair = py::reinterpret_borrow<py::sequence>(plane);
              keep.symmetry_planes.push_back(
                  {vec3(pair[0], "symmetry plane point"), vec3(pair[1], "symmetry plane normal")});
            }
            keep.tolerance = tolerance;
            const Points3 l = points_in(moved, "moved");
            deform::KeptMove k;
            {
              py::gil_scoped_release free;
              k = deform::keep_properties(j, l, keep);
            }
            // The mass properties only when measured (the volume or centroid kept).
            py::dict d =
                keep.volume_mm3 || keep.centroid_mm ? properties_dict(k.properties) : py::dict();
            d["iterations"] = k.iterations;
            d["volume_error"] = k.volume_error;
            d["centroid_error_mm"] = k.centroid_error_mm;
            if (keep.area_mm2) {
              d["area_mm2"] = k.area_mm2;
              d["area_error"] = k.area_error;
            }
            d["linear_error_mm"] = k.linear_error_mm;
            return py::make_tuple(owned(std::move(k.points)), d);
          },
          py::arg("moved"), py::kw_only(), py::arg("volume_mm3") = py::none(),
          py::arg("centroid_mm") = py::none(), py::arg("area_mm2") = py::none(),
          py::arg("held") = std::vector<int>{}, py::arg("fixed_faces") = std::vector<int>{},
          py::arg("symmetry_planes") = py::list(), py::arg("tolerance") = 1e-13,
          "(points, report): the moved lattice points corrected so that the fixed faces stay "
          "exactly where they are and the displacement mirrors across the symmetry planes "
          "((point, normal) pairs; least squares onto those linear constraints first), then "
          "along the kept properties' projected gradients (Newton) so that the volume, centroid "
          "and/or area equal the targets to `tolerance` (relative); `held` points do not move "
          "(the dragged one).");

  lattice_methods(py::reinterpret_borrow<py::class_<BezierLattice>>(m.attr("BezierLattice")));
  lattice_methods(py::reinterpret_borrow<py::class_<BSplineLattice>>(m.attr("BSplineLattice")));
  py::reinterpret_borrow<py::class_<brep::Model>>(m.attr("Model"))
      .def(
          "mass_properties",
          [](const brep::Model& x, const py::object& body) {
            brep::MassProperties p;
            if (body.is_none()) {
              py::gil_scoped_release free;
              p = brep::mass_properties(x);
            } else {
              const int b = body.cast<int>();
              py::gil_scoped_release free;
              p = brep::mass_properties(x, b);
            }
            return properties_dict(p);
          },
          py::arg("body") = py::none(),
          "{volume_mm3, centroid_mm (3,), inertia_mm5 (3, 3)}: the solids' mass properties "
          "(unit density; inertia about the centroid), or body `body`'s. An assembly: "
          "flattened() first.")
      .def(
          "surface_area",
          [](const brep::Model& x, const py::object& body) {
            brep::SurfaceArea a;
            if (body.is_none()) {
              py::gil_scoped_release free;
              a = brep::surface_area(x);
            } else {
              const int b = body.cast<int>();
              py::gil_scoped_release free;
              a = brep::surface_area(x, b);
            }
            return area_dict(a);
          },
          py::arg("body") = py::none(),
          "{area_mm2, bound_mm2, faces_mm2}: the area of every body's faces (solids, shells, "
          "sheets), or body `body`'s, with a bound on its error (|error| <= bound_mm2) and each "
          "face's area. An assembly: flattened() first.");
}

}  // namespace clay::python
