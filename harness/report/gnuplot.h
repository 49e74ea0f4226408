// The one gnuplot writer: scripts from the program's own text (figures, series styles, engine markers), data only in .dat files, run without a shell.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

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

// One curve of a figure: block `index` of `data_file` (a name the program made, e.g. plot-2.dat),
// columns 1:2, titled by the block's header line (gp_column_header).
struct GpSeries {
  std::string data_file;
  int index = 0;
  std::string colour = "#000000";  // #rrggbb
  double line_width = 1.5;
  int dash = 1;          // gnuplot dashtype 1..5
  int point_type = 0;    // 0: a line without markers
  int point_every = 1;   // a marker every N points (pointinterval)
  bool points_only = false;
};

// One SVG. Every string is the program's own (gp_literal refuses anything else).
struct GpFigure {
  std::string output, title, xlabel, ylabel;
  bool logx = false, logy = false;
  bool equal_axes = false;                       // a path in the plane
  std::optional<double> xmark, ymark;            // a dashed vertical / horizontal line
  std::optional<std::pair<double, double>> yrange;
  std::vector<GpSeries> series;
};

struct GpPage {
  std::string comment;  // the script's first line, after "# "
  int width = 960, height = 540;
  int font_size = 13;
  std::string key = "below horizontal";  // gnuplot `set key` text
};

// The script that draws every figure with at least one series, each into its own output; the
// figures' settings are reset between them.
std::string gnuplot_script(const GpPage& page, const std::vector<GpFigure>& figures);

// Colour-blind-safe markers: a distinct gnuplot point type for each registered engine (by its
// place in the registry, so that a marker means the same engine on every page), a spare one for
// a name no longer registered. Colours are the registry's (EngineInfo::colour).
int engine_point_type(const std::string& engine);
std::string engine_colour(const std::string& engine);

}  // namespace tippe
