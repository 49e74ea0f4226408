// An output directory that one tippe command at a time writes, and whose files are replaced as one unit.
#include "harness/io/output_dir.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <nlohmann/json.hpp>

#include "harness/io/interrupt.h"

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
    // Lexically: fs::relative resolves a symbolic link to its target, which would re-create the
    // link outside `to` (where its target lies); a link is copied as the link it is, in place.
    const fs::path rel = e.path().lexically_relative(from), target = to / rel;
    if (e.is_directory() && !e.is_symlink())
      fs::create_directory(target);
    else if (e.is_symlink())
      fs::copy_symlink(e.path(), target);
    else
      fs::create_hard_link(e.path(), target);
  }
}

// A name against a pattern with at most one '*' (any characters).
bool matches(const std::string& name, const std::string& pattern) {
  const size_t star = pattern.find('*');
  if (star == std::string::npos) return name == pattern;
  const std::string head = pattern.substr(0, star), tail = pattern.substr(star + 1);
  return name.size() >= head.size() + tail.size() && name.compare(0, head.size(), head) == 0 &&
         name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
}

bool matches_any(const std::string& name, const std::vector<std::string>& patterns) {
  return std::any_of(patterns.begin(), patterns.end(), [&](const std::string& p) { return matches(name, p); });
}

// What each kind writes into DIR itself, outside a staged unit (a sweep's records grow in place).
const std::vector<std::string>& direct_names(OutputKind kind) {
  static const std::vector<std::string> none, sweep = {"sweep.json", "records.jsonl", "records.jsonl.old*", "reference"};
  return kind == OutputKind::Sweep ? sweep : none;
}

// A directory written before the marker: its kind's record, and the names that kind writes.
const char* legacy_record(OutputKind kind) {
  switch (kind) {
    case OutputKind::Run: return "summary.json";
    case OutputKind::Comparison: return "comparison.json";
    case OutputKind::Sweep: return "sweep.json";
  }
  return "";
}

const std::vector<std::string>& legacy_names(OutputKind kind) {
  static const std::vector<std::string> run = {"summary.json", "trajectory.csv"};
  static const std::vector<std::string> comparison = {"comparison.json", "report.md", "index.html", "plots.gp",
                                                      "plots.log", "*.csv", "*.svg", "plot-*.dat"};
  static const std::vector<std::string> sweep = {"sweep.json", "records.jsonl", "records.jsonl.old*", "reference",
                                                 "report.md", "index.html", "sweep-plots.gp", "plots.log",
                                                 "*.svg", "sweep-*.dat"};
  return kind == OutputKind::Run ? run : kind == OutputKind::Comparison ? comparison : sweep;
}

// The marker's kind and files; nullopt-like (ok false) when it is missing or not a marker.
struct Marker {
  bool ok = false;
  std::string kind;
  std::vector<std::string> files;
};

Marker read_marker(const fs::path& dir) {
  Marker m;
  std::error_code ec;
  const fs::path file = dir / kOutputMarker;
  if (!fs::is_regular_file(fs::symlink_status(file, ec))) return m;
  try {
    const nlohmann::json j = nlohmann::json::parse(read_file_text(file.string(), kMaxInputFileBytes));
    if (!j.is_object() || !j.contains("tippe_output") || !j.at("tippe_output").is_string() || !j.contains("files") ||
        !j.at("files").is_array())
      return m;
    for (const auto& f : j.at("files")) {
      if (!f.is_string()) return m;
      m.files.push_back(f.get<std::string>());
    }
    m.kind = j.at("tippe_output").get<std::string>();
    m.ok = true;
  } catch (const std::exception&) {
    m.ok = false;
  }
  return m;
}

void write_marker(const fs::path& dir, OutputKind kind) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name != kOutputMarker) files.push_back(name);
  }
  std::sort(files.begin(), files.end());
  const nlohmann::json j = {{"tippe_output", to_string(kind)}, {"files", files}};
  write_file_atomic((dir / kOutputMarker).string(), j.dump(1) + "\n");
}

// Whether `inner` is `outer` or lies inside it (both absolute and normal).
bool within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

fs::path real(const fs::path& p) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
  if (ec) r = fs::absolute(p, ec).lexically_normal();
  if (!r.has_filename() && r != r.root_path()) r = r.parent_path();
  return r;
}

}  // namespace

const char* to_string(OutputKind kind) {
  switch (kind) {
    case OutputKind::Run: return "run";
    case OutputKind::Comparison: return "comparison";
    case OutputKind::Sweep: return "sweep";
  }
  return "?";
}

void refuse_output_over_inputs(const fs::path& out, const std::vector<fs::path>& inputs, const std::string& option) {
  const fs::path o = real(out);
  std::error_code ec;
  for (const fs::path& in : inputs) {
    if (in.empty()) continue;
    const fs::path i = real(in);
    // The same file by another name (a hard link) is the input too.
    if (i == o || (fs::exists(in, ec) && fs::exists(out, ec) && fs::equivalent(in, out, ec)))
      throw OutputError(option + " " + out.string() + ": is the input " + in.string() +
                        "; writing there would destroy it: give another " + option);
    if (within(i, o))
      throw OutputError(option + " " + out.string() + ": contains the input " + in.string() +
                        "; the output replaces what it holds: give another " + option);
  }
}

void OutputDir::check_contents(const fs::path& given) {
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_, ec)) names.push_back(e.path().filename().string());
  if (ec) throw OutputError(given.string() + ": cannot list the output directory: " + ec.message());
  std::sort(names.begin(), names.end());
  const bool has_marker = std::find(names.begin(), names.end(), kOutputMarker) != names.end();
  const Marker m = has_marker ? read_marker(dir_) : Marker{};
  if (m.ok && m.kind != to_string(kind_))
    throw OutputError(given.string() + ": is a " + m.kind + "'s output directory (its " + kOutputMarker +
                      " says so); a " + to_string(kind_) + " never replaces it: give another --out");
  auto holds = [&](const char* name) { return std::find(names.begin(), names.end(), name) != names.end(); };
  const bool legacy = !has_marker && holds(legacy_record(kind_));
  if (!has_marker && !legacy)
    for (OutputKind other : {OutputKind::Sweep, OutputKind::Comparison, OutputKind::Run})
      if (other != kind_ && holds(legacy_record(other)))
        throw OutputError(given.string() + ": is a " + to_string(other) + "'s output directory (it holds " +
                          legacy_record(other) + "); a " + to_string(kind_) + " never replaces it: give another --out");
  std::vector<std::string> foreign;
  for (const std::string& n : names) {
    if (n == kOutputMarker && m.ok) continue;
    const bool own = m.ok ? (std::find(m.files.begin(), m.files.end(), n) != m.files.end() ||
                             matches_any(n, direct_names(kind_)))
                          : legacy && matches_any(n, legacy_names(kind_));
    if (!own) foreign.push_back(n);
  }
  if (foreign.empty()) return;
  std::string list;
  const size_t shown = std::min<size_t>(foreign.size(), 10);
  for (size_t i = 0; i < shown; ++i) list += (i ? ", " : "") + foreign[i];
  if (foreign.size() > shown) list += " and " + std::to_string(foreign.size() - shown) + " more";
  throw OutputError(given.string() + " holds files tippe did not write: " + list +
                    "; use an empty or a tippe directory");
}

OutputDir::OutputDir(const fs::path& dir, OutputKind kind, const std::vector<fs::path>& inputs) : kind_(kind) {
  refuse_output_over_inputs(dir, inputs);
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
  // What DIR holds is checked under the lock, so that no other tippe changes it in between.
  try {
    check_contents(dir);
    // A sweep writes its records into DIR itself: DIR says it is a sweep's from the start.
    if (!direct_names(kind_).empty()) write_marker(dir_, kind_);
  } catch (...) {
    ::close(dir_fd_);
    dir_fd_ = -1;
    throw;
  }

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
  // A directory made for nothing (a marker alone at most) is removed again.
  if (created_) {
    bool only_marker = true;
    for (const auto& e : fs::directory_iterator(dir_, ec))
      only_marker = only_marker && e.path().filename() == kOutputMarker;
    if (only_marker && !ec) {
      fs::remove(dir_ / kOutputMarker, ec);
      fs::remove(dir_, ec);
    }
  }
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
  // The unit says what it is and which files are tippe's.
  write_marker(staging_, kind_);
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
