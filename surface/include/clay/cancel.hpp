#pragma once
/// Stopping long kernel work from outside (issue #40: a long job has a cancel). A caller that
/// may want to stop a call (the studio's server, an embedder's UI thread) opens a CancelScope on
/// the thread that makes the call, with a check that says whether to stop. The kernel's long
/// loops (an exact composition patch by patch, a refit's rounds, a style's rounds, a model's
/// faces, a recipe's steps and outputs) call throw_if_cancelled(), which throws Cancelled when
/// the check returns true. Work split over threads carries the check to them (run_parts).
///
/// Cancelled is deliberately not a clay::Error (nor a std::exception): no fallback that catches
/// a failure (an exact composition falling back to a refit, a step reported as failed) takes a
/// cancel for a failure; it unwinds to the caller that asked for it.
#include <clay/surface/export.hpp>

#include <functional>
#include <string>

namespace clay {

/// Thrown by throw_if_cancelled when the calling thread's check says stop.
struct CLAY_SURFACE_API Cancelled {
  std::string where;  ///< the loop that noticed ("exact composition", "recipe step ...")
};

/// While it lives, throw_if_cancelled() on this thread calls `check` (the innermost scope's;
/// an empty check never cancels). Not copyable; open it on the thread that does the work.
class CLAY_SURFACE_API CancelScope {
 public:
  explicit CancelScope(std::function<bool()> check);
  ~CancelScope();
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  std::function<bool()> check_;
  const std::function<bool()>* outer_;
};

/// Throws Cancelled{where} when the calling thread's innermost CancelScope's check returns true;
/// nothing otherwise (and nothing when no scope is open). Costs one call of the check.
CLAY_SURFACE_API void throw_if_cancelled(const char* where);

/// The calling thread's current check (empty when none is open): what a caller hands to the
/// threads it starts, each opening a CancelScope with it.
CLAY_SURFACE_API std::function<bool()> current_cancel_check();

}  // namespace clay
