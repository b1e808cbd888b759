#include <clay/cancel.hpp>
#include <clay/parallel.hpp>

#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace clay {

void run_on_threads(std::size_t parts, const std::function<void(std::size_t part)>& task) {
  std::exception_ptr first;
  std::mutex guard;
  // A task that throws on a worker would otherwise end the process (std::thread calls terminate).
  // The caller's cancel check goes with the work (clay/cancel.hpp): a thread of ours has none.
  const std::function<bool()> check = current_cancel_check();
  auto run = [&](std::size_t part) {
    try {
      const CancelScope scope(check);
      task(part);
    } catch (...) {
      const std::lock_guard lock(guard);
      if (!first) first = std::current_exception();
    }
  };
  std::vector<std::thread> workers;
  workers.reserve(parts > 0 ? parts - 1 : 0);
  for (std::size_t part = 1; part < parts; ++part) workers.emplace_back(run, part);
  if (parts > 0) run(0);
  for (auto& w : workers) w.join();
  if (first) std::rethrow_exception(first);
}

}  // namespace clay
