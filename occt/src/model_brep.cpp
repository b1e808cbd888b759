// Models to and from OpenCASCADE's BRep text (clay/occt/model_exchange.hpp): the lossless path
// between an embedding CAD system's shapes (FreeCAD's Part.Shape) and Clayform's models. The
// text holds the shapes exactly; names and colours travel beside it as BrepAttributes. Here:
// the .brep file into an XCAF document for read_model (read_brep_file, its face tags), read_brep
// and write_brep.
#include <clay/brep/model.hpp>
#include <clay/error.hpp>
#include <clay/internal/format.hpp>
#include <clay/occt/model_exchange.hpp>

#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

#include "convert.hpp"
#include "model_shapes.hpp"
#include "model_transfer.hpp"
#include "session.hpp"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Quantity_Color.hxx>
#include <TCollection_ExtendedString.hxx>
#include <TDF_Label.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Trsf.hxx>

namespace clay::brep {

namespace fs = std::filesystem;

namespace detail {

using surface::occt::quoted;

/// The prefix read_brep_file gives face k's name: "\x1f" k "\x1f", a control character no name
/// read from a file holds; untag_brep_faces takes it off.
std::string brep_face_tag(int k) { return "\x1f" + std::to_string(k) + "\x1f"; }

/// Takes the tags off the faces' names, recording each face's place in the text in
/// report.brep_faces. Throws clay::Error(Internal) for a face that lost its tag.
void untag_brep_faces(ImportedModel& imported) {
  imported.report.brep_faces.assign(imported.model.faces.size(), -1);
  for (std::size_t j = 0; j < imported.model.faces.size(); ++j) {
    std::string& name = imported.model.faces[j].name;
    const std::size_t end =
        name.size() > 1 && name[0] == '\x1f' ? name.find('\x1f', 1) : std::string::npos;
    if (end == std::string::npos)
      throw Error(ErrorCategory::Internal,
                  "read_model: face " + std::to_string(j) + " of the BRep text lost its place");
    imported.report.brep_faces[j] = std::stoi(name.substr(1, end - 1));
    name.erase(0, end + 1);
  }
}

/// Reads OpenCASCADE's BRep `file` into `document` as one free shape, with `attributes`' names
/// and colours on it and on its faces (TopExp::MapShapes order). Throws clay::Error(Exchange) when
/// the file is not BRep or holds no shape, InvalidArgument when a face list does not match.
bool read_brep_file(const fs::path& file, const BrepAttributes& attributes,
                    const Handle(TDocStd_Document) & document) {
  TopoDS_Shape shape;
  BRep_Builder builder;
  if (!BRepTools::Read(shape, file.string().c_str(), builder) || shape.IsNull())
    throw Error(ErrorCategory::Exchange,
                "read_model: " + quoted(file) +
                    " could not be parsed as an OpenCASCADE BRep file (BRepTools::Write's text)");
  // XCAF gives a located top shape's faces no sub-shape labels (AddSubShape returns none:
  // FreeCAD writes every recomputed feature's shape with its Placement as a location). An
  // identity location is dropped; any other is kept one level down, in a compound.
  if (!shape.Location().IsIdentity()) {
    if (shape.Location().Transformation().Form() == gp_Identity) {
      shape.Location(TopLoc_Location());
    } else {
      TopoDS_Compound wrapper;
      builder.MakeCompound(wrapper);
      builder.Add(wrapper, shape);
      shape = wrapper;
    }
  }
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
  const Handle(XCAFDoc_ColorTool) colours = XCAFDoc_DocumentTool::ColorTool(document->Main());
  // Not "prepared" (XCAF would move a located shape's location into a new one): the faces below
  // are the text's own, numbered as TopExp::MapShapes numbers them.
  const TDF_Label label = shapes->AddShape(shape, false, false);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shapes->GetShape(label), TopAbs_FACE, faces);
  auto check_count = [&](std::size_t given, const char* field) {
    if (given != 0 && given != static_cast<std::size_t>(faces.Extent()))
      throw Error(ErrorCategory::InvalidArgument,
                  "read_model: brep." + std::string(field) + " has " + std::to_string(given) +
                      " entries but " + quoted(file) + " has " + std::to_string(faces.Extent()) +
                      " faces; give one per face (Shape.Faces order) or none");
  };
  check_count(attributes.face_colours.size(), "face_colours");
  check_count(attributes.face_names.size(), "face_names");
  // (Pointers rather than optionals copied: GCC 12 takes a copied empty optional's fields for
  // uninitialized.)
  auto put = [&](const TDF_Label& l, const std::string& name, const Colour* c) {
    // UTF-8 in, as name_of reads it back.
    if (!name.empty()) TDataStd_Name::Set(l, TCollection_ExtendedString(name.c_str(), true));
    if (c != nullptr)
      colours->SetColor(l, Quantity_Color(c->r, c->g, c->b, Quantity_TOC_sRGB), XCAFDoc_ColorSurf);
  };
  put(label, attributes.name, attributes.colour ? &*attributes.colour : nullptr);
  for (int i = 1; i <= faces.Extent(); ++i) {
    const auto k = static_cast<std::size_t>(i - 1);
    // Every face's name carries its place in the text (brep_face_tag), so that the model's faces,
    // numbered solids first and a face of two solids twice, are traced back to the text's.
    const std::string name = brep_face_tag(static_cast<int>(k)) +
                             (k < attributes.face_names.size() ? attributes.face_names[k] : "");
    const Colour* colour = k < attributes.face_colours.size() && attributes.face_colours[k]
                               ? &*attributes.face_colours[k]
                               : nullptr;
    const TDF_Label sub = shapes->AddSubShape(label, faces(i));
    if (sub.IsNull())
      throw Error(ErrorCategory::Exchange, "read_model: face " + std::to_string(k) + " of " +
                                               quoted(file) + " could not be given its attributes");
    put(sub, name, colour);
  }
  return true;
}

}  // namespace detail

ImportedModel read_brep(std::string_view text, const ModelReadOptions& options) {
  options.validate();
  // read_model reads files (an isolated read hands the child a path): the text goes to a file of
  // this process's own, created exclusively (mkstemps), removed whatever happens.
  std::error_code ec;
  const fs::path folder = fs::temp_directory_path(ec);
  if (ec)
    throw Error(ErrorCategory::Io, "read_brep: no temporary folder (" + ec.message() +
                                       "); set TMPDIR to a writable folder");
  std::string name = (folder / "clayform-brep-XXXXXX.brep").string();
  const int fd = ::mkstemps(name.data(), 5);
  if (fd < 0)
    throw Error(ErrorCategory::Io, "read_brep: could not create a temporary file in " +
                                       surface::occt::quoted(folder) +
                                       "; set TMPDIR to a writable folder");
  struct Removed {
    std::string file;
    ~Removed() { std::remove(file.c_str()); }
  } removed{name};
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    written += static_cast<std::size_t>(n);
  }
  const bool closed = ::close(fd) == 0;
  if (written != text.size() || !closed)
    throw Error(ErrorCategory::Io, "read_brep: could not write the BRep text to " +
                                       surface::occt::quoted(name) + " (" + std::strerror(errno) +
                                       "); set TMPDIR to a folder with room");
  try {
    return read_model(name, options);
  } catch (const Error& e) {
    // The temporary file is gone when the caller reads the message: name what it held.
    std::string message = e.message();
    const std::string quoted_name = surface::occt::quoted(name);
    for (std::size_t at = message.find(quoted_name); at != std::string::npos;
         at = message.find(quoted_name, at))
      message.replace(at, quoted_name.size(), "the BRep text");
    throw Error(e.category(), message);
  }
}

BrepText write_brep(const Model& model) {
  const Model flat = model.is_assembly() ? flattened(model) : Model();
  const Model& m = model.is_assembly() ? flat : model;
  const Shapes shapes = build_shapes(m);
  surface::occt::ExchangeSession session;
  return surface::occt::guarded(ErrorCategory::Exchange, "write_brep", [&] {
    TopoDS_Shape shape;
    if (shapes.bodies.size() == 1) {
      shape = shapes.bodies.front();
    } else {
      TopoDS_Compound compound;
      BRep_Builder builder;
      builder.MakeCompound(compound);
      for (const TopoDS_Shape& body : shapes.bodies) builder.Add(compound, body);
      shape = compound;
    }
    BrepText out;
    std::ostringstream stream;
    BRepTools::Write(shape, stream);
    if (!stream)
      throw Error(ErrorCategory::Exchange, "write_brep: OpenCASCADE could not write the shapes");
    out.text = std::move(stream).str();

    // Each face's body, for its colour.
    std::vector<int> body_of(m.faces.size(), -1);
    for (std::size_t b = 0; b < m.bodies.size(); ++b)
      for (const Shell& shell : m.bodies[b].shells)
        for (int f : shell.faces) body_of[static_cast<std::size_t>(f)] = static_cast<int>(b);
    TopTools_DataMapOfShapeInteger index;  // by IsSame: orientation does not matter
    for (std::size_t k = 0; k < shapes.faces.size(); ++k)
      index.Bind(shapes.faces[k], static_cast<int>(k));
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    bool any_colour = false, any_name = false;
    for (int i = 1; i <= faces.Extent(); ++i) {
      std::optional<Colour> colour;
      std::string name;
      if (!index.IsBound(faces(i)))
        throw Error(ErrorCategory::Internal, "write_brep: face " + std::to_string(i - 1) +
                                                 " of the written shape is none of the model's");
      {
        const auto k = static_cast<std::size_t>(index.Find(faces(i)));
        const Face& face = m.faces[k];
        colour = face.colour;
        if (!colour && body_of[k] >= 0)
          colour = m.bodies[static_cast<std::size_t>(body_of[k])].colour;
        name = face.name;
      }
      any_colour = any_colour || colour.has_value();
      any_name = any_name || !name.empty();
      out.attributes.face_colours.push_back(colour);
      out.attributes.face_names.push_back(name);
    }
    if (!any_colour) out.attributes.face_colours.clear();
    if (!any_name) out.attributes.face_names.clear();
    if (m.bodies.size() == 1) {
      out.attributes.name = m.bodies.front().name;
      out.attributes.colour = m.bodies.front().colour;
    }
    return out;
  });
}

}  // namespace clay::brep
