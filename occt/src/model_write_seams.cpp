// Seam loops in STEP files (model_shapes.hpp: write_seam_loops).
//
// OpenCASCADE's STEP writer writes a loop made only of a seam (and the poles' degenerate edges)
// as a VERTEX_LOOP (TopoDSToStep_MakeStepWire: CAX-IF's convention for a complete sphere). Its
// reader turns a vertex loop into the surface's natural bounds only when it is the face's one
// bound; otherwise it skips it and adds the natural bounds back only on an analytic sphere or a
// surface periodic both ways. A B-spline face around a pole with holes (Alibre's s1 assembly:
// a sphere minus a cap and a small hole, both poles inside the face) then read back as its holes
// alone: OpenCASCADE took each hole for a face of its own (108 faces for 104, 10 shells for 8,
// the body's volume halved). Such a loop is written here as what it is, an EDGE_LOOP of the seam
// edge used both ways: an EDGE_CURVE on a SEAM_CURVE with both pcurves, as the writer writes
// every other seam; the reader adds the poles' degenerate edges back as it does for any face
// whose loop runs into a pole.
#include <clay/error.hpp>

#include <cmath>
#include <string>

#include "model_shapes.hpp"

#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <GeomToStep_MakeCartesianPoint.hxx>
#include <GeomToStep_MakeCurve.hxx>
#include <Geom_Curve.hxx>
#include <Interface_Protocol.hxx>
#include <StepData_StepModel.hxx>
#include <StepGeom_CartesianPoint.hxx>
#include <StepGeom_GeometricRepresentationContextAndParametricRepresentationContext.hxx>
#include <StepGeom_HArray1OfPcurveOrSurface.hxx>
#include <StepGeom_Pcurve.hxx>
#include <StepGeom_PcurveOrSurface.hxx>
#include <StepGeom_SeamCurve.hxx>
#include <StepRepr_DefinitionalRepresentation.hxx>
#include <StepRepr_HArray1OfRepresentationItem.hxx>
#include <StepShape_AdvancedFace.hxx>
#include <StepShape_EdgeCurve.hxx>
#include <StepShape_EdgeLoop.hxx>
#include <StepShape_FaceBound.hxx>
#include <StepShape_HArray1OfFaceBound.hxx>
#include <StepShape_HArray1OfOrientedEdge.hxx>
#include <StepShape_OrientedEdge.hxx>
#include <StepShape_VertexLoop.hxx>
#include <StepShape_VertexPoint.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TopoDS.hxx>
#include <TransferBRep.hxx>
#include <TransferBRep_ShapeMapper.hxx>
#include <Transfer_FinderProcess.hxx>
#include <XSControl_TransferWriter.hxx>
#include <XSControl_WorkSession.hxx>

namespace clay::brep {
namespace {

/// The seam edge a loop consists of (its other coedges degenerate), or -1.
int pure_seam(const Model& m, const Loop& loop) {
  int seam = -1, forward = 0, backward = 0;
  for (const Coedge& c : loop.coedges) {
    if (m.edges[static_cast<std::size_t>(c.edge)].degenerate) continue;
    if (seam != -1 && c.edge != seam) return -1;
    seam = c.edge;
    (c.same_sense ? forward : backward) += 1;
  }
  return forward == 1 && backward == 1 ? seam : -1;
}

Handle(TCollection_HAsciiString) no_name() { return new TCollection_HAsciiString(""); }

/// The pcurve of `edge` (oriented as the face uses it) as STEP's PCURVE on `surface`.
Handle(StepGeom_Pcurve) step_pcurve(const TopoDS_Edge& edge, const TopoDS_Face& face,
                                    const Handle(StepGeom_Surface) & surface) {
  double first = 0, last = 0;
  const Handle(Geom2d_Curve) curve = BRep_Tool::CurveOnSurface(edge, face, first, last);
  if (curve.IsNull()) return nullptr;
  GeomToStep_MakeCurve make(curve);
  if (!make.IsDone()) return nullptr;
  auto items = new StepRepr_HArray1OfRepresentationItem(1, 1);
  items->SetValue(1, make.Value());
  Handle(StepGeom_GeometricRepresentationContextAndParametricRepresentationContext) context =
      new StepGeom_GeometricRepresentationContextAndParametricRepresentationContext();
  context->Init(new TCollection_HAsciiString("2D SPACE"), no_name(), 2);
  Handle(StepRepr_DefinitionalRepresentation) representation =
      new StepRepr_DefinitionalRepresentation();
  representation->Init(no_name(), items, context);
  Handle(StepGeom_Pcurve) pcurve = new StepGeom_Pcurve();
  pcurve->Init(no_name(), surface, representation);
  return pcurve;
}

/// The STEP vertex written for `vertex`, else the vertex loop's own when it lies there, else a
/// new one.
Handle(StepShape_Vertex)
    step_vertex(const Handle(Transfer_FinderProcess) & finder, const TopoDS_Vertex& vertex,
                const Handle(StepShape_VertexLoop) & loop) {
  Handle(StepShape_VertexPoint) found;
  if (finder->FindTypedTransient(TransferBRep::ShapeMapper(finder, vertex),
                                 STANDARD_TYPE(StepShape_VertexPoint), found))
    return Handle(StepShape_Vertex)(found);
  const gp_Pnt p = BRep_Tool::Pnt(vertex);
  const auto on_loop = Handle(StepShape_VertexPoint)::DownCast(loop->LoopVertex());
  if (!on_loop.IsNull()) {
    const auto point = Handle(StepGeom_CartesianPoint)::DownCast(on_loop->VertexGeometry());
    if (!point.IsNull() && point->NbCoordinates() == 3 &&
        p.Distance(gp_Pnt(point->CoordinatesValue(1), point->CoordinatesValue(2),
                          point->CoordinatesValue(3))) <= BRep_Tool::Tolerance(vertex))
      return Handle(StepShape_Vertex)(on_loop);
  }
  Handle(StepShape_VertexPoint) made = new StepShape_VertexPoint();
  made->Init(no_name(), GeomToStep_MakeCartesianPoint(p).Value());
  return Handle(StepShape_Vertex)(made);
}

}  // namespace

void write_seam_loops(const Model& m, const Shapes& s, STEPControl_Writer& writer) {
  const Handle(Transfer_FinderProcess) finder = writer.WS()->TransferWriter()->FinderProcess();
  const Handle(StepData_StepModel) step_model = writer.Model();
  const Handle(Interface_Protocol) protocol = step_model->Protocol();
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Face& face = m.faces[f];
    if (face.loops.size() < 2) continue;  // a vertex loop alone is read as the natural bounds
    for (const Loop& loop : face.loops) {
      const int seam = pure_seam(m, loop);
      if (seam < 0) continue;
      auto failed = [&](const std::string& why) {
        return Error(ErrorCategory::Exchange,
                     "write_model: face " + std::to_string(f) + "'s loop along its seam (edge " +
                         std::to_string(seam) + ") cannot be written as STEP: " + why +
                         "; write IGES instead");
      };
      Handle(StepShape_AdvancedFace) step_face;
      if (!finder->FindTypedTransient(TransferBRep::ShapeMapper(finder, s.faces[f]),
                                      STANDARD_TYPE(StepShape_AdvancedFace), step_face))
        throw failed("OpenCASCADE's translator did not record the face");
      Handle(StepShape_FaceBound) bound;
      Handle(StepShape_VertexLoop) vertex_loop;
      for (int b = 1; b <= step_face->NbBounds() && vertex_loop.IsNull(); ++b) {
        bound = step_face->BoundsValue(b);
        vertex_loop = Handle(StepShape_VertexLoop)::DownCast(bound->Bound());
      }
      if (vertex_loop.IsNull()) continue;  // written as an edge loop after all

      const TopoDS_Edge& edge = s.edges[static_cast<std::size_t>(seam)];
      const TopoDS_Face& occt_face = s.faces[f];
      double first = 0, last = 0;
      const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first, last);
      if (curve.IsNull()) throw failed("the seam has no 3D curve");
      GeomToStep_MakeCurve make_curve(curve);
      const Handle(StepGeom_Surface) surface = step_face->FaceGeometry();
      // The writer's order for a seam: the pcurve of the edge's forward use first.
      const auto forward =
          step_pcurve(TopoDS::Edge(edge.Oriented(TopAbs_FORWARD)), occt_face, surface);
      const auto backward =
          step_pcurve(TopoDS::Edge(edge.Oriented(TopAbs_REVERSED)), occt_face, surface);
      if (!make_curve.IsDone() || forward.IsNull() || backward.IsNull())
        throw failed("its curves could not be translated");
      auto associated = new StepGeom_HArray1OfPcurveOrSurface(1, 2);
      StepGeom_PcurveOrSurface first_pcurve, second_pcurve;
      first_pcurve.SetValue(forward);
      second_pcurve.SetValue(backward);
      associated->SetValue(1, first_pcurve);
      associated->SetValue(2, second_pcurve);
      Handle(StepGeom_SeamCurve) seam_curve = new StepGeom_SeamCurve();
      seam_curve->Init(no_name(), make_curve.Value(), associated, StepGeom_pscrPcurveS1);

      const Edge& e = m.edges[static_cast<std::size_t>(seam)];
      Handle(StepShape_EdgeCurve) edge_curve = new StepShape_EdgeCurve();
      edge_curve->Init(
          no_name(),
          step_vertex(finder, s.vertices[static_cast<std::size_t>(e.start)], vertex_loop),
          step_vertex(finder, s.vertices[static_cast<std::size_t>(e.end)], vertex_loop), seam_curve,
          true);
      auto uses = new StepShape_HArray1OfOrientedEdge(1, 2);
      for (int k = 1; k <= 2; ++k) {
        Handle(StepShape_OrientedEdge) use = new StepShape_OrientedEdge();
        use->Init(no_name(), edge_curve, k == 1);
        uses->SetValue(k, use);
        step_model->AddWithRefs(use, protocol);
      }
      Handle(StepShape_EdgeLoop) edge_loop = new StepShape_EdgeLoop();
      edge_loop->Init(no_name(), uses);
      bound->SetBound(edge_loop);
      // The edge loop takes the vertex loop's place in the file (nothing else refers to it).
      step_model->ReplaceEntity(step_model->Number(vertex_loop), edge_loop);
    }
  }
}

}  // namespace clay::brep
