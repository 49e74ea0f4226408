// The registry of simulators: the reference, linked in, and the engines of engine_list.h (one line each), each loaded from its module on first use.
#include "engines/core/registry.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>

#ifdef TIPPE_ENGINE_MODULES
#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#endif

namespace tippe {

EngineLoadError::~EngineLoadError() = default;

namespace {

// One registered simulator: its name, and its entry once loaded. The reference's entry is there
// from the start; an engine's is set once, under the registry's mutex, and never cleared (a
// module is never closed: its code may be on the stack of an atexit handler or a sanitizer's
// report, and its EngineInfo is referenced for the life of the process).
struct Slot {
  std::string name;
  std::atomic<const EngineInfo*> info{nullptr};
#if !defined(TIPPE_ENGINE_MODULES) && !defined(TIPPE_REFERENCE_ONLY)
  const EngineInfo* (*entry)() = nullptr;  // linked in: the engine's entry point itself
#endif
};

#if !defined(TIPPE_ENGINE_MODULES) && !defined(TIPPE_REFERENCE_ONLY)
}  // namespace
}  // namespace tippe
// Linked in (TIPPE_ENGINE_MODULES=OFF): the entry points the modules would export.
#define TIPPE_ENGINE(name) extern "C" const ::tippe::EngineInfo* tippe_engine_##name();
#include "engines/core/engine_list.h"
#undef TIPPE_ENGINE
namespace tippe {
namespace {
#endif

std::vector<Slot>& slots() {
  static std::vector<Slot> all = [] {
    std::vector<Slot> v(1
#ifndef TIPPE_REFERENCE_ONLY
#define TIPPE_ENGINE(name) +1
#include "engines/core/engine_list.h"
#undef TIPPE_ENGINE
#endif
    );
    v[0].name = analytic_engine_info().name;
    v[0].info = &analytic_engine_info();
#ifndef TIPPE_REFERENCE_ONLY
    size_t i = 1;
#if defined(TIPPE_ENGINE_MODULES)
#define TIPPE_ENGINE(engine) v[i++].name = #engine;
#else
#define TIPPE_ENGINE(engine) v[i].name = #engine, v[i++].entry = tippe_engine_##engine;
#endif
#include "engines/core/engine_list.h"
#undef TIPPE_ENGINE
#endif
    return v;
  }();
  return all;
}

Slot* find_slot(const std::string& name) {
  for (Slot& s : slots())
    if (s.name == name) return &s;
  return nullptr;
}

#ifdef TIPPE_ENGINE_MODULES
// The directory of the shared library (or executable) this code is in, from the loader itself.
std::string own_directory() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&own_directory), &info) == 0 || !info.dli_fname) return "";
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::canonical(info.dli_fname, ec);
  return ec ? std::filesystem::path(info.dli_fname).parent_path().string() : p.parent_path().string();
}

// dlopen with RTLD_NOW (a symbol the module needs and nothing provides fails here, with the
// loader's message, not at some later call) and RTLD_LOCAL (the module's engine libraries stay
// out of the global scope: two modules may carry libraries that export the same C++ symbols).
// The module finds the bench's own code (the Simulator interface, the shared step checks, the
// reference model) in the one shared runtime it links, already loaded: one copy of each typeinfo
// and vtable, so dynamic_cast and catching an exception across the module boundary see one type.
const EngineInfo* load_module(const Slot& slot) {
  const std::string file = engine_module_file(slot.name);
  std::string tried;
  for (const std::string& dir : engine_module_dirs()) {
    const std::filesystem::path path = std::filesystem::path(dir) / file;
    tried += (tried.empty() ? "" : ", ") + path.string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) continue;
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      throw EngineLoadError("engine \"" + slot.name + "\": cannot load its module " + path.string() + ": " +
                            (why ? why : "dlopen failed"));
    }
    const std::string symbol = "tippe_engine_" + slot.name;
    dlerror();
    void* entry = dlsym(handle, symbol.c_str());
    if (!entry) {
      const char* why = dlerror();
      throw EngineLoadError("engine \"" + slot.name + "\": its module " + path.string() + " has no entry point " +
                            symbol + (why ? std::string(": ") + why : std::string()));
    }
    const EngineInfo* info = reinterpret_cast<const EngineInfo* (*)()>(entry)();
    if (!info || info->name != slot.name)
      throw EngineLoadError("engine \"" + slot.name + "\": its module " + path.string() + " registers " +
                            (info ? "\"" + info->name + "\"" : std::string("nothing")));
    return info;
  }
  throw EngineLoadError("engine \"" + slot.name + "\": its module " + file + " was not found (tried " + tried +
                        "; TIPPE_ENGINE_PATH names other directories)");
}
#endif

const EngineInfo& load(Slot& slot) {
  if (const EngineInfo* info = slot.info.load(std::memory_order_acquire)) return *info;
#ifdef TIPPE_REFERENCE_ONLY
  throw std::logic_error("engine \"" + slot.name + "\" registered without an entry");
#else
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  if (const EngineInfo* info = slot.info.load(std::memory_order_acquire)) return *info;
#ifdef TIPPE_ENGINE_MODULES
  const EngineInfo* info = load_module(slot);
#else
  const EngineInfo* info = slot.entry();
#endif
  slot.info.store(info, std::memory_order_release);
  return *info;
#endif
}

}  // namespace

bool engines_in_modules() {
#ifdef TIPPE_ENGINE_MODULES
  return true;
#else
  return false;
#endif
}

std::string engine_module_file(const std::string& name) { return "libtippe_engine_" + name + ".so"; }

std::vector<std::string> engine_module_dirs() {
  std::vector<std::string> dirs;
#ifdef TIPPE_ENGINE_MODULES
  if (const char* env = std::getenv("TIPPE_ENGINE_PATH")) {
    std::string s = env;
    for (size_t start = 0; start <= s.size();) {
      const size_t end = std::min(s.find(':', start), s.size());
      if (end > start) dirs.push_back(s.substr(start, end - start));
      start = end + 1;
    }
  }
  if (!dirs.empty()) return dirs;
  const std::string own = own_directory();
  if (!own.empty()) dirs.push_back((std::filesystem::path(own) / "tippe" / "engines").string());
#endif
  return dirs;
}

const std::vector<EngineInfo>& engine_registry() {
  static const std::vector<EngineInfo> registry = [] {
    std::vector<EngineInfo> v;
    for (Slot& s : slots()) v.push_back(load(s));
    return v;
  }();
  return registry;
}

const EngineInfo* find_engine(const std::string& name) {
  Slot* s = find_slot(name);
  return s ? &load(*s) : nullptr;
}

bool engine_loaded(const std::string& name) {
  const Slot* s = find_slot(name);
  return s && s->info.load(std::memory_order_acquire) != nullptr;
}

const std::vector<EngineFileSetting>& engine_file_settings() {
  static const std::vector<EngineFileSetting> all = {
#define TIPPE_ENGINE_FILE(engine, key, what) {#engine, #key, what},
#include "engines/core/engine_list.h"
#undef TIPPE_ENGINE_FILE
  };
  return all;
}

std::string engine_list_text(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return s;
}

const EngineInfo& engine_info(const std::string& name) {
  if (const EngineInfo* e = find_engine(name)) return *e;
  throw std::invalid_argument("unknown engine \"" + name + "\" (expected " + engine_list_text(available_engines()) + ")");
}

const EngineInfo& reference_engine() { return analytic_engine_info(); }

std::vector<std::string> available_engines() {
  std::vector<std::string> names;
  for (const Slot& s : slots()) names.push_back(s.name);
  return names;
}

std::vector<std::string> engine_names() {
  std::vector<std::string> names;
  for (const Slot& s : slots())
    if (s.name != reference_engine().name) names.push_back(s.name);
  return names;
}

std::string engine_plot_colour(const std::string& name) {
  // A colour is no reason to fail a report: an engine whose module cannot be loaded is grey,
  // as a name from an old record is.
  try {
    const EngineInfo* e = find_engine(name);
    return e ? e->colour : "#7f7f7f";
  } catch (const EngineLoadError&) {
    return "#7f7f7f";
  }
}

void validate_engine_settings(const Scene& scene) {
  for (const auto& kv : scene.engines) {
    const Slot* slot = find_slot(kv.first);
#ifdef TIPPE_REFERENCE_ONLY
    // Tables of engines this library does not have: the reference never reads them, and checking
    // them needs those engines' settings, so they are accepted unread (a scene valid in the full
    // build stays valid here).
    if (!slot) continue;
#endif
    if (!slot) throw std::invalid_argument("engines." + kv.first + ": unknown engine (expected " +
                                           engine_list_text(available_engines()) + ")");
    // An engine's empty [engines.NAME] table sets nothing: the engine's checks of its defaults
    // against the scene run when it is made (every adapter reads and checks its settings in its
    // constructor), so a run of another simulator does not load this engine's module for it.
    if (kv.second.empty() && kv.first != reference_engine().name) continue;
    engine_info(kv.first).validate(scene);
  }
}

std::unique_ptr<Simulator> make_simulator(const std::string& engine, const Scene& scene) {
#ifdef TIPPE_REFERENCE_ONLY
  if (!find_slot(engine))
#ifdef TIPPE_ENGINES_IN_MODULES
    throw std::invalid_argument("engine \"" + engine +
                                "\" is not in this static library: the engines are modules of the shared build "
                                "(the tippe command); configure with TIPPE_ENGINE_MODULES=OFF for a static "
                                "library with every engine linked in");
#else
    throw std::invalid_argument("engine \"" + engine +
                                "\" is not built (configured with TIPPE_ENGINES=OFF: only the reference is available)");
#endif
#endif
  return engine_info(engine).make(scene);
}

}  // namespace tippe
