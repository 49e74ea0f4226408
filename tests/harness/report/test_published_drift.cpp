// The drift check of the published records (scripts/check-published.sh, scripts/check_published.py): a fresh run of the code passes against reports/, and a published record edited on purpose (status, class, regime, an event time by more than 1e-6) fails it.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/support/files.h"
#include "tests/support/process.h"

namespace test_published_drift {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kSource = TIPPE_SOURCE_DIR;
const fs::path kReports = kSource / "reports";
// The cheapest published scene (0.6 CPU s of engines): the end-to-end runs use it alone.
const std::string kScene = "leine_glocker_coupled";

struct Outcome {
  ChildExit exit;
  std::string out;
};

Outcome run(const std::vector<std::string>& argv, const TempDir& dir) {
  const fs::path out = dir.path() / "output.txt";
  const pid_t pid = spawn_process(argv, out, out);
  Outcome r;
  r.exit = wait_process_within(pid, 300);
  r.out = slurp(out);
  return r;
}

Outcome check(const std::string& kind, const fs::path& published, const fs::path& fresh, const TempDir& dir) {
  return run({"python3", (kSource / "scripts/check_published.py").string(), kind, published.string(), fresh.string()}, dir);
}

// scripts/check-published.sh against PUBLISHED (a copy of reports/, tampered or not), on kScene
// alone or on the sweep alone.
Outcome check_published(const fs::path& published, bool sweep, const TempDir& dir) {
  return run({"env", "PUBLISHED_DIR=" + published.string(), "CHECK_SCENES=" + std::string(sweep ? "" : kScene),
              "CHECK_SWEEP=" + std::string(sweep ? "harness/sweeps/published-check.toml" : ""), "JOBS=2", "bash",
              (kSource / "scripts/check-published.sh").string(), TIPPE_BINARY_DIR},
             dir);
}

json read_json(const fs::path& p) { return json::parse(slurp(p)); }

// The first engine of a comparison that has an event, and that event's index: what gets moved.
std::pair<size_t, size_t> first_event(const json& c) {
  for (size_t e = 0; e < c.at("engines").size(); ++e)
    if (!c.at("engines")[e].at("summary").value("events", json::array()).empty()) return {e, 0};
  return {0, 0};
}

class ComparisonDrift : public ::testing::Test {
 protected:
  void SetUp() override {
    published_ = kReports / kScene / "comparison.json";
    record_ = read_json(published_);
  }
  // A copy of the published record with `edit` applied, checked against the published one.
  Outcome tampered(const std::function<void(json&)>& edit) {
    json c = record_;
    edit(c);
    const std::string file = dir_.write("tampered.json", c.dump(2));
    return check("comparison", published_, file, dir_);
  }
  TempDir dir_{"tippe-drift"};
  fs::path published_;
  json record_;
};

TEST_F(ComparisonDrift, TheSameRecordPasses) {
  const Outcome r = check("comparison", published_, published_, dir_);
  EXPECT_EQ(r.exit.code, 0) << r.out;
  EXPECT_NE(r.out.find("as published"), std::string::npos) << r.out;
}

TEST_F(ComparisonDrift, EachEditedFieldIsCaught) {
  // Plain variables, not a structured binding: the lambdas below capture them (C++17).
  const size_t e = first_event(record_).first, k = first_event(record_).second;
  ASSERT_FALSE(record_.at("engines")[e].at("summary").at("events").empty()) << "no engine of " << kScene << " has an event";
  const std::string engine = record_.at("engines")[e].at("engine");
  // Status.
  Outcome r = tampered([&](json& c) { c["engines"][e]["summary"]["status"] = "diverged"; });
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find(engine + ": status published 'ok', now 'diverged'"), std::string::npos) << r.out;
  // Regime: an inversion where there was none, or none where there was one.
  r = tampered([&](json& c) {
    json& s = c["engines"][e]["summary"];
    s["inversion_time"] = s["inversion_time"].is_number() ? json(nullptr) : json(1.0);
  });
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find(engine + ": regime published"), std::string::npos) << r.out;
  // An event time moved by 1e-5 relative (beyond 1e-6) is caught; by 1e-7 it is not.
  r = tampered([&](json& c) {
    json& t = c["engines"][e]["summary"]["events"][k]["time"];
    t = t.get<double>() * (1 + 1e-5) + 1e-5;
  });
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find(engine + ": event " + std::to_string(k) + " published"), std::string::npos) << r.out;
  r = tampered([&](json& c) {
    json& t = c["engines"][e]["summary"]["events"][k]["time"];
    t = t.get<double>() * (1 + 1e-7);
  });
  EXPECT_EQ(r.exit.code, 0) << r.out;
  // A dropped engine.
  r = tampered([&](json& c) { c["engines"].erase(c["engines"].begin() + static_cast<long>(e)); });
  EXPECT_EQ(r.exit.code, 1) << r.out;
}

TEST(SweepDrift, AnEditedClassOrRegimeIsCaught) {
  TempDir dir("tippe-drift");
  const fs::path published = kReports / "sweep-default" / "records.jsonl";
  const std::string text = slurp(published);
  ASSERT_FALSE(text.empty());
  const json first = json::parse(text.substr(0, text.find('\n')));
  // The check reads the fresh records' points among the published ones: the first line alone.
  const std::string fresh = dir.write("fresh.jsonl", first.dump() + "\n");
  Outcome r = check("sweep", published, fresh, dir);
  EXPECT_EQ(r.exit.code, 0) << r.out;
  json edited = first;
  edited["class"]["name"] = first["class"]["name"] == "ok" ? "diverged" : "ok";
  r = check("sweep", published, dir.write("class.jsonl", edited.dump() + "\n"), dir);
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find("class published"), std::string::npos) << r.out;
  edited = first;
  edited["metrics"]["inversion_event"] = "drifted";
  r = check("sweep", published, dir.write("regime.jsonl", edited.dump() + "\n"), dir);
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find("regime (inversion event) published"), std::string::npos) << r.out;
  edited = first;
  edited["point_id"] = "0000000000000000";
  r = check("sweep", published, dir.write("unknown.jsonl", edited.dump() + "\n"), dir);
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find("is not among the published records"), std::string::npos) << r.out;
}

// End to end, as CI runs it: the code gives the published record of kScene, and the same check
// against a copy of that record with one event time moved fails, naming it.
TEST(PublishedDrift, TheCheckPassesOnThePublishedRecordAndFailsOnAnEditedCopy) {
  TempDir dir("tippe-drift");
  const fs::path copy = dir.path() / "reports";
  fs::create_directories(copy / kScene);
  fs::copy_file(kReports / kScene / "comparison.json", copy / kScene / "comparison.json");
  Outcome r = check_published(copy, false, dir);
  ASSERT_EQ(r.exit.code, 0) << "the code no longer gives reports/" << kScene << " (republish):\n" << r.out;

  json c = read_json(copy / kScene / "comparison.json");
  const size_t e = first_event(c).first, k = first_event(c).second;
  json& t = c["engines"][e]["summary"]["events"][k]["time"];
  t = t.get<double>() + 1e-3;
  spit(copy / kScene / "comparison.json", c.dump(2));
  r = check_published(copy, false, dir);
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find("drift: " + kScene + ": " + c["engines"][e]["engine"].get<std::string>() + ": event " +
                       std::to_string(k) + " published"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("republish from a clean checkout"), std::string::npos) << r.out;
}

// The sweep part: the points of harness/sweeps/published-check.toml are among the published
// default sweep's and agree with them; a published class edited on purpose fails.
TEST(PublishedDrift, TheSweepPointsMatchThePublishedSweepAndAnEditedClassFails) {
  TempDir dir("tippe-drift");
  const fs::path copy = dir.path() / "reports";
  fs::create_directories(copy / "sweep-default");
  const fs::path records = copy / "sweep-default" / "records.jsonl";
  fs::copy_file(kReports / "sweep-default" / "records.jsonl", records);
  Outcome r = check_published(copy, true, dir);
  ASSERT_EQ(r.exit.code, 0) << "the code no longer gives reports/sweep-default's points (republish):\n" << r.out;

  // Every published record of toy_viscous at ODE's 1e-3 step (a point of the check) gets another class.
  std::string edited, line;
  std::istringstream in(slurp(records));
  size_t n = 0;
  while (std::getline(in, line)) {
    json j = json::parse(line);
    if (j["scene"] == "toy_viscous" && j["setup"] == "ode" && j["ladder_label"] == "0.001") {
      j["class"]["name"] = j["class"]["name"] == "ok" ? "unphysical" : "ok";
      ++n;
    }
    edited += j.dump() + "\n";
  }
  ASSERT_EQ(n, 1u);
  spit(records, edited);
  r = check_published(copy, true, dir);
  EXPECT_EQ(r.exit.code, 1) << r.out;
  EXPECT_NE(r.out.find("drift: toy_viscous ode engines.ode.timestep=0.001: class published"), std::string::npos) << r.out;
}

}  // namespace

}  // namespace test_published_drift
