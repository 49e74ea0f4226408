// An output directory that one tippe command at a time writes, and whose files are replaced as one unit.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/io/files.h"

namespace tippe {

// OutputError (records.h) for every path here that cannot be used: cannot be created, is not a
// directory, is held by another tippe, cannot be staged beside.

// The kinds of output directory: a directory of one kind is never written by a command of
// another (a run never replaces a sweep's records).
enum class OutputKind { Run, Comparison, Sweep };
const char* to_string(OutputKind kind);

// The file in every output directory that says tippe wrote it: JSON {"tippe_output": KIND,
// "files": [NAME, ...]}, the kind and the top-level names the last unit committed. Written into
// each unit before its swap (and, for a sweep, whose records grow in DIR itself, when DIR is
// opened). What tippe owns in DIR is what this file lists, plus the names a sweep writes straight
// into DIR (sweep.json, records.jsonl, records.jsonl.old*, reference/). A directory written
// before the marker existed is recognised by its record (summary.json, comparison.json,
// sweep.json) and then owns the names its kind writes (summary.json and trajectory.csv;
// comparison.json, report.md, index.html, *.csv, *.svg, plot-*.dat, plots.gp; a sweep's report).
inline constexpr const char* kOutputMarker = ".tippe-output";

// DIR for the life of a command:
//  - refused when it is, or contains, one of `inputs` (a scene, a model, a sweep file, a shard:
//    the swap would delete it), or when it holds a marker of another kind, or anything tippe did
//    not write ("DIR holds files tippe did not write: a, b; use an empty or a tippe directory");
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
  OutputDir(const std::filesystem::path& dir, OutputKind kind, const std::vector<std::filesystem::path>& inputs = {});
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
  void check_contents(const std::filesystem::path& given);
  OutputKind kind_;
  std::filesystem::path dir_, staging_;
  int dir_fd_ = -1, staging_fd_ = -1;
  bool created_ = false;
};

// Throws OutputError when `out` (an output file or directory) is one of `inputs` or, for a
// directory, contains one: "OPTION OUT: is the input FILE" / "contains the input FILE".
void refuse_output_over_inputs(const std::filesystem::path& out, const std::vector<std::filesystem::path>& inputs,
                               const std::string& option = "--out");

// A result file named on the command line (--junit, --json): "" when `path` can be written, else
// the reason. Checked before any work, so that a typo does not cost a whole run.
std::string result_file_problem(const std::string& path);
// Writes it: through a symbolic link, the file the link names; a character device or a FIFO is
// written directly, never replaced by a regular file; a regular or new file (its directories
// created) is replaced atomically with write_file_atomic. Throws OutputError naming the path.
void write_result_file(const std::string& path, const std::string& text);

}  // namespace tippe
