// tests: loading characters — the humanoid's and the dog's structure and
// bindings, and bad config input reported as InputError naming the file.
#include "sim/character.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <regex>

#include "common/error.h"
#include "common/file_io.h"
#include "sim/simulation.h"
#include "sim_test_util.h"

namespace m2d {
namespace {

using testing::HumanoidConfigPath;
using testing::LoadDog;
using testing::LoadHumanoid;
using testing::SourcePath;
using testing::TempDir;

TEST(CharacterTest, HumanoidHas15BodiesAnd28ActuatedDofPlusFreeRoot) {
  auto character = LoadHumanoid("flat");
  const mjModel* m = character->model();
  EXPECT_EQ(character->bodies().size(), 15u);
  EXPECT_EQ(character->num_actions(), 28);
  EXPECT_EQ(m->nu, 28);
  // Free root (7 qpos, 6 dof) + 28 hinges; the flat scene has nothing else.
  EXPECT_EQ(m->nq, 7 + 28);
  EXPECT_EQ(m->nv, 6 + 28);
  EXPECT_EQ(m->jnt_type[m->body_jntadr[character->root_body()]], mjJNT_FREE);
  EXPECT_STREQ(mj_id2name(m, mjOBJ_BODY, character->root_body()), "pelvis");
  EXPECT_EQ(character->keypoint_sites().size(), 17u);
  EXPECT_TRUE(character->free_objects().empty());
  // Every hinge has its own position servo and a finite range.
  for (const ActuatedHinge& hinge : character->hinges()) {
    EXPECT_LT(hinge.range_low_rad, hinge.range_high_rad);
    EXPECT_EQ(m->actuator_trnid[2 * hinge.actuator_id], hinge.joint_id);
    EXPECT_GT(m->actuator_gainprm[hinge.actuator_id * mjNGAIN], 0.0);
  }
}

// A hinge's PD servo as its source gives it.
struct ServoFacts {
  const char* joint;
  double kp, kd, torque_limit;
};

// Each joint's servo has the expected kp (actuator gain), kd (joint
// damping) and torque limit, and the joint no passive spring.
void ExpectServos(const Character& character,
                  std::initializer_list<ServoFacts> expected) {
  const mjModel* m = character.model();
  for (const ServoFacts& e : expected) {
    const int id = mj_name2id(m, mjOBJ_JOINT, e.joint);
    const ActuatedHinge* hinge = nullptr;
    for (const ActuatedHinge& h : character.hinges())
      if (h.joint_id == id) hinge = &h;
    ASSERT_NE(hinge, nullptr) << e.joint;
    EXPECT_EQ(m->actuator_gainprm[hinge->actuator_id * mjNGAIN], e.kp)
        << e.joint;
    EXPECT_EQ(m->dof_damping[hinge->dof_address], e.kd) << e.joint;
    EXPECT_EQ(m->actuator_forcerange[2 * hinge->actuator_id + 1],
              e.torque_limit)
        << e.joint;
    EXPECT_EQ(m->jnt_stiffness[hinge->joint_id], 0.0) << e.joint;
  }
}

TEST(CharacterTest, HumanoidPhysicsFollowsTheSourceFacts) {
  auto character = LoadHumanoid("flat");
  const mjModel* m = character->model();
  auto body_mass = [&](const char* name) {
    return m->body_mass[character->BodyId(name)];
  };
  // Limb masses equal DeepMimic's humanoid3d BodyDefs.
  EXPECT_NEAR(body_mass("right_thigh"), 4.5, 0.01);
  EXPECT_NEAR(body_mass("right_shin"), 3.0, 0.01);
  EXPECT_NEAR(body_mass("right_foot"), 1.0, 0.01);
  EXPECT_NEAR(body_mass("left_upper_arm"), 1.5, 0.01);
  EXPECT_NEAR(body_mass("left_lower_arm"), 1.0, 0.01);
  EXPECT_NEAR(body_mass("left_hand"), 0.5, 0.01);
  // PD gains (MimicKit) and no passive springs.
  ExpectServos(*character, {{"abdomen_y", 1000, 100, 200},
                            {"neck_x", 100, 10, 50},
                            {"left_shoulder_z", 400, 40, 100},
                            {"right_elbow", 300, 30, 60},
                            {"left_hip_y", 500, 50, 200},
                            {"right_knee", 500, 50, 150},
                            {"left_ankle_x", 400, 40, 90}});
}

// The dog (scripts/deepmimic_dog_to_mjcf.py from DeepMimic's dog3d): 23
// bodies, 18 ball joints and 4 elbows and knees, AP-10K keypoint sites.
TEST(CharacterTest, DogHas23BodiesAnd58ActuatedDofPlusFreeRoot) {
  auto character = LoadDog("flat");
  const mjModel* m = character->model();
  EXPECT_EQ(character->bodies().size(), 23u);
  EXPECT_EQ(character->num_actions(), 18 * 3 + 4);
  EXPECT_EQ(m->nq, 7 + 58);
  EXPECT_EQ(m->nv, 6 + 58);
  EXPECT_STREQ(mj_id2name(m, mjOBJ_BODY, character->root_body()), "root");
  EXPECT_EQ(character->keypoint_layout().name, "ap10k");
  EXPECT_EQ(character->keypoint_sites().size(), 17u);
  EXPECT_EQ(character->ground_contact_bodies().size(), 4u);
  for (const ActuatedHinge& hinge : character->hinges()) {
    EXPECT_LT(hinge.range_low_rad, hinge.range_high_rad);
    EXPECT_EQ(m->actuator_trnid[2 * hinge.actuator_id], hinge.joint_id);
  }
}

// Masses and torque limits are DeepMimic's dog3d character file's, PD gains
// its dog3d controller's.
TEST(CharacterTest, DogPhysicsFollowsTheSourceFacts) {
  auto character = LoadDog("flat");
  const mjModel* m = character->model();
  double total_kg = 0.0;
  for (int body : character->bodies()) total_kg += m->body_mass[body];
  EXPECT_NEAR(total_kg, 29.25, 1e-6);
  EXPECT_NEAR(m->body_mass[character->BodyId("spine1")], 7.0, 1e-9);
  EXPECT_NEAR(m->body_mass[character->BodyId("tail1")], 0.25, 1e-9);
  ExpectServos(*character, {{"spine0_y", 500, 50, 200},
                            {"head_x", 50, 5, 50},
                            {"left_shoulder_z", 200, 20, 150},
                            {"right_forearm", 200, 20, 100},
                            {"left_upper_leg_y", 300, 30, 200},
                            {"right_leg", 200, 20, 150},
                            {"left_toe_x", 80, 8, 50},
                            {"tail1_z", 10, 1, 25}});
}

TEST(CharacterTest, BallSceneAddsAFreeBallObject) {
  auto character = LoadHumanoid("ball");
  ASSERT_EQ(character->free_objects().size(), 1u);
  const FreeObject& ball = character->free_objects()[0];
  EXPECT_EQ(ball.name, "ball");
  const mjModel* m = character->model();
  EXPECT_NEAR(m->body_mass[ball.body_id], 0.43, 1e-9);
  const int geom = m->body_geomadr[ball.body_id];
  EXPECT_NEAR(m->geom_size[3 * geom], 0.11, 1e-9);
  EXPECT_FALSE(character->IsCharacterBody(ball.body_id));
  EXPECT_EQ(character->bodies().size(), 15u);
}

TEST(CharacterTest, PhysicsTimestepComesFromTheOptions) {
  SimulationOptions options;
  options.physics_substeps = 3;
  auto character = LoadHumanoid("flat", options);
  EXPECT_DOUBLE_EQ(character->model()->opt.timestep, 1.0 / 90.0);
  SimulationOptions other;
  other.physics_substeps = 4;
  EXPECT_THROW(Simulation(character, other), ConfigError);
}

// Writes a copy of the humanoid config into a temp folder with `edit`
// applied, and copies of the asset files it points to (so that MJCF edits
// are possible too); returns the config path.
class BadConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = TempDir("sim_bad_config");
    std::filesystem::create_directories(dir_ + "/characters");
    std::filesystem::create_directories(dir_ + "/scenes");
    std::filesystem::create_directories(dir_ + "/skeletons");
    for (const char* file :
         {"characters/humanoid.yaml", "characters/humanoid.xml",
          "characters/soccer_ball.xml", "scenes/humanoid_flat.xml",
          "scenes/humanoid_ball.xml", "scenes/humanoid_floating.xml",
          "scenes/look.xml", "skeletons/humanoid.yaml",
          "skeletons/humanoid.coco17.yaml"}) {
      std::filesystem::copy_file(SourcePath(std::string("assets/") + file),
                                 dir_ + "/" + file);
    }
  }
  void Edit(const std::string& file, const std::string& from,
            const std::string& to) {
    const std::string path = dir_ + "/" + file;
    std::string text = ReadFileText(path);
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(path) << text;
  }
  std::string ConfigPath() const { return dir_ + "/characters/humanoid.yaml"; }
  // The InputError raised when loading; fails the test if none is.
  InputError LoadError() {
    try {
      LoadCharacterForSimulation(ConfigPath(), "flat", SimulationOptions());
    } catch (const InputError& e) {
      return e;
    }
    ADD_FAILURE() << "loading succeeded";
    return InputError("", "");
  }
  std::string dir_;
};

TEST_F(BadConfigTest, CopiedConfigLoads) {
  EXPECT_NO_THROW(
      LoadCharacterForSimulation(ConfigPath(), "ball", SimulationOptions()));
}

TEST_F(BadConfigTest, MissingModelFileNamesTheFile) {
  std::filesystem::remove(dir_ + "/scenes/humanoid_flat.xml");
  InputError e = LoadError();
  EXPECT_NE(e.source().find("humanoid_flat.xml"), std::string::npos)
      << e.what();
  EXPECT_NE(e.problem().find("not found"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, MalformedMjcfCarriesMujocoMessage) {
  Edit("characters/humanoid.xml", "<geom name=\"torso\"",
       "<gem name=\"torso\"");
  InputError e = LoadError();
  EXPECT_NE(e.source().find("humanoid_flat.xml"), std::string::npos)
      << e.what();
  EXPECT_NE(e.problem().find("MuJoCo"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, UnknownHingeNameNamesConfigAndJoint) {
  Edit("characters/humanoid.yaml", "hinges: [neck_x, neck_y, neck_z]",
       "hinges: [neck_x, neck_q, neck_z]");
  InputError e = LoadError();
  EXPECT_EQ(e.source(), ConfigPath());
  EXPECT_NE(e.problem().find("neck_q"), std::string::npos) << e.what();
  EXPECT_NE(e.problem().find("joints.neck"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, UnknownSkeletonJointIsRejected) {
  Edit("characters/humanoid.yaml", "  left_wrist: {body: left_hand}",
       "  left_wrist: {body: left_hand}\n  tail: {body: pelvis}");
  InputError e = LoadError();
  EXPECT_EQ(e.source(), ConfigPath());
  EXPECT_NE(e.problem().find("tail"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, UnboundSkeletonJointIsRejected) {
  Edit("characters/humanoid.yaml", "  left_wrist: {body: left_hand}\n", "");
  InputError e = LoadError();
  EXPECT_NE(e.problem().find("left_wrist"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, UnknownBodyIsRejected) {
  Edit("characters/humanoid.yaml", "{body: right_shin,", "{body: right_calf,");
  InputError e = LoadError();
  EXPECT_EQ(e.source(), ConfigPath());
  EXPECT_NE(e.problem().find("right_calf"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, MissingKeypointSiteNamesTheModel) {
  Edit("characters/humanoid.yaml", "keypoint_site_prefix: kp_",
       "keypoint_site_prefix: keypoint_");
  InputError e = LoadError();
  EXPECT_NE(e.source().find("humanoid_flat.xml"), std::string::npos);
  EXPECT_NE(e.problem().find("keypoint_nose"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, MisplacedKeypointSiteIsRejected) {
  Edit("characters/humanoid.xml",
       "<site name=\"kp_nose\" pos=\"0.095 0 0.165\"/>",
       "<site name=\"kp_nose\" pos=\"0.095 0 0.175\"/>");
  InputError e = LoadError();
  EXPECT_NE(e.problem().find("kp_nose"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, BodyOffsetDisagreeingWithSkeletonIsRejected) {
  Edit("characters/humanoid.xml",
       "<body name=\"right_shin\" pos=\"0 0 -0.421546\">",
       "<body name=\"right_shin\" pos=\"0 0 -0.43\">");
  InputError e = LoadError();
  EXPECT_NE(e.problem().find("right_shin"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, HingeWithoutServoIsRejected) {
  Edit("characters/humanoid.xml",
       "<position name=\"neck_y\" class=\"neck\" joint=\"neck_y\"/>",
       "<motor name=\"neck_y\" joint=\"neck_y\"/>");
  InputError e = LoadError();
  EXPECT_NE(e.problem().find("neck_y"), std::string::npos) << e.what();
}

TEST_F(BadConfigTest, UnknownSceneListsTheKnownOnes) {
  try {
    LoadCharacterForSimulation(ConfigPath(), "moon", SimulationOptions());
    FAIL() << "loading succeeded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), ConfigPath());
    EXPECT_NE(e.problem().find("flat"), std::string::npos) << e.what();
  }
}

TEST_F(BadConfigTest, MisspelledKeyIsRejected) {
  Edit("characters/humanoid.yaml", "action_range_scale:", "action_range_scal:");
  InputError e = LoadError();
  EXPECT_EQ(e.source(), ConfigPath());
  EXPECT_NE(e.problem().find("action_range_scal"), std::string::npos)
      << e.what();
}

TEST_F(BadConfigTest, MisspelledJointKeyIsRejected) {
  Edit("characters/humanoid.yaml",
       "{body: head, hinges:", "{body: head, hinge:");
  InputError e = LoadError();
  EXPECT_NE(e.problem().find("joints.neck.hinge"), std::string::npos)
      << e.what();
}

TEST_F(BadConfigTest, MissingConfigFileNamesIt) {
  try {
    LoadCharacterConfig(dir_ + "/characters/nobody.yaml");
    FAIL() << "loading succeeded";
  } catch (const InputError& e) {
    EXPECT_NE(e.source().find("nobody.yaml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace m2d
