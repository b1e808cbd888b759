#pragma once
// What every OpenCASCADE exchange call shares (internal to clay_occt): the lock around
// OpenCASCADE's translators, quiet messages, and the file checks and atomic writes of
// surface/exchange.cpp and brep model exchange.
#include <clay/error.hpp>
#include <clay/internal/fenv.hpp>
#include <clay/occt/surface_exchange.hpp>

#include <cstdint>
#include <cstring>

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <mutex>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <BRepCheck_Analyzer.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <TDocStd_Document.hxx>
#include <TopoDS_Face.hxx>

namespace clay::surface::occt {

/// OpenCASCADE 7.6's STEP/IGES translators (and their Interface_Static settings) are not
/// thread-safe: every exchange call holds this lock.
std::mutex& exchange_mutex();

/// While alive, OpenCASCADE's default messenger prints failures only (its translators otherwise
/// print transfer banners and statistics on standard output). Restores the levels on exit.
class QuietMessages {
 public:
  QuietMessages() {
    Message_SequenceOfPrinters& printers = Message::DefaultMessenger()->ChangePrinters();
    for (Message_SequenceOfPrinters::Iterator it(printers); it.More(); it.Next()) {
      saved_.push_back(it.Value()->GetTraceLevel());
      it.Value()->SetTraceLevel(Message_Fail);
    }
  }
  ~QuietMessages() {
    Message_SequenceOfPrinters& printers = Message::DefaultMessenger()->ChangePrinters();
    size_t k = 0;
    for (Message_SequenceOfPrinters::Iterator it(printers); it.More() && k < saved_.size();
         it.Next())
      it.Value()->SetTraceLevel(saved_[k++]);
  }
  QuietMessages(const QuietMessages&) = delete;
  QuietMessages& operator=(const QuietMessages&) = delete;

 private:
  std::vector<Message_Gravity> saved_;
};

/// While alive, every OpenCASCADE exchange setting (Interface_Static) changed through
/// set_static is put back as it was when it ends. OpenCASCADE's settings are the process's: a
/// host application in the same process (FreeCAD, a workbench) keeps its own. Our readers left
/// read.iges.bspline.continuity at 0, and FreeCAD's own IGES reading then kept curves whole that
/// it splits by default.
class KeptSettings {
 public:
  KeptSettings();
  ~KeptSettings();
  KeptSettings(const KeptSettings&) = delete;
  KeptSettings& operator=(const KeptSettings&) = delete;
  /// Records `name`'s value (an integer or a text setting) before its first change here.
  void remember(const char* name, bool integer);

 private:
  struct Saved {
    std::string name;
    bool integer = false;
    int ival = 0;
    std::string cval;
  };
  std::vector<Saved> saved_;
  KeptSettings* outer_ = nullptr;
};

/// The exchange lock, quiet messages, non-stop floating point and the settings put back, for one
/// public call.
struct ExchangeSession {
  std::lock_guard<std::mutex> lock{exchange_mutex()};
  QuietMessages quiet;
  internal::FpTrapsHeld floating_point;
  KeptSettings settings;
};

/// A new XCAF document, closed when this goes out of scope, also when an exception leaves it:
/// an open document stays registered with the XCAF application, its shapes and all (sanitized,
/// a leak; in a host application such as FreeCAD, memory kept for the process's life).
class XcafDocument {
 public:
  XcafDocument();
  ~XcafDocument();
  XcafDocument(const XcafDocument&) = delete;
  XcafDocument& operator=(const XcafDocument&) = delete;
  /// The document (OpenCASCADE's transfers take it by non-const reference).
  Handle(TDocStd_Document) & get() { return document_; }

 private:
  Handle(TDocStd_Document) document_;
};

/// 'path', for messages.
std::string quoted(const std::filesystem::path& path);

/// True when the file's extension, in lower case, is one of `list` (".step", ".igs", ...).
bool extension_is(const std::filesystem::path& file, std::initializer_list<const char*> list);

/// Checks that the folder of `file` exists and `file` names a file in it (clay::Error(Io)).
void check_target(const std::filesystem::path& file, std::string_view caller);

/// Writes through `write(temp_path)` with internal::write_atomically_via (a temporary made by
/// mkstemp next to `file`, flushed, renamed onto it) after check_target. On any failure the
/// temporary file is removed and the error rethrown, so nothing is left behind.
void write_atomically(const std::filesystem::path& file, std::string_view caller,
                      const std::function<void(const std::filesystem::path&)>& write);

/// Opens `temp` for writing, lets `print` fill it and checks the stream.
void write_stream(const std::filesystem::path& temp, std::string_view caller,
                  const std::function<bool(std::ostream&)>& print);

/// clay::Error(Io) when `file` is missing, not a regular file or cannot be opened.
void check_readable(const std::filesystem::path& file, std::string_view caller);

/// Interface_Static::SetCVal / SetIVal, throwing clay::Error(Internal) when refused.
void set_static(const char* name, const char* value);
void set_static(const char* name, int value);

/// Appends x's bytes (native layout: the isolated read's pipe joins two processes of one build).
template <class T>
void put(std::string& out, const T& x) {
  out.append(reinterpret_cast<const char*>(&x), sizeof x);
}
/// Appends a count and n doubles.
inline void put_doubles(std::string& out, const double* p, std::size_t n) {
  put(out, static_cast<std::uint64_t>(n));
  out.append(reinterpret_cast<const char*>(p), n * sizeof(double));
}

/// Reads back what put and put_doubles wrote; throws Internal when the bytes are short.
class Unpacker {
 public:
  explicit Unpacker(const std::string& bytes) : bytes_(bytes) {}
  template <class T>
  T take() {
    T x;
    need(sizeof x);
    std::memcpy(&x, bytes_.data() + at_, sizeof x);
    at_ += sizeof x;
    return x;
  }
  std::vector<double> doubles() {
    const auto n = take<std::uint64_t>();
    if (n > (bytes_.size() - at_) / sizeof(double)) need(bytes_.size() + 1);
    std::vector<double> out(static_cast<std::size_t>(n));
    std::memcpy(out.data(), bytes_.data() + at_, out.size() * sizeof(double));
    at_ += out.size() * sizeof(double);
    return out;
  }

 private:
  const std::string& bytes_;
  std::size_t at_ = 0;
  void need(std::size_t n) const {
    if (bytes_.size() - at_ < n)
      throw Error(ErrorCategory::Internal, "isolated read: the child's answer is truncated");
  }
};

/// What read_in_child throws when the child died of a signal (OpenCASCADE crashed): a
/// clay::Error(Exchange), typed so that a caller can try another way of reading the file.
class ChildCrashed : public Error {
 public:
  using Error::Error;
};

/// What an isolated read runs in the child: reads the file and returns its answer as bytes.
using Producer = std::function<std::string(const std::filesystem::path&)>;

/// Runs produce(file) in a forked child process under options' time and memory limits and
/// returns its bytes. A crash, hang or memory blow-up of the child becomes clay::Error(Exchange)
/// naming the file; a clay::Error the child raised is raised again here (ReadOptions::isolate).
std::string read_in_child(const std::filesystem::path& file, const ReadOptions& options,
                          std::string_view caller, const Producer& produce);

/// Every BRepCheck status found on `face` and its sub-shapes, in words ("edge 2:
/// BRepCheck_InvalidCurveOnSurface"), without repeats.
std::vector<std::string> check_statuses(const TopoDS_Face& face,
                                        const BRepCheck_Analyzer& analyzer);

}  // namespace clay::surface::occt
