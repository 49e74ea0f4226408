// Whole files, read with a size bound and written atomically (fsynced, then renamed into place).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace tippe {

// An output that cannot be written (a path that cannot be created, a full disk, a file that
// cannot be renamed into place): exit 2, like bad input. The message names the path and the reason.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Size bounds of the files tippe reads. Input files (scenes, sweeps, gates): the largest shipped
// one is under 10 KB, so 1 MiB is a hundred times any real one. Records and reference files
// (records.jsonl, summary.json, comparison.json): a record line is ~3 KB and a plan has at most
// kMaxSweepPoints (sweep.h) = 1e5 points, ~300 MB; 1 GiB leaves room and still fits in memory.
constexpr size_t kMaxInputFileBytes = size_t{1} << 20;
constexpr size_t kMaxRecordFileBytes = size_t{1} << 30;
// The longest row of trajectory.csv (33 columns of at most 32 characters): scene files bound their
// sample count by it, so that no trajectory outgrows kMaxRecordFileBytes.
constexpr size_t kTrajectoryRowMax = 33 * 32;

// What errno says now (strerror), for an error message.
std::string errno_text();
// The temporary a file is written to before it is renamed into place: `path.tmp.PID`.
std::string temp_name(const std::string& path);

// Writes `text` to `path.tmp.PID`, fsyncs it and renames it over `path`, so readers see the old
// file or the new one, never a part. Throws OutputError (temporary removed) on failure.
void write_file_atomic(const std::string& path, const std::string& text);
// A whole file's bytes, at most max_bytes of them; throws std::runtime_error "PATH: cannot read:
// reason" (a directory included, and a file longer than max_bytes: /dev/zero or a FIFO ends
// there instead of filling the memory). The file readers turn it into their own error type.
std::string read_file_text(const std::string& path, size_t max_bytes = kMaxRecordFileBytes);

// Copies `from` over `to` through a temporary beside it, so readers see the old file or the new one.
void copy_file_atomic(const std::string& from, const std::string& to);

}  // namespace tippe
