// Runs gnuplot on a script the program wrote, without a shell, and quotes only the program's own strings into it.
#pragma once

#include <filesystem>
#include <string>

namespace tippe {

// Nothing read from a file (a scene or engine name, a setup, a description) is ever part of a
// gnuplot script: records are files people share and download, and a gnuplot script can run
// commands (`system`, backquotes, a newline ending a string). Labels that come from data go into
// the data files, read back with `title columnheader(1)`, where gnuplot only ever sees data.

// The command that runs gnuplot: $TIPPE_GNUPLOT when set ("none" disables plots), else gnuplot
// found on PATH. Empty when there is none; `why_not` then says why, as the page should. It is one
// program path, run without a shell.
std::string gnuplot_command(std::string* why_not = nullptr);

// A single-quoted gnuplot string of a label or file name that the program wrote itself. Throws
// std::logic_error (a bug, never input) for a character that could end the string or be expanded
// (a quote, a backslash, a backquote, '@', '$', a control character).
std::string gp_literal(const std::string& text);

// A data block's header line (its first line; `title columnheader(1)` reads it): the title as one
// double-quoted field. Characters gnuplot's data reader would split on (a double quote, a
// control character) become '_': the line is data, so nothing in it can run.
std::string gp_column_header(const std::string& title);

// Runs `program script` with `dir` as working directory, stdin from /dev/null and stdout and
// stderr into dir/log, never through a shell. Returns the exit status, 127 when the program could
// not be started, -1 when it died from a signal.
int run_gnuplot(const std::string& program, const std::filesystem::path& dir, const std::string& script,
                const std::string& log);

}  // namespace tippe
