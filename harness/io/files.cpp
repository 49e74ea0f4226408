// Whole files: read with a size bound, written and copied atomically.
#include "harness/io/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace tippe {

std::string errno_text() { return std::strerror(errno); }

std::string temp_name(const std::string& path) { return path + ".tmp." + std::to_string(::getpid()); }

void write_file_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = temp_name(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError(path + ": cannot write: " + errno_text());
  auto fail = [&](const char* what) {
    const std::string why = errno_text();
    ::close(fd);
    ::unlink(tmp.c_str());
    throw OutputError(path + ": " + what + ": " + why);
  };
  const char* p = text.data();
  size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot write");
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) fail("cannot sync");
  if (::close(fd) != 0) {
    const std::string why = errno_text();
    ::unlink(tmp.c_str());
    throw OutputError(path + ": cannot close: " + why);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = errno_text();
    ::unlink(tmp.c_str());
    throw OutputError(path + ": cannot rename " + tmp + ": " + why);
  }
}

std::string read_file_text(const std::string& path, size_t max_bytes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw std::runtime_error(path + ": cannot read: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read: " + errno_text());
  // Chunks up to one byte past the bound, so that an endless file (/dev/zero) stops there.
  std::string text;
  char buf[1 << 16];
  while (in) {
    in.read(buf, static_cast<std::streamsize>(std::min(sizeof buf, max_bytes + 1 - text.size())));
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (text.size() > max_bytes)
      throw std::runtime_error(path + ": cannot read: larger than " + std::to_string(max_bytes) +
                               " bytes (the bound for this kind of file)");
  }
  if (in.bad()) throw std::runtime_error(path + ": cannot read: " + errno_text());
  return text;
}

void copy_file_atomic(const std::string& from, const std::string& to) {
  const std::string tmp = temp_name(to);
  std::filesystem::copy_file(from, tmp, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::rename(tmp, to);
}

}  // namespace tippe
