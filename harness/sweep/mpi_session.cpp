// The MPI session and farm through the MPI module, opened when a launcher started the process: no other tippe maps libmpi.
#include <dlfcn.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engines/core/registry.h"
#include "harness/sweep/mpi_farm.h"
#include "harness/sweep/mpi_module.h"

namespace tippe {

namespace {

// lib/tippe/ beside libtippe_runtime.so (the build tree and an installed tree), found from the
// loader as the registry finds the engines' modules; for a program that links the runtime
// statically (TIPPE_ENGINE_MODULES=OFF), lib/tippe/ and ../lib/tippe/ beside the program.
std::vector<std::filesystem::path> mpi_module_candidates() {
  std::vector<std::filesystem::path> paths;
  std::error_code ec;
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&engine_module_dirs), &info) != 0 && info.dli_fname) {
    const std::filesystem::path lib = std::filesystem::canonical(info.dli_fname, ec);
    if (!ec) paths.push_back(lib.parent_path() / "tippe" / kMpiModuleFile);
  }
  const std::filesystem::path exe = std::filesystem::canonical("/proc/self/exe", ec);
  if (!ec)
    for (const auto& dir : {exe.parent_path() / "lib" / "tippe", exe.parent_path().parent_path() / "lib" / "tippe"})
      if (std::find(paths.begin(), paths.end(), dir / kMpiModuleFile) == paths.end()) paths.push_back(dir / kMpiModuleFile);
  return paths;
}

// RTLD_GLOBAL: Open MPI opens its own components, which take libmpi's symbols from the global
// scope (they do not name libmpi as a dependency). The module is never closed (MPI_Finalize runs
// from a destructor).
const MpiModule& mpi_module() {
  static const MpiModule* module = [] {
    std::string tried;
    for (const auto& path : mpi_module_candidates()) {
      std::error_code ec;
      if (!std::filesystem::exists(path, ec)) {
        tried += (tried.empty() ? "" : ", ") + path.string();
        continue;
      }
      void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
      if (!handle) throw std::runtime_error("cannot load the MPI module " + path.string() + ": " + dlerror());
      auto* entry = reinterpret_cast<const MpiModule* (*)()>(dlsym(handle, kMpiModuleEntry));
      if (!entry) throw std::runtime_error(path.string() + " is not tippe's MPI module (no " + kMpiModuleEntry + ")");
      return entry();
    }
    throw std::runtime_error(std::string("the MPI module ") + kMpiModuleFile + " was not found (tried " + tried + ")");
  }();
  return *module;
}

}  // namespace

MpiSession::MpiSession() { mpi_module().init(&rank_, &size_); }

MpiSession::~MpiSession() { mpi_module().finalize(); }

std::unique_ptr<TaskFarm> make_mpi_farm(const MpiSession& session) {
  return std::unique_ptr<TaskFarm>(mpi_module().make_farm(session.rank(), session.size()));
}

std::string mpi_library_version() { return mpi_module().library_version(); }

}  // namespace tippe
