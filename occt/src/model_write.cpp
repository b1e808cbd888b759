// Writing whole models (clay/occt/model_exchange.hpp): brep::Model -> OpenCASCADE shapes -> XCAF
// document (names, colours, assembly) -> STEP or IGES, printed with 17 significant digits.
//
// The shapes are built with BRep_Builder from the model's data, never recomputed: every surface,
// 3D curve and pcurve is copied through the bit-exact adapter (convert.hpp), edges are created
// once and shared by their faces, ranges and tolerances are the model's, and the edges are
// declared same-parameter and same-range (brep::problems has checked it by sampling before).
// A face read as a plane is written as a plane (Face::elementary): the only surface rebuilt
// rather than copied, from its frame, which the file stores as it is.
#include <clay/brep/volume.hpp>
#include <clay/occt/model_exchange.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "convert.hpp"
#include "model_shapes.hpp"
#include "session.hpp"

#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom_Plane.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESCAFControl_Writer.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESData_IGESWriter.hxx>
#include <IGESSelect_WorkLibrary.hxx>
#include <Precision.hxx>
#include <Quantity_Color.hxx>
#include <STEPCAFControl_Controller.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <StepData_Protocol.hxx>
#include <StepData_StepModel.hxx>
#include <StepData_StepWriter.hxx>
#include <StepGeom_BSplineCurve.hxx>
#include <StepGeom_BSplineSurface.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array1OfPnt2d.hxx>
#include <TDF_Label.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Trsf.hxx>

namespace clay::brep {
namespace {

namespace fs = std::filesystem;
using internal::shortest;
using surface::occt::extension_is;
using surface::occt::quoted;

/// A 2D OCCT curve from a pcurve (control points (u, v, 0)), copied exactly.
Handle(Geom2d_BSplineCurve) pcurve_to_occt(const surface::BSplineCurve& c) {
  std::vector<double> distinct;
  std::vector<int> multiplicity;
  for (double k : c.basis.knots) {
    if (distinct.empty() || k != distinct.back()) {
      distinct.push_back(k);
      multiplicity.push_back(1);
    } else {
      ++multiplicity.back();
    }
  }
  const int n = static_cast<int>(c.points.rows());
  TColgp_Array1OfPnt2d poles(1, n);
  for (int i = 0; i < n; ++i) poles.SetValue(i + 1, gp_Pnt2d(c.points(i, 0), c.points(i, 1)));
  TColStd_Array1OfReal knots(1, static_cast<int>(distinct.size()));
  TColStd_Array1OfInteger mults(1, static_cast<int>(distinct.size()));
  for (std::size_t k = 0; k < distinct.size(); ++k) {
    knots.SetValue(static_cast<int>(k) + 1, distinct[k]);
    mults.SetValue(static_cast<int>(k) + 1, multiplicity[k]);
  }
  if (!c.is_rational()) return new Geom2d_BSplineCurve(poles, knots, mults, c.basis.degree);
  TColStd_Array1OfReal weights(1, n);
  for (int i = 0; i < n; ++i) weights.SetValue(i + 1, c.weights[i]);
  return new Geom2d_BSplineCurve(poles, weights, knots, mults, c.basis.degree);
}

/// A face's surface for the file: a plane as a plane (its NURBS has the plane's parameters, so the
/// pcurves serve both, and the reader rebuilds the same NURBS from them), anything else as its
/// NURBS. Cylinders, cones, spheres and tori are written as NURBS: their NURBS parameter is not
/// the angle, and an angle-space pcurve of the same edge parameter is not a B-spline.
Handle(Geom_Surface) surface_to_occt(const Face& face, const std::string& name) {
  if (face.elementary && face.elementary->kind == ElementaryKind::Plane && !face.loops.empty()) {
    const Elementary& e = *face.elementary;
    auto pnt = [](const Eigen::Vector3d& p) { return gp_Pnt(p.x(), p.y(), p.z()); };
    auto dir = [](const Eigen::Vector3d& d) { return gp_Dir(d.x(), d.y(), d.z()); };
    // The right-handed frame with the same x and y (z = x × y): the same parameters, and the
    // only kind of frame STEP's axis2_placement_3d holds (a mirrored instance's plane is
    // left-handed in the model).
    return new Geom_Plane(gp_Ax3(pnt(e.origin), dir(e.x_axis.cross(e.y_axis)), dir(e.x_axis)));
  }
  return surface::occt::to_occt(face.surface, name);
}

}  // namespace

Shapes build_shapes(const Model& m) {
  validate(m);
  BRep_Builder b;
  Shapes s;
  for (const Vertex& v : m.vertices) {
    TopoDS_Vertex vertex;
    b.MakeVertex(vertex, gp_Pnt(v.point.x(), v.point.y(), v.point.z()), v.tolerance_mm);
    s.vertices.push_back(vertex);
  }
  for (std::size_t i = 0; i < m.edges.size(); ++i) {
    const Edge& e = m.edges[i];
    TopoDS_Edge edge;
    if (e.degenerate) {
      b.MakeEdge(edge);
      b.Degenerated(edge, true);
    } else {
      b.MakeEdge(edge, surface::occt::to_occt(e.curve, "edge " + std::to_string(i)),
                 e.tolerance_mm);
    }
    const TopoDS_Vertex& start = s.vertices[static_cast<std::size_t>(e.start)];
    const TopoDS_Vertex& end = s.vertices[static_cast<std::size_t>(e.end)];
    b.Add(edge, start.Oriented(TopAbs_FORWARD));
    b.Add(edge, end.Oriented(TopAbs_REVERSED));
    s.edges.push_back(edge);
  }
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Face& face = m.faces[f];
    double tolerance = Precision::Confusion();
    for (const Loop& loop : face.loops)
      for (const Coedge& c : loop.coedges)
        tolerance = std::min(tolerance, m.edges[static_cast<std::size_t>(c.edge)].tolerance_mm);
    TopoDS_Face out;
    b.MakeFace(out, surface_to_occt(face, "face " + std::to_string(f)), tolerance);
    // Pcurves per edge and sense: a seam (one edge used both ways by the face) needs both at once.
    std::map<int, std::array<Handle(Geom2d_BSplineCurve), 2>> pcurves;
    for (const Loop& loop : face.loops)
      for (const Coedge& c : loop.coedges)
        pcurves[c.edge][c.same_sense ? 0 : 1] = pcurve_to_occt(c.pcurve);
    for (const auto& [index, pair] : pcurves) {
      const Edge& e = m.edges[static_cast<std::size_t>(index)];
      TopoDS_Edge edge = s.edges[static_cast<std::size_t>(index)];
      if (!pair[0].IsNull() && !pair[1].IsNull())
        b.UpdateEdge(TopoDS::Edge(edge.Oriented(TopAbs_FORWARD)), pair[0], pair[1], out,
                     e.tolerance_mm);
      else
        b.UpdateEdge(
            TopoDS::Edge(edge.Oriented(pair[0].IsNull() ? TopAbs_REVERSED : TopAbs_FORWARD)),
            pair[0].IsNull() ? pair[1] : pair[0], out, e.tolerance_mm);
    }
    for (const Loop& loop : face.loops) {
      TopoDS_Wire wire;
      b.MakeWire(wire);
      for (const Coedge& c : loop.coedges)
        b.Add(wire, s.edges[static_cast<std::size_t>(c.edge)].Oriented(
                        c.same_sense ? TopAbs_FORWARD : TopAbs_REVERSED));
      wire.Closed(true);
      b.Add(out, wire);
    }
    s.faces.push_back(out);
  }
  // Ranges last: Range() sets the 3D curve's and every pcurve's at once.
  for (std::size_t i = 0; i < m.edges.size(); ++i) {
    const Edge& e = m.edges[i];
    TopoDS_Edge& edge = s.edges[i];
    b.Range(edge, e.t0, e.t1);
    b.UpdateVertex(
        TopoDS::Vertex(s.vertices[static_cast<std::size_t>(e.start)].Oriented(TopAbs_FORWARD)),
        e.t0, edge, m.vertices[static_cast<std::size_t>(e.start)].tolerance_mm);
    b.UpdateVertex(
        TopoDS::Vertex(s.vertices[static_cast<std::size_t>(e.end)].Oriented(TopAbs_REVERSED)), e.t1,
        edge, m.vertices[static_cast<std::size_t>(e.end)].tolerance_mm);
    b.SameParameter(edge, true);
    b.SameRange(edge, true);
  }
  auto oriented = [&](int f) {
    const TopoDS_Face& face = s.faces[static_cast<std::size_t>(f)];
    return m.faces[static_cast<std::size_t>(f)].reversed ? TopoDS::Face(face.Reversed()) : face;
  };
  for (const Body& body : m.bodies) {
    std::vector<TopoDS_Shell> shells;
    for (const Shell& shell : body.shells) {
      TopoDS_Shell out;
      b.MakeShell(out);
      for (int f : shell.faces) b.Add(out, oriented(f));
      out.Closed(BRep_Tool::IsClosed(out));
      shells.push_back(out);
    }
    if (body.kind == BodyKind::Wire) {
      // Free edges as a compound of edges: STEP's translator writes it as a curve set
      // (GEOMETRICALLY_BOUNDED_WIREFRAME), IGES's as curves.
      TopoDS_Compound compound;
      b.MakeCompound(compound);
      for (int e : body.edges) b.Add(compound, s.edges[static_cast<std::size_t>(e)]);
      s.bodies.push_back(compound);
    } else if (body.kind == BodyKind::Solid) {
      TopoDS_Solid solid;
      b.MakeSolid(solid);
      for (const TopoDS_Shell& shell : shells) b.Add(solid, shell);
      s.bodies.push_back(solid);
    } else if (body.kind == BodyKind::Shell && shells.size() == 1) {
      s.bodies.push_back(shells.front());
    } else {
      TopoDS_Compound compound;
      b.MakeCompound(compound);
      for (const TopoDS_Shell& shell : shells) {
        if (body.kind == BodyKind::Shell) {
          b.Add(compound, shell);
        } else {
          for (TopExp_Explorer e(shell, TopAbs_FACE); e.More(); e.Next())
            b.Add(compound, e.Current());
        }
      }
      s.bodies.push_back(compound);
    }
  }
  return s;
}

namespace {

/// BRepCheck of every body, and the volume of the solids (each instance once).
ModelCheck check_shapes(const Model& m, const Shapes& s) {
  ModelCheck out;
  out.valid = true;
  std::vector<double> body_volume(m.bodies.size(), 0.0);
  for (std::size_t bi = 0; bi < m.bodies.size(); ++bi) {
    const TopoDS_Shape& shape = s.bodies[bi];
    const BRepCheck_Analyzer analyzer(shape);
    if (!analyzer.IsValid()) {
      out.valid = false;
      bool named = false;
      for (const Shell& shell : m.bodies[bi].shells)
        for (int f : shell.faces) {
          const auto statuses =
              surface::occt::check_statuses(s.faces[static_cast<std::size_t>(f)], analyzer);
          for (const auto& status : statuses) {
            out.problems.push_back("body " + std::to_string(bi) + " face " + std::to_string(f) +
                                   ": " + status);
            named = true;
          }
        }
      if (!named)
        out.problems.push_back("body " + std::to_string(bi) +
                               ": BRepCheck finds the body invalid (its shells or solid)");
    }
    if (m.bodies[bi].kind == BodyKind::Solid) {
      GProp_GProps props;
      BRepGProp::VolumeProperties(shape, props, 1e-9);
      body_volume[bi] = props.Mass();
    }
  }
  out.volume_mm3 = volume_mm3(m);
  if (!m.is_assembly()) {
    for (double v : body_volume) out.occt_volume_mm3 += v;
    return out;
  }
  // Each instance counts once: a part's volume times the number of times the tree places it.
  std::function<double(int, int)> part_volume = [&](int p, int depth) -> double {
    if (depth > static_cast<int>(m.parts.size())) return 0.0;  // cycles are refused by validate
    const Part& part = m.parts[static_cast<std::size_t>(p)];
    double v = 0;
    for (int bi : part.bodies) v += body_volume[static_cast<std::size_t>(bi)];
    for (const Instance& c : part.components) v += part_volume(c.part, depth + 1);
    return v;
  };
  for (const Instance& root : m.roots) out.occt_volume_mm3 += part_volume(root.part, 0);
  return out;
}

TopLoc_Location location_of(const Eigen::Isometry3d& placement) {
  gp_Trsf t;
  const Eigen::Matrix4d& a = placement.matrix();
  t.SetValues(a(0, 0), a(0, 1), a(0, 2), a(0, 3), a(1, 0), a(1, 1), a(1, 2), a(1, 3), a(2, 0),
              a(2, 1), a(2, 2), a(2, 3));
  return TopLoc_Location(t);
}

Quantity_Color colour_to_occt(const Colour& c) {
  return Quantity_Color(c.r, c.g, c.b, Quantity_TOC_sRGB);
}

/// Fills an XCAF document with the model's shapes, names, colours and assembly tree.
class DocumentWriter {
 public:
  DocumentWriter(const Model& m, const Shapes& s, Handle(XCAFDoc_ShapeTool) shapes,
                 Handle(XCAFDoc_ColorTool) colours)
      : m_(m), s_(s), shapes_(std::move(shapes)), colours_(std::move(colours)) {}

  void fill() {
    if (!m_.is_assembly()) {
      if (m_.bodies.size() == 1) {
        body_label(0);
      } else {
        std::vector<int> all(m_.bodies.size());
        for (std::size_t bi = 0; bi < all.size(); ++bi) all[bi] = static_cast<int>(bi);
        bodies_label(all);
      }
    } else {
      part_labels_.assign(m_.parts.size(), TDF_Label());
      for (const Instance& root : m_.roots) {
        const TDF_Label part = part_label(root.part);
        if (!root.placement.matrix().isIdentity(0.0)) {
          // A placed root: an assembly of its own holds it.
          const TDF_Label holder = shapes_->NewShape();
          attribute(holder, root.name, std::nullopt, XCAFDoc_ColorGen);
          shapes_->AddComponent(holder, part, location_of(root.placement));
        }
      }
    }
    shapes_->UpdateAssemblies();
  }

 private:
  void attribute(const TDF_Label& label, const std::string& name,
                 const std::optional<Colour>& colour, XCAFDoc_ColorType type) {
    if (!name.empty()) TDataStd_Name::Set(label, TCollection_ExtendedString(name.c_str(), true));
    if (colour) colours_->SetColor(label, colour_to_occt(*colour), type);
  }

  void face_labels(const TDF_Label& label, std::size_t body) {
    for (const Shell& shell : m_.bodies[body].shells)
      for (int f : shell.faces) {
        const Face& face = m_.faces[static_cast<std::size_t>(f)];
        if (face.name.empty() && !face.colour) continue;
        const TopoDS_Face& shape = s_.faces[static_cast<std::size_t>(f)];
        const TDF_Label sub =
            shapes_->AddSubShape(label, face.reversed ? TopoDS::Face(shape.Reversed()) : shape);
        if (!sub.IsNull()) attribute(sub, face.name, face.colour, XCAFDoc_ColorSurf);
      }
  }

  /// Several bodies as one compound: a reader finds one shape with its bodies, as it was read
  /// (a part of several bodies stays one part, not an assembly of one part per body).
  TDF_Label bodies_label(const std::vector<int>& bodies) {
    TopoDS_Compound all;
    BRep_Builder b;
    b.MakeCompound(all);
    for (int bi : bodies) b.Add(all, s_.bodies[static_cast<std::size_t>(bi)]);
    const TDF_Label label = shapes_->AddShape(all, false);
    for (int bi : bodies) {
      const Body& body = m_.bodies[static_cast<std::size_t>(bi)];
      if (!body.name.empty() || body.colour) {
        const TDF_Label sub = shapes_->AddSubShape(label, s_.bodies[static_cast<std::size_t>(bi)]);
        if (!sub.IsNull()) attribute(sub, body.name, body.colour, XCAFDoc_ColorGen);
      }
      face_labels(label, static_cast<std::size_t>(bi));
    }
    return label;
  }

  TDF_Label body_label(std::size_t body) {
    const TDF_Label label = shapes_->AddShape(s_.bodies[body], false);
    attribute(label, m_.bodies[body].name, m_.bodies[body].colour, XCAFDoc_ColorGen);
    face_labels(label, body);
    return label;
  }

  TDF_Label part_label(int p) {
    TDF_Label& known = part_labels_[static_cast<std::size_t>(p)];
    if (!known.IsNull()) return known;
    const Part& part = m_.parts[static_cast<std::size_t>(p)];
    TDF_Label label;
    if (part.components.empty() && part.bodies.size() == 1) {
      label = body_label(static_cast<std::size_t>(part.bodies.front()));
      // The part's name and colour win over its one body's (they are one label in XCAF).
      if (part.name.empty() && part.colour == std::nullopt) {
        known = label;
        return label;
      }
    } else if (part.components.empty() && part.bodies.size() > 1) {
      label = bodies_label(part.bodies);
    } else {
      label = shapes_->NewShape();
      for (int bi : part.bodies)
        shapes_->AddComponent(label, body_label(static_cast<std::size_t>(bi)), TopLoc_Location());
      for (const Instance& c : part.components) {
        const TDF_Label component =
            shapes_->AddComponent(label, part_label(c.part), location_of(c.placement));
        if (!c.name.empty())
          TDataStd_Name::Set(component, TCollection_ExtendedString(c.name.c_str(), true));
      }
    }
    attribute(label, part.name, part.colour, XCAFDoc_ColorGen);
    known = label;
    return label;
  }

  const Model& m_;
  const Shapes& s_;
  Handle(XCAFDoc_ShapeTool) shapes_;
  Handle(XCAFDoc_ColorTool) colours_;
  std::vector<TDF_Label> part_labels_;
};

}  // namespace

void fill_document(const Model& m, const Shapes& s, const Handle(TDocStd_Document) & document) {
  DocumentWriter(m, s, XCAFDoc_DocumentTool::ShapeTool(document->Main()),
                 XCAFDoc_DocumentTool::ColorTool(document->Main()))
      .fill();
}

std::string ModelCheck::brief() const {
  if (!checked) return "not checked";
  char text[96] = "";
  if (volume_mm3 != 0) std::snprintf(text, sizeof text, ", volume %.10g mm^3", volume_mm3);
  if (valid) return "valid (BRepCheck)" + std::string(text);
  return "NOT valid (BRepCheck)" + std::string(text) + ": " + std::to_string(problems.size()) +
         (problems.size() == 1 ? " problem: " : " problems, the first: ") +
         (problems.empty() ? std::string("?") : problems.front());
}

ModelCheck check_model(const Model& model) {
  const Shapes shapes = build_shapes(model);
  surface::occt::ExchangeSession session;
  return surface::occt::guarded(ErrorCategory::Exchange, "check_model",
                                [&] { return check_shapes(model, shapes); });
}

ModelCheck write_model(const Model& model, const fs::path& file, const ModelWriteOptions& options) {
  constexpr std::string_view caller = "write_model";
  const bool step = extension_is(file, {".step", ".stp"});
  const bool iges = extension_is(file, {".iges", ".igs"});
  const bool glb = extension_is(file, {".glb"});
  if (!step && !iges && !glb)
    throw Error(ErrorCategory::InvalidArgument,
                "write_model: " + quoted(file) +
                    " has an unknown extension; name a .step, .stp, .iges, .igs or .glb file");
  if (glb) options.mesh.validate();
  surface::occt::check_target(file, caller);
  // OpenCASCADE's IGES translator has no assemblies: each placed instance becomes a body.
  const Model flat = iges && model.is_assembly() ? flattened(model) : Model();
  const Model& m = iges && model.is_assembly() ? flat : model;
  const Shapes shapes = build_shapes(m);
  surface::occt::ExchangeSession session;
  return surface::occt::guarded(ErrorCategory::Exchange, caller, [&] {
    ModelCheck check;
    if (options.check)
      check = check_shapes(m, shapes);
    else
      check.checked = false;
    surface::occt::XcafDocument held;  // closed on every way out
    Handle(TDocStd_Document)& document = held.get();
    fill_document(m, shapes, document);
    if (glb) {
      write_glb(m, shapes, file, options.mesh, document);
    } else if (step) {
      // Settings go after Init() and before the writer is constructed (OCCT-NOTES).
      STEPCAFControl_Controller::Init();
      surface::occt::set_static("write.step.schema", options.schema == surface::StepSchema::AP242
                                                         ? "AP242DIS"
                                                         : "AP214IS");
      surface::occt::set_static("write.step.unit", "MM");
      surface::occt::set_static("xstep.cascade.unit", "MM");
      surface::occt::set_static("write.stepcaf.subshapes.name", 1);
      STEPCAFControl_Writer writer;
      writer.SetColorMode(true);
      writer.SetNameMode(true);
      if (!writer.Transfer(document, STEPControl_AsIs))
        throw Error(ErrorCategory::Exchange,
                    "write_model: OpenCASCADE's STEP translator refused the model");
      write_seam_loops(m, shapes, writer.ChangeWriter());
      Handle(StepData_StepModel) step_model = writer.ChangeWriter().Model();
      // Closed flags off: OpenCASCADE's reader makes a surface or curve it is told is closed
      // periodic, merging its first and last rows of poles, which then differ from ours in
      // the last bit (a torus's rows agree only to rounding). Our surfaces are not periodic.
      for (int i = 1; i <= step_model->NbEntities(); ++i) {
        if (auto s = Handle(StepGeom_BSplineSurface)::DownCast(step_model->Value(i)); !s.IsNull()) {
          s->SetUClosed(StepData_LFalse);
          s->SetVClosed(StepData_LFalse);
        } else if (auto c = Handle(StepGeom_BSplineCurve)::DownCast(step_model->Value(i));
                   !c.IsNull()) {
          c->SetClosedCurve(StepData_LFalse);
        }
      }
      surface::occt::write_atomically(file, caller, [&](const fs::path& temp) {
        surface::occt::write_stream(temp, caller, [&](std::ostream& out) {
          StepData_StepWriter step_writer(step_model);
          step_writer.FloatWriter().SetFormat("%.16E");  // 17 significant digits: lossless
          step_writer.SendModel(Handle(StepData_Protocol)::DownCast(step_model->Protocol()));
          return static_cast<bool>(step_writer.Print(out));
        });
      });
    } else {
      bool solids = false;
      for (const Body& b : m.bodies) solids = solids || b.kind == BodyKind::Solid;
      IGESControl_Controller::Init();
      surface::occt::set_static("write.iges.unit", "MM");
      surface::occt::set_static("xstep.cascade.unit", "MM");
      surface::occt::set_static("write.iges.brep.mode", solids ? 1 : 0);  // 186/514 or 144
      IGESCAFControl_Writer writer;
      writer.SetColorMode(true);
      writer.SetNameMode(true);
      if (!writer.Transfer(document))
        throw Error(ErrorCategory::Exchange,
                    "write_model: OpenCASCADE's IGES translator refused the model");
      writer.ComputeModel();
      Handle(IGESData_IGESModel) iges_model = writer.Model();
      surface::occt::write_atomically(file, caller, [&](const fs::path& temp) {
        surface::occt::write_stream(temp, caller, [&](std::ostream& out) {
          IGESData_IGESWriter iges_writer(iges_model);
          iges_writer.FloatWriter().SetFormat("%.16E");
          iges_writer.SendModel(IGESSelect_WorkLibrary::DefineProtocol());
          return static_cast<bool>(iges_writer.Print(out));
        });
      });
    }
    return check;
  });
}

}  // namespace clay::brep
