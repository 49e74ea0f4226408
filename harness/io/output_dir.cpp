// An output directory that one tippe command at a time writes, and whose files are replaced as one unit.
#include "io/output_dir.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "io/interrupt.h"

namespace tippe {

namespace fs = std::filesystem;

namespace {

std::string why(int err) { return std::strerror(err); }

// Opens `path` as a directory and takes its lock without waiting. Returns the descriptor, -1 when
// another process holds the lock (errno EWOULDBLOCK), -2 for any other failure (errno set).
int open_locked(const fs::path& path) {
  for (int attempt = 0; attempt < 8; ++attempt) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return -2;
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      ::close(fd);
      errno = err;
      return err == EWOULDBLOCK ? -1 : -2;
    }
    // The path may have been swapped between the open and the lock (another run's commit): the
    // lock must be on what the path names now.
    struct stat held {}, named {};
    if (::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino)
      return fd;
    ::close(fd);
  }
  errno = EAGAIN;
  return -2;
}

std::string staging_prefix(const fs::path& dir) { return "." + dir.filename().string() + ".staging-"; }

// Hard links of every file under `from` in `to` (directories made anew).
void link_tree(const fs::path& from, const fs::path& to) {
  for (const auto& e : fs::recursive_directory_iterator(from)) {
    const fs::path rel = fs::relative(e.path(), from), target = to / rel;
    if (e.is_directory() && !e.is_symlink())
      fs::create_directory(target);
    else if (e.is_symlink())
      fs::copy_symlink(e.path(), target);
    else
      fs::create_hard_link(e.path(), target);
  }
}

}  // namespace

OutputDir::OutputDir(const fs::path& dir) {
  std::error_code ec;
  // Symbolic links are followed (DIR through a link writes the directory it names): the swap
  // renames the real directory, and the link keeps naming it.
  dir_ = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (ec) throw OutputError(dir.string() + ": not a usable output directory: " + ec.message());
  if (!dir_.has_filename()) dir_ = dir_.parent_path();  // "out/" -> "out"
  if (dir_ == dir_.root_path())
    throw OutputError(dir.string() + ": not a usable output directory: it is the root of the filesystem");
  const fs::file_status st = fs::status(dir_, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) throw OutputError(dir.string() + ": exists and is not a directory");
  } else {
    fs::create_directories(dir_, ec);
    if (ec) throw OutputError(dir.string() + ": cannot create the output directory: " + ec.message());
    created_ = true;
  }
  dir_fd_ = open_locked(dir_);
  if (dir_fd_ == -1) throw OutputError(dir.string() + ": in use by another tippe command (locked)");
  if (dir_fd_ < 0) throw OutputError(dir.string() + ": cannot lock the output directory: " + why(errno));

  // Staging directories of runs that died (killed, the machine lost) are free to lock: removed.
  const std::string prefix = staging_prefix(dir_);
  for (const auto& e : fs::directory_iterator(dir_.parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const int fd = open_locked(e.path());
    if (fd < 0) continue;  // a live run's (of another DIR with a name that shares the prefix)
    fs::remove_all(e.path(), ec);
    ::close(fd);
  }
}

OutputDir::~OutputDir() {
  remove_staging();
  std::error_code ec;
  if (created_ && fs::is_empty(dir_, ec) && !ec) fs::remove(dir_, ec);
  if (dir_fd_ >= 0) ::close(dir_fd_);
}

void OutputDir::remove_staging() {
  if (staging_.empty()) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
  if (staging_fd_ >= 0) ::close(staging_fd_);
  staging_fd_ = -1;
  staging_.clear();
}

fs::path OutputDir::stage(bool keep_existing) {
  remove_staging();
  const fs::path s = dir_.parent_path() / (staging_prefix(dir_) + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(s, ec);  // this process's own, from an earlier unit
  if (!fs::create_directory(s, ec) || ec)
    throw OutputError(dir_.string() + ": cannot make a staging directory beside it (" + s.string() +
                      "): " + (ec ? ec.message() : std::string("exists")));
  staging_ = s;
  staging_fd_ = open_locked(s);
  if (staging_fd_ < 0) {
    const int err = errno;
    remove_staging();
    throw OutputError(s.string() + ": cannot lock the staging directory: " + why(err));
  }
  // Same permissions as DIR: the swap must not change who can read the results.
  struct stat st {};
  if (::fstat(dir_fd_, &st) == 0) ::fchmod(staging_fd_, st.st_mode & 07777);
  if (keep_existing) {
    try {
      link_tree(dir_, staging_);
    } catch (const fs::filesystem_error& e) {
      remove_staging();
      throw OutputError(dir_.string() + ": cannot stage its files for the new report: " + e.code().message());
    }
  }
  return staging_;
}

void OutputDir::commit() {
  if (staging_.empty()) throw std::logic_error("OutputDir::commit without stage");
  // A signal that came while the unit was written keeps the old set.
  check_interrupted();
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, dir_.c_str(), RENAME_EXCHANGE) != 0) {
    const int err = errno;
    throw OutputError(dir_.string() + ": cannot replace it with the new files: " + why(err));
  }
  // The path names the new set now; this process holds both locks, so nobody else writes either.
  std::swap(dir_fd_, staging_fd_);
  created_ = false;
  // staging_ now holds the old set.
  remove_staging();
}

namespace {

// The file a result path names: symbolic links followed, so that the link itself is never replaced.
fs::path resolved(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? fs::path(path) : p;
}

}  // namespace

std::string result_file_problem(const std::string& path) {
  if (path.empty()) return "empty file name";
  const fs::path p = resolved(path);
  std::error_code ec;
  const fs::file_status st = fs::status(p, ec);
  if (fs::exists(st)) {
    if (fs::is_directory(st)) return "is a directory";
    if (fs::is_socket(st) || fs::is_block_file(st)) return "is a socket or a block device, not a file to write";
    if (::access(p.c_str(), W_OK) != 0) return std::string("cannot write: ") + why(errno);
    if (fs::is_character_file(st) || fs::is_fifo(st)) return "";
    // A regular file is replaced by rename: its directory must be writable.
    if (::access(p.parent_path().c_str(), W_OK) != 0)
      return "cannot replace it: " + p.parent_path().string() + ": " + why(errno);
    return "";
  }
  // A new file: its nearest existing ancestor must be a writable directory (the rest is created).
  for (fs::path a = p.parent_path();; a = a.parent_path()) {
    if (fs::exists(a, ec)) {
      if (!fs::is_directory(a, ec)) return a.string() + " is not a directory";
      if (::access(a.c_str(), W_OK) != 0) return "cannot create it: " + a.string() + ": " + why(errno);
      return "";
    }
    if (a == a.parent_path()) return "no existing directory above it";
  }
}

void write_result_file(const std::string& path, const std::string& text) {
  if (const std::string problem = result_file_problem(path); !problem.empty()) throw OutputError(path + ": " + problem);
  const fs::path p = resolved(path);
  std::error_code ec;
  const fs::file_status st = fs::status(p, ec);
  if (fs::is_character_file(st) || fs::is_fifo(st)) {
    // A device or a FIFO is written where it is (a FIFO's open waits for its reader).
    const int fd = ::open(p.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) throw OutputError(path + ": cannot write: " + why(errno));
    const char* at = text.data();
    size_t left = text.size();
    while (left > 0) {
      const ssize_t n = ::write(fd, at, left);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        const int err = errno;
        ::close(fd);
        throw OutputError(path + ": cannot write: " + why(err));
      }
      at += n;
      left -= static_cast<size_t>(n);
    }
    if (::close(fd) != 0) throw OutputError(path + ": cannot write: " + why(errno));
    return;
  }
  if (p.has_parent_path()) fs::create_directories(p.parent_path(), ec);
  if (ec) throw OutputError(path + ": cannot create " + p.parent_path().string() + ": " + ec.message());
  write_file_atomic(p.string(), text);
}

}  // namespace tippe
