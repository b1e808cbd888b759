#pragma once
// What OpenCASCADE's transfer of a STEP or IGES file left out or did not know, for the report of
// read_model (model_read.cpp), its plain reader (no XCAF), which reads files its XCAF readers
// crash on, and its reader of BRep files (model_brep.cpp). Internal to the OCCT library.
#include <clay/occt/model_exchange.hpp>

#include <Standard_Handle.hxx>
#include <TDocStd_Document.hxx>
#include <XSControl_WorkSession.hxx>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace clay::brep::detail {

/// The entities of a file OpenCASCADE does not know, per type, for the report.
struct UnknownEntities {
  std::vector<std::pair<std::string, std::pair<int, std::string>>> types;  // count, first
  /// Counts one entity of `type`, the first one's place (`where`: "#99", "D17") kept.
  void add(const std::string& type, const std::string& where);
  /// One line per type: "FOO_BAR x 3 (the first #999)".
  std::vector<std::string> lines() const;
};

/// The entities whose transfer OpenCASCADE gave up on, one line each ("#73 CYLINDRICAL_SURFACE:
/// <its failure>"). OpenCASCADE catches an exception per entity (a Standard_ConstructionError on
/// a negative radius) and leaves the entity, and what is built on it, out of the shape: the rest
/// is read, and these lines say what is missing.
std::vector<std::string> failed_entities(const Handle(XSControl_WorkSession) & session);

/// The shapes of `file` by OpenCASCADE's plain reader (no XCAF: no names, colours or assembly),
/// as one free shape of `document`; whether the transfer gave a shape. The entities it could not
/// transfer go to `failed`, its work session (for naming entities) to `session`.
bool read_plain(const std::filesystem::path& file, bool step,
                const Handle(TDocStd_Document) & document, std::vector<std::string>& failed,
                Handle(XSControl_WorkSession) & session);

/// The prefix read_brep_file gives face k's name ("\x1f" k "\x1f": a control character no name
/// read from a file holds), so that the model's faces are traced back to the text's.
std::string brep_face_tag(int k);

/// Takes the tags off the faces' names, recording each face's place in the text in
/// report.brep_faces. Throws clay::Error(Internal) for a face that lost its tag.
void untag_brep_faces(ImportedModel& imported);

/// Reads OpenCASCADE's BRep `file` into `document` as one free shape, with `attributes`' names
/// and colours on it and on its faces (TopExp::MapShapes order), every face's name tagged
/// (brep_face_tag). Throws clay::Error(Exchange) when the file is not BRep or holds no shape,
/// InvalidArgument when a face list does not match (model_brep.cpp).
bool read_brep_file(const std::filesystem::path& file, const BrepAttributes& attributes,
                    const Handle(TDocStd_Document) & document);

}  // namespace clay::brep::detail
