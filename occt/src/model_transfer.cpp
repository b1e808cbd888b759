// What OpenCASCADE's transfer left out or did not know, and its plain reader (model_transfer.hpp).
#include "model_transfer.hpp"

#include <clay/error.hpp>

#include "session.hpp"

#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_InterfaceModel.hxx>
#include <STEPControl_Controller.hxx>
#include <STEPControl_Reader.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TopoDS_Shape.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XSControl_TransferReader.hxx>

namespace clay::brep::detail {

namespace fs = std::filesystem;
using surface::occt::quoted;

void UnknownEntities::add(const std::string& type, const std::string& where) {
  for (auto& [t, seen] : types)
    if (t == type) {
      ++seen.first;
      return;
    }
  types.push_back({type, {1, where}});
}

std::vector<std::string> UnknownEntities::lines() const {
  std::vector<std::string> out;
  for (const auto& [t, seen] : types)
    out.push_back(t + " x " + std::to_string(seen.first) + " (the first " + seen.second + ")");
  return out;
}

std::vector<std::string> failed_entities(const Handle(XSControl_WorkSession) & session) {
  std::vector<std::string> out;
  if (session.IsNull() || session->TransferReader().IsNull()) return out;
  const Handle(Transfer_TransientProcess)& process = session->TransferReader()->TransientProcess();
  if (process.IsNull()) return out;
  const Handle(Interface_InterfaceModel) model = process->Model();
  const Interface_CheckIterator checks = process->CheckList(true);
  for (checks.Start(); checks.More(); checks.Next()) {
    const Handle(Interface_Check)& check = checks.Value();
    if (check.IsNull() || !check->HasFailed()) continue;
    std::string line = "an entity";
    if (check->HasEntity() && !model.IsNull() && model->Contains(check->Entity())) {
      const Handle(TCollection_HAsciiString) label = model->StringLabel(check->Entity());
      line = (label.IsNull() ? std::string("?") : std::string(label->ToCString())) + " " +
             model->TypeName(check->Entity(), false);
    }
    line += ": " + std::string(check->CFail(1));
    if (check->NbFails() > 1) line += " (and " + std::to_string(check->NbFails() - 1) + " more)";
    out.push_back(line);
  }
  return out;
}

bool read_plain(const fs::path& file, bool step, const Handle(TDocStd_Document) & document,
                std::vector<std::string>& failed, Handle(XSControl_WorkSession) & session) {
  TopoDS_Shape shape;
  if (step) {
    STEPControl_Controller::Init();
    surface::occt::set_static("xstep.cascade.unit", "MM");  // after Init (OCCT-NOTES)
    STEPControl_Reader reader;
    if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
      throw Error(ErrorCategory::Exchange,
                  "read_model: " + quoted(file) + " could not be parsed as a STEP file");
    reader.TransferRoots();
    shape = reader.OneShape();
    failed = failed_entities(reader.WS());
    session = reader.WS();
  } else {
    IGESControl_Controller::Init();
    surface::occt::set_static("xstep.cascade.unit", "MM");
    surface::occt::set_static("read.iges.bspline.continuity", 0);
    IGESControl_Reader reader;
    if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
      throw Error(ErrorCategory::Exchange,
                  "read_model: " + quoted(file) + " could not be parsed as an IGES file");
    reader.TransferRoots();
    shape = reader.OneShape();
    failed = failed_entities(reader.WS());
    session = reader.WS();
  }
  if (shape.IsNull()) return false;
  XCAFDoc_DocumentTool::ShapeTool(document->Main())->AddShape(shape, false);
  return true;
}

}  // namespace clay::brep::detail
