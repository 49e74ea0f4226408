// `tippe import-mjcf` and [engines.mujoco] model: a user's MJCF read as MuJoCo compiles it, and its MuJoCo run plain MuJoCo's bit for bit.
//
// Four models written for these tests (tests/data): MuJoCo's tutorial top as published (frame at
// the ball's centre, a flat-ended cylinder stem, a non-colliding ballast); a top whose frame is at
// its centre of mass with the symmetry axis along the frame's x axis and a sliding, tilted,
// turned keyframe; a top built from <default> classes and densities with a tilted keyframe that
// is not the first; an eccentric ball without a stem and without a keyframe (qpos0, tilted). Each is imported by the real `tippe` binary; the scene it writes is then
// checked against the compiled mjModel and run.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "analytic/initial_state.h"
#include "engines/mujoco/mujoco_import.h"
#include "engines/mujoco/mujoco_sim.h"
#include "harness/records/records.h"
#include "harness/measure/run.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "engines/core/simulator.h"
#include "tests/support/process.h"

namespace tippe::test_import_mjcf {
namespace {

namespace fs = std::filesystem;

const std::string kData = std::string(TIPPE_SOURCE_DIR) + "/tests/data/";
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";

struct Model {
  const char* file;
  const char* body;
  const char* keyframe;  // "" : the importer's default (the first)
  bool stem;
};

const Model kModels[] = {
    {"mujoco_tutorial_top.xml", "top", "", true},
    {"import_com_frame_top.xml", "spinner", "", true},
    {"import_classes_top.xml", "toy", "tilted", true},
    {"import_ball_top.xml", "ball", "", false},
};

// gtest shows a model by its file.
void PrintTo(const Model& m, std::ostream* os) { *os << m.file; }

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

ModelPtr load(const std::string& path) {
  char error[1024] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, error, sizeof error));
  EXPECT_NE(m, nullptr) << path << ": " << error;
  return m;
}

class ImportMjcf : public ::testing::TestWithParam<Model> {
 protected:
  void SetUp() override {
    std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    for (char& c : test)
      if (c == '/') c = '_';  // a parameterised test's name has one
    dir_ = fs::temp_directory_path() / ("tippe_import_mjcf_" + std::to_string(::getpid()) + "_" + test);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    xml_ = kData + GetParam().file;
    scene_ = (dir_ / "imported.toml").string();
    std::vector<std::string> argv = {kBinary, "import-mjcf", xml_, "--out", scene_, "--duration", "0.05"};
    if (*GetParam().keyframe) argv.insert(argv.end(), {"--keyframe", GetParam().keyframe});
    const ChildExit e = wait_process_within(spawn_process(argv, dir_ / "stdout", dir_ / "stderr"), 60);
    std::ifstream err(dir_ / "stderr");
    std::stringstream text;
    text << err.rdbuf();
    ASSERT_EQ(e.code, 0) << text.str();
    m_ = load(xml_);
    ASSERT_NE(m_, nullptr);
    body_ = mj_name2id(m_.get(), mjOBJ_BODY, GetParam().body);
    ASSERT_GE(body_, 0);
    key_ = *GetParam().keyframe ? mj_name2id(m_.get(), mjOBJ_KEY, GetParam().keyframe) : (m_->nkey > 0 ? 0 : -1);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The start plain MuJoCo takes: the keyframe, or qpos0 at rest when the model has none.
  void reset(mjData* d) const {
    if (key_ >= 0) mj_resetDataKeyframe(m_.get(), d, key_);
    else mj_resetData(m_.get(), d);
  }

  fs::path dir_;
  std::string xml_, scene_;
  ModelPtr m_;
  int body_ = -1, key_ = 0;
};

// The compiled model's own numbers: body_mass, body_inertia with body_iquat, body_ipos and the
// ball's geom_pos and geom_size. 1e-12: the scene writes them with 17 significant digits, which
// read back exactly; A is the mean of two moments equal to rounding.
TEST_P(ImportMjcf, MassPropertiesAreTheCompiledModels) {
  const Scene s = load_scene(scene_);
  const mjModel* m = m_.get();
  int ball = -1;
  // The ball: the body's sphere that can touch the floor (contype 1 against the floor's conaffinity 1).
  for (int g = 0; g < m->ngeom; ++g)
    if (m->geom_bodyid[g] == body_ && m->geom_type[g] == mjGEOM_SPHERE && m->geom_contype[g] != 0) ball = g;
  ASSERT_GE(ball, 0);
  const Vec3 G(m->body_ipos + 3 * body_), O(m->geom_pos + 3 * ball);
  const Vec3 axis = (O - G).normalized();  // every test model has G below the ball's centre
  const Eigen::Matrix3d R_FI =
      Quat(m->body_iquat[4 * body_], m->body_iquat[4 * body_ + 1], m->body_iquat[4 * body_ + 2], m->body_iquat[4 * body_ + 3])
          .toRotationMatrix();
  double C = 0;
  std::vector<double> transverse;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(R_FI.col(k).dot(axis)) > 1 - 1e-9) C = m->body_inertia[3 * body_ + k];
    else transverse.push_back(m->body_inertia[3 * body_ + k]);
  }
  ASSERT_EQ(transverse.size(), 2u);
  auto near = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::abs(b); };
  EXPECT_PRED2(near, s.mass.mass, m->body_mass[body_]);
  EXPECT_PRED2(near, s.mass.com_offset, (O - G).norm());
  EXPECT_PRED2(near, s.mass.inertia_axial, C);
  EXPECT_PRED2(near, s.mass.inertia_transverse, transverse[0]);
  EXPECT_PRED2(near, s.mass.inertia_transverse, transverse[1]);
  EXPECT_PRED2(near, s.body.sphere_radius, m->geom_size[3 * ball]);
  EXPECT_EQ(s.body.mass_model, MassModel::Given);
  EXPECT_EQ(s.contact.stem, GetParam().stem);
}

// The scene's start is the keyframe's state of G, as MuJoCo itself computes it after
// mj_forward: xipos (G), mj_objectVelocity of the body (angular velocity and the velocity of G,
// world frame), the principal axis in ximat. 1e-12 of each scale: two roundings of the same numbers.
TEST_P(ImportMjcf, StartIsTheKeyframesStateOfG) {
  const Scene s = load_scene(scene_);
  const BodyState x = scene_initial_state(s);
  DataPtr d(mj_makeData(m_.get()));
  reset(d.get());
  mj_forward(m_.get(), d.get());
  mjtNum vel[6];
  mj_objectVelocity(m_.get(), d.get(), mjOBJ_BODY, body_, vel, 0);
  const Vec3 w_W(vel[0], vel[1], vel[2]), v_G(vel[3], vel[4], vel[5]);
  const Vec3 G(d->xipos + 3 * body_);
  const double R = s.body.sphere_radius;
  EXPECT_LE((x.p_WG - G).norm(), 1e-12 * (R + G.norm())) << x.p_WG.transpose() << " vs " << G.transpose();
  EXPECT_LE((x.q_WB * x.w_B - w_W).norm(), 1e-12 * w_W.norm());
  EXPECT_LE((x.v_WG - v_G).norm(), 1e-12 * (v_G.norm() + w_W.norm() * R)) << x.v_WG.transpose() << " vs " << v_G.transpose();
  // e_Z: the principal axis through the ball's centre, in the world.
  const Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> ximat(d->ximat + 9 * body_);
  const Eigen::Matrix3d R_WI = Eigen::Matrix3d(ximat);
  double best = 0;
  for (int k = 0; k < 3; ++k) best = std::max(best, std::abs(R_WI.col(k).dot(x.q_WB * Vec3::UnitZ())));
  EXPECT_GT(best, 1 - 1e-12);
}

// The scene's MuJoCo run is plain MuJoCo: mj_loadXML of the same file, mj_resetDataKeyframe,
// mj_step; after N steps the body's xpos and xquat, and qpos and qvel, are the same bits.
TEST_P(ImportMjcf, MujocoRunIsPlainMujocoBitForBit) {
  const Scene s = load_scene(scene_);
  auto sim = make_simulator("mujoco", s);
  const int n = 400;
  const double dt = m_->opt.timestep;
  sim->advance_to(n * dt);
  ASSERT_EQ(sim->work().steps, n);
  DataPtr d(mj_makeData(m_.get()));
  reset(d.get());
  for (int i = 0; i < n; ++i) mj_step(m_.get(), d.get());
  const std::vector<double> pose = mujoco_body_pose(*sim), qpos = mujoco_qpos(*sim), qvel = mujoco_qvel(*sim);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pose[i], d->xpos[3 * body_ + i]) << "xpos[" << i << "]";
  for (int i = 0; i < 4; ++i) EXPECT_EQ(pose[3 + i], d->xquat[4 * body_ + i]) << "xquat[" << i << "]";
  for (int i = 0; i < m_->nq; ++i) EXPECT_EQ(qpos[i], d->qpos[i]) << "qpos[" << i << "]";
  for (int i = 0; i < m_->nv; ++i) EXPECT_EQ(qvel[i], d->qvel[i]) << "qvel[" << i << "]";
  // And the run moved: a test of a frozen state would pass as well.
  DataPtr d0(mj_makeData(m_.get()));
  reset(d0.get());
  EXPECT_NE(qvel, std::vector<double>(d0->qvel, d0->qvel + m_->nv));
}

// The reference runs on the imported scene and starts with the keyframe's energy
// (E = M v_G^2 / 2 + w.I w / 2 + M g z_G from the compiled model; 1e-12 relative: the same sums).
TEST_P(ImportMjcf, ReferenceRunsOnTheImportedScene) {
  const Scene s = load_scene(scene_, {"run.self_check=false"});
  const RunRecord r = run_scene(s, "analytic", nullptr);
  EXPECT_EQ(r.status, "ok") << r.status_detail;
  EXPECT_GT(r.samples, 10);
  DataPtr d(mj_makeData(m_.get()));
  reset(d.get());
  mj_forward(m_.get(), d.get());
  mjtNum vel[6];
  mj_objectVelocity(m_.get(), d.get(), mjOBJ_BODY, body_, vel, 1);  // local: the principal frame
  const mjtNum* I = m_->body_inertia + 3 * body_;
  const double M = m_->body_mass[body_];
  const Vec3 v(vel[3], vel[4], vel[5]);
  const double E = 0.5 * M * v.squaredNorm() +
                   0.5 * (I[0] * vel[0] * vel[0] + I[1] * vel[1] * vel[1] + I[2] * vel[2] * vel[2]) +
                   M * s.gravity * d->xipos[3 * body_ + 2];
  EXPECT_LE(std::abs(r.energy_initial - E), 1e-12 * std::abs(E)) << r.energy_initial << " vs " << E;
}

INSTANTIATE_TEST_SUITE_P(Models, ImportMjcf, ::testing::ValuesIn(kModels),
                         [](const ::testing::TestParamInfo<Model>& info) {
                           std::string n = fs::path(info.param.file).stem().string();
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

// MuJoCo's mixing of the ball's and the floor's contact parameters, read from the compiled
// contact: classes give the ball condim 4, friction 0.4 0.003 and the floor condim 3, friction
// 0.6 0.002 at equal priority, so the contact takes the larger of each.
TEST(ImportMjcfContact, FrictionIsMujocosMixing) {
  const MjcfTopImport c = import_mjcf_top(kData + "import_classes_top.xml", "", "tilted");
  EXPECT_EQ(c.condim, 4);
  EXPECT_EQ(c.contact.friction, FrictionLaw::Coulomb);
  EXPECT_EQ(c.contact.mu, 0.6);
  EXPECT_EQ(c.contact.drilling, 0.003);
  EXPECT_EQ(c.keyframe_index, 1);
  const MjcfTopImport t = import_mjcf_top(kData + "mujoco_tutorial_top.xml");
  EXPECT_EQ(t.condim, 3);
  EXPECT_EQ(t.contact.mu, 1.0);
  EXPECT_EQ(t.contact.drilling, 0.0);  // condim 3: the torsional coefficient is not used
  EXPECT_EQ(t.stem_type, "cylinder");
  ASSERT_FALSE(t.notes.empty());
  bool said = false;
  for (const auto& n : t.notes) said = said || n.find("flat-ended cylinder") != std::string::npos;
  EXPECT_TRUE(said) << "the cylinder's approximation must be a note";
}

// A geom of higher priority decides the contact alone (MuJoCo 2.2: its condim and friction), and
// an explicit <pair> replaces the geoms' parameters altogether: both read from the contact
// MuJoCo builds, never from the geoms' attributes.
TEST(ImportMjcfContact, PriorityAndPairsAreMujocos) {
  const fs::path dir = fs::temp_directory_path() / ("tippe_import_priority_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string ball = "<body name=\"top\" pos=\"0 0 .02\"><freejoint/><inertial pos=\"0 0 -.004\" mass=\".05\" "
                           "diaginertia=\"1e-5 1e-5 1.1e-5\"/><geom name=\"ball\" type=\"sphere\" size=\".02\" condim=\"3\" "
                           "friction=\"0.9 0.01 0\"/></body>";
  const std::string priority = "<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"1 1 1\" priority=\"1\" "
                               "condim=\"1\" friction=\"0.2 0 0\"/>" + ball + "</worldbody></mujoco>";
  const std::string pair = "<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"1 1 1\"/>" + ball +
                           "</worldbody><contact><pair geom1=\"floor\" geom2=\"ball\" condim=\"4\" "
                           "friction=\"0.35 0.35 0.002 0 0\"/></contact></mujoco>";
  std::ofstream(dir / "priority.xml") << priority;
  std::ofstream(dir / "pair.xml") << pair;
  const MjcfTopImport p = import_mjcf_top((dir / "priority.xml").string());
  EXPECT_EQ(p.condim, 1);
  EXPECT_EQ(p.contact.friction, FrictionLaw::None);
  EXPECT_FALSE(p.stem);
  const MjcfTopImport q = import_mjcf_top((dir / "pair.xml").string());
  EXPECT_EQ(q.condim, 4);
  EXPECT_EQ(q.contact.mu, 0.35);
  EXPECT_EQ(q.contact.drilling, 0.002);
  // A pair may make the friction anisotropic, which the reference's Coulomb law is not.
  std::string anisotropic = pair;
  anisotropic.replace(anisotropic.find("0.35 0.35"), 9, "0.35 0.5");
  std::ofstream(dir / "anisotropic.xml") << anisotropic;
  EXPECT_THROW(import_mjcf_top((dir / "anisotropic.xml").string()), MjcfImportError);
  fs::remove_all(dir);
}

// Scenes over a user's model, in a directory of their own: the model beside the scene.
class ImportMjcfScene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("tippe_import_scene_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::copy_file(kData + "mujoco_tutorial_top.xml", dir_ / "top.xml");
    scene_ = (dir_ / "top.toml").string();
    const ChildExit e = wait_process_within(
        spawn_process({kBinary, "import-mjcf", (dir_ / "top.xml").string(), "--out", scene_}, dir_ / "out", dir_ / "err"), 60);
    ASSERT_EQ(e.code, 0);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::string scene_;
};

// The model's bytes are part of the scene's content hash: a changed model is a changed scene.
TEST_F(ImportMjcfScene, ChangedModelIsAChangedScene) {
  const std::string before = load_scene(scene_).content_hash;
  EXPECT_EQ(load_scene(scene_).content_hash, before);
  std::ofstream(dir_ / "top.xml", std::ios::app) << "<!-- edited -->\n";
  EXPECT_NE(load_scene(scene_).content_hash, before);
}

// A scene whose body no longer is the model's would compare the reference with another top.
TEST_F(ImportMjcfScene, SceneThatIsNotTheModelIsRefused) {
  try {
    load_scene(scene_, {"body.mass=0.1"});
    FAIL() << "a scene with another mass than its model's was accepted";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("engines.mujoco.model"), std::string::npos) << what;
    EXPECT_NE(what.find("body.mass = 0.1 but the model has 0.0554745693576"), std::string::npos) << what;
  }
  // Settings that shape only the bench's own MJCF are refused, not ignored.
  EXPECT_THROW(load_scene(scene_, {"engines.mujoco.body_frame=\"com\""}), SceneError);
}

// A changed start runs from the scene's state, converted to the model's frame; option overrides
// land on the compiled model.
TEST_F(ImportMjcfScene, SceneStartAndOptionsOverrideTheModel) {
  const Scene s = load_scene(scene_, {"initial.omega=[0.0, 1.0, 100.0]", "engines.mujoco.timestep=0.001",
                                      "engines.mujoco.integrator=\"Euler\""});
  auto sim = make_simulator("mujoco", s);
  const std::vector<double> v = mujoco_qvel(*sim);
  // The tutorial's frame is the principal frame moved to the ball's centre: omega_B as given.
  EXPECT_EQ(v[3], 0.0);
  EXPECT_EQ(v[4], 1.0);
  EXPECT_EQ(v[5], 100.0);
  EXPECT_EQ(mujoco_model_readback(*sim).timestep, 0.001);
  const SettingsList list = sim->settings();
  std::map<std::string, std::string> settings(list.begin(), list.end());
  EXPECT_EQ(settings["start"], "scene");
  EXPECT_EQ(settings["integrator"], "Euler");
  const Scene plain = load_scene(scene_);
  auto sim2 = make_simulator("mujoco", plain);
  const SettingsList list2 = sim2->settings();
  std::map<std::string, std::string> settings2(list2.begin(), list2.end());
  EXPECT_EQ(settings2["start"], "keyframe");
  EXPECT_EQ(settings2["integrator"], "RK4");
}

// `--out` into a directory that does not exist yet (a new user's first `--out out/my_top.toml`):
// the scene names the model relative to out/, and its check before writing must read that model,
// not "out/../top.xml" through a directory that is not there.
TEST_F(ImportMjcfScene, OutIntoADirectoryThatDoesNotExistYet) {
  const fs::path scene = dir_ / "new" / "deeper" / "my_top.toml";
  ASSERT_FALSE(fs::exists(dir_ / "new"));
  const ChildExit e = wait_process_within(
      spawn_process({kBinary, "import-mjcf", (dir_ / "top.xml").string(), "--out", scene.string()}, dir_ / "out2",
                    dir_ / "err2"),
      60);
  std::ifstream err(dir_ / "err2");
  std::stringstream text;
  text << err.rdbuf();
  ASSERT_EQ(e.code, 0) << text.str();
  ASSERT_TRUE(fs::exists(scene));
  std::ifstream written(scene);
  std::stringstream toml;
  toml << written.rdbuf();
  EXPECT_NE(toml.str().find("\"../../top.xml\""), std::string::npos) << "named relative to the scene\n" << toml.str();
  const Scene loaded = load_scene(scene.string());
  EXPECT_EQ(std::get<std::string>(loaded.engines.at("mujoco").at("model")), (dir_ / "top.xml").lexically_normal().string());
}

}  // namespace
}  // namespace tippe
