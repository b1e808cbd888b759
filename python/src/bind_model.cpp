// Whole CAD models (B-rep: trimmed faces, shells, solids, assemblies): read, inspect, mesh,
// deform by a recipe's stack, write. A Model is a value: copies are independent.
#include "common.hpp"

#include <clay/brep/model.hpp>
#include <clay/brep/volume.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/deform/stack.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/recipe/recipe.hpp>

#include <pybind11/stl/filesystem.h>

namespace clay::python {

namespace {

/// A ModelCheck as the dict Model.write and Model.check return.
py::dict check_dict(const brep::ModelCheck& c) {
  py::dict d;
  d["valid"] = c.valid;
  d["problems"] = c.problems;
  d["volume_mm3"] = c.volume_mm3;
  d["occt_volume_mm3"] = c.occt_volume_mm3;
  d["message"] = c.brief();
  return d;
}

/// None, or (r, g, b) in [0, 1] (checked by BrepAttributes::problems).
std::optional<brep::Colour> colour_in(const py::handle& obj, const std::string& what) {
  if (obj.is_none()) return std::nullopt;
  const Eigen::Vector3d c = vec3(obj, what);
  return brep::Colour{c.x(), c.y(), c.z()};
}

py::object colour_out(const std::optional<brep::Colour>& c) {
  if (!c) return py::none();
  return py::make_tuple(c->r, c->g, c->b);
}

py::dict counts_dict(const brep::Counts& c) {
  py::dict d;
  d["bodies"] = c.bodies;
  d["solids"] = c.solids;
  d["shells"] = c.shells;
  d["faces"] = c.faces;
  d["trimmed_faces"] = c.trimmed_faces;
  d["loops"] = c.loops;
  d["inner_loops"] = c.inner_loops;
  d["edges"] = c.edges;
  d["vertices"] = c.vertices;
  d["parts"] = c.parts;
  d["instances"] = c.instances;
  d["wires"] = c.wires;
  d["wire_edges"] = c.wire_edges;
  return d;
}

/// A read's report as the dict read_model and read_brep return.
py::dict read_report(const brep::ModelReadReport& r) {
  py::dict d;
  d["counts"] = counts_dict(r.counts);
  d["size_mm"] = r.size_mm;
  d["faces_bspline"] = r.faces_bspline;
  d["faces_affine"] = r.faces_affine;
  d["faces_angular"] = r.faces_angular;
  d["max_edge_gap_mm"] = r.max_edge_gap_mm;
  d["healing"] = r.healing;
  d["ignored"] = r.ignored;
  d["skipped"] = r.skipped;
  d["left_out"] = r.left_out;
  d["problems"] = r.problems;
  d["shape_faces"] = r.brep_faces;
  d["message"] = r.brief();
  return d;
}

const char* kind_name(brep::BodyKind k) {
  switch (k) {
    case brep::BodyKind::Solid:
      return "solid";
    case brep::BodyKind::Shell:
      return "shell";
    case brep::BodyKind::Sheet:
      return "sheet";
    case brep::BodyKind::Wire:
      return "wire";
  }
  return "sheet";
}

brep::Face& face_at(brep::Model& m, int k) {
  if (k < 0 || k >= static_cast<int>(m.faces.size()))
    throw Error(ErrorCategory::InvalidArgument, "model: no face " + std::to_string(k) +
                                                    "; it has " + std::to_string(m.faces.size()) +
                                                    " (0-based)");
  return m.faces[static_cast<std::size_t>(k)];
}

/// A model deformation's (Model, report dict), as Recipe.deform_model and Model.deform give it.
py::tuple model_result(recipe::ModelRunResult&& result) {
  const auto& x = result.report;
  py::dict d;
  d["counts"] = counts_dict(x.counts);
  d["faces_exact"] = x.faces_exact;
  d["faces_refit"] = x.faces_refit;
  d["faces_untouched"] = x.faces_untouched;
  d["profile"] = x.profile;
  d["faces_elevated"] = x.faces_elevated;
  d["faces_restricted"] = x.faces_restricted;
  d["max_certified_bound_mm"] = x.max_certified_bound_mm;
  d["max_edge_gap_mm"] = x.max_edge_gap_mm;
  d["volume_before_mm3"] = x.volume_before_mm3;
  d["volume_after_mm3"] = x.volume_after_mm3;
  d["fold_free"] = result.fold_free;
  // How the faces meet along each shared edge, after and before (brep::edge_continuity).
  py::list edges;
  for (std::size_t k = 0; k < x.continuity_after.edges.size(); ++k) {
    const auto& e = x.continuity_after.edges[k];
    py::dict one;
    one["edge"] = e.edge;
    one["faces"] = py::make_tuple(e.face_a, e.face_b);
    one["gap_mm"] = e.gap_mm;
    one["angle_deg"] = e.angle_deg;
    one["relative_curvature_jump"] = e.relative_curvature_jump;
    if (k < x.continuity_before.edges.size()) {
      one["angle_deg_before"] = x.continuity_before.edges[k].angle_deg;
      one["relative_curvature_jump_before"] = x.continuity_before.edges[k].relative_curvature_jump;
    }
    edges.append(one);
  }
  d["continuity"] = edges;
  d["message"] = x.brief();
  d["seconds"] = result.seconds;
  return py::make_tuple(std::move(result.model), d);
}

/// Every enabled step of a stack, or one lattice as a stack of one step.
deform::DeformationStack stack_of(const py::handle& deformation) {
  if (py::isinstance<deform::DeformationStack>(deformation))
    return deformation.cast<deform::DeformationStack>();
  deform::DeformationStack stack;
  if (py::isinstance<deform::BezierLattice>(deformation))
    stack.steps.push_back({deformation.cast<deform::BezierLattice>(), "lattice", true});
  else if (py::isinstance<deform::BSplineLattice>(deformation))
    stack.steps.push_back({deformation.cast<deform::BSplineLattice>(), "lattice", true});
  else
    throw Error(ErrorCategory::InvalidArgument,
                "Model.deform: deformation is a " +
                    std::string(py::str(deformation.get_type().attr("__name__"))) +
                    "; give a BezierLattice, a BSplineLattice or a DeformationStack (taper, "
                    "twist and bend: DeformationStack.from_json)");
  return stack;
}

std::vector<int> face_list(const py::object& faces) {
  return faces.is_none() ? std::vector<int>{} : faces.cast<std::vector<int>>();
}

}  // namespace

/// The recipe's deformation of a whole model (bind_recipe.cpp calls it on its Recipe class).
py::tuple deform_model(const recipe::Recipe& r, const brep::Model& model,
                       const std::string& deformation, bool allow_fold,
                       const std::string& profile) {
  recipe::ModelRunResult result;
  {
    py::gil_scoped_release free;
    result = recipe::deform_model(r, model, deformation, allow_fold, profile);
  }
  return model_result(std::move(result));
}

void bind_model(py::module_& m) {
  py::class_<brep::Model>(
      m, "Model",
      "A whole B-rep model: faces (NURBS surfaces with trimming loops), "
      "edges, vertices, bodies (solids, shells, sheets, wires of free edges), an assembly "
      "tree.")
      .def_property_readonly("counts",
                             [](const brep::Model& x) { return counts_dict(brep::counts(x)); })
      .def_property_readonly("is_assembly", &brep::Model::is_assembly)
      .def_property_readonly(
          "bodies",
          [](const brep::Model& x) {
            py::list out;
            for (const auto& b : x.bodies) {
              py::dict d;
              d["name"] = b.name;
              d["colour"] = colour_out(b.colour);
              d["kind"] = kind_name(b.kind);
              std::vector<int> faces;
              for (const auto& s : b.shells)
                faces.insert(faces.end(), s.faces.begin(), s.faces.end());
              d["faces"] = faces;
              d["edges"] = b.edges;
              out.append(d);
            }
            return out;
          },
          "Each body's name, kind (solid, shell, sheet, wire), face indices and (a wire body's) "
          "free edge indices.")
      .def_property_readonly("face_count", [](const brep::Model& x) { return x.faces.size(); })
      .def(
          "face_surface", [](brep::Model& x, int k) { return face_at(x, k).surface; },
          py::arg("face"), "The face's NURBS surface (a copy; the loops trim it).")
      .def(
          "face_name", [](brep::Model& x, int k) { return face_at(x, k).name; }, py::arg("face"))
      .def(
          "face_colour", [](brep::Model& x, int k) { return colour_out(face_at(x, k).colour); },
          py::arg("face"), "The face's own colour (r, g, b), or None (it takes its body's).")
      .def(
          "volume_mm3",
          [](const brep::Model& x) {
            py::gil_scoped_release free;
            return brep::volume_mm3(x);
          },
          "The volume of the solids (mm^3), from the exact faces.")
      .def(
          "problems", [](const brep::Model& x) { return brep::problems(x); },
          "Every invariant the model breaks, in words; [] when valid.")
      .def(
          "flattened",
          [](const brep::Model& x) {
            py::gil_scoped_release free;
            return brep::flattened(x);
          },
          "The model without its assembly: each placed body in world coordinates.")
      .def(
          "tessellate",
          [](const brep::Model& x, double relative_deflection) {
            brep::MeshOptions o;
            o.relative_deflection = relative_deflection;
            brep::ModelMesh mesh;
            {
              py::gil_scoped_release free;
              mesh = brep::tessellate(x, o);
            }
            Points3 positions(static_cast<Eigen::Index>(mesh.positions.size()), 3);
            for (std::size_t i = 0; i < mesh.positions.size(); ++i)
              positions.row(static_cast<Eigen::Index>(i)) = mesh.positions[i].transpose();
            py::array_t<std::int32_t> triangles(
                {static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
            auto t = triangles.mutable_unchecked<2>();
            for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
              for (int k = 0; k < 3; ++k)
                t(static_cast<py::ssize_t>(i), k) = mesh.triangles[i][static_cast<std::size_t>(k)];
            py::array_t<std::int32_t> face(static_cast<py::ssize_t>(mesh.triangle_face.size()));
            std::copy(mesh.triangle_face.begin(), mesh.triangle_face.end(), face.mutable_data());
            return py::make_tuple(owned(std::move(positions)), triangles, face);
          },
          py::arg("relative_deflection") = 5e-4,
          "The trimmed faces meshed (OpenCASCADE): (vertices (n, 3), triangles (m, 3) int32, "
          "the face of each triangle (m,)); holes are holes.")
      .def(
          "write",
          [](const brep::Model& x, const std::filesystem::path& path) {
            brep::ModelCheck c;
            {
              py::gil_scoped_release free;
              c = brep::write_model(x, path);
            }
            return check_dict(c);
          },
          py::arg("path"),
          "Writes STEP (.step/.stp), IGES (.igs/.iges) or a glTF preview (.glb), atomically, read "
          "back and checked (BRepCheck): the check as a dict (valid, problems, volume_mm3, "
          "occt_volume_mm3: OpenCASCADE's BRepGProp at 1e-9, message).")
      .def(
          "check",
          [](const brep::Model& x) {
            brep::ModelCheck c;
            {
              py::gil_scoped_release free;
              c = brep::check_model(x);
            }
            return check_dict(c);
          },
          "OpenCASCADE's view of the model, as write() checks it without writing: {valid "
          "(BRepCheck), problems, volume_mm3 (ours, exact), occt_volume_mm3 (BRepGProp at 1e-9: "
          "an independent integration), message}.")
      .def(
          "bounding_box",
          [](const brep::Model& x, const py::object& faces) {
            const brep::Box b = brep::control_box(x, face_list(faces));
            return py::make_tuple(tuple_of(b.lo), tuple_of(b.hi));
          },
          py::arg("faces") = py::none(),
          "((x, y, z) low, (x, y, z) high): the box of the faces' control points and the wire "
          "bodies' curves' (of the flattened model; faces: indices into flattened().faces, only "
          "those faces; None: all), which contains the faces, their untrimmed surfaces and the "
          "free curves, as a lattice must to compose them exactly.")
      .def(
          "deform",
          [](const brep::Model& x, const py::handle& deformation, const py::object& faces,
             bool allow_fold, const std::string& profile, double tolerance_mm) {
            const deform::DeformationStack stack = stack_of(deformation);
            const std::vector<int> chosen = face_list(faces);
            recipe::ModelRunResult result;
            {
              py::gil_scoped_release free;
              result = recipe::deform_model(stack, x, allow_fold, profile, chosen, tolerance_mm);
            }
            return model_result(std::move(result));
          },
          py::arg("deformation"), py::kw_only(), py::arg("faces") = py::none(),
          py::arg("allow_fold") = false, py::arg("profile") = "", py::arg("tolerance_mm") = 0.0,
          "The model deformed by a lattice (BezierLattice, BSplineLattice) or a "
          "DeformationStack, as `clayform deform` does with a recipe's default composition: "
          "(Model, report). Faces compose exactly; above the budget, certified light forms. "
          "faces: indices into flattened().faces to deform (None: all; an edge shared with a "
          "kept face must not move). A lattice not proven fold-free raises "
          "InvalidGeometryError unless allow_fold=True. profile: the receiver (exact, "
          "opencascade, catia, class_a, bicubic; '' none). tolerance_mm > 0: a face that cannot be "
          "exact (a B-spline lattice's knot plane across it, twist, bend) is refitted within it, "
          "certified; 0: refused, naming the face.")
      .def(
          "to_brep",
          [](const brep::Model& x) {
            brep::BrepText t;
            {
              py::gil_scoped_release free;
              t = brep::write_brep(x);
            }
            py::dict d;
            d["brep"] = py::str(t.text);
            d["name"] = t.attributes.name;
            d["colour"] = colour_out(t.attributes.colour);
            py::list colours;
            for (const auto& c : t.attributes.face_colours) colours.append(colour_out(c));
            d["face_colours"] = colours;
            d["face_names"] = t.attributes.face_names;
            return d;
          },
          "The model as OpenCASCADE's BRep text (FreeCAD: Part.Shape().importBrepFromString), "
          "exact to the last bit (an assembly flattened), with what the text cannot hold: "
          "{brep, name, colour, face_colours, face_names}, the lists per face in the written "
          "shape's Shape.Faces order (empty when no face has one; a face's colour is its own or "
          "its body's). clayform.read_brep reads it back.")
      .def("__copy__", [](const brep::Model& x) { return x; })
      .def("__deepcopy__", [](const brep::Model& x, py::dict) { return x; })
      .def("__repr__", [](const brep::Model& x) {
        const auto c = brep::counts(x);
        return "<clayform.Model " + std::to_string(c.bodies) + " bodies (" +
               std::to_string(c.solids) + " solids), " + std::to_string(c.faces) + " faces" +
               (x.is_assembly() ? ", assembly" : "") + ">";
      });

  m.def(
      "read_model",
      [](const std::filesystem::path& path, bool sew, bool isolate, bool strict) {
        brep::ModelReadOptions o;
        o.sew = sew;
        o.read.isolate = isolate;
        o.strict = strict;
        brep::ImportedModel imported;
        {
          py::gil_scoped_release free;
          imported = brep::read_model(path, o);
        }
        py::dict d = read_report(imported.report);
        return py::make_tuple(std::move(imported.model), d);
      },
      py::arg("path"), py::arg("sew") = false, py::arg("isolate") = true, py::arg("strict") = false,
      "Reads a whole STEP or IGES model (trimmed faces, solids, assembly): (Model, report). "
      "isolate=True (the default) reads in a child process, so a file that crashes OpenCASCADE "
      "raises ExchangeError (or, when only its XCAF reader crashes, is read by its plain reader "
      "and report['healing'] says so) instead of killing the interpreter; isolate=False reads in "
      "this process. report['healing'] lists what was healed, report['ignored'] the entity types "
      "OpenCASCADE does not know, report['skipped'] the entities it failed to transfer (the rest "
      "is read), report['left_out'] the shapes a model cannot hold (an unbounded line); free "
      "curves become wire bodies; strict=True heals as before "
      "issue #39 (pcurves outside their domains, gaps wider than the file's tolerances and "
      "misordered loops are listed in report['problems'] instead).");

  m.def(
      "read_brep",
      [](const std::string& text, const std::string& name, const py::object& colour,
         const py::object& face_colours, const py::object& face_names, bool isolate) {
        brep::ModelReadOptions o;
        o.read.isolate = isolate;
        o.brep.name = name;
        o.brep.colour = colour_in(colour, "colour");
        if (!face_colours.is_none()) {
          std::size_t k = 0;
          for (const py::handle c : face_colours)
            o.brep.face_colours.push_back(
                colour_in(c, "face_colours[" + std::to_string(k++) + "]"));
        }
        if (!face_names.is_none()) o.brep.face_names = face_names.cast<std::vector<std::string>>();
        brep::ImportedModel imported;
        {
          py::gil_scoped_release free;
          imported = brep::read_brep(text, o);
        }
        py::dict d = read_report(imported.report);
        return py::make_tuple(std::move(imported.model), d);
      },
      py::arg("text"), py::kw_only(), py::arg("name") = "", py::arg("colour") = py::none(),
      py::arg("face_colours") = py::none(), py::arg("face_names") = py::none(),
      py::arg("isolate") = true,
      "Reads a model from OpenCASCADE's BRep text (FreeCAD's Shape.exportBrepToString()): "
      "(Model, report), as read_model reads a file. BRep holds no names or colours: name and "
      "colour ((r, g, b) in [0, 1]) go to the shape's body, face_colours and face_names (None, "
      "or one entry per face in Shape.Faces order; a None colour: the body's) to its faces. "
      "report['shape_faces'][j]: model face j's index in Shape.Faces (the model numbers faces "
      "solids first and holds a face two solids share twice). Model.to_brep() is the way back.");

  m.def(
      "lattice_around",
      [](const brep::Model& model, std::array<int, 3> degrees, const py::object& cells,
         double margin, const py::object& faces) -> py::object {
        const deform::Frame frame = deform::frame_around(model, margin, face_list(faces));
        if (cells.is_none()) return py::cast(deform::make_bezier_lattice(frame, degrees));
        return py::cast(
            deform::make_bspline_lattice(frame, degrees, cells.cast<std::array<int, 3>>()));
      },
      py::arg("model"), py::arg("degrees") = std::array<int, 3>{3, 3, 3},
      py::arg("cells") = py::none(), py::arg("margin") = 0.05, py::arg("faces") = py::none(),
      "An undisplaced lattice around a model (or its faces: indices into flattened().faces), "
      "axes along x, y, z: Model.bounding_box() grown by margin of its extent on each side (an "
      "axis thinner than a tenth of the diagonal as if that thick). cells=None: a BezierLattice of "
      "the degrees; else a "
      "BSplineLattice with those cells. Move its points, then Model.deform(lattice).");
}

}  // namespace clay::python
