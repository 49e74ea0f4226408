// An output directory that one tippe command at a time writes, and whose files are replaced as one unit.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "io/files.h"

namespace tippe {

// OutputError (records.h) for every path here that cannot be used: cannot be created, is not a
// directory, is held by another tippe, cannot be staged beside.

// DIR for the life of a command:
//  - created (with its parents) when missing; an existing DIR must be a directory;
//  - locked: flock on the directory itself, not on a file in it, so deleting or replacing a lock
//    file cannot let a second writer in; a DIR replaced between open and lock is opened again;
//  - replaced as one unit: stage() gives a fresh directory beside DIR (".NAME.staging-PID"), to be
//    filled with the unit's files; commit() swaps it with DIR in one rename (renameat2
//    RENAME_EXCHANGE) and removes the old set, so a reader sees the old files or the new ones,
//    never a mix. The lock moves with the swap (the staging directory is locked too).
// Destroyed without commit (an error, an exception, an interrupt) it removes its staging
// directory, and DIR itself when this object created it and nothing is in it. Staging
// directories that an earlier, killed run left beside DIR are removed when DIR is opened.
class OutputDir {
 public:
  explicit OutputDir(const std::filesystem::path& dir);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  // DIR as an absolute path (the swap renames it, so "." or a relative path would be ambiguous).
  const std::filesystem::path& path() const { return dir_; }

  // Starts a unit and returns the directory to write it into: empty, or (keep_existing) holding
  // hard links to every file DIR holds now (records that stay, a report rebuilt beside them).
  // Files must be replaced in it by rename (write_file_atomic), never rewritten in place: a hard
  // link shares its bytes with DIR's file until the swap. Throws OutputError.
  std::filesystem::path stage(bool keep_existing);
  // The swap; then the old set is removed. Throws OutputError when the swap fails (DIR unchanged).
  void commit();

 private:
  void remove_staging();
  std::filesystem::path dir_, staging_;
  int dir_fd_ = -1, staging_fd_ = -1;
  bool created_ = false;
};

// A result file named on the command line (--junit, --json): "" when `path` can be written, else
// the reason. Checked before any work, so that a typo does not cost a whole run.
std::string result_file_problem(const std::string& path);
// Writes it: through a symbolic link, the file the link names; a character device or a FIFO is
// written directly, never replaced by a regular file; a regular or new file (its directories
// created) is replaced atomically with write_file_atomic. Throws OutputError naming the path.
void write_result_file(const std::string& path, const std::string& text);

}  // namespace tippe
