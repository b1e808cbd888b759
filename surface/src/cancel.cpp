#include <clay/cancel.hpp>

#include <utility>

namespace clay {

namespace {
// The innermost open scope's check on this thread (null: none). A thread-local pointer, so
// that concurrent calls on other threads (Dask's workers, an embedder's pool) are not stopped.
thread_local const std::function<bool()>* innermost = nullptr;
}  // namespace

CancelScope::CancelScope(std::function<bool()> check)
    : check_(std::move(check)), outer_(innermost) {
  innermost = &check_;
}

CancelScope::~CancelScope() { innermost = outer_; }

void throw_if_cancelled(const char* where) {
  if (innermost && *innermost && (*innermost)()) throw Cancelled{where};
}

std::function<bool()> current_cancel_check() {
  return innermost ? *innermost : std::function<bool()>{};
}

}  // namespace clay
