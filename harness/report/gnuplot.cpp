// The one gnuplot writer: scripts from the program's own text, data only in .dat files, run without a shell.
#include "harness/report/gnuplot.h"

#include "engines/core/registry.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

extern char** environ;

namespace tippe {

namespace {

bool executable(const std::string& path) {
  std::error_code ec;
  return ::access(path.c_str(), X_OK) == 0 && !std::filesystem::is_directory(path, ec);
}

}  // namespace

std::string gnuplot_command(std::string* why_not) {
  auto say = [&](const std::string& why) {
    if (why_not) *why_not = why;
    return std::string();
  };
  if (const char* env = std::getenv("TIPPE_GNUPLOT"); env && *env) {
    if (std::string(env) == "none") return say("plots skipped: disabled by TIPPE_GNUPLOT=none");
    return env;
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/gnuplot";
    if (executable(candidate)) return candidate;
  }
  return say("plots skipped: gnuplot not found");
}

std::string gp_literal(const std::string& text) {
  for (unsigned char c : text) {
    // Bytes >= 0x80 are UTF-8 (the program's own labels use θ): they cannot end a string.
    if (c < 0x20 || c == 0x7f || c == '\'' || c == '"' || c == '\\' || c == '`' || c == '@' || c == '$')
      throw std::logic_error("gnuplot script: refusing to quote \"" + text + "\" (not a label of the program's own)");
  }
  return "'" + text + "'";
}

std::string gp_column_header(const std::string& title) {
  std::string out = "\"";
  for (unsigned char c : title) out += (c < 0x20 || c == 0x7f || c == '"') ? '_' : static_cast<char>(c);
  return out + "\"";
}

int run_gnuplot(const std::string& program, const std::filesystem::path& dir, const std::string& script,
                const std::string& log) {
  posix_spawn_file_actions_t actions;
  if (posix_spawn_file_actions_init(&actions) != 0) return 127;
  const std::string dir_text = dir.string();
  // The child's own working directory: the script names its files relative to dir.
  int rc = posix_spawn_file_actions_addchdir_np(&actions, dir_text.c_str());
  if (rc == 0) rc = posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  if (rc == 0) rc = posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (rc == 0) rc = posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  std::vector<char*> argv = {const_cast<char*>(program.c_str()), const_cast<char*>(script.c_str()), nullptr};
  if (rc == 0) rc = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return 127;
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return -1;
}

namespace {

std::string g9(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

std::string gnuplot_script(const GpPage& page, const std::vector<GpFigure>& figures) {
  std::string s = "# " + page.comment + "\n";
  s += "set encoding utf8\n";
  s += "set terminal svg size " + std::to_string(page.width) + "," + std::to_string(page.height) +
       " dynamic noenhanced font 'Helvetica," + std::to_string(page.font_size) + "' background rgb 'white'\n";
  s += "set grid lc rgb '#dddddd'\nset border lc rgb '#444444'\n";
  s += "set key " + page.key + "\n";
  for (const GpFigure& f : figures) {
    if (f.series.empty()) continue;
    s += "\nset output " + gp_literal(f.output) + "\n";
    s += "set title " + gp_literal(f.title) + "\n";
    s += "set xlabel " + gp_literal(f.xlabel) + "\nset ylabel " + gp_literal(f.ylabel) + "\n";
    s += f.logx ? "set logscale x\nset format x '%g'\n" : "unset logscale x\nset format x '%g'\n";
    s += f.logy ? "set logscale y\nset format y '%g'\n" : "unset logscale y\nset format y '%g'\n";
    s += f.equal_axes ? "set size ratio -1\n" : "set size noratio\n";
    s += f.yrange ? "set yrange [" + g9(f.yrange->first) + ":" + g9(f.yrange->second) + "]\n"
                  : std::string("set autoscale y\n");
    // Keeps the extreme points of a log axis off the frame.
    s += std::string("set offsets ") + (f.logx ? "graph 0.04, graph 0.04" : "0, 0") + ", " +
         (f.logx || f.logy ? "graph 0.06, graph 0.06" : "0, 0") + "\n";
    s += "unset arrow\n";
    if (f.xmark && std::isfinite(*f.xmark))
      s += "set arrow 1 from " + g9(*f.xmark) + ", graph 0 to " + g9(*f.xmark) +
           ", graph 1 nohead dashtype 2 lc rgb '#888888'\n";
    if (f.ymark && std::isfinite(*f.ymark))
      s += "set arrow 2 from graph 0, first " + g9(*f.ymark) + " to graph 1, first " + g9(*f.ymark) +
           " nohead dashtype 2 lc rgb '#555555'\n";
    s += "plot ";
    for (size_t i = 0; i < f.series.size(); ++i) {
      const GpSeries& r = f.series[i];
      if (i) s += ", \\\n     ";
      s += gp_literal(r.data_file) + " index " + std::to_string(r.index) + " using 1:2";
      if (r.points_only)
        s += " with points pt " + std::to_string(r.point_type) + " ps 1.2";
      else if (r.point_type > 0)
        s += " with linespoints lw " + g9(r.line_width) + " dt " + std::to_string(r.dash) + " pt " +
             std::to_string(r.point_type) + " pi " + std::to_string(r.point_every < 1 ? 1 : r.point_every) + " ps 0.9";
      else
        s += " with lines lw " + g9(r.line_width) + " dt " + std::to_string(r.dash);
      s += " lc rgb " + gp_literal(r.colour) + " title columnheader(1)";
    }
    s += "\nunset output\n";
  }
  return s;
}

int engine_point_type(const std::string& engine) {
  // Filled circle, square, triangle, diamond, inverted triangle, then open ones: told apart in
  // grey print and by readers who cannot tell the colours apart.
  static const int types[] = {7, 5, 9, 13, 11, 6, 4, 8};
  const std::vector<std::string> all = available_engines();  // names only: no engine module loaded
  for (size_t i = 0; i < all.size(); ++i)
    if (all[i] == engine) return types[i % 8];
  return 2;  // a cross: a name from an old record
}

std::string engine_colour(const std::string& engine) { return engine_plot_colour(engine); }

}  // namespace tippe
