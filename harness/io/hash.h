// The one content hash of the harness: FNV-1a 64 (scene hashes, sweep point ids, plan hashes).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace tippe {

// FNV-1a 64: not cryptographic; it names contents, so that a changed scene or sweep is noticed
// and records are matched to their points. Its values are in published records: never change it.
class Fnv1a64 {
 public:
  void add(unsigned char c) {
    h_ ^= c;
    h_ *= 0x100000001b3ULL;
  }
  void add(const std::string& bytes) {
    for (unsigned char c : bytes) add(c);
  }
  // 16 lower-case hex digits.
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
    return buf;
  }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// FNV-1a 64 of the parts, each followed by a 0 byte, as 16 hex digits.
inline std::string fnv1a_hex(const std::vector<std::string>& parts) {
  Fnv1a64 h;
  for (const auto& p : parts) {
    h.add(p);
    h.add(static_cast<unsigned char>(0));
  }
  return h.hex();
}

}  // namespace tippe
