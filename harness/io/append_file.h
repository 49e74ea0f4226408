// An append-only file of whole lines, each fsynced before the next is counted (records.jsonl survives a crash).
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>

namespace tippe {

class RecordAppender {
 public:
  explicit RecordAppender(const std::filesystem::path& path) : path_(path.string()) {
    const bool existed = std::filesystem::exists(path);
    fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw std::runtime_error(path_ + ": cannot open: " + std::strerror(errno));
    if (!existed) {
      // The new file's directory entry must survive a crash too.
      const int dir = ::open(path.parent_path().empty() ? "." : path.parent_path().c_str(), O_RDONLY | O_CLOEXEC);
      if (dir >= 0) {
        ::fsync(dir);
        ::close(dir);
      }
    }
  }
  ~RecordAppender() {
    if (fd_ >= 0) ::close(fd_);
  }
  RecordAppender(const RecordAppender&) = delete;
  RecordAppender& operator=(const RecordAppender&) = delete;

  void append(const std::string& line) {
    std::lock_guard<std::mutex> lock(m_);
    size_t off = 0;
    while (off < line.size()) {
      const ssize_t n = ::write(fd_, line.data() + off, line.size() - off);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw std::runtime_error(path_ + ": cannot write: " + std::strerror(errno));
      off += static_cast<size_t>(n);
    }
    if (::fsync(fd_) != 0) throw std::runtime_error(path_ + ": cannot sync: " + std::strerror(errno));
  }

 private:
  std::string path_;
  int fd_ = -1;
  std::mutex m_;
};

}  // namespace tippe
