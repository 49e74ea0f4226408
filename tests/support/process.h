// Child processes for the tests that run the tool itself: fork and exec without a shell, output into files, waits with a deadline.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

struct ChildExit {
  int code = -1;           // exit status; -1 when a signal ended it (or it was killed at the deadline)
  int signal = 0;          // the signal that ended it
  bool timed_out = false;  // still running at the deadline of wait_process_within, and killed
};

// Starts argv[0] (looked up in PATH when it has no '/') with its stdout into out_file and its
// stderr into err_file; the same path for both gives one file with both, in order.
inline pid_t spawn_process(const std::vector<std::string>& argv, const std::filesystem::path& out_file,
                           const std::filesystem::path& err_file) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = err_file == out_file ? out : ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, 1);
    ::dup2(err, 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  return pid;
}

inline ChildExit exit_of(int status) {
  ChildExit e;
  if (WIFEXITED(status)) e.code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) e.signal = WTERMSIG(status);
  return e;
}

inline ChildExit wait_process(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return exit_of(status);
}

// wait_process, but a child still running after `seconds` (a hung job) is sent SIGTERM, reaped
// and reported with timed_out.
inline ChildExit wait_process_within(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return exit_of(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGTERM);
  ChildExit e = wait_process(pid);
  e.code = -1;
  e.timed_out = true;
  return e;
}
