// The process-wide progress mode: a terminal gets a redrawn line, anything else whole lines.
#include "harness/io/progress.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>

namespace tippe {

namespace {
// -1: not set yet (decided from stderr on first use).
std::atomic<int> g_mode{-1};
}  // namespace

ProgressMode progress_mode_for_stderr(bool quiet) {
  if (quiet) return ProgressMode::Quiet;
  return ::isatty(STDERR_FILENO) ? ProgressMode::Redraw : ProgressMode::Lines;
}

ProgressMode progress_mode() {
  int m = g_mode.load();
  if (m < 0) {
    m = static_cast<int>(progress_mode_for_stderr(false));
    g_mode.store(m);
  }
  return static_cast<ProgressMode>(m);
}

void set_progress_mode(ProgressMode mode) { g_mode.store(static_cast<int>(mode)); }

void ProgressLine::write(std::string line, bool final_line) {
  if (whole_lines_) {
    std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
    return;
  }
  const size_t len = line.size();
  if (line.size() < width_) line.append(width_ - line.size(), ' ');
  width_ = len;
  std::fprintf(stderr, "\r%s", line.c_str());
  if (final_line) std::fputc('\n', stderr);
  std::fflush(stderr);
}

}  // namespace tippe
