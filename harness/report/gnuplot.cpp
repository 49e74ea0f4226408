// Runs gnuplot on a script the program wrote, without a shell, and quotes only the program's own strings into it.
#include "report/gnuplot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
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

}  // namespace tippe
