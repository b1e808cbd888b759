// STEP, IGES and glTF exchange through OpenCASCADE (see clay/occt/surface_exchange.hpp).
//
// Faces: BRepBuilderAPI_MakeFace(surface, 1e-7) with the natural bounds builds exactly the face we
// want: its four edges are the exact iso-curves Geom_BSplineSurface::UIso/VIso (poles copied, no
// approximation) with exact Geom2d_Line pcurves, tolerance 1e-7, a seam edge for a closed
// direction and degenerate edges at collapsed sides. Measured: the gap between each edge curve
// and the surface along its pcurve is 0 (both evaluated by de Boor) for random degree-25 surfaces.
//
// Losslessness: the writers' models are serialized by StepData_StepWriter / IGESData_IGESWriter
// with the float format "%.16E" (17 significant digits, enough to round-trip every double), and
// the IGES reader's C0 knot removal ("read.iges.bspline.continuity") is switched off.
#include <clay/occt/surface_exchange.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/fenv.hpp>
#include <clay/surface/tessellate.hpp>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <mutex>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include "convert.hpp"
#include "exchange_precheck.hpp"
#include "session.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <APIHeaderSection_MakeHeader.hxx>
#include <BRepAdaptor_Curve.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepCheck.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepCheck_ListOfStatus.hxx>
#include <BRepCheck_Result.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomConvert.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESControl_Writer.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESData_IGESWriter.hxx>
#include <IGESSelect_WorkLibrary.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <Message_ProgressRange.hxx>
#include <Poly_Triangle.hxx>
#include <Poly_Triangulation.hxx>
#include <Precision.hxx>
#include <RWGltf_CafWriter.hxx>
#include <STEPControl_Controller.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <StepBasic_Product.hxx>
#include <StepData_Protocol.hxx>
#include <StepData_StepModel.hxx>
#include <StepData_StepWriter.hxx>
#include <TColStd_IndexedDataMapOfStringString.hxx>
#include <TCollection_AsciiString.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shell.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

namespace clay::surface {
namespace {

namespace fs = std::filesystem;

/// Edge and vertex tolerance of every face we build (mm); never raised.
constexpr double face_tolerance = 1e-7;

using occt::check_readable;
using occt::check_statuses;
using occt::check_target;
using occt::ExchangeSession;
using occt::put;
using occt::put_doubles;
using occt::set_static;
using occt::Unpacker;
using occt::write_atomically;
using occt::write_stream;

using occt::quoted;

std::string surface_name(size_t k) { return "surface #" + std::to_string(k); }

// ---- faces ---------------------------------------------------------------------------------

struct BuiltFaces {
  TopoDS_Compound compound;  // the faces, in order
  std::vector<TopoDS_Face> faces;
  std::vector<Handle(Geom_BSplineSurface)> surfaces;
  ExchangeReport report;
};

/// Validates the list (empty -> InvalidArgument, invalid surface -> InvalidGeometry naming it,
/// degree above 25 -> DegreeLimit) and converts every surface.
std::vector<Handle(Geom_BSplineSurface)> convert_all(const std::vector<BSplineSurface>& surfaces,
                                                     std::string_view caller) {
  if (surfaces.empty())
    throw Error(ErrorCategory::InvalidArgument,
                std::string(caller) + ": the surface list is empty; give at least one surface");
  std::vector<Handle(Geom_BSplineSurface)> out;
  out.reserve(surfaces.size());
  for (size_t k = 0; k < surfaces.size(); ++k)
    out.push_back(occt::to_occt(surfaces[k], surface_name(k)));
  return out;
}

TopoDS_Face make_face(const Handle(Geom_BSplineSurface) & surface, const std::string& name) {
  try {
    // Natural bounds: edges are the exact iso-curves UIso/VIso with Geom2d_Line pcurves.
    BRepBuilderAPI_MakeFace maker(surface, face_tolerance);
    if (!maker.IsDone())
      throw Error(ErrorCategory::Exchange,
                  name + ": OpenCASCADE could not build a face on the surface (BRepLib_FaceError " +
                      std::to_string(static_cast<int>(maker.Error())) + ")");
    return maker.Face();
  } catch (const Standard_Failure& failure) {
    throw Error(ErrorCategory::Exchange,
                name + ": OpenCASCADE failed to build its face: " + occt::describe(failure));
  }
}

/// Largest gap between each edge's 3D curve and the surface along its pcurve, both evaluated
/// exactly (Geom_*::D0, de Boor), at 101 parameters per edge.
double exact_edge_gap(const TopoDS_Face& face, const Handle(Geom_BSplineSurface) & surface) {
  double gap = 0.0;
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    if (BRep_Tool::Degenerated(edge)) continue;
    double first = 0, last = 0, pfirst = 0, plast = 0;
    const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first, last);
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, pfirst, plast);
    if (curve.IsNull() || pcurve.IsNull()) continue;
    for (int i = 0; i <= 100; ++i) {
      const double t = first + (last - first) * i / 100.0;
      const gp_Pnt2d uv = pcurve->Value(t);
      gap = std::max(gap, curve->Value(t).Distance(surface->Value(uv.X(), uv.Y())));
    }
  }
  return gap;
}

/// Largest gap between OpenCASCADE's cached evaluation (GeomAdaptor_Surface, a power basis per
/// span, used by BRepCheck) and exact evaluation, on a grid of up to 8 steps per knot span and
/// about 64 parameters per direction (the error is largest near span ends, which are sampled).
double cached_evaluation_error(const Handle(Geom_BSplineSurface) & surface) {
  GeomAdaptor_Surface adaptor(surface);
  auto parameters = [](const TColStd_Array1OfReal& knots, int first, int last) {
    const int steps = std::clamp(64 / std::max(1, last - first), 1, 8);
    std::vector<double> out;
    for (int k = first; k < last; ++k)
      for (int s = 0; s < steps; ++s)
        out.push_back(knots(k) + (knots(k + 1) - knots(k)) * s / steps);
    out.push_back(knots(last));
    return out;
  };
  const auto us =
      parameters(surface->UKnots(), surface->FirstUKnotIndex(), surface->LastUKnotIndex());
  const auto vs =
      parameters(surface->VKnots(), surface->FirstVKnotIndex(), surface->LastVKnotIndex());
  double error = 0.0;
  for (double u : us)
    for (double v : vs) error = std::max(error, adaptor.Value(u, v).Distance(surface->Value(u, v)));
  return error;
}

std::string format_mm(double value) {
  std::ostringstream out;
  out.precision(2);
  out << std::scientific << value;
  return out.str();
}

/// Builds one face per surface, checks each with BRepCheck_Analyzer and fills the report.
BuiltFaces build_faces(const std::vector<BSplineSurface>& input, std::string_view caller) {
  BuiltFaces built;
  built.surfaces = convert_all(input, caller);
  BRep_Builder builder;
  builder.MakeCompound(built.compound);
  ExchangeReport& report = built.report;
  report.tolerance_mm = face_tolerance;
  report.valid = true;
  for (size_t k = 0; k < input.size(); ++k) {
    const std::string name = surface_name(k);
    const Handle(Geom_BSplineSurface)& surface = built.surfaces[k];
    TopoDS_Face face = make_face(surface, name);
    built.faces.push_back(face);
    builder.Add(built.compound, face);
    report.faces += 1;
    report.max_degree = std::max({report.max_degree, input[k].u.degree, input[k].v.degree});
    report.control_points += static_cast<long>(input[k].points.rows());
    try {
      BRepCheck_Analyzer analyzer(face);
      if (analyzer.IsValid()) continue;
      report.valid = false;
      std::string text = name + ": BRepCheck at " + format_mm(face_tolerance) + " mm finds ";
      const auto statuses = check_statuses(face, analyzer);
      for (size_t i = 0; i < statuses.size(); ++i) text += (i ? ", " : "") + statuses[i];
      const double edge_gap = exact_edge_gap(face, surface);
      const double cache_error = cached_evaluation_error(surface);
      report.evaluation_error = std::max(report.evaluation_error, cache_error);
      text += ". The edges are the exact iso-curves (gap " + format_mm(edge_gap) +
              " mm by exact evaluation)";
      if (cache_error > face_tolerance)
        text += ", but OpenCASCADE's cached power-basis evaluation of this degree (" +
                std::to_string(input[k].u.degree) + ", " + std::to_string(input[k].v.degree) +
                ") surface, which BRepCheck uses, is off by up to " + format_mm(cache_error) +
                " mm; the file is exact, but OpenCASCADE-based readers will see the face as out "
                "of tolerance. Shorter knot spans (knot insertion), a lower degree or a smoother "
                "control net bring that error down";
      report.problems.push_back(text);
    } catch (const Standard_Failure& failure) {
      report.valid = false;
      report.problems.push_back(name + ": BRepCheck_Analyzer failed: " + occt::describe(failure));
    }
  }
  return built;
}

// ---- reading ---------------------------------------------------------------------------------

/// The B-spline surface under a face read from a file: Geom_BSplineSurface as is, trimmed and
/// offset wrappers removed where they change nothing, other surfaces converted by GeomConvert
/// (restricted to the face's parameter box when they are infinite).
BSplineSurface surface_of_face(const TopoDS_Face& face, const std::string& name) {
  Handle(Geom_Surface) surface = BRep_Tool::Surface(face);  // the face's location applied
  if (surface.IsNull()) throw Error(ErrorCategory::Exchange, name + ": the face has no surface");
  bool trimmed = false;
  double tu0 = 0, tu1 = 0, tv0 = 0, tv1 = 0;
  for (;;) {
    if (auto trim = Handle(Geom_RectangularTrimmedSurface)::DownCast(surface); !trim.IsNull()) {
      if (!trimmed) trim->Bounds(tu0, tu1, tv0, tv1);
      trimmed = true;
      surface = trim->BasisSurface();
      continue;
    }
    if (auto offset = Handle(Geom_OffsetSurface)::DownCast(surface); !offset.IsNull()) {
      if (offset->Offset() == 0.0) {
        surface = offset->BasisSurface();
        continue;
      }
      if (Handle(Geom_Surface) equivalent = offset->Surface(); !equivalent.IsNull()) {
        surface = equivalent;  // an offset of an elementary surface is elementary
        continue;
      }
    }
    break;
  }
  Handle(Geom_BSplineSurface) bspline = Handle(Geom_BSplineSurface)::DownCast(surface);
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  surface->Bounds(u0, u1, v0, v1);
  const double eps = Precision::PConfusion();
  if (!bspline.IsNull()) {
    if (trimmed && !bspline->IsUPeriodic() && !bspline->IsVPeriodic() &&
        (tu0 > u0 + eps || tu1 < u1 - eps || tv0 > v0 + eps || tv1 < v1 - eps)) {
      bspline = Handle(Geom_BSplineSurface)::DownCast(bspline->Copy());
      bspline->Segment(std::max(tu0, u0), std::min(tu1, u1), std::max(tv0, v0), std::min(tv1, v1));
    }
    return occt::from_occt(bspline, name);
  }
  if (!trimmed && (Precision::IsInfinite(u0) || Precision::IsInfinite(u1) ||
                   Precision::IsInfinite(v0) || Precision::IsInfinite(v1))) {
    BRepTools::UVBounds(face, tu0, tu1, tv0, tv1);
    trimmed = true;
  }
  if (trimmed) surface = new Geom_RectangularTrimmedSurface(surface, tu0, tu1, tv0, tv1);
  bspline = GeomConvert::SurfaceToBSplineSurface(surface);
  return occt::from_occt(bspline, name);
}

std::vector<BSplineSurface> surfaces_of_shape(const TopoDS_Shape& shape, const fs::path& file,
                                              std::string_view caller) {
  std::vector<BSplineSurface> out;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next())
    out.push_back(surface_of_face(TopoDS::Face(e.Current()),
                                  quoted(file) + " face #" + std::to_string(out.size())));
  if (out.empty())
    throw Error(ErrorCategory::Exchange, std::string(caller) + ": " + quoted(file) +
                                             " holds no face or surface that could be read");
  return out;
}

/// Runs `body`, turning OpenCASCADE exceptions into clay::Error(Exchange).
template <class Body>
auto guarded(std::string_view caller, Body&& body) -> decltype(body()) {
  return occt::guarded(ErrorCategory::Exchange, caller, std::forward<Body>(body));
}

/// read_step's work; the caller holds the exchange session.
std::vector<BSplineSurface> read_step_locked(const fs::path& file) {
  constexpr std::string_view caller = "read_step";
  return guarded(caller, [&] {
    STEPControl_Controller::Init();
    set_static("xstep.cascade.unit", "MM");
    STEPControl_Reader reader;
    if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
      throw Error(ErrorCategory::Exchange,
                  "read_step: " + quoted(file) + " could not be parsed as a STEP file");
    reader.TransferRoots();
    return surfaces_of_shape(reader.OneShape(), file, caller);
  });
}

/// read_iges's work; the caller holds the exchange session.
std::vector<BSplineSurface> read_iges_locked(const fs::path& file) {
  constexpr std::string_view caller = "read_iges";
  return guarded(caller, [&] {
    IGESControl_Controller::Init();
    set_static("xstep.cascade.unit", "MM");
    // Default 1 removes knots of multiplicity = degree where it can (changes the data).
    set_static("read.iges.bspline.continuity", 0);
    IGESControl_Reader reader;
    if (reader.ReadFile(file.string().c_str()) != IFSelect_RetDone)
      throw Error(ErrorCategory::Exchange,
                  "read_iges: " + quoted(file) + " could not be parsed as an IGES file");
    reader.TransferRoots();
    return surfaces_of_shape(reader.OneShape(), file, caller);
  });
}

// ---- reading in a child process -------------------------------------------------------------
// The child reads with OpenCASCADE under an address-space limit and writes what it read (or the
// clay::Error it raised) into a pipe as raw native-endian data, then _exits; the parent collects
// the bytes with a deadline, and the child's exit status says which of the two it was, or how it
// died. Same machine, same build: no portable format is needed.

enum ChildStatus : int {
  child_read = 0,
  child_error = 2,
  child_out_of_memory = 3,
  child_unknown = 4
};

std::string serialize(const std::vector<BSplineSurface>& surfaces) {
  std::string out;
  put(out, static_cast<std::uint64_t>(surfaces.size()));
  for (const BSplineSurface& s : surfaces) {
    put(out, static_cast<std::int32_t>(s.u.degree));
    put(out, static_cast<std::int32_t>(s.v.degree));
    put_doubles(out, s.u.knots.data(), s.u.knots.size());
    put_doubles(out, s.v.knots.data(), s.v.knots.size());
    put_doubles(out, s.points.data(),
                static_cast<std::size_t>(s.points.size()));  // row-major x y z
    put_doubles(out, s.weights.data(), static_cast<std::size_t>(s.weights.size()));
  }
  return out;
}

std::vector<BSplineSurface> deserialize(const std::string& bytes) {
  Unpacker in(bytes);
  std::vector<BSplineSurface> out(static_cast<std::size_t>(in.take<std::uint64_t>() & 0xffffffffu));
  for (BSplineSurface& s : out) {
    s.u.degree = in.take<std::int32_t>();
    s.v.degree = in.take<std::int32_t>();
    s.u.knots = in.doubles();
    s.v.knots = in.doubles();
    const std::vector<double> points = in.doubles(), weights = in.doubles();
    s.points =
        Eigen::Map<const Points3>(points.data(), static_cast<Eigen::Index>(points.size() / 3), 3);
    s.weights = Eigen::Map<const Eigen::VectorXd>(weights.data(),
                                                  static_cast<Eigen::Index>(weights.size()));
  }
  return out;
}

void write_all(int fd, const std::string& bytes) {
  for (std::size_t at = 0; at < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + at, bytes.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the parent stopped listening: it reports why
    at += static_cast<std::size_t>(n);
  }
}

/// Bytes of address space the process maps now (/proc/self/statm), 0 when unknown.
unsigned long long mapped_bytes() {
  std::ifstream statm("/proc/self/statm");
  unsigned long long pages = 0;
  statm >> pages;
  return pages * static_cast<unsigned long long>(::sysconf(_SC_PAGESIZE));
}

/// The most this process has had mapped (VmPeak of /proc/self/status), in bytes; 0 if unknown.
unsigned long long peak_mapped_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  unsigned long long kb = 0;
  while (status >> key)
    if (key == "VmPeak:") {
      status >> kb;
      return kb * 1024;
    }
  return 0;
}

/// In the child: read, answer, exit. Never returns, and nothing escapes it (noexcept: whatever
/// might would otherwise unwind into the caller's copy of its own stack and run on as a second
/// process); never runs the parent's atexit handlers or flushes its stdio buffers (_exit).
[[noreturn]] void answer_in_child(int fd, const fs::path& file, const ReadOptions& options,
                                  const occt::Producer& produce) noexcept {
  int status = child_unknown;
  try {
    // Die of a crash, so the parent sees the signal: the caller's handlers (a test framework's,
    // a crash reporter's) must not run in the child.
    struct sigaction by_default {};
    by_default.sa_handler = SIG_DFL;
    for (int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL})
      ::sigaction(sig, &by_default, nullptr);
    // The limit counts what is mapped already (shared libraries, the parent's heap).
    rlimit limit{};
    ::getrlimit(RLIMIT_AS, &limit);
    const unsigned long long allowance =
        static_cast<unsigned long long>(options.memory_limit_mb) * 1024 * 1024;
    const unsigned long long start = mapped_bytes();
    const rlim_t wanted = static_cast<rlim_t>(start + allowance);
    if (limit.rlim_max == RLIM_INFINITY || wanted < limit.rlim_max) limit.rlim_cur = wanted;
    ::setrlimit(RLIMIT_AS, &limit);
    std::string payload;
    try {
      payload = produce(file);
      status = child_read;
    } catch (const Error& e) {
      // OpenCASCADE's parsers catch a failed allocation and report the file as unreadable: a
      // failure after using more than half the allowance is the memory limit's doing.
      const unsigned long long peak = peak_mapped_bytes();
      if (e.message().find("Standard_OutOfMemory") != std::string::npos ||
          (peak > start && peak - start > allowance / 2)) {
        status = child_out_of_memory;
      } else {
        put(payload, static_cast<std::int32_t>(e.category()));
        payload += e.message();
        status = child_error;
      }
    }
    write_all(fd, payload);
  } catch (const std::bad_alloc&) {
    status = child_out_of_memory;
  } catch (...) {
    status = child_unknown;
  }
  ::_exit(status);
}

std::string signal_name(int sig) {
  switch (sig) {
    case SIGSEGV:
      return "SIGSEGV";
    case SIGBUS:
      return "SIGBUS";
    case SIGABRT:
      return "SIGABRT";
    case SIGFPE:
      return "SIGFPE";
    case SIGILL:
      return "SIGILL";
    case SIGKILL:
      return "SIGKILL";
    default:
      return "signal " + std::to_string(sig);
  }
}

/// `read(file)` in a forked child process with options' time and memory limits. The caller holds
/// the exchange session across the fork, so no other thread of this process is inside
/// OpenCASCADE while the child's copy of it starts; the child calls `read` without locking.
}  // namespace

std::string occt::read_in_child(const fs::path& file, const ReadOptions& options,
                                std::string_view caller, const Producer& produce) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw Error(ErrorCategory::Io,
                std::string(caller) + ": cannot create a pipe: " + std::strerror(errno));
  // The child would otherwise write out a copy of whatever the caller has buffered.
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(ErrorCategory::Io, std::string(caller) + ": cannot start a process to read " +
                                       quoted(file) + ": " + std::strerror(e));
  }
  if (pid == 0) {
    ::close(fds[0]);
    answer_in_child(fds[1], file, options, produce);
  }
  ::close(fds[1]);
  // Whatever happens on this side (a throw included), the pipe is closed and the child reaped:
  // killed first unless it was reaped already.
  struct Child {
    pid_t pid;
    int fd;
    bool reaped = false;
    ~Child() {
      if (fd >= 0) ::close(fd);
      if (!reaped) {
        ::kill(pid, SIGKILL);
        while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
        }
      }
    }
  } child{pid, fds[0]};
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(options.time_limit_seconds);
  auto left_ms =
      [&] {  // poll's timeout is an int: wait at most ~16 minutes at a time, then look again
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        return static_cast<int>(std::clamp<long long>(left.count(), 0, 1000000));
      };
  auto past_deadline = [&] { return std::chrono::steady_clock::now() >= deadline; };
  std::string bytes;
  bool timed_out = false;
  for (char buffer[65536];;) {
    pollfd p{child.fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, left_ms());
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) {
      if (!past_deadline()) continue;
      timed_out = true;
      break;
    }
    const ssize_t n = ::read(child.fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of file: the child is exiting
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(child.fd);
  child.fd = -1;
  int status = 0;
  if (!timed_out) {
    // The pipe closed; the child exits at once unless a descendant holds it, so wait within the
    // deadline too.
    for (;;) {
      const pid_t got = ::waitpid(pid, &status, WNOHANG);
      if (got == pid) {
        child.reaped = true;
        break;
      }
      if (got < 0 && errno == EINTR) continue;
      if (got < 0)  // ECHILD: reaped elsewhere (SIGCHLD ignored, or a waitpid(-1) in the host)
        throw Error(ErrorCategory::Exchange,
                    std::string(caller) + ": the process reading " + quoted(file) +
                        " ended, but its exit status is lost to this process (is SIGCHLD ignored, "
                        "or are children "
                        "reaped elsewhere?); read the file without isolation to see its outcome");
      if (past_deadline()) {
        timed_out = true;
        break;
      }
      ::usleep(1000);
    }
  }
  if (timed_out) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", options.time_limit_seconds);
    throw Error(ErrorCategory::Exchange,
                std::string(caller) + ": reading " + quoted(file) + " took longer than " + limit +
                    " s, the time limit, so it was stopped; the file is malformed in a way the "
                    "pre-check does not catch, or too large to read within the limit");
  }
  const std::string memory = std::to_string(options.memory_limit_mb) + " MB";
  if (WIFSIGNALED(status))
    throw ChildCrashed(ErrorCategory::Exchange,
                       std::string(caller) + ": OpenCASCADE crashed (" +
                           signal_name(WTERMSIG(status)) + ") while reading " + quoted(file) +
                           "; the file is malformed (or it needed more than " + memory +
                           "): export it again or repair it");
  switch (WIFEXITED(status) ? WEXITSTATUS(status) : child_unknown) {
    case child_read:
      return bytes;
    case child_error: {
      Unpacker in(bytes);
      const auto category = static_cast<ErrorCategory>(in.take<std::int32_t>());
      throw Error(category, bytes.substr(sizeof(std::int32_t)));
    }
    case child_out_of_memory:
      throw Error(ErrorCategory::Exchange, std::string(caller) + ": reading " + quoted(file) +
                                               " needed more than " + memory +
                                               ", the memory limit, so it was stopped");
    default:
      throw Error(ErrorCategory::Exchange,
                  std::string(caller) + ": the process reading " + quoted(file) +
                      " failed without an answer (exit status " +
                      std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  }
}

namespace {

using Reader = std::vector<BSplineSurface> (*)(const fs::path&);

/// The checks and the read every public read goes through.
std::vector<BSplineSurface> read_guarded(const fs::path& file, const ReadOptions& options,
                                         std::string_view caller,
                                         void (*precheck)(const fs::path&, std::string_view, int),
                                         Reader read) {
  options.validate();
  check_readable(file, caller);
  if (options.precheck) precheck(file, caller, max_exchange_degree);
  ExchangeSession session;
  std::vector<BSplineSurface> surfaces =
      options.isolate
          ? deserialize(occt::read_in_child(
                file, options, caller, [read](const fs::path& f) { return serialize(read(f)); }))
          : read(file);
  // What came through the pipe is checked again here: a surface the child's OpenCASCADE accepted
  // must still be one this kernel can use.
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    if (const auto list =
            surface::problems(surfaces[k], quoted(file) + " face #" + std::to_string(k));
        !list.empty())
      throw Error(ErrorCategory::Exchange, std::string(caller) + ": " + list.front());
  return surfaces;
}

}  // namespace

// ---- public API ----------------------------------------------------------------------------

std::string ExchangeReport::brief() const {
  char head[160];
  std::snprintf(head, sizeof head,
                "%d face%s, max degree %d, %ld control points, %s (BRepCheck at %.0e mm)", faces,
                faces == 1 ? "" : "s", max_degree, control_points, valid ? "valid" : "NOT valid",
                tolerance_mm);
  std::string line = head;
  if (!problems.empty())
    line += ": " + std::to_string(problems.size()) +
            (problems.size() == 1 ? " problem: " : " problems, the first: ") + problems.front();
  return line;
}

ExchangeReport check_faces(const std::vector<BSplineSurface>& surfaces) {
  ExchangeSession session;
  return guarded("check_faces", [&] { return build_faces(surfaces, "check_faces").report; });
}

ExchangeReport write_step(const std::vector<BSplineSurface>& surfaces, const fs::path& file,
                          const StepWriteOptions& options) {
  constexpr std::string_view caller = "write_step";
  if (options.product_name.empty())
    throw Error(ErrorCategory::InvalidArgument,
                "write_step: StepWriteOptions::product_name is empty; give a product name");
  ExchangeSession session;
  return guarded(caller, [&] {
    BuiltFaces built = build_faces(surfaces, caller);
    check_target(file, caller);
    // Settings go after Init() and before the writer is constructed (OCCT-NOTES).
    STEPControl_Controller::Init();
    set_static("write.step.schema", options.schema == StepSchema::AP242 ? "AP242DIS" : "AP214IS");
    set_static("write.step.unit", "MM");
    set_static("xstep.cascade.unit", "MM");
    set_static("write.step.product.name", options.product_name.c_str());
    set_static("write.step.assembly", 0);
    STEPControl_Writer writer;
    if (writer.Transfer(built.compound, STEPControl_AsIs) != IFSelect_RetDone)
      throw Error(ErrorCategory::Exchange,
                  "write_step: OpenCASCADE's STEP translator refused the faces");
    Handle(StepData_StepModel) model = writer.Model();
    // OCCT numbers products with a process-wide counter ("clayform 7"): give the plain name.
    const Handle(TCollection_HAsciiString) product =
        new TCollection_HAsciiString(options.product_name.c_str());
    for (int i = 1; i <= model->NbEntities(); ++i)
      if (auto p = Handle(StepBasic_Product)::DownCast(model->Value(i)); !p.IsNull()) {
        p->SetId(product);
        p->SetName(product);
      }
    APIHeaderSection_MakeHeader header(model);
    header.SetName(new TCollection_HAsciiString(file.filename().string().c_str()));
    header.SetOriginatingSystem(new TCollection_HAsciiString("Clayform"));
    write_atomically(file, caller, [&](const fs::path& temp) {
      write_stream(temp, caller, [&](std::ostream& out) {
        StepData_StepWriter step_writer(model);
        step_writer.FloatWriter().SetFormat("%.16E");  // 17 significant digits: lossless
        step_writer.SendModel(Handle(StepData_Protocol)::DownCast(model->Protocol()));
        return static_cast<bool>(step_writer.Print(out));
      });
    });
    return built.report;
  });
}

ExchangeReport write_iges(const std::vector<BSplineSurface>& surfaces, const fs::path& file) {
  constexpr std::string_view caller = "write_iges";
  ExchangeSession session;
  return guarded(caller, [&] {
    BuiltFaces built = build_faces(surfaces, caller);
    check_target(file, caller);
    IGESControl_Controller::Init();
    set_static("write.iges.unit", "MM");
    set_static("xstep.cascade.unit", "MM");
    set_static("write.iges.brep.mode", 0);  // faces: 144 trimmed surface over 128 B-spline
    IGESControl_Writer writer("MM", 0);
    if (!writer.AddShape(built.compound))
      throw Error(ErrorCategory::Exchange,
                  "write_iges: OpenCASCADE's IGES translator refused the faces");
    writer.ComputeModel();
    write_atomically(file, caller, [&](const fs::path& temp) {
      write_stream(temp, caller, [&](std::ostream& out) {
        IGESData_IGESWriter iges_writer(writer.Model());
        iges_writer.FloatWriter().SetFormat("%.16E");  // 17 significant digits: lossless
        iges_writer.SendModel(IGESSelect_WorkLibrary::DefineProtocol());
        return static_cast<bool>(iges_writer.Print(out));
      });
    });
    return built.report;
  });
}

std::vector<std::string> ReadOptions::problems() const {
  std::vector<std::string> out;
  auto fail = [&out](const std::string& what) { out.push_back("ReadOptions::" + what); };
  if (!(time_limit_seconds > 0 && time_limit_seconds <= 86400))
    fail("time_limit_seconds = " + std::to_string(time_limit_seconds) + ": must be in (0, 86400]");
  if (memory_limit_mb < 1 || memory_limit_mb > 1048576)
    fail("memory_limit_mb = " + std::to_string(memory_limit_mb) + ": must be in [1, 1048576]");
  return out;
}

void ReadOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

std::vector<BSplineSurface> read_step(const fs::path& file, const ReadOptions& options) {
  return read_guarded(file, options, "read_step", &detail::precheck_step, &read_step_locked);
}

std::vector<BSplineSurface> read_iges(const fs::path& file, const ReadOptions& options) {
  return read_guarded(file, options, "read_iges", &detail::precheck_iges, &read_iges_locked);
}

std::vector<std::string> GltfWriteOptions::problems() const {
  std::vector<std::string> out;
  if (!(relative_area > 0.0 && relative_area < 0.5))
    out.push_back("GltfWriteOptions::relative_area is " + std::to_string(relative_area) +
                  "; it must be in (0, 0.5), e.g. 0.005");
  if (max_vertices < 289)
    out.push_back("GltfWriteOptions::max_vertices is " + std::to_string(max_vertices) +
                  "; it must be at least 289 (a 17 x 17 grid)");
  return out;
}

void GltfWriteOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

void write_gltf(const std::vector<BSplineSurface>& surfaces, const fs::path& file,
                const GltfWriteOptions& options) {
  constexpr std::string_view caller = "write_gltf";
  // The preview is our own tessellation (the viewer's grid, refined until its area is within
  // relative_area of the surface's), attached to each face as its triangulation: OpenCASCADE's
  // mesher gave zero-area meshes on surfaces with poles (the handset, the bent superellipsoid),
  // and only the writer is needed from it.
  const auto bad = options.problems();
  if (!bad.empty())
    throw Error(ErrorCategory::InvalidArgument, "write_gltf: " + internal::join_problems(bad));
  for (size_t k = 0; k < surfaces.size(); ++k) validate(surfaces[k], surface_name(k));
  const long share = options.max_vertices / std::max<long>(1, static_cast<long>(surfaces.size()));
  const int max_samples = static_cast<int>(
      std::clamp<long>(static_cast<long>(std::sqrt(static_cast<double>(share))), 17, 1025));
  std::vector<GridMesh> meshes;
  meshes.reserve(surfaces.size());
  for (size_t k = 0; k < surfaces.size(); ++k) {
    try {
      meshes.push_back(tessellate_to_area(surfaces[k], options.relative_area, max_samples));
    } catch (
        const Error& e) {  // say which surface and which file, not only the tessellator's figures
      throw Error(e.category(), "write_gltf: the preview of " + surface_name(k) + " for " +
                                    quoted(file) +
                                    " cannot be meshed within its area tolerance: " + e.message() +
                                    "; raise GltfWriteOptions::max_vertices or relative_area");
    }
  }
  ExchangeSession session;
  guarded(caller, [&] {
    const std::vector<Handle(Geom_BSplineSurface)> converted = convert_all(surfaces, caller);
    check_target(file, caller);
    BRep_Builder builder;
    TopoDS_Compound compound;
    builder.MakeCompound(compound);
    for (size_t k = 0; k < converted.size(); ++k) {
      TopoDS_Face face = make_face(converted[k], surface_name(k));
      const GridMesh& m = meshes[k];
      const int cells = (m.rows - 1) * (m.cols - 1);
      Handle(Poly_Triangulation) triangulation =
          new Poly_Triangulation(m.rows * m.cols, 2 * cells, Standard_False, Standard_True);
      for (int v = 0; v < m.rows * m.cols; ++v) {
        triangulation->SetNode(v + 1,
                               gp_Pnt(m.positions(v, 0), m.positions(v, 1), m.positions(v, 2)));
        const Eigen::Vector3d n = m.normals.row(v).transpose();
        triangulation->SetNormal(
            v + 1, n.squaredNorm() > 0 ? gp_Dir(n.x(), n.y(), n.z()) : gp_Dir(0, 0, 1));
      }
      int t = 0;
      for (int i = 0; i + 1 < m.rows; ++i)
        for (int j = 0; j + 1 < m.cols; ++j)
          for (const auto& tri : cell_triangles(m, i, j))
            triangulation->SetTriangle(++t, Poly_Triangle(tri[0] + 1, tri[1] + 1, tri[2] + 1));
      builder.UpdateFace(face, triangulation);
      builder.Add(compound, face);
    }
    occt::XcafDocument held;  // closed on every way out
    Handle(TDocStd_Document)& document = held.get();
    XCAFDoc_DocumentTool::ShapeTool(document->Main())->AddShape(compound, false);
    write_atomically(file, caller, [&](const fs::path& temp) {
      RWGltf_CafWriter writer(TCollection_AsciiString(temp.string().c_str()), true);
      writer.ChangeCoordinateSystemConverter().SetInputLengthUnit(0.001);  // model in mm
      writer.ChangeCoordinateSystemConverter().SetInputCoordinateSystem(
          RWMesh_CoordinateSystem_Zup);
      TColStd_IndexedDataMapOfStringString info;
      info.Add("generator", "Clayform");
      if (!writer.Perform(document, info, Message_ProgressRange()))
        throw Error(ErrorCategory::Io,
                    "write_gltf: OpenCASCADE's glTF writer failed to write " + quoted(temp));
      std::error_code ec;
      if (!fs::is_regular_file(temp, ec) || fs::file_size(temp, ec) == 0)
        throw Error(ErrorCategory::Io, "write_gltf: no data was written to " + quoted(temp));
    });
  });
}

}  // namespace clay::surface
