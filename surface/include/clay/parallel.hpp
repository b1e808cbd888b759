#pragma once
/// Who runs the kernel's parallel work. Bulk calls (deform_points of lattices, stacks, regular
/// and extended deformations) split their points into parts; by default each call starts
/// parts − 1 std::threads and works on the first part itself. An embedder that owns a thread
/// pool hands it in as an Executor (DeformOptions::executor) and caps the parts with
/// DeformOptions::threads, so the kernel starts no thread of its own.
#include <clay/surface/export.hpp>

#include <cstddef>
#include <functional>

namespace clay {

/// Runs task(part) once for every part in [0, parts), possibly concurrently, and returns when
/// every call has returned. It may run the calls in any order and on any threads (the calling
/// thread included); it must rethrow an exception a task throws (or std::terminate).
using Executor =
    std::function<void(std::size_t parts, const std::function<void(std::size_t part)>& task)>;

/// The default Executor: parts − 1 new std::threads plus the calling thread. Every task runs to
/// its end; the first exception thrown by a task is rethrown on the calling thread afterwards.
CLAY_SURFACE_API void run_on_threads(std::size_t parts,
                                     const std::function<void(std::size_t part)>& task);

}  // namespace clay
