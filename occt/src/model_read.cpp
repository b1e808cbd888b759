// Reading whole models into brep::Model (clay/occt/model_exchange.hpp), through OpenCASCADE's XCAF
// readers, so that names, colours and the assembly tree come with the shapes.
//
// Converting faces, edges and pcurves: model_convert.hpp; the isolated read's answer:
// model_wire.hpp; what OpenCASCADE's transfer left out or did not know, and its plain reader:
// model_transfer.hpp; the options' checks and the report's line: model_read_report.cpp.
#include <clay/occt/model_exchange.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

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
#include "model_convert.hpp"
#include "model_heal.hpp"
#include "model_transfer.hpp"
#include "model_wire.hpp"
#include "session.hpp"

#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_BSplineCurve.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESData_UndefinedEntity.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Precision.hxx>
#include <Quantity_Color.hxx>
#include <STEPCAFControl_Controller.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <ShapeFix_Solid.hxx>
#include <StepData_StepModel.hxx>
#include <StepData_UndefinedEntity.hxx>
#include <TCollection_AsciiString.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>

namespace clay::brep {
namespace {

namespace fs = std::filesystem;
using namespace detail;
using internal::shortest;
using surface::occt::extension_is;
using surface::occt::quoted;

/// What read_model throws when the file gave no shape (`what`: "holds no face"): OpenCASCADE's
/// failures on entities (failed_entities), when there are any, name what broke, and FreeCAD, on
/// the same OpenCASCADE, reads nothing from such a file either.
[[noreturn]] void nothing_read(const fs::path& file, std::string_view what,
                               const std::vector<std::string>& failed) {
  std::string m = "read_model: " + quoted(file) + " " + std::string(what);
  if (!failed.empty())
    m += ": OpenCASCADE failed to transfer " + std::to_string(failed.size()) + " entit" +
         (failed.size() == 1 ? "y" : "ies") + ", the first " + failed.front() +
         "; correct that entity in the sending system";
  throw Error(ErrorCategory::Exchange, m);
}

/// Gaps up to this fraction of the model size raise an edge's tolerance on reading (see
/// ModelBuilder::raise_tolerances_to_gaps).
constexpr double tolerant_edge_relative = 1e-4;

// ---- names, colours and the assembly ----------------------------------------------------------

std::string name_of(const TDF_Label& label) {
  Handle(TDataStd_Name) attribute;
  if (label.IsNull() || !label.FindAttribute(TDataStd_Name::GetID(), attribute)) return {};
  // Without a replacement character the conversion is to UTF-8.
  std::string name = TCollection_AsciiString(attribute->Get()).ToCString();
  // XCAF names unnamed references after their target's label entry ("=>[0:1:1:2]"): no name.
  if (name.rfind("=>[", 0) == 0) name.clear();
  return name;
}

std::optional<Colour> colour_of(const Handle(XCAFDoc_ColorTool) & tool, const TDF_Label& label) {
  Quantity_Color c;
  if (tool->GetColor(label, XCAFDoc_ColorSurf, c) || tool->GetColor(label, XCAFDoc_ColorGen, c)) {
    double r = 0, g = 0, b = 0;
    c.Values(r, g, b, Quantity_TOC_sRGB);
    return Colour{std::clamp(r, 0.0, 1.0), std::clamp(g, 0.0, 1.0), std::clamp(b, 0.0, 1.0)};
  }
  return std::nullopt;
}

struct Attributes {
  std::string name;
  std::optional<Colour> colour;
};

Eigen::Isometry3d isometry_of(const TopLoc_Location& location, const std::string& name) {
  const gp_Trsf t = location.Transformation();
  if (std::abs(t.ScaleFactor() - 1.0) > 1e-12)
    throw Error(ErrorCategory::Exchange, name + ": the placement scales by " +
                                             shortest(t.ScaleFactor()) +
                                             "; only rigid placements are supported");
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) out.matrix()(i, j) = t.Value(i + 1, j + 1);
  return out;
}

// ---- the reader -------------------------------------------------------------------------------

class ModelBuilder {
 public:
  /// `failed`: the entities OpenCASCADE failed to transfer (failed_entities), for the messages.
  ModelBuilder(const fs::path& file, const ModelReadOptions& options,
               Handle(XCAFDoc_ShapeTool) shapes, Handle(XCAFDoc_ColorTool) colours,
               std::vector<std::string> failed, Handle(XSControl_WorkSession) session)
      : file_(file),
        options_(options),
        shapes_(std::move(shapes)),
        colours_(std::move(colours)),
        failed_(std::move(failed)),
        session_(std::move(session)) {}

  ImportedModel build() {
    TDF_LabelSequence free;
    shapes_->GetFreeShapes(free);
    if (free.IsEmpty()) nothing_read(file_, "holds no shape", failed_);
    // The model's size (tolerances are relative to it): OpenCASCADE's box of every free shape.
    Bnd_Box box;
    for (int i = 1; i <= free.Length(); ++i) add_finite(shapes_->GetShape(free.Value(i)), box);
    // A void box (only unbounded curves): read_locked refuses the file if nothing is held and
    // nothing named as left out.
    size_ = std::sqrt(box.SquareExtent());
    if (!(size_ > 0) || !std::isfinite(size_)) size_ = 1;

    const bool flat = free.Length() == 1 && !shapes_->IsAssembly(free.Value(1));
    if (flat) {
      const TDF_Label label = free.Value(1);
      const auto bodies = bodies_of(label, shapes_->GetShape(label));
      const std::string name = name_of(label);
      const auto colour = colour_of(colours_, label);
      for (int b : bodies) {
        Body& body = model_.bodies[static_cast<std::size_t>(b)];
        if (body.name.empty() && bodies.size() == 1) body.name = name;
        if (!body.colour && bodies.size() == 1) body.colour = colour;
      }
    } else {
      for (int i = 1; i <= free.Length(); ++i) {
        Instance root;
        root.part = part_of(free.Value(i));
        root.name = name_of(free.Value(i));
        root.placement = isometry_of(own_location(free.Value(i)), "free shape '" + root.name + "'");
        model_.roots.push_back(root);
      }
    }
    if (!options_.strict)
      if (const auto pulled = pull_pcurves_into_domains(model_); pulled.count > 0)
        report_.healing.push_back(describe(pulled));
    raise_tolerances_to_gaps();
    if (const int turned = options_.strict ? 0 : outer_loops_first(model_); turned > 0)
      report_.healing.push_back("took the counter-clockwise loop as the outer loop of " +
                                std::to_string(turned) + (turned == 1 ? " face" : " faces") +
                                " (OpenCASCADE's OuterWire had chosen a hole)");
    if (free_edges_given_vertices_ > 0)
      report_.healing.push_back("gave " + std::to_string(free_edges_given_vertices_) +
                                " free edge" + (free_edges_given_vertices_ == 1 ? "" : "s") +
                                " without vertices vertices at their curves' ends");
    if (faces_enclosing_nothing_ > 0)
      report_.healing.push_back(
          "kept " + std::to_string(faces_enclosing_nothing_) +
          (faces_enclosing_nothing_ == 1 ? " face that encloses" : " faces that enclose") +
          " no area (a loop along one line), on a surface widened across that line");
    ImportedModel out;
    out.report = report_;
    out.report.size_mm = size_;
    out.report.max_rederivation_error_mm = max_error_;
    for (const Edge& e : model_.edges)
      out.report.max_edge_tolerance_mm = std::max(out.report.max_edge_tolerance_mm, e.tolerance_mm);
    out.model = std::move(model_);
    complete_report(out);
    return out;
  }

 private:
  /// Adds `shape` to `box`, leaving out unbounded edges (OpenCASCADE's +-2e100 range of a line in
  /// a curve set would make the model's size, and every tolerance relative to it, 4e100).
  static void add_finite(const TopoDS_Shape& shape, Bnd_Box& box) {
    for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next())
      BRepBndLib::Add(f.Current(), box);
    for (TopExp_Explorer e(shape, TopAbs_EDGE, TopAbs_FACE); e.More(); e.Next()) {
      double first = 0, last = 0;
      BRep_Tool::Range(TopoDS::Edge(e.Current()), first, last);
      if (!Precision::IsInfinite(first) && !Precision::IsInfinite(last))
        BRepBndLib::Add(e.Current(), box);
    }
    for (TopExp_Explorer v(shape, TopAbs_VERTEX, TopAbs_EDGE); v.More(); v.Next())
      BRepBndLib::Add(v.Current(), box);
  }

  /// A file's edge tolerance is what its writer (or OpenCASCADE's reader, for STEP, which stores
  /// none) measured by sampling a few points; edge_gaps samples every knot span densely and finds
  /// gaps up to twice as large (0.0012 mm where OpenCASCADE's STEP reader set 0.00075 mm on a
  /// refitted solid). Such an edge's tolerance (and its vertices') is raised to the measured gap,
  /// and the report says so, when the gap is within 1.5 times the tolerance or within 1e-4 of
  /// the model's size (7.5 um on a 75 mm part: tighter than the 10 um linear tolerance CAD
  /// systems commonly work to). A larger gap is the file's defect, left for problems() to name.
  void raise_tolerances_to_gaps() {
    for (const Edge& e : model_.edges)
      if (!e.degenerate && !surface::problems(e.curve, "").empty()) return;  // problems() says
    std::vector<EdgeGap> gaps;
    try {
      gaps = edge_gaps(model_);
    } catch (const Error&) {
      return;  // a broken coedge: problems() names it
    }
    if (rederive_pcurves_from_edges(gaps)) {
      try {
        gaps = edge_gaps(model_);
      } catch (const Error&) {
        return;
      }
    }
    // The largest gap per edge first, then one decision against the file's tolerance.
    std::map<int, double> widest;
    for (const EdgeGap& g : gaps) widest[g.edge] = std::max(widest[g.edge], g.gap_mm);
    std::set<int> raised, widened;
    double largest = 0, widest_gap = 0;
    for (const auto& [edge, gap] : widest) {
      Edge& e = model_.edges[static_cast<std::size_t>(edge)];
      if (!(gap > e.tolerance_mm)) continue;
      if (gap <= std::max(1.5 * e.tolerance_mm, tolerant_edge_relative * size_)) {
        raised.insert(edge);
        largest = std::max(largest, gap - e.tolerance_mm);
      } else if (!options_.strict && gap <= healed_gap_relative * size_) {
        widened.insert(edge);
        widest_gap = std::max(widest_gap, gap);
      } else {
        continue;
      }
      // 0.1 % to spare, as deform_model leaves: BRepCheck measures the gap by its own sampling
      // and rounding (it found Alibre's bulged annulus above the gap x (1 + 1e-9)); and a margin
      // of rounding at the model's size: a placed instance, rotated when an assembly is
      // flattened, measures the same gap 3e-15 mm wider (CATIA's as1 assembly).
      e.tolerance_mm = gap * (1 + 1e-3) + 1e-12 * size_;
      for (int v : {e.start, e.end})
        if (v >= 0 && static_cast<std::size_t>(v) < model_.vertices.size())
          model_.vertices[static_cast<std::size_t>(v)].tolerance_mm =
              std::max(model_.vertices[static_cast<std::size_t>(v)].tolerance_mm, e.tolerance_mm);
    }
    if (!raised.empty())
      report_.healing.push_back("raised the tolerances of " + std::to_string(raised.size()) +
                                " edge" + (raised.size() == 1 ? "" : "s") +
                                " to the gaps measured densely (by at most " + shortest(largest) +
                                " mm)");
    if (!widened.empty())
      report_.healing.push_back("set the tolerances of " + std::to_string(widened.size()) +
                                " edge" + (widened.size() == 1 ? "" : "s") +
                                " to the file's own gaps between faces and edges (up to " +
                                shortest(widest_gap) + " mm, " + shortest(widest_gap / size_) +
                                " of the model's size)");
  }

  /// A pcurve parametrized unlike its edge, though the edge lies on the face: an I-DEAS IGES
  /// solid gives a circle's 3D curve as a 120-degree rational B-spline and its pcurve as a line
  /// across a 90-degree rational cone, declared same-parameter, so at equal parameters the face
  /// is 0.12 mm from the edge (BRepCheck samples 23 points and misses it). Each coedge whose gap
  /// is beyond what raise_tolerances_to_gaps accepts gets a pcurve re-derived from its edge: the
  /// edge's points projected onto the face by Newton from the old pcurve's point at the same
  /// parameter, interpolated by cubics piece by piece (between the edge's knots) until the face
  /// along it is within fit_relative of the size from the edge. Only where every projected point
  /// lies on the face within the accepted gap: the edge and face must share the curve. Returns
  /// whether any pcurve was replaced (the report says how many).
  bool rederive_pcurves_from_edges(const std::vector<EdgeGap>& gaps) {
    int replaced = 0;
    double worst_before = 0, worst_fit = 0;
    for (const EdgeGap& g : gaps) {
      Edge& edge = model_.edges[static_cast<std::size_t>(g.edge)];
      const double accepted = std::max(1.5 * edge.tolerance_mm, tolerant_edge_relative * size_);
      if (edge.degenerate || !(g.gap_mm > accepted)) continue;
      Face& face = model_.faces[static_cast<std::size_t>(g.face)];
      Coedge& coedge =
          face.loops[static_cast<std::size_t>(g.loop)].coedges[static_cast<std::size_t>(g.coedge)];
      if (auto fitted =
              pcurve_from_edge(face.surface, edge, coedge.pcurve, accepted, fit_relative * size_)) {
        coedge.pcurve = std::move(fitted->first);
        worst_fit = std::max(worst_fit, fitted->second);
        worst_before = std::max(worst_before, g.gap_mm);
        ++replaced;
      }
    }
    if (replaced > 0)
      report_.healing.push_back(
          "re-derived " + std::to_string(replaced) +
          (replaced == 1 ? " pcurve from its edge" : " pcurves from their edges") +
          " (parametrized unlike their edges: gaps up to " + shortest(worst_before) +
          " mm at equal parameters, " + shortest(worst_fit) + " mm after)");
    return replaced > 0;
  }

  /// The part of a label (a simple shape or an assembly), converted once.
  int part_of(const TDF_Label& label) {
    for (const auto& [known, index] : parts_)
      if (known.IsEqual(label)) return index;
    Part part;
    part.name = name_of(label);
    part.colour = colour_of(colours_, label);
    if (shapes_->IsAssembly(label)) {
      TDF_LabelSequence components;
      shapes_->GetComponents(label, components, false);
      for (int i = 1; i <= components.Length(); ++i) {
        const TDF_Label component = components.Value(i);
        TDF_Label referred;
        if (!shapes_->GetReferredShape(component, referred)) continue;
        Instance instance;
        instance.name = name_of(component);
        // The part is stored without its own location: the instance carries it.
        instance.placement = isometry_of(shapes_->GetLocation(component) * own_location(referred),
                                         "instance '" + instance.name + "' of '" + part.name + "'");
        instance.part = part_of(referred);
        part.components.push_back(instance);
      }
    } else {
      TopoDS_Shape shape = shapes_->GetShape(label);
      shape.Location(TopLoc_Location());  // the part in its own coordinates
      part.bodies = bodies_of(label, shape);
    }
    model_.parts.push_back(std::move(part));
    const int index = static_cast<int>(model_.parts.size()) - 1;
    parts_.emplace_back(label, index);
    return index;
  }

  /// The location of a simple shape's own shape (parts are stored without it); none for an
  /// assembly.
  TopLoc_Location own_location(const TDF_Label& label) const {
    return shapes_->IsAssembly(label) ? TopLoc_Location() : shapes_->GetShape(label).Location();
  }

  /// Names and colours of the sub-shapes (solids, shells, faces) a label carries.
  std::vector<std::pair<TopoDS_Shape, Attributes>> sub_attributes(const TDF_Label& label) {
    std::vector<std::pair<TopoDS_Shape, Attributes>> out;
    TDF_LabelSequence subs;
    shapes_->GetSubShapes(label, subs);
    for (int i = 1; i <= subs.Length(); ++i)
      out.push_back({shapes_->GetShape(subs.Value(i)),
                     Attributes{name_of(subs.Value(i)), colour_of(colours_, subs.Value(i))}});
    return out;
  }

  const Attributes* find(const std::vector<std::pair<TopoDS_Shape, Attributes>>& list,
                         const TopoDS_Shape& shape) const {
    for (const auto& [s, a] : list)
      if (s.IsSame(shape)) return &a;
    return nullptr;
  }

  /// Heals what the conversion needs: 3D curves of edges that have only pcurves, same parameter.
  void heal(const TopoDS_Shape& shape) {
    int built = 0, same_parameter = 0;
    TopTools_IndexedMapOfShape edges;
    TopExp::MapShapes(shape, TopAbs_EDGE, edges);
    for (int i = 1; i <= edges.Extent(); ++i) {
      const TopoDS_Edge& e = TopoDS::Edge(edges(i));
      if (BRep_Tool::Degenerated(e)) continue;
      double f = 0, l = 0;
      if (BRep_Tool::Curve(e, f, l).IsNull()) {
        if (!BRepLib::BuildCurve3d(e))
          throw Error(ErrorCategory::Exchange, edge_name(e) +
                                                   ": it has no 3D curve, and "
                                                   "none could be built from its pcurves");
        ++built;
      }
      if (!BRep_Tool::SameParameter(e) || !BRep_Tool::SameRange(e)) {
        BRepLib::SameParameter(e, BRep_Tool::Tolerance(e));
        ++same_parameter;
      }
    }
    if (built > 0)
      report_.healing.push_back("built the 3D curves of " + std::to_string(built) +
                                " edges from their pcurves");
    if (same_parameter > 0)
      report_.healing.push_back("made " + std::to_string(same_parameter) +
                                " edges same-parameter (BRepLib::SameParameter)");
  }

  /// The file's entity a shape was transferred from ("#15 LINE", "D23 entity type 126"), or
  /// "entity unknown" when the transfer did not record it.
  std::string entity_of(const TopoDS_Shape& shape) const {
    if (session_.IsNull() || session_->TransferReader().IsNull()) return "entity unknown";
    const Handle(Standard_Transient) entity =
        session_->TransferReader()->EntityFromShapeResult(shape, 1);
    const Handle(Interface_InterfaceModel) model = session_->Model();
    if (entity.IsNull() || model.IsNull() || !model->Contains(entity)) return "entity unknown";
    const Handle(TCollection_HAsciiString) label = model->StringLabel(entity);
    return (label.IsNull() ? std::string("?") : std::string(label->ToCString())) + " " +
           model->TypeName(entity, false);
  }

  std::string edge_name(const TopoDS_Edge&) const {
    return "read_model: " + quoted(file_) + " edge #" + std::to_string(model_.edges.size());
  }

  /// Sews the loose faces of `shape` into shells and closed shells into solids.
  TopoDS_Shape sewn(const TopoDS_Shape& shape) {
    std::vector<TopoDS_Shape> kept;
    BRepBuilderAPI_Sewing sewing(options_.sewing_tolerance_mm);
    int loose = 0;
    for (TopExp_Explorer e(shape, TopAbs_SOLID); e.More(); e.Next()) kept.push_back(e.Current());
    for (TopExp_Explorer e(shape, TopAbs_SHELL, TopAbs_SOLID); e.More(); e.Next())
      kept.push_back(e.Current());
    for (TopExp_Explorer e(shape, TopAbs_FACE, TopAbs_SHELL); e.More(); e.Next()) {
      sewing.Add(e.Current());
      ++loose;
    }
    if (loose == 0) return shape;
    sewing.Perform();
    TopoDS_Compound out;
    BRep_Builder builder;
    builder.MakeCompound(out);
    for (const TopoDS_Shape& s : kept) builder.Add(out, s);
    int shells = 0, solids = 0;
    const TopoDS_Shape result = sewing.SewedShape();
    for (TopExp_Explorer e(result, TopAbs_SHELL); e.More(); e.Next()) {
      const TopoDS_Shell shell = TopoDS::Shell(e.Current());
      ++shells;
      if (BRep_Tool::IsClosed(shell)) {
        const TopoDS_Solid solid = ShapeFix_Solid().SolidFromShell(shell);
        if (!solid.IsNull()) {
          builder.Add(out, solid);
          ++solids;
          continue;
        }
      }
      builder.Add(out, shell);
    }
    for (TopExp_Explorer e(result, TopAbs_FACE, TopAbs_SHELL); e.More(); e.Next())
      builder.Add(out, e.Current());
    report_.healing.push_back("sewed " + std::to_string(loose) + " loose faces into " +
                              std::to_string(shells) + " shells, " + std::to_string(solids) +
                              " of them closed into solids");
    return out;
  }

  /// The bodies of one part's shape: its solids, then free shells, then loose faces together.
  std::vector<int> bodies_of(const TDF_Label& label, TopoDS_Shape shape) {
    if (options_.sew) shape = sewn(shape);
    heal(shape);
    const auto attributes = sub_attributes(label);
    std::vector<int> out;
    auto add_body = [&](BodyKind kind, const TopoDS_Shape& s) {
      Body body;
      body.kind = kind;
      if (const Attributes* a = find(attributes, s)) {
        body.name = a->name;
        body.colour = a->colour;
      }
      model_.bodies.push_back(std::move(body));
      out.push_back(static_cast<int>(model_.bodies.size()) - 1);
      return out.back();
    };
    for (TopExp_Explorer e(shape, TopAbs_SOLID); e.More(); e.Next()) {
      const int b = add_body(BodyKind::Solid, e.Current());
      for (TopoDS_Iterator it(e.Current()); it.More(); it.Next())
        if (it.Value().ShapeType() == TopAbs_SHELL) add_shell(b, it.Value(), attributes);
    }
    for (TopExp_Explorer e(shape, TopAbs_SHELL, TopAbs_SOLID); e.More(); e.Next())
      add_shell(add_body(BodyKind::Shell, e.Current()), e.Current(), attributes);
    std::vector<TopoDS_Face> loose;
    for (TopExp_Explorer e(shape, TopAbs_FACE, TopAbs_SHELL); e.More(); e.Next())
      loose.push_back(TopoDS::Face(e.Current()));
    if (!loose.empty()) {
      const int b = add_body(BodyKind::Sheet, TopoDS_Shape());
      Shell shell;
      for (const TopoDS_Face& f : loose) shell.faces.push_back(add_face(f, attributes));
      model_.bodies[static_cast<std::size_t>(b)].shells.push_back(std::move(shell));
    }
    // Free curves (a wireframe, curves sent beside the surfaces): a wire body per free wire,
    // and one for the loose edges. Edges inside faces are not visited (faces hold wires).
    TopTools_IndexedMapOfShape visited;
    auto wire_body = [&](const TopoDS_Shape& holder, const std::vector<TopoDS_Edge>& edges) {
      std::vector<int> held;
      for (const TopoDS_Edge& e : edges)
        if (const auto index = free_edge_of(e)) held.push_back(*index);
      if (held.empty()) return;
      model_.bodies[static_cast<std::size_t>(add_body(BodyKind::Wire, holder))].edges =
          std::move(held);
    };
    for (TopExp_Explorer w(shape, TopAbs_WIRE, TopAbs_FACE); w.More(); w.Next()) {
      std::vector<TopoDS_Edge> edges;
      for (TopExp_Explorer e(w.Current(), TopAbs_EDGE); e.More(); e.Next())
        if (!visited.Contains(e.Current())) {
          visited.Add(e.Current());
          edges.push_back(TopoDS::Edge(e.Current()));
        }
      wire_body(w.Current(), edges);
    }
    std::vector<TopoDS_Edge> loose_edges;
    for (TopExp_Explorer e(shape, TopAbs_EDGE, TopAbs_WIRE); e.More(); e.Next())
      if (!visited.Contains(e.Current())) {
        visited.Add(e.Current());
        loose_edges.push_back(TopoDS::Edge(e.Current()));
      }
    wire_body(TopoDS_Shape(), loose_edges);
    int points = 0;
    for (TopExp_Explorer v(shape, TopAbs_VERTEX, TopAbs_EDGE); v.More(); v.Next()) ++points;
    if (points > 0)
      report_.left_out.push_back(std::to_string(points) + " free point" + (points == 1 ? "" : "s") +
                                 " (vertices no edge uses): a model holds points only as the "
                                 "ends of edges");
    return out;
  }

  /// The model edge of a free edge (one no face uses), converted once; nullopt when the model
  /// cannot hold it (an unbounded line or curve: report_.left_out says so). An edge without
  /// vertices gets vertices at its curve's ends, within its tolerance.
  std::optional<int> free_edge_of(const TopoDS_Edge& edge) {
    if (const int found = edges_.FindIndex(edge); found > 0) return found - 1;
    const std::string name = "a free edge (" + entity_of(edge) + ")";
    if (BRep_Tool::Degenerated(edge)) {
      report_.left_out.push_back(name + ": a degenerate free edge (a point)");
      return std::nullopt;
    }
    double f = 0, l = 0;
    const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, f, l);
    if (curve.IsNull()) {
      report_.left_out.push_back(name + ": a free edge without a 3D curve");
      return std::nullopt;
    }
    if (Precision::IsInfinite(f) || Precision::IsInfinite(l)) {
      // OpenCASCADE gives an unbounded line (STEP's LINE in a curve set) the range +-2e100: it
      // has no extent for a lattice to hold or a B-spline to write back.
      report_.left_out.push_back(name + ": an unbounded " + curve->DynamicType()->Name() +
                                 " (OpenCASCADE's range [" + shortest(f) + ", " + shortest(l) +
                                 "]): it has no extent to deform or write back; give it end "
                                 "points in the sending system");
      return std::nullopt;
    }
    TopoDS_Vertex first, last;
    TopExp::Vertices(TopoDS::Edge(edge.Oriented(TopAbs_FORWARD)), first, last);
    if (first.IsNull() || last.IsNull()) {
      // Vertices at the curve's ends, made on a copy: the shape stays as it was read.
      TopoDS_Edge copy = TopoDS::Edge(edge.EmptyCopied().Oriented(TopAbs_FORWARD));
      BRep_Builder builder;
      const double tolerance = BRep_Tool::Tolerance(edge);
      builder.MakeVertex(first, curve->Value(f), tolerance);
      builder.MakeVertex(last, curve->Value(l), tolerance);
      if (curve->Value(f).Distance(curve->Value(l)) <= tolerance) last = first;
      builder.Add(copy, first.Oriented(TopAbs_FORWARD));
      builder.Add(copy, last.Oriented(TopAbs_REVERSED));
      ++free_edges_given_vertices_;
      const int index = edge_of(copy);
      edges_.Substitute(edges_.FindIndex(copy), edge);  // found again by the file's edge
      return index;
    }
    return edge_of(edge);
  }

  void add_shell(int body, const TopoDS_Shape& shell_shape,
                 const std::vector<std::pair<TopoDS_Shape, Attributes>>& attributes) {
    Shell shell;
    for (TopExp_Explorer e(shell_shape, TopAbs_FACE); e.More(); e.Next())
      shell.faces.push_back(add_face(TopoDS::Face(e.Current()), attributes));
    model_.bodies[static_cast<std::size_t>(body)].shells.push_back(std::move(shell));
  }

  int vertex_of(const TopoDS_Vertex& v) {
    const int found = vertices_.FindIndex(v);
    if (found > 0) return found - 1;
    vertices_.Add(v);
    Vertex vertex;
    const gp_Pnt p = BRep_Tool::Pnt(v);
    vertex.point = {p.X(), p.Y(), p.Z()};
    vertex.tolerance_mm = BRep_Tool::Tolerance(v);
    model_.vertices.push_back(vertex);
    return static_cast<int>(model_.vertices.size()) - 1;
  }

  /// The model edge of `edge` (any orientation), converted once.
  int edge_of(const TopoDS_Edge& edge) {
    const int found = edges_.FindIndex(edge);
    if (found > 0) return found - 1;
    const TopoDS_Edge forward = TopoDS::Edge(edge.Oriented(TopAbs_FORWARD));
    const std::string name = edge_name(forward);
    EdgeConversion c = convert_edge(forward, size_, name);
    Edge e;
    e.degenerate = c.old_curve.IsNull();
    if (!e.degenerate) e.curve = checked_curve(c.nurbs, name);
    e.t0 = c.s0;
    e.t1 = c.s1;
    e.tolerance_mm = BRep_Tool::Tolerance(forward);
    TopoDS_Vertex first, last;
    TopExp::Vertices(forward, first, last);
    if (first.IsNull() || last.IsNull())
      throw Error(ErrorCategory::Exchange, name + ": the edge has no vertex at one end");
    e.start = vertex_of(first);
    e.end = vertex_of(last);
    edges_.Add(edge);
    conversions_.push_back(std::move(c));
    model_.edges.push_back(std::move(e));
    return static_cast<int>(model_.edges.size()) - 1;
  }

  /// A seam lies on an end of the domain of its full turn: files give it 5e-13 off (0 after the
  /// box was snapped to one period), which OpenCASCADE's readers then shift by a period.
  static double at_end(double x, double lo, double hi) {
    const double eps = 1e-9 * (hi - lo);
    return std::abs(x - lo) <= eps ? lo : std::abs(x - hi) <= eps ? hi : x;
  }

  /// A seam of an angular face (one edge used both ways by the face, along an iso-line): its
  /// new curve is the new surface's iso-curve there, parametrized by the surface's own
  /// parameter, so that both pcurves are exact lines and OpenCASCADE's readers, which rebuild
  /// seams from the surface, read back the same curve. Returns the edge and whether it runs
  /// against the old edge; nullopt when the seam is not an iso-line.
  std::optional<std::pair<int, bool>> seam_of(const TopoDS_Edge& edge, const TopoDS_Face& face,
                                              const FaceConversion& conversion) {
    const int found = edges_.FindIndex(edge);
    if (found > 0) {
      const auto flip = seam_flipped_.find(found - 1);
      if (flip == seam_flipped_.end()) return std::nullopt;
      return std::pair{found - 1, flip->second};
    }
    const TopoDS_Edge forward = TopoDS::Edge(edge.Oriented(TopAbs_FORWARD));
    double f = 0, l = 0;
    const Handle(Geom2d_Curve) p = BRep_Tool::CurveOnSurface(forward, face, f, l);
    if (p.IsNull()) return std::nullopt;
    const gp_Pnt2d a = p->Value(f), b = p->Value(l);
    const bool iso_u = std::abs(a.X() - b.X()) <= 1e-12 * (conversion.nu1 - conversion.nu0);
    const bool iso_v = std::abs(a.Y() - b.Y()) <= 1e-12 * (conversion.nv1 - conversion.nv0);
    if (iso_u == iso_v) return std::nullopt;
    const Eigen::Vector2d na = conversion.map(a.X(), a.Y()), nb = conversion.map(b.X(), b.Y());
    const double c = iso_u ? at_end(na.x(), conversion.nu0, conversion.nu1)
                           : at_end(na.y(), conversion.nv0, conversion.nv1);
    const double w0 = iso_u ? na.y() : na.x(), w1 = iso_u ? nb.y() : nb.x();
    const bool flipped = w1 < w0;
    Handle(Geom_BSplineCurve) iso = Handle(Geom_BSplineCurve)::DownCast(
        iso_u ? conversion.nurbs->UIso(c) : conversion.nurbs->VIso(c));
    if (iso.IsNull()) return std::nullopt;
    const std::string name = edge_name(forward);
    Edge e;
    e.curve = checked_curve(iso, name);
    e.t0 = std::min(w0, w1);
    e.t1 = std::max(w0, w1);
    e.tolerance_mm = BRep_Tool::Tolerance(forward);
    TopoDS_Vertex first, last;
    TopExp::Vertices(forward, first, last);
    if (first.IsNull() || last.IsNull())
      throw Error(ErrorCategory::Exchange, name + ": the edge has no vertex at one end");
    e.start = vertex_of(flipped ? last : first);
    e.end = vertex_of(flipped ? first : last);
    edges_.Add(edge);
    EdgeConversion identity;
    identity.nurbs = iso;
    identity.s0 = e.t0;
    identity.s1 = e.t1;
    conversions_.push_back(identity);
    model_.edges.push_back(std::move(e));
    const int index = static_cast<int>(model_.edges.size()) - 1;
    seam_flipped_[index] = flipped;
    return std::pair{index, flipped};
  }

  /// The exact line pcurve of one use of a seam made by seam_of.
  surface::BSplineCurve seam_pcurve(const TopoDS_Edge& oriented, const TopoDS_Face& face,
                                    const FaceConversion& conversion, const Edge& e) const {
    double f = 0, l = 0;
    const Handle(Geom2d_Curve) p = BRep_Tool::CurveOnSurface(oriented, face, f, l);
    const gp_Pnt2d a = p->Value(f), b = p->Value(l);
    const bool iso_u = std::abs(a.X() - b.X()) <= std::abs(a.Y() - b.Y());
    const Eigen::Vector2d na = conversion.map(a.X(), a.Y());
    const double c = iso_u ? at_end(na.x(), conversion.nu0, conversion.nu1)
                           : at_end(na.y(), conversion.nv0, conversion.nv1);
    surface::Points3 points(2, 3);
    if (iso_u)
      points << c, e.t0, 0.0, c, e.t1, 0.0;
    else
      points << e.t0, c, 0.0, e.t1, c, 0.0;
    return surface::make_curve(1, {e.t0, e.t0, e.t1, e.t1}, std::move(points));
  }

  int add_face(const TopoDS_Face& face,
               const std::vector<std::pair<TopoDS_Shape, Attributes>>& attributes) {
    const int index = static_cast<int>(model_.faces.size());
    const std::string name = "read_model: " + quoted(file_) + " face #" + std::to_string(index);
    const TopoDS_Face forward = TopoDS::Face(face.Oriented(TopAbs_FORWARD));
    const FaceConversion conversion = convert_face(forward, size_, name);
    Face out;
    out.surface = checked_surface(conversion.nurbs, name);
    if (conversion.encloses_nothing) ++faces_enclosing_nothing_;
    out.reversed = face.Orientation() == TopAbs_REVERSED;
    if (const Attributes* a = find(attributes, face)) {
      out.name = a->name;
      out.colour = a->colour;
    } else if (auto c = colour_of_shape(face)) {
      out.colour = c;
    }
    switch (conversion.kind) {
      case FaceKind::BSpline:
        ++report_.faces_bspline;
        break;
      case FaceKind::Affine:
        ++report_.faces_affine;
        break;
      case FaceKind::Angular:
        ++report_.faces_angular;
        break;
      case FaceKind::Approximated:
        ++report_.faces_approximated;
        report_.max_approximation_error_mm =
            std::max(report_.max_approximation_error_mm, conversion.approximation_error);
        break;
    }
    // Loops: the outer wire first, each walked in order on the forward face.
    const TopoDS_Wire outer = BRepTools::OuterWire(forward);
    std::vector<TopoDS_Wire> wires;
    if (!outer.IsNull()) wires.push_back(outer);
    for (TopoDS_Iterator it(forward); it.More(); it.Next())
      if (it.Value().ShapeType() == TopAbs_WIRE && !it.Value().IsSame(outer))
        wires.push_back(TopoDS::Wire(it.Value()));
    for (const TopoDS_Wire& wire : wires) {
      Loop loop;
      for (BRepTools_WireExplorer w(wire, forward); w.More(); w.Next()) {
        const TopoDS_Edge& edge = w.Current();
        Coedge coedge;
        if (conversion.kind == FaceKind::Angular && !BRep_Tool::Degenerated(edge) &&
            BRep_Tool::IsClosed(edge, forward)) {
          if (const auto seam = seam_of(edge, forward, conversion)) {
            coedge.edge = seam->first;
            coedge.same_sense = (edge.Orientation() != TopAbs_REVERSED) != seam->second;
            coedge.pcurve = seam_pcurve(edge, forward, conversion,
                                        model_.edges[static_cast<std::size_t>(seam->first)]);
            ++report_.pcurves_exact;
            loop.coedges.push_back(std::move(coedge));
            continue;
          }
        }
        coedge.edge = edge_of(edge);
        coedge.same_sense = edge.Orientation() != TopAbs_REVERSED;
        const std::string coedge_name = name + " edge #" + std::to_string(coedge.edge);
        double f = 0, l = 0;
        const Handle(Geom2d_Curve) p = BRep_Tool::CurveOnSurface(edge, forward, f, l);
        if (p.IsNull())
          throw Error(ErrorCategory::Exchange,
                      coedge_name + ": the edge has no pcurve on the face");
        Rederived r = rederive(conversion, conversions_[static_cast<std::size_t>(coedge.edge)], p,
                               coedge_name);
        coedge.pcurve = std::move(r.pcurve);
        switch (r.way) {
          case PcurveWay::Kept:
            ++report_.pcurves_kept;
            break;
          case PcurveWay::Exact:
            ++report_.pcurves_exact;
            break;
          case PcurveWay::Fitted:
            ++report_.pcurves_fitted;
            max_error_ = std::max(max_error_, r.error_mm);
            break;
        }
        loop.coedges.push_back(std::move(coedge));
      }
      if (!loop.coedges.empty()) out.loops.push_back(std::move(loop));
    }
    // The edges lie on the offset surface; the approximated face is off it by up to its error.
    if (conversion.kind == FaceKind::Approximated)
      for (const Loop& loop : out.loops)
        for (const Coedge& co : loop.coedges) {
          Edge& e = model_.edges[static_cast<std::size_t>(co.edge)];
          double& applied = widened_[co.edge];  // once per edge: the larger of its faces' errors
          if (conversion.approximation_error <= applied) continue;
          e.tolerance_mm += conversion.approximation_error - applied;
          applied = conversion.approximation_error;
          for (int v : {e.start, e.end})
            if (v >= 0 && static_cast<std::size_t>(v) < model_.vertices.size())
              model_.vertices[static_cast<std::size_t>(v)].tolerance_mm = std::max(
                  model_.vertices[static_cast<std::size_t>(v)].tolerance_mm, e.tolerance_mm);
        }
    out.elementary = elementary_of(conversion.old_surface);
    if (out.elementary && out.elementary->kind == ElementaryKind::Plane && !out.loops.empty())
      out.surface = plane_over_pcurves(*out.elementary, out.loops, model_.edges);
    model_.faces.push_back(std::move(out));
    return index;
  }

  std::optional<Colour> colour_of_shape(const TopoDS_Shape& shape) const {
    Quantity_Color c;
    if (colours_->GetColor(shape, XCAFDoc_ColorSurf, c) ||
        colours_->GetColor(shape, XCAFDoc_ColorGen, c)) {
      double r = 0, g = 0, b = 0;
      c.Values(r, g, b, Quantity_TOC_sRGB);
      return Colour{std::clamp(r, 0.0, 1.0), std::clamp(g, 0.0, 1.0), std::clamp(b, 0.0, 1.0)};
    }
    return std::nullopt;
  }

  fs::path file_;
  ModelReadOptions options_;
  Handle(XCAFDoc_ShapeTool) shapes_;
  Handle(XCAFDoc_ColorTool) colours_;
  std::vector<std::string> failed_;
  Handle(XSControl_WorkSession) session_;  // may be null
  Model model_;
  ModelReadReport report_;
  double size_ = 1;
  double max_error_ = 0;
  std::vector<std::pair<TDF_Label, int>> parts_;  // few: a linear search
  TopTools_IndexedMapOfShape vertices_, edges_;
  std::vector<EdgeConversion> conversions_;
  std::map<int, bool> seam_flipped_;   // seams made by seam_of: runs against the old edge
  std::map<int, double> widened_;      // edges widened for approximated faces, by how much
  int faces_enclosing_nothing_ = 0;    // kept on a widened box (face_box)
  int free_edges_given_vertices_ = 0;  // free edges the file gave no vertices (free_edge_of)
};

/// read_model's work; the caller holds the exchange session. `plain`: read_plain instead of
/// the XCAF readers.
ImportedModel read_locked(const fs::path& file, const ModelReadOptions& options, bool step,
                          bool plain = false, bool brep = false) {
  return surface::occt::guarded(ErrorCategory::Exchange, "read_model", [&] {
    surface::occt::XcafDocument held;  // closed on every way out
    Handle(TDocStd_Document)& document = held.get();
    bool read = false;
    UnknownEntities unknown;
    std::vector<std::string> failed;
    Handle(XSControl_WorkSession) session;  // for naming the entities of shapes left out
    if (brep) {
      read = read_brep_file(file, options.brep, document);
    } else if (plain) {
      read = read_plain(file, step, document, failed, session);
    } else if (step) {
      STEPCAFControl_Controller::Init();
      surface::occt::set_static("xstep.cascade.unit", "MM");
      surface::occt::set_static("read.stepcaf.subshapes.name", 1);  // names of faces and solids
      STEPCAFControl_Reader reader;
      reader.SetColorMode(true);
      reader.SetNameMode(true);
      reader.SetLayerMode(false);
      if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
        throw Error(ErrorCategory::Exchange,
                    "read_model: " + quoted(file) + " could not be parsed as a STEP file");
      const Handle(StepData_StepModel) model = reader.Reader().StepModel();
      for (int i = 1; !model.IsNull() && i <= model->NbEntities(); ++i)
        if (auto u = Handle(StepData_UndefinedEntity)::DownCast(model->Value(i)); !u.IsNull())
          unknown.add(u->StepType(), "#" + std::to_string(model->IdentLabel(u)));
      read = reader.Transfer(document);
      failed = failed_entities(reader.Reader().WS());
      session = reader.Reader().WS();
    } else {
      IGESControl_Controller::Init();
      surface::occt::set_static("xstep.cascade.unit", "MM");
      surface::occt::set_static("read.iges.bspline.continuity", 0);
      IGESCAFControl_Reader reader;
      reader.SetColorMode(true);
      reader.SetNameMode(true);
      reader.SetLayerMode(false);
      if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
        throw Error(ErrorCategory::Exchange,
                    "read_model: " + quoted(file) + " could not be parsed as an IGES file");
      const Handle(IGESData_IGESModel) model = reader.IGESModel();
      for (int i = 1; !model.IsNull() && i <= model->NbEntities(); ++i)
        if (auto u = Handle(IGESData_UndefinedEntity)::DownCast(model->Value(i)); !u.IsNull())
          unknown.add("entity type " + std::to_string(u->TypeNumber()),
                      "D" + std::to_string(2 * i - 1));
      read = reader.Transfer(document);
      failed = failed_entities(reader.WS());
      session = reader.WS();
    }
    if (!read) nothing_read(file, "gave OpenCASCADE no shape to transfer", failed);
    ModelBuilder builder(file, options, XCAFDoc_DocumentTool::ShapeTool(document->Main()),
                         XCAFDoc_DocumentTool::ColorTool(document->Main()), failed, session);
    ImportedModel out = builder.build();
    out.report.ignored = unknown.lines();
    out.report.skipped = failed;
    if (out.model.faces.empty() && counts(out.model).wire_edges == 0 && out.report.left_out.empty())
      nothing_read(file, "holds no face or curve that could be read", failed);
    return out;
  });
}

/// What came through the pipe from an isolated read is checked again here, as the surface
/// reader does.
void check_piped_surfaces(const ImportedModel& out, const fs::path& file, std::string_view caller) {
  for (std::size_t k = 0; k < out.model.faces.size(); ++k)
    if (const auto list = surface::problems(out.model.faces[k].surface,
                                            quoted(file) + " face #" + std::to_string(k));
        !list.empty())
      throw Error(ErrorCategory::Exchange, std::string(caller) + ": " + list.front());
}

}  // namespace

ImportedModel read_model(const fs::path& file, const ModelReadOptions& options) {
  constexpr std::string_view caller = "read_model";
  options.validate();
  const bool step = extension_is(file, {".step", ".stp"});
  const bool iges = extension_is(file, {".iges", ".igs"});
  const bool brep = extension_is(file, {".brep", ".brp"});
  if (!step && !iges && !brep)
    throw Error(ErrorCategory::InvalidArgument,
                "read_model: " + quoted(file) +
                    " has an unknown extension; name a .step, .stp, .iges, .igs, .brep or .brp "
                    "file");
  const BrepAttributes& a = options.brep;
  if (!brep && (!a.name.empty() || a.colour || !a.face_colours.empty() || !a.face_names.empty()))
    throw Error(ErrorCategory::InvalidArgument,
                "read_model: " + quoted(file) +
                    " carries its own names and colours; give ModelReadOptions::brep only for a "
                    ".brep file");
  surface::occt::check_readable(file, caller);
  if (brep) {
    // A BRep file has no pre-check (OpenCASCADE's own format, no entity graph to size up); an
    // isolated read still bounds its time and memory.
    surface::occt::ExchangeSession session;
    ImportedModel out;
    if (!options.read.isolate) {
      out = read_locked(file, options, false, false, true);
    } else {
      out = deserialize(
          surface::occt::read_in_child(file, options.read, caller, [&](const fs::path& f) {
            return serialize(read_locked(f, options, false, false, true));
          }));
      check_piped_surfaces(out, file, caller);
    }
    untag_brep_faces(out);
    complete_report(out);
    return out;
  }
  if (options.read.precheck) {
    if (step)
      surface::detail::precheck_step(file, caller, surface::max_exchange_degree);
    else
      surface::detail::precheck_iges(file, caller, surface::max_exchange_degree);
  }
  surface::occt::ExchangeSession session;
  if (!options.read.isolate) return read_locked(file, options, step);
  auto isolated = [&](bool plain) {
    return deserialize(surface::occt::read_in_child(
        file, options.read, caller,
        [&](const fs::path& f) { return serialize(read_locked(f, options, step, plain)); }));
  };
  ImportedModel out;
  try {
    out = isolated(false);
  } catch (const surface::occt::ChildCrashed& crash) {
    // OpenCASCADE's XCAF readers crash on some files its plain readers read (IGES subfigures
    // nested in subfigures, from C3D Converter): the shapes again without XCAF, and said so. A
    // second crash is the file's.
    out = isolated(true);
    out.report.healing.push_back(
        "OpenCASCADE's XCAF reader crashed on this file, so its plain reader read it: the "
        "shapes are whole, but names, colours and the assembly tree are not read");
  }
  check_piped_surfaces(out, file, caller);
  complete_report(out);
  return out;
}

}  // namespace clay::brep
