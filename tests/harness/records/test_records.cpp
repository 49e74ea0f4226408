// Tests of run records (harness/records/records.cpp): the summary of samples, JSON round trips and older summaries, atomic files, the trajectory CSV, and counts read back as integers.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/measure/compare.h"
#include "harness/records/records.h"
#include "tests/support/files.h"
#include "tests/support/observations.h"

namespace test_records {

namespace fs = std::filesystem;
using namespace tippe;

namespace {

using namespace tippe::fixtures;

TEST(Records, JellettDriftPerSurface) {
  SampleSummary sum;
  sum.add(sample(0, Surface::Ball, 2.0));
  sum.add(sample(1, Surface::Ball, 2.002));  // 1e-3
  sum.add(sample(2, Surface::Ball, 1.999));
  sum.add(sample(3, Surface::Stem, -4.0));   // a new run: the jump is not drift
  sum.add(sample(4, Surface::Stem, -4.02));  // 5e-3
  sum.add(sample(5, Surface::Both, 7.0));    // not counted, ends the run
  sum.add(sample(6, Surface::Stem, 1.0));
  sum.add(sample(7, Surface::Stem, 1.001));  // 1e-3
  sum.add(sample(8, Surface::Ball, 3.0, 0.25));
  sum.add(sample(9, Surface::Ball, 3.0));
  sum.add(sample(10, Surface::Ball, 5.0, 0.5), /*contact_switched=*/true);  // a switch between samples
  sum.add(sample(11, Surface::Ball, 5.01));  // 2e-3
  RunRecord r;
  sum.fill(r);
  EXPECT_EQ(r.samples, 12);
  ASSERT_TRUE(r.jellett_drift_ball && r.jellett_drift_stem);
  EXPECT_NEAR(*r.jellett_drift_ball, 2e-3, 1e-12);
  EXPECT_NEAR(*r.jellett_drift_stem, 5e-3, 1e-12);
  EXPECT_NEAR(r.jellett_max_relative_drift, 5e-3, 1e-12);
  EXPECT_EQ(r.jellett_initial, 2.0);
  EXPECT_EQ(r.energy_initial, 10.0);
  EXPECT_EQ(r.energy_final, -1.0);
  EXPECT_EQ(r.final_time, 11.0);
  EXPECT_NEAR(r.final_tilt, 1.1, 1e-15);
  EXPECT_EQ(r.min_normal_force, 0.25);
}

TEST(Records, JellettDriftAbsentSurface) {
  SampleSummary sum;
  sum.add(sample(0, Surface::Ball, 0.0));
  sum.add(sample(1, Surface::Ball, 0.0));
  RunRecord r;
  sum.fill(r);
  EXPECT_FALSE(r.jellett_drift_stem.has_value());
  EXPECT_EQ(*r.jellett_drift_ball, 0.0);  // J = 0 throughout: no division by zero
}

bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

RunRecord example_record() {
  RunRecord r;
  r.scene_name = "toy";
  r.scene_file = "harness/scenes/toy.toml";
  r.scene_hash = "0123456789abcdef";
  r.scene_spec = {{"gravity", 9.81}};
  r.engine = "mujoco";
  r.engine_version = "mujoco 2.2.2";
  r.status = "diverged";
  r.status_time = 1.0 / 3.0;
  r.status_detail = "energy doubled";
  r.events = {{"inversion", 0.1 + 0.2, "theta crosses 90 deg", 0.0}, {"impact", 2.5, "stem", 1e-7}};
  r.settings = {{"cone", "elliptic"}, {"timestep", "0.0001"}};
  r.notes = {"rolling approximated by mu = 1e3"};
  r.work = {12345, 23456, 7, 1.25, 1.125};
  r.mass = {0.0123, 0.00123, 1.1e-6, 1.2e-6};
  r.inversion_possible = true;
  r.provenance = {"abc123", "GNU 12.2.0", "-O2", "2024-01-01T00:00:00Z", "host"};
  r.inversion_time = 0.30000000000000004;
  r.stem_contact_time = std::nullopt;
  r.samples = 8001;
  r.final_time = 8.0;
  r.final_tilt = 3.0;
  r.energy_initial = 1.0 / 7.0;
  r.energy_final = std::numeric_limits<double>::quiet_NaN();
  r.jellett_initial = -1.5637593718755574;
  r.jellett_max_relative_drift = 3e-12;
  r.jellett_drift_ball = 3e-12;
  r.jellett_drift_stem = std::nullopt;
  r.min_normal_force = -0.0;
  return r;
}

TEST(Records, JsonRoundTrip) {
  const RunRecord a = example_record();
  const nlohmann::json j = to_json(a);
  EXPECT_TRUE(j.at("stem_contact_time").is_null());
  EXPECT_TRUE(j.at("energy_final").is_null());
  for (const char* key : {"scene", "engine", "status", "inversion_time", "final_tilt", "energy_initial",
                          "jellett_initial", "jellett_max_relative_drift", "min_normal_force", "mass_properties",
                          "work", "events", "settings", "notes", "engine_version", "scene_file", "scene_hash",
                          "status_time", "status_detail", "inversion_possible", "provenance"})
    EXPECT_TRUE(j.contains(key)) << key;
  const RunRecord b = from_json(nlohmann::json::parse(j.dump(2)));
  EXPECT_EQ(b.scene_name, a.scene_name);
  EXPECT_EQ(b.scene_file, a.scene_file);
  EXPECT_EQ(b.scene_hash, a.scene_hash);
  EXPECT_EQ(b.scene_spec, a.scene_spec);
  EXPECT_EQ(b.engine, a.engine);
  EXPECT_EQ(b.engine_version, a.engine_version);
  EXPECT_EQ(b.status, a.status);
  EXPECT_EQ(b.status_time, a.status_time);
  EXPECT_EQ(b.status_detail, a.status_detail);
  ASSERT_EQ(b.events.size(), a.events.size());
  for (size_t i = 0; i < a.events.size(); ++i) {
    EXPECT_EQ(b.events[i].name, a.events[i].name);
    EXPECT_EQ(b.events[i].time, a.events[i].time);
    EXPECT_EQ(b.events[i].detail, a.events[i].detail);
    EXPECT_EQ(b.events[i].value, a.events[i].value);
  }
  EXPECT_EQ(b.settings, a.settings);  // already sorted by key
  EXPECT_EQ(b.notes, a.notes);
  EXPECT_EQ(b.work.steps, a.work.steps);
  EXPECT_EQ(b.work.rhs_evaluations, a.work.rhs_evaluations);
  EXPECT_EQ(b.work.solver_iterations, a.work.solver_iterations);
  EXPECT_EQ(b.work.wall_seconds, a.work.wall_seconds);
  EXPECT_EQ(b.work.cpu_seconds, a.work.cpu_seconds);
  EXPECT_EQ(b.mass.mass, a.mass.mass);
  EXPECT_EQ(b.mass.com_offset, a.mass.com_offset);
  EXPECT_EQ(b.mass.inertia_transverse, a.mass.inertia_transverse);
  EXPECT_EQ(b.mass.inertia_axial, a.mass.inertia_axial);
  EXPECT_EQ(b.inversion_possible, a.inversion_possible);
  EXPECT_EQ(b.provenance.git_commit, a.provenance.git_commit);
  EXPECT_EQ(b.provenance.compiler, a.provenance.compiler);
  EXPECT_EQ(b.provenance.cxx_flags, a.provenance.cxx_flags);
  EXPECT_EQ(b.provenance.date, a.provenance.date);
  EXPECT_EQ(b.provenance.hostname, a.provenance.hostname);
  EXPECT_EQ(b.inversion_time, a.inversion_time);
  EXPECT_EQ(b.stem_contact_time, a.stem_contact_time);
  EXPECT_EQ(b.samples, a.samples);
  EXPECT_EQ(b.final_time, a.final_time);
  EXPECT_EQ(b.final_tilt, a.final_tilt);
  EXPECT_EQ(b.energy_initial, a.energy_initial);
  EXPECT_TRUE(same(b.energy_final, a.energy_final));
  EXPECT_EQ(b.jellett_initial, a.jellett_initial);
  EXPECT_EQ(b.jellett_max_relative_drift, a.jellett_max_relative_drift);
  EXPECT_EQ(b.jellett_drift_ball, a.jellett_drift_ball);
  EXPECT_EQ(b.jellett_drift_stem, a.jellett_drift_stem);
  EXPECT_EQ(b.min_normal_force, a.min_normal_force);
  EXPECT_EQ(to_json(b), j);
}

// summary.json names its format; one written before it did is still read, another format is not.
TEST(Records, FormatIsWrittenAndOldSummariesAreRead) {
  nlohmann::json j = to_json(example_record());
  EXPECT_EQ(j.at("format"), kRunRecordFormat);
  j.erase("format");
  EXPECT_EQ(to_json(from_json(j)).at("final_tilt"), j.at("final_tilt"));
  j["format"] = "tippe-run-2";
  EXPECT_THROW(from_json(j), nlohmann::json::exception);
}

// friction_work (Simulator::friction_work) round-trips; a summary written before it existed is
// read as not reported (NaN), and not reported is written as null.
TEST(Records, FrictionWorkRoundTripsAndOldSummariesReadWithoutIt) {
  RunRecord r = example_record();
  r.friction_work = -0.0111;
  nlohmann::json j = to_json(r);
  EXPECT_EQ(from_json(j).friction_work, -0.0111);
  j.erase("friction_work");
  EXPECT_TRUE(std::isnan(from_json(j).friction_work));
  EXPECT_TRUE(to_json(from_json(j)).at("friction_work").is_null());
}

// The energy ledger's totals round-trip; a summary written before them reads them as not
// available (NaN, no list of missing terms).
TEST(Records, EnergyLedgerRoundTripsAndOldSummariesReadWithoutIt) {
  RunRecord r = example_record();
  r.normal_work = 1.5e-3;
  r.impact_energy = 0.25;
  r.elastic_energy_max = 2e-7;
  r.numerical_energy_max = 3e-6;
  r.numerical_energy_final = -2e-6;
  r.ledger_not_available = {"drilling_work"};
  nlohmann::json j = to_json(r);
  const RunRecord back = from_json(j);
  EXPECT_EQ(back.normal_work, 1.5e-3);
  EXPECT_EQ(back.impact_energy, 0.25);
  EXPECT_EQ(back.elastic_energy_max, 2e-7);
  EXPECT_EQ(back.numerical_energy_max, 3e-6);
  EXPECT_EQ(back.numerical_energy_final, -2e-6);
  EXPECT_TRUE(std::isnan(back.drilling_work));
  EXPECT_EQ(back.ledger_not_available, std::vector<std::string>{"drilling_work"});
  for (const char* k : {"normal_work", "drilling_work", "impact_energy", "elastic_energy_max", "numerical_energy_max",
                        "numerical_energy_final", "ledger_not_available"})
    j.erase(k);
  const RunRecord old = from_json(j);
  EXPECT_TRUE(std::isnan(old.normal_work));
  EXPECT_TRUE(std::isnan(old.numerical_energy_max));
  EXPECT_TRUE(old.ledger_not_available.empty());
}

bool has_temporaries(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) return true;
  return false;
}

TEST(Records, WriteFileAtomic) {
  TempDir dir{"tippe-test"};
  const std::string path = (dir.path() / "summary.json").string();
  write_file_atomic(path, "first\n");
  write_file_atomic(path, "second\n");
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "second\n");
  EXPECT_FALSE(has_temporaries(dir.path()));
  EXPECT_THROW(write_file_atomic((dir.path() / "no/such/dir/x").string(), "x"), std::runtime_error);
  EXPECT_FALSE(has_temporaries(dir.path()));
}

TEST(Records, CsvRoundTripAndCommit) {
  TempDir dir{"tippe-test"};
  const std::string path = (dir.path() / "trajectory.csv").string();
  Observation a = sample(0.1, Surface::Ball, -1.5637593718755574);
  a.state.p_WG = Vec3(1.0 / 3.0, -2e-17, 0.7);
  a.state.q_WB = Quat(Eigen::AngleAxisd(0.1, Vec3::UnitX()));
  a.state.w_B = Vec3(0, 0, 150);
  a.engine_contact_valid = true;
  a.p_WC_engine = Vec3(1, 2, 3);
  Observation b = sample(0.2, Surface::Both, 2.0);
  {
    CsvTrajectoryWriter w(path);
    w.write(a);
    w.write(b);
    EXPECT_FALSE(fs::exists(path));  // nothing visible before the commit
    w.commit();
  }
  EXPECT_FALSE(has_temporaries(dir.path()));
  const CsvTrajectory tr = read_trajectory_csv(path);
  EXPECT_EQ(tr.columns, trajectory_columns());
  ASSERT_EQ(tr.rows(), 2u);
  EXPECT_EQ(tr.surface[0], static_cast<int>(Surface::Ball));
  EXPECT_EQ(tr.surface[1], static_cast<int>(Surface::Both));
  EXPECT_EQ(tr.column("t")[1], 0.2);
  EXPECT_EQ(tr.column("x_G")[0], 1.0 / 3.0);
  EXPECT_EQ(tr.column("y_G")[0], -2e-17);
  EXPECT_EQ(tr.column("qx")[0], a.state.q_WB.x());
  EXPECT_EQ(tr.column("wz_B")[0], 150.0);
  EXPECT_EQ(tr.column("jellett")[0], a.jellett);
  EXPECT_EQ(tr.column("y_C_engine")[0], 2.0);
  EXPECT_TRUE(std::isnan(tr.column("y_C_engine")[1]));  // engine reported no contact point
  EXPECT_THROW(tr.column("no_such_column"), std::out_of_range);
}

TEST(Records, CsvWithoutCommitLeavesNothing) {
  TempDir dir{"tippe-test"};
  const std::string path = (dir.path() / "trajectory.csv").string();
  try {
    CsvTrajectoryWriter w(path);
    w.write(sample(0, Surface::Ball, 1));
    throw std::runtime_error("the run failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// ---- records read back (summary.json, comparison.json, the reference cache) -----------------

// Counts in a record must be JSON integers: found by fuzz_records, a float like 1e300 reached
// json::get<long long>, a conversion with undefined behaviour (UBSan: "outside the range of
// representable values of type 'long long'"); now it is a json exception like any mistyped field.
TEST(RecordInputs, CountsMustBeIntegers) {
  const nlohmann::json good = to_json(RunRecord{});
  EXPECT_NO_THROW(from_json(good));
  const struct {
    const char* where;
    const char* key;
    nlohmann::json value;
  } bad[] = {{"", "samples", 1e300},        {"", "samples", -1e30},       {"", "samples", 2.5},
             {"", "samples", "8001"},       {"work", "steps", 1e19},      {"work", "rhs_evaluations", nullptr},
             {"work", "solver_iterations", 18446744073709551615ULL}};
  for (const auto& c : bad) {
    nlohmann::json j = good;
    (*c.where ? j[c.where] : j)[c.key] = c.value;
    EXPECT_THROW(from_json(j), nlohmann::json::exception) << c.where << "." << c.key << " = " << c.value.dump();
  }
  nlohmann::json big = good;
  big["samples"] = 9223372036854775807LL;
  EXPECT_EQ(from_json(big).samples, 9223372036854775807LL);

  const nlohmann::json metrics = to_json(Metrics{});
  EXPECT_NO_THROW(metrics_from_json(metrics));
  for (const char* key : {"steps", "energy_gain_events"}) {
    nlohmann::json j = metrics;
    j[key] = 1e300;
    EXPECT_THROW(metrics_from_json(j), nlohmann::json::exception) << key;
  }
}

}  // namespace

}  // namespace test_records
