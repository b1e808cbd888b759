#pragma once
// What every OpenCASCADE exchange call shares (internal to clay_occt): the lock around
// OpenCASCADE's translators, quiet messages, and the file checks and atomic writes of
// surface/exchange.cpp and brep model exchange.
#include <clay/internal/fenv.hpp>

#include <filesystem>
#include <functional>
#include <mutex>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <BRepCheck_Analyzer.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
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

/// The exchange lock, quiet messages and non-stop floating point, for one public call.
struct ExchangeSession {
  std::lock_guard<std::mutex> lock{exchange_mutex()};
  QuietMessages quiet;
  internal::FpTrapsHeld floating_point;
};

/// 'path', for messages.
std::string quoted(const std::filesystem::path& path);

/// Checks that the folder of `file` exists and `file` names a file in it (clay::Error(Io)).
void check_target(const std::filesystem::path& file, std::string_view caller);

/// Writes through `write(temp_path)` into a temporary file next to `file` (".NAME.tmp-<random>")
/// and renames it onto `file`. On any failure the temporary file is removed and the error
/// rethrown, so nothing is left behind.
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

/// Every BRepCheck status found on `face` and its sub-shapes, in words ("edge 2:
/// BRepCheck_InvalidCurveOnSurface"), without repeats.
std::vector<std::string> check_statuses(const TopoDS_Face& face,
                                        const BRepCheck_Analyzer& analyzer);

}  // namespace clay::surface::occt
