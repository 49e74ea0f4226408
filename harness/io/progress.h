// How progress reaches stderr: redrawn in place on a terminal, a line now and then in a log, or not at all (--quiet).
#pragma once

#include <cstddef>
#include <string>

namespace tippe {

enum class ProgressMode { Redraw, Lines, Quiet };

// Process-wide, set once by main (--quiet -> Quiet). Until set: Redraw when stderr is a terminal,
// Lines otherwise, so that a CI log or a file gets whole lines, never carriage returns.
ProgressMode progress_mode();
void set_progress_mode(ProgressMode mode);
// Quiet when asked, else by what stderr is.
ProgressMode progress_mode_for_stderr(bool quiet);

// In Lines mode, at most one line per this many seconds of a long run (and one at its end): a
// log of a 20-minute sweep gets ~120 lines, not the ten redraws a second a terminal gets.
inline constexpr double kProgressLineSeconds = 10.0;

// The one writer of a progress line on stderr, shared by every progress display: as a whole line
// (`whole_lines`: a log), or redrawn in place with '\r', padded over the tail of the longer line
// drawn before (`width` keeps that length between calls), with a newline after the final one.
class ProgressLine {
 public:
  explicit ProgressLine(bool whole_lines) : whole_lines_(whole_lines) {}
  void write(std::string line, bool final_line);

 private:
  bool whole_lines_;
  size_t width_ = 0;
};

}  // namespace tippe
