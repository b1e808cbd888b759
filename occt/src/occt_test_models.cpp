// Test models built and written by OpenCASCADE, and OpenCASCADE's own reading (test_models.hpp).
#include "occt_test_models.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_GTransform.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepGProp.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GC_MakeArcOfCircle.hxx>
#include <GProp_GProps.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESCAFControl_Writer.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <Quantity_Color.hxx>
#include <STEPCAFControl_Controller.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Reader.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TDF_Label.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Ax2.hxx>
#include <gp_Ax3.hxx>
#include <gp_Circ.hxx>
#include <gp_Elips.hxx>
#include <gp_GTrsf.hxx>
#include <gp_Pnt.hxx>
#include <gp_Trsf.hxx>

namespace clay::surface::occt_reference {
namespace {

namespace fs = std::filesystem;

bool is_iges(const fs::path& file) {
  const std::string ext = file.extension().string();
  return ext == ".igs" || ext == ".iges" || ext == ".IGS" || ext == ".IGES";
}

Quantity_Color srgb(double r, double g, double b) {
  return Quantity_Color(r, g, b, Quantity_TOC_sRGB);
}

TopoDS_Shape filleted_block() {
  TopoDS_Shape block = BRepPrimAPI_MakeBox(60, 40, 20).Shape();
  BRepFilletAPI_MakeFillet fillet(block);
  for (TopExp_Explorer e(block, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    TopoDS_Vertex a, b;
    TopExp::Vertices(edge, a, b);
    const gp_Pnt pa = BRep_Tool::Pnt(a), pb = BRep_Tool::Pnt(b);
    if (std::abs(pa.X() - pb.X()) < 1e-9 && std::abs(pa.Y() - pb.Y()) < 1e-9)
      fillet.Add(5.0, edge);  // vertical
  }
  TopoDS_Shape shape = fillet.Shape();
  for (double x : {15.0, 45.0}) {
    const TopoDS_Shape hole =
        BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, 20, -1), gp::DZ()), 4.0, 22.0).Shape();
    shape = BRepAlgoAPI_Cut(shape, hole).Shape();
  }
  const TopoDS_Shape pocket = BRepPrimAPI_MakeBox(gp_Pnt(24, 12, 12), 12, 16, 9).Shape();
  return BRepAlgoAPI_Cut(shape, pocket).Shape();
}

TopoDS_Shape bottle() {
  const gp_Pnt p0(0, 0, 0), p1(15, 0, 0), p2(15, 0, 40), mid(12.5, 0, 50), p3(8, 0, 55),
      p4(8, 0, 65), p5(0, 0, 65);
  BRepBuilderAPI_MakeWire wire;
  wire.Add(BRepBuilderAPI_MakeEdge(p0, p1).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(p1, p2).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(p2, mid, p3).Value()).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(p3, p4).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(p4, p5).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(p5, p0).Edge());
  const TopoDS_Face profile = BRepBuilderAPI_MakeFace(wire.Wire(), true).Face();
  return BRepPrimAPI_MakeRevol(profile, gp::OZ()).Shape();
}

/// The bottle with an embossed label band: the body's cylinder r 15 rises by 45-degree cones to a
/// band r 16 for z in [14, 30].
TopoDS_Shape label_bottle() {
  const std::vector<gp_Pnt> points{{0, 0, 0},   {15, 0, 0},  {15, 0, 13}, {16, 0, 14},
                                   {16, 0, 30}, {15, 0, 31}, {15, 0, 40}};
  BRepBuilderAPI_MakeWire wire;
  for (std::size_t k = 0; k + 1 < points.size(); ++k)
    wire.Add(BRepBuilderAPI_MakeEdge(points[k], points[k + 1]).Edge());
  const gp_Pnt mid(12.5, 0, 50), p3(8, 0, 55), p4(8, 0, 65), p5(0, 0, 65);
  wire.Add(BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(points.back(), mid, p3).Value()).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(p3, p4).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(p4, p5).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(p5, points.front()).Edge());
  const TopoDS_Face profile = BRepBuilderAPI_MakeFace(wire.Wire(), true).Face();
  return BRepPrimAPI_MakeRevol(profile, gp::OZ()).Shape();
}

/// The loft of TestModel::LoftWithHoles: BRepOffsetAPI_ThruSections, ruled, through three closed
/// sections (closed cubic B-splines through 12 points of a circle or an ellipse, on the same
/// parameters, so the loft keeps them: bicubic-by-linear side faces, two planar caps), then two
/// cylinders cut across it at 45 degrees to the seam (each makes two holes, away from the seam).
TopoDS_Shape loft_with_holes() {
  // Closed, not periodic (ThruSections refuses periodic sections): 13 points, the last the first.
  auto section = [](double a, double b, double z) {
    constexpr int n = 12;
    Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, n + 1);
    Handle(TColStd_HArray1OfReal) parameters = new TColStd_HArray1OfReal(1, n + 1);
    for (int k = 0; k <= n; ++k) {
      const double t = 2 * M_PI * k / n;
      points->SetValue(k + 1, gp_Pnt(a * std::cos(t), b * std::sin(t), z));
      parameters->SetValue(k + 1, t);
    }
    points->SetValue(n + 1, points->Value(1));
    GeomAPI_Interpolate interpolate(points, parameters, false, 1e-9);
    interpolate.Perform();
    return BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(interpolate.Curve()).Edge()).Wire();
  };
  BRepOffsetAPI_ThruSections loft(true, true);
  loft.AddWire(section(20, 20, 0));
  loft.AddWire(section(30, 15, 30));
  loft.AddWire(section(12, 12, 60));
  loft.Build();
  TopoDS_Shape shape = loft.Shape();
  for (const auto& [z, direction] :
       {std::pair{15.0, gp_Dir(1, 1, 0)}, std::pair{45.0, gp_Dir(1, -1, 0)}}) {
    const gp_Pnt start = gp_Pnt(0, 0, z).Translated(-40 * gp_Vec(direction));
    shape = BRepAlgoAPI_Cut(shape,
                            BRepPrimAPI_MakeCylinder(gp_Ax2(start, direction), 4.0, 80.0).Shape())
                .Shape();
  }
  return shape;
}

TopoDS_Shape loose_box_faces() {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(30, 20, 10).Shape();
  TopoDS_Compound faces;
  BRep_Builder builder;
  builder.MakeCompound(faces);
  for (TopExp_Explorer e(box, TopAbs_FACE); e.More(); e.Next()) builder.Add(faces, e.Current());
  return faces;
}

/// Adds a named, coloured simple shape; names and colours the faces `faces` says.
TDF_Label add_part(const Handle(XCAFDoc_ShapeTool) & shapes,
                   const Handle(XCAFDoc_ColorTool) & colours, const TopoDS_Shape& shape,
                   const char* name, const Quantity_Color& colour) {
  const TDF_Label label = shapes->AddShape(shape, false);
  TDataStd_Name::Set(label, name);
  colours->SetColor(label, colour, XCAFDoc_ColorGen);
  return label;
}

void write_document(const Handle(TDocStd_Document) & document, const fs::path& file, bool faces) {
  if (is_iges(file)) {
    IGESControl_Controller::Init();
    Interface_Static::SetCVal("write.iges.unit", "MM");
    Interface_Static::SetIVal("write.iges.brep.mode", faces ? 0 : 1);
    IGESCAFControl_Writer writer;
    writer.SetColorMode(true);
    writer.SetNameMode(true);
    if (!writer.Transfer(document) || !writer.Write(file.string().c_str()))
      throw std::runtime_error("write_test_model: IGES writing failed");
    return;
  }
  STEPCAFControl_Controller::Init();
  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  Interface_Static::SetCVal("write.step.unit", "MM");
  Interface_Static::SetIVal("write.stepcaf.subshapes.name", 1);  // face names
  STEPCAFControl_Writer writer;
  writer.SetColorMode(true);
  writer.SetNameMode(true);
  if (!writer.Transfer(document, STEPControl_AsIs) ||
      writer.Write(file.string().c_str()) != IFSelect_RetDone)
    throw std::runtime_error("write_test_model: STEP writing failed");
}

}  // namespace

void write_test_model(TestModel model, const fs::path& file) {
  Handle(TDocStd_Document) document;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document);
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
  const Handle(XCAFDoc_ColorTool) colours = XCAFDoc_DocumentTool::ColorTool(document->Main());
  switch (model) {
    case TestModel::FilletedBlock: {
      const TopoDS_Shape shape = filleted_block();
      const TDF_Label label = add_part(shapes, colours, shape, "block", srgb(0.8, 0.5, 0.2));
      // The top face (the planar face highest in z) gets its own name and colour.
      TopoDS_Face top;
      double best = -1e300;
      for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) {
        GProp_GProps props;
        BRepGProp::SurfaceProperties(e.Current(), props);
        if (props.CentreOfMass().Z() > best) {
          best = props.CentreOfMass().Z();
          top = TopoDS::Face(e.Current());
        }
      }
      const TDF_Label face = shapes->AddSubShape(label, top);
      TDataStd_Name::Set(face, "top");
      colours->SetColor(face, srgb(0.1, 0.3, 0.9), XCAFDoc_ColorSurf);
      break;
    }
    case TestModel::Sphere:
      add_part(shapes, colours, BRepPrimAPI_MakeSphere(10.0).Shape(), "sphere",
               srgb(0.2, 0.7, 0.3));
      break;
    case TestModel::Torus:
      add_part(shapes, colours, BRepPrimAPI_MakeTorus(20.0, 5.0).Shape(), "torus",
               srgb(0.9, 0.9, 0.1));
      break;
    case TestModel::Cone:
      add_part(shapes, colours, BRepPrimAPI_MakeCone(10.0, 4.0, 15.0).Shape(), "cone",
               srgb(0.5, 0.5, 0.5));
      break;
    case TestModel::Bottle:
      add_part(shapes, colours, bottle(), "bottle", srgb(0.3, 0.6, 0.9));
      break;
    case TestModel::LabelBottle: {
      const TopoDS_Shape shape = label_bottle();
      const TDF_Label label = add_part(shapes, colours, shape, "bottle", srgb(0.3, 0.6, 0.9));
      // The band (the cylinder of radius 16) is the label: named and coloured.
      for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) {
        BRepAdaptor_Surface surface(TopoDS::Face(e.Current()));
        if (surface.GetType() != GeomAbs_Cylinder || surface.Cylinder().Radius() != 16) continue;
        const TDF_Label face = shapes->AddSubShape(label, e.Current());
        TDataStd_Name::Set(face, "label");
        colours->SetColor(face, srgb(0.95, 0.85, 0.2), XCAFDoc_ColorSurf);
      }
      break;
    }
    case TestModel::OffsetSheet: {
      // A bicubic bump over [0, 40] x [0, 30] (4 x 4 poles, the middle ones raised), offset by 2.
      TColgp_Array2OfPnt poles(1, 4, 1, 4);
      for (int i = 1; i <= 4; ++i)
        for (int j = 1; j <= 4; ++j)
          poles.SetValue(i, j,
                         gp_Pnt(40.0 * (i - 1) / 3, 30.0 * (j - 1) / 3,
                                (i == 2 || i == 3) && (j == 2 || j == 3) ? 8.0 : 0.0));
      TColStd_Array1OfReal knots(1, 2);
      knots.SetValue(1, 0);
      knots.SetValue(2, 1);
      TColStd_Array1OfInteger mults(1, 2);
      mults.SetValue(1, 4);
      mults.SetValue(2, 4);
      Handle(Geom_BSplineSurface) bump =
          new Geom_BSplineSurface(poles, knots, knots, mults, mults, 3, 3);
      Handle(Geom_OffsetSurface) offset = new Geom_OffsetSurface(bump, 2.0);
      add_part(shapes, colours, BRepBuilderAPI_MakeFace(offset, 0, 1, 0, 1, 1e-7).Face(),
               "offset sheet", srgb(0.6, 0.6, 0.8));
      break;
    }
    case TestModel::TurnedSeams: {
      constexpr double pi = 3.14159265358979323846;
      auto frame = [](double x, double y) {
        return gp_Ax3(gp_Pnt(x, y, 0), gp_Dir(0, 0, 1), gp_Dir(1, 0, 0));
      };
      auto face = [&](const Handle(Geom_Surface) & s, double u0, double v0, double v1,
                      const char* name) {
        add_part(shapes, colours, BRepBuilderAPI_MakeFace(s, u0, u0 + 2 * pi, v0, v1, 1e-7).Face(),
                 name, srgb(0.7, 0.7, 0.7));
      };
      face(new Geom_CylindricalSurface(frame(0, 0), 3.5), pi / 2, 0, 6, "cylinder");
      face(new Geom_ConicalSurface(frame(20, 0), 0.3, 4.0), 1.0, 0, 6, "cone");
      face(new Geom_SphericalSurface(frame(0, 20), 5.0), -pi / 2, -1.2, 1.2, "sphere");
      face(new Geom_ToroidalSurface(frame(20, 20), 10.0, 3.0), pi / 2, 0, 2 * pi, "torus");
      break;
    }
    case TestModel::Assembly: {
      const TDF_Label assembly = shapes->NewShape();
      TDataStd_Name::Set(assembly, "bracket assembly");
      const TDF_Label plate = shapes->AddShape(BRepPrimAPI_MakeBox(50, 30, 5).Shape(), false);
      TDataStd_Name::Set(plate, "plate");
      colours->SetColor(plate, srgb(0.8, 0.1, 0.1), XCAFDoc_ColorGen);
      const TDF_Label pin = shapes->AddShape(
          BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp::DZ()), 3.0, 12.0).Shape(), false);
      TDataStd_Name::Set(pin, "pin");
      colours->SetColor(pin, srgb(0.1, 0.1, 0.8), XCAFDoc_ColorGen);
      shapes->AddComponent(assembly, plate, TopLoc_Location());
      for (double x : {10.0, 40.0}) {
        gp_Trsf move;
        move.SetTranslation(gp_Vec(x, 15, 5));
        shapes->AddComponent(assembly, pin, TopLoc_Location(move));
      }
      shapes->UpdateAssemblies();
      break;
    }
    case TestModel::Separated: {
      TopoDS_Compound both;
      BRep_Builder builder;
      builder.MakeCompound(both);
      builder.Add(both, BRepPrimAPI_MakeBox(20, 20, 20).Shape());
      builder.Add(both, BRepPrimAPI_MakeSphere(gp_Pnt(50, 10, 10), 5.0).Shape());
      add_part(shapes, colours, both, "pair", srgb(0.4, 0.4, 0.4));
      break;
    }
    case TestModel::HolePlate: {
      TopoDS_Shape plate = BRepPrimAPI_MakeBox(200, 200, 10).Shape();
      BRepFilletAPI_MakeFillet fillet(plate);
      for (TopExp_Explorer e(plate, TopAbs_EDGE); e.More(); e.Next()) {
        TopoDS_Vertex a, b;
        TopExp::Vertices(TopoDS::Edge(e.Current()), a, b);
        const gp_Pnt pa = BRep_Tool::Pnt(a), pb = BRep_Tool::Pnt(b);
        if (std::abs(pa.X() - pb.X()) < 1e-9 && std::abs(pa.Y() - pb.Y()) < 1e-9)
          fillet.Add(8.0, TopoDS::Edge(e.Current()));
      }
      TopoDS_Compound holes;
      BRep_Builder builder;
      builder.MakeCompound(holes);
      for (int i = 0; i < 19; ++i)
        for (int j = 0; j < 10; ++j)
          builder.Add(holes, BRepPrimAPI_MakeCylinder(
                                 gp_Ax2(gp_Pnt(10 + 10 * i, 19 + 18 * j, -1), gp::DZ()), 3.0, 12.0)
                                 .Shape());
      add_part(shapes, colours, BRepAlgoAPI_Cut(fillet.Shape(), holes).Shape(), "plate",
               srgb(0.7, 0.7, 0.75));
      break;
    }
    case TestModel::ObliqueCut: {
      const TopoDS_Shape cylinder =
          BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp::DZ()), 10.0, 40.0).Shape();
      // A box above the plane z = 25 + x tan(30 deg), turned about the y axis.
      gp_Trsf turn;
      turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 25), gp::DY()), -std::atan(1.0) * 4 / 6);
      const TopoDS_Shape cutter = BRepPrimAPI_MakeBox(gp_Pnt(-50, -50, 25), 100, 100, 50)
                                      .Shape()
                                      .Moved(TopLoc_Location(turn));
      add_part(shapes, colours, BRepAlgoAPI_Cut(cylinder, cutter).Shape(), "cut cylinder",
               srgb(0.6, 0.3, 0.3));
      break;
    }
    case TestModel::LooseFaces:
      add_part(shapes, colours, loose_box_faces(), "faces", srgb(0.6, 0.6, 0.6));
      break;
    case TestModel::LoftWithHoles:
      add_part(shapes, colours, loft_with_holes(), "loft", srgb(0.4, 0.7, 0.7));
      break;
  }
  write_document(document, file, model == TestModel::LooseFaces);
  XCAFApp_Application::GetApplication()->Close(document);
}

namespace {

TopoDS_Shape read_shape(const fs::path& file) {
  if (is_iges(file)) {
    IGESControl_Controller::Init();
    // As our reader: no C0 knot removal, which splits an edge at a C0 knot (ANSA's faces read
    // as 15 edges with it, 14 without). The setting is process-wide, so it is set each time:
    // the answer must not depend on which reader ran first in this process.
    Interface_Static::SetIVal("read.iges.bspline.continuity", 0);
    IGESControl_Reader reader;
    if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
      throw std::runtime_error("facts_of_file: cannot read " + file.string());
    reader.TransferRoots();
    return reader.OneShape();
  }
  STEPControl_Reader reader;
  if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
    throw std::runtime_error("facts_of_file: cannot read " + file.string());
  reader.TransferRoots();
  return reader.OneShape();
}

int count(const TopoDS_Shape& shape, TopAbs_ShapeEnum type) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(shape, type, map);
  return map.Extent();
}

}  // namespace

ShapeFacts facts_of_file(const fs::path& file) {
  const TopoDS_Shape shape = read_shape(file);
  ShapeFacts facts;
  facts.solids = count(shape, TopAbs_SOLID);
  facts.shells = count(shape, TopAbs_SHELL);
  facts.faces = count(shape, TopAbs_FACE);
  facts.edges = count(shape, TopAbs_EDGE);
  facts.vertices = count(shape, TopAbs_VERTEX);
  for (TopExp_Explorer e(shape, TopAbs_SOLID); e.More(); e.Next()) {
    GProp_GProps props;
    BRepGProp::VolumeProperties(e.Current(), props, 1e-9);
    facts.volume += props.Mass();
  }
  facts.valid = BRepCheck_Analyzer(shape).IsValid();
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  for (int i = 1; i <= faces.Extent(); ++i) {
    GProp_GProps props;
    BRepGProp::SurfaceProperties(faces(i), props, 1e-10);
    facts.area += props.Mass();
  }
  for (int i = 1; i <= faces.Extent(); ++i) {
    switch (BRepAdaptor_Surface(TopoDS::Face(faces(i)), false).GetType()) {
      case GeomAbs_Plane:
        ++facts.planes;
        break;
      case GeomAbs_Cylinder:
        ++facts.cylinders;
        break;
      case GeomAbs_Cone:
        ++facts.cones;
        break;
      case GeomAbs_Sphere:
        ++facts.spheres;
        break;
      case GeomAbs_Torus:
        ++facts.tori;
        break;
      default:
        ++facts.other_surfaces;
    }
  }
  return facts;
}

double max_distance_to_surfaces(const fs::path& file,
                                const std::vector<std::vector<Eigen::Vector3d>>& points) {
  const TopoDS_Shape shape = read_shape(file);
  double worst = 0;
  std::size_t k = 0;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More() && k < points.size(); e.Next(), ++k) {
    const Handle(Geom_Surface) surface = BRep_Tool::Surface(TopoDS::Face(e.Current()));
    for (const Eigen::Vector3d& p : points[k]) {
      GeomAPI_ProjectPointOnSurf projection(gp_Pnt(p.x(), p.y(), p.z()), surface);
      worst = std::max(worst, projection.NbPoints() > 0 ? projection.LowerDistance()
                                                        : std::numeric_limits<double>::infinity());
    }
  }
  if (k != points.size()) return std::numeric_limits<double>::infinity();
  return worst;
}

std::vector<std::vector<Eigen::Vector3d>> edge_points(
    const fs::path& file, const std::vector<std::vector<double>>& parameters) {
  const TopoDS_Shape shape = read_shape(file);
  TopTools_IndexedMapOfShape edges;
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  std::vector<std::vector<Eigen::Vector3d>> out;
  for (int i = 1; i <= edges.Extent() && out.size() < parameters.size(); ++i) {
    const BRepAdaptor_Curve curve(TopoDS::Edge(edges(i)));
    std::vector<Eigen::Vector3d> points;
    for (double t : parameters[out.size()]) {
      const gp_Pnt p = curve.Value(t);
      points.emplace_back(p.X(), p.Y(), p.Z());
    }
    out.push_back(std::move(points));
  }
  return out;
}

struct GTransformReference::Impl {
  TopoDS_Shape shape;
};

GTransformReference::GTransformReference(const fs::path& file) : impl_(std::make_unique<Impl>()) {
  impl_->shape = read_shape(file);
}

GTransformReference::~GTransformReference() = default;

int GTransformReference::transform(const Eigen::Matrix<double, 3, 4>& a) const {
  gp_GTrsf map;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) map.SetValue(i + 1, j + 1, a(i, j));
  BRepBuilderAPI_GTransform transform(impl_->shape, map, true);
  return count(transform.Shape(), TopAbs_FACE);
}

}  // namespace clay::surface::occt_reference
