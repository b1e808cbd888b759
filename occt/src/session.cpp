// The shared exchange helpers of session.hpp.
#include "session.hpp"

#include <clay/error.hpp>
#include <clay/internal/files.hpp>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include <BRepCheck.hxx>
#include <BRepCheck_ListOfStatus.hxx>
#include <BRepCheck_Result.hxx>
#include <Interface_Static.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <XCAFApp_Application.hxx>

namespace clay::surface::occt {

namespace fs = std::filesystem;

std::mutex& exchange_mutex() {
  static std::mutex mutex;
  return mutex;
}

XcafDocument::XcafDocument() {
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document_);
}

XcafDocument::~XcafDocument() {
  try {
    XCAFApp_Application::GetApplication()->Close(document_);
  } catch (const Standard_Failure&) {
    // nothing to do in a destructor: the document was not open
  }
}

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

bool extension_is(const fs::path& file, std::initializer_list<const char*> list) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  for (const char* e : list)
    if (ext == e) return true;
  return false;
}

/// Checks that the folder of `file` exists and `file` names a file in it.
void check_target(const fs::path& file, std::string_view caller) {
  if (file.empty() || !file.has_filename())
    throw Error(ErrorCategory::Io, std::string(caller) + ": " + quoted(file) +
                                       " does not name a file; give a file path");
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw Error(ErrorCategory::Io, std::string(caller) + ": the output folder " + quoted(folder) +
                                       " of " + quoted(file) +
                                       " does not exist; create it before writing");
}

/// Writes through `write(temp_path)` with internal::write_atomically_via (a temporary made by
/// mkstemp beside `file`, flushed, renamed over it; removed on any failure), after check_target.
/// The helper's own errors are prefixed with `caller`, as the writers' are.
void write_atomically(const fs::path& file, std::string_view caller,
                      const std::function<void(const fs::path&)>& write) {
  check_target(file, caller);
  const std::string prefix = std::string(caller) + ": ";
  try {
    internal::write_atomically_via(file, "file", write);
  } catch (const Error& e) {
    if (e.message().rfind(prefix, 0) == 0) throw;
    throw Error(e.category(), prefix + e.message());
  }
}

/// Opens `temp` for writing, lets `print` fill it and checks the stream.
void write_stream(const fs::path& temp, std::string_view caller,
                  const std::function<bool(std::ostream&)>& print) {
  std::ofstream out(temp, std::ios::binary | std::ios::trunc);
  if (!out)
    throw Error(ErrorCategory::Io, std::string(caller) + ": could not create " + quoted(temp) +
                                       "; check that the folder is writable");
  const bool printed = print(out);
  out.flush();
  if (!printed)
    throw Error(ErrorCategory::Exchange,
                std::string(caller) + ": OpenCASCADE could not serialize the model");
  out.close();
  if (!out)
    throw Error(ErrorCategory::Io, std::string(caller) + ": writing " + quoted(temp) +
                                       " failed (disk full or folder not writable?)");
}

void check_readable(const fs::path& file, std::string_view caller) {
  std::error_code ec;
  if (!fs::exists(file, ec))
    throw Error(ErrorCategory::Io,
                std::string(caller) + ": " + quoted(file) + " does not exist; check the path");
  if (!fs::is_regular_file(file, ec))
    throw Error(ErrorCategory::Io,
                std::string(caller) + ": " + quoted(file) + " is not a regular file");
  std::ifstream probe(file, std::ios::binary);
  if (!probe)
    throw Error(ErrorCategory::Io, std::string(caller) + ": " + quoted(file) +
                                       " cannot be opened; check its permissions");
}

namespace {
// The KeptSettings of the exchange call in progress (one at a time: the exchange lock).
KeptSettings* kept_settings = nullptr;
}  // namespace

KeptSettings::KeptSettings() : outer_(kept_settings) { kept_settings = this; }

KeptSettings::~KeptSettings() {
  for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) {
    if (it->integer)
      Interface_Static::SetIVal(it->name.c_str(), it->ival);
    else
      Interface_Static::SetCVal(it->name.c_str(), it->cval.c_str());
  }
  kept_settings = outer_;
}

void KeptSettings::remember(const char* name, bool integer) {
  if (!Interface_Static::IsPresent(name)) return;  // set_static refuses it
  for (const Saved& s : saved_)
    if (s.name == name) return;
  Saved s;
  s.name = name;
  s.integer = integer;
  if (integer)
    s.ival = Interface_Static::IVal(name);
  else if (const char* text = Interface_Static::CVal(name))
    s.cval = text;
  saved_.push_back(std::move(s));
}

void set_static(const char* name, const char* value) {
  if (kept_settings) kept_settings->remember(name, false);
  if (!Interface_Static::SetCVal(name, value))
    throw Error(ErrorCategory::Internal,
                std::string("OpenCASCADE setting '") + name + "' does not accept '" + value + "'");
}

void set_static(const char* name, int value) {
  if (kept_settings) kept_settings->remember(name, true);
  if (!Interface_Static::SetIVal(name, value))
    throw Error(ErrorCategory::Internal, std::string("OpenCASCADE setting '") + name +
                                             "' does not accept " + std::to_string(value));
}

std::vector<std::string> check_statuses(const TopoDS_Face& face,
                                        const BRepCheck_Analyzer& analyzer) {
  std::vector<std::string> found;
  auto add = [&](const char* kind, int index, BRepCheck_Status status) {
    if (status == BRepCheck_NoError) return;
    std::ostringstream text;
    BRepCheck::Print(status, text);
    std::string line =
        std::string(kind) + (index >= 0 ? " " + std::to_string(index) : "") + ": " + text.str();
    while (!line.empty() && (line.back() == '\n' || line.back() == ' ')) line.pop_back();
    for (const auto& f : found)
      if (f == line) return;
    found.push_back(line);
  };
  auto scan = [&](const TopoDS_Shape& shape, const char* kind, int index) {
    // Result() throws Standard_NoSuchObject for a shape the analyzer did not reach (an edge of a
    // face it stopped at); such a shape has no status to report.
    Handle(BRepCheck_Result) result;
    try {
      result = analyzer.Result(shape);
    } catch (const Standard_NoSuchObject&) {
      return;
    }
    if (result.IsNull()) return;
    for (BRepCheck_ListIteratorOfListOfStatus it(result->Status()); it.More(); it.Next())
      add(kind, index, it.Value());
    for (result->InitContextIterator(); result->MoreShapeInContext(); result->NextShapeInContext())
      for (BRepCheck_ListIteratorOfListOfStatus it(result->StatusOnShape()); it.More(); it.Next())
        add(kind, index, it.Value());
  };
  scan(face, "face", -1);
  int index = 0;
  for (TopExp_Explorer e(face, TopAbs_WIRE); e.More(); e.Next()) scan(e.Current(), "wire", index++);
  index = 0;
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) scan(e.Current(), "edge", index++);
  index = 0;
  for (TopExp_Explorer e(face, TopAbs_VERTEX); e.More(); e.Next())
    scan(e.Current(), "vertex", index++);
  return found;
}

}  // namespace clay::surface::occt
