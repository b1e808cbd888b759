// Models to and from OpenCASCADE's BRep text (clay/occt/model_exchange.hpp): the lossless path
// between an embedding CAD system's shapes (FreeCAD's Part.Shape) and Clayform's models. The
// text holds the shapes exactly; names and colours travel beside it as BrepAttributes.
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
#include "session.hpp"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <TopExp.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>

namespace clay::brep {

namespace fs = std::filesystem;

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
