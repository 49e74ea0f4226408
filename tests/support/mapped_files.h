// This process's mapped files (/proc/self/maps) by name: which libraries loading an engine's module brought in.
#pragma once

#include <fstream>
#include <string>
#include <vector>

// The lines of /proc/self/maps that contain any of `parts` (e.g. "libode", a library's file
// name), one per line; empty when none is mapped.
inline std::string mapped_lines(const std::vector<std::string>& parts) {
  std::ifstream maps("/proc/self/maps");
  std::string line, found;
  while (std::getline(maps, line))
    for (const std::string& part : parts)
      if (line.find(part) != std::string::npos) {
        found += line + "\n";
        break;
      }
  return found;
}
