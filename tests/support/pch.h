// The test programs' precompiled header: the system and library headers most of them parse.
// Only headers outside the project (a change to the project's headers rebuilds what uses them,
// not this header). Parsing these is a third of a test program's compile time (test_metrics:
// 16.8 -> 11.2 s, test_ode 5.3 -> 4.1 s, test_cli_conventions 10.0 -> 8.3 s with g++ 12 at -O1):
// CI builds every program twice (Release and the sanitizers).
#pragma once
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <variant>
#include <vector>
