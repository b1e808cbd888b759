#pragma once
// Files (internal, not installed): reading a whole text file, names that must stay inside a
// folder, and writing a file atomically. Used by the recipe library, the studio and the Python
// package, so each rule is written once.
#include <clay/error.hpp>
#include <clay/internal/format.hpp>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace clay::internal {

/// The file's bytes. Throws clay::Error(Io) naming `what` and the file ("cannot read the recipe
/// \"x.json\"; check the path").
inline std::string read_text(const std::filesystem::path& file, const std::string& what) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw Error(ErrorCategory::Io,
                "cannot read the " + what + " \"" + file.string() + "\"; check the path");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Why `name` is not a plain file name, or nothing when it is one: not empty, at most 255 bytes,
/// not "." or "..", no '/', '\\', NUL or control character (a newline in a name breaks every
/// listing of it). A plain name resolved in a folder stays in that folder.
inline std::optional<std::string> file_name_problem(std::string_view name) {
  if (name.empty()) return "it is empty";
  if (name.size() > 255) return "it is longer than 255 bytes";
  if (name == "." || name == "..") return "\"" + std::string(name) + "\" names a folder";
  for (char c : name) {
    if (c == '/' || c == '\\') return "it has a '" + std::string(1, c) + "' (a folder in it)";
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      return "it has a control character (byte " + std::to_string(static_cast<unsigned char>(c)) +
             ")";
  }
  return std::nullopt;
}

/// `name` as a plain file name; clay::Error(InvalidArgument) naming `what`, the problem and the
/// fix otherwise.
inline void check_file_name(std::string_view name, const std::string& what) {
  if (const auto problem = file_name_problem(name))
    throw Error(ErrorCategory::InvalidArgument,
                what + " \"" + clip_utf8(name, 60) + "\" is not a plain file name: " + *problem +
                    "; give a name such as \"part_v2\" (no folders, no \"..\")");
}

/// `relative` (plain names joined by '/', e.g. "out" or "exports/v2") resolved under `folder`,
/// refusing an absolute path, "..", "." and empty segments, and a path that leaves `folder`
/// through a symbolic link already there (clay::Error(InvalidArgument) naming `what`).
inline std::filesystem::path path_under(const std::filesystem::path& folder,
                                        std::string_view relative, const std::string& what) {
  namespace fs = std::filesystem;
  if (relative.empty() || relative.front() == '/')
    throw Error(ErrorCategory::InvalidArgument,
                what + " \"" + clip_utf8(relative, 60) +
                    "\" must be relative to the recipe's folder (e.g. \"out\"), not absolute");
  fs::path out = folder;
  std::size_t at = 0;
  while (at <= relative.size()) {
    const std::size_t slash = std::min(relative.find('/', at), relative.size());
    const std::string_view segment = relative.substr(at, slash - at);
    if (const auto problem = file_name_problem(segment))
      throw Error(ErrorCategory::InvalidArgument,
                  what + " \"" + clip_utf8(relative, 60) + "\" has a part that is not a plain " +
                      "name (" + *problem + "); give names joined by '/' inside the recipe's " +
                      "folder, e.g. \"out\" or \"exports/v2\"");
    out /= fs::path(std::string(segment));
    at = slash + 1;
  }
  // A symbolic link on the way may point elsewhere: what exists of the path must resolve inside.
  std::error_code ec;
  const fs::path base = fs::weakly_canonical(fs::absolute(folder), ec);
  const fs::path resolved = fs::weakly_canonical(fs::absolute(out), ec);
  const auto [b, r] = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
  if (ec || b != base.end())
    throw Error(ErrorCategory::InvalidArgument,
                what + " \"" + clip_utf8(relative, 60) + "\" leads out of the recipe's folder \"" +
                    base.string() + "\" (through a symbolic link); give a folder inside it");
  return out;
}

namespace files_detail {

/// Refuses to replace anything but a regular file or a symbolic link (which rename replaces, never
/// follows): a device, a FIFO, a folder.
inline void refuse_special(const std::filesystem::path& file, const std::string& what) {
  struct stat st {};
  if (::lstat(file.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode))
    throw Error(ErrorCategory::Io,
                "cannot write the " + what + " \"" + file.string() +
                    "\": it exists and is not a regular file; give another name");
}

/// A new, empty temporary beside `file`, made by mkstemp (O_CREAT | O_EXCL: a planted file or
/// link is never followed, concurrent writers never share one); its descriptor in `fd`.
inline std::string temporary_beside(const std::filesystem::path& file, const std::string& what,
                                    int& fd) {
  namespace fs = std::filesystem;
  std::string pattern = (file.parent_path().empty() ? fs::path(".") : file.parent_path()) /
                        ("." + file.filename().string() + ".XXXXXX");
  fd = ::mkstemp(pattern.data());
  if (fd < 0)
    throw Error(ErrorCategory::Io, "cannot write the " + what + " \"" + file.string() +
                                       "\": " + std::strerror(errno) + "; check the folder");
  return pattern;
}

/// Renames the finished temporary over `file`; removes it and throws on failure.
inline void rename_over(const std::string& temporary, const std::filesystem::path& file,
                        const std::string& what) {
  if (::rename(temporary.c_str(), file.c_str()) != 0) {
    const int err = errno;
    ::unlink(temporary.c_str());
    throw Error(ErrorCategory::Io, "cannot write the " + what + " \"" + file.string() +
                                       "\": " + std::strerror(err) + "; check the folder");
  }
}

}  // namespace files_detail

/// Writes `bytes` to `file` atomically: into a temporary made beside it by mkstemp (O_CREAT |
/// O_EXCL: a planted file or symbolic link is never followed, and concurrent writers never share
/// it), flushed to disk, then renamed over `file`. The temporary is removed on every failure.
/// Refuses to replace anything but a regular file (a device, a FIFO, a folder). Throws
/// clay::Error(Io) naming `what` and the file. The one way the libraries write a file (issue #37:
/// it was written three times); write_atomically_via is the same for writers that need a path.
inline void write_atomically(const std::filesystem::path& file, std::string_view bytes,
                             const std::string& what) {
  files_detail::refuse_special(file, what);
  int fd = -1;
  const std::string temporary = files_detail::temporary_beside(file, what, fd);
  auto fail = [&](const std::string& doing) {
    const int err = errno;
    ::close(fd);
    ::unlink(temporary.c_str());
    throw Error(ErrorCategory::Io, "cannot write the " + what + " \"" + file.string() + "\" (" +
                                       doing + "): " + std::strerror(err) +
                                       "; check the folder and the free space");
  };
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("writing");
    done += static_cast<std::size_t>(n);
  }
  if (::fchmod(fd, 0644) != 0 || ::fsync(fd) != 0) fail("flushing");
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(temporary.c_str());
    throw Error(ErrorCategory::Io, "cannot write the " + what + " \"" + file.string() +
                                       "\": " + std::strerror(err) + "; check the free space");
  }
  files_detail::rename_over(temporary, file, what);
}

/// write_atomically for writers that take a path (OpenCASCADE's STEP, IGES and glTF writers):
/// `write(temporary)` fills a temporary that mkstemp made beside `file` (it exists, is empty and
/// is ours), which is then flushed and renamed over `file`. On any failure the temporary is
/// removed and the writer's exception rethrown.
inline void write_atomically_via(const std::filesystem::path& file, const std::string& what,
                                 const std::function<void(const std::filesystem::path&)>& write) {
  files_detail::refuse_special(file, what);
  int fd = -1;
  const std::string temporary = files_detail::temporary_beside(file, what, fd);
  ::close(fd);
  try {
    write(temporary);
    const int flush = ::open(temporary.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (flush < 0 || ::fchmod(flush, 0644) != 0 || ::fsync(flush) != 0) {
      const int err = errno;
      if (flush >= 0) ::close(flush);
      throw Error(ErrorCategory::Io, "cannot write the " + what + " \"" + file.string() +
                                         "\" (flushing): " + std::strerror(err) +
                                         "; check the folder and the free space");
    }
    ::close(flush);
  } catch (...) {
    ::unlink(temporary.c_str());
    throw;
  }
  files_detail::rename_over(temporary, file, what);
}

}  // namespace clay::internal
