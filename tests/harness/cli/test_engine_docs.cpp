// docs/engines.md is what `tippe info --markdown` prints from the engine registry: the committed settings reference never drifts from the code.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "engines/core/registry.h"
#include "tests/support/files.h"
#include "tests/support/process.h"

namespace test_engine_docs {

namespace {

namespace fs = std::filesystem;

std::string generated(const TempDir& dir) {
  const fs::path out = dir.path() / "engines.md", err = dir.path() / "stderr.txt";
  const pid_t pid = spawn_process({std::string(TIPPE_BINARY_DIR) + "/tippe", "info", "--markdown"}, out, err);
  const ChildExit e = wait_process_within(pid, 60);
  EXPECT_EQ(e.code, 0) << slurp(err);
  return slurp(out);
}

TEST(EngineDocs, CommittedFileIsTheGeneratedOne) {
  TempDir dir("tippe-engine-docs");
  const std::string now = generated(dir);
  const std::string committed = slurp(fs::path(TIPPE_SOURCE_DIR) / "docs" / "engines.md");
  EXPECT_EQ(committed, now) << "docs/engines.md differs from the registry's settings; regenerate it:\n"
                               "  ./build/tippe info --markdown > docs/engines.md";
}

// What the comparison rests on: every registered simulator and every one of its settings (with
// its default) is in the generated text, so a setting added to a `visit` shows up in it.
TEST(EngineDocs, EverySettingOfEveryEngineIsListed) {
  TempDir dir("tippe-engine-docs");
  const std::string text = generated(dir);
  for (const tippe::EngineInfo& e : tippe::engine_registry()) {
    EXPECT_NE(text.find("\n## " + e.name + "\n"), std::string::npos) << e.name;
    ASSERT_TRUE(e.describe_settings) << e.name << " registers no describe_settings";
    const auto docs = e.describe_settings();
    const auto defaults = e.default_settings();
    ASSERT_EQ(docs.size(), defaults.size()) << e.name;
    for (size_t i = 0; i < docs.size(); ++i) {
      EXPECT_EQ(docs[i].key, defaults[i].first) << e.name;
      EXPECT_NE(text.find("| `" + docs[i].key + "` |"), std::string::npos) << e.name << "." << docs[i].key;
    }
  }
}

}  // namespace

}  // namespace test_engine_docs
