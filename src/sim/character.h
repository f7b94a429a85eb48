// sim: MuJoCo physics for characters — models, simulations, PD control,
// pose mapping, keypoints and contacts.
#ifndef MIMIC2D_SIM_CHARACTER_H_
#define MIMIC2D_SIM_CHARACTER_H_

#include <mujoco/mujoco.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "motion/skeleton.h"
#include "sim/mujoco_handles.h"

namespace m2d {

// Which MJCF body a skeleton joint moves and through which hinges
// (free root: none, the body's freejoint; spherical: 3 hinges about x, y, z
// in that order; revolute: 1 hinge; fixed: none).
struct JointBinding {
  std::string skeleton_joint;
  std::string body;
  std::vector<std::string> hinges;
};

// A character config file (assets/characters/<name>.yaml, described in
// docs/simulation.md). Paths are resolved relative to the file.
struct CharacterConfig {
  std::string source_path;  // the YAML file, for error messages
  std::string name;
  std::string skeleton_path;
  std::string keypoint_map_path;
  std::string keypoint_site_prefix = "kp_";
  // Optional: the learned pose prior the fit uses (fit/pose_prior.h); empty
  // when the character has none.
  std::string pose_prior_path;
  std::map<std::string, std::string> scene_paths;  // scene name -> MJCF
  std::vector<JointBinding> joints;
  std::vector<std::string> ground_contact_bodies;
  // PD target = mid + a * scale * half_range for an action a in [-1, 1].
  double action_range_scale = 1.0;

  // Structural checks; InputError naming `source_path`.
  void Validate() const;
};

// Parses and validates a character config; InputError naming the file.
CharacterConfig LoadCharacterConfig(const std::string& yaml_path);

// One actuated hinge, in action order: its addresses in MuJoCo's arrays and
// the map from a normalized action to its PD target.
struct ActuatedHinge {
  int joint_id = -1;
  int qpos_address = -1;
  int dof_address = -1;
  int actuator_id = -1;
  double range_low_rad = 0.0;
  double range_high_rad = 0.0;
  double target_mid_rad = 0.0;         // centre of the joint range
  double target_half_range_rad = 0.0;  // half width x action_range_scale
  // The PD's gains and limit, as the MJCF holds them: the servo's kp, the
  // joint's damping (kd) and the actuator's forcerange.
  double kp_nm_per_rad = 0.0;
  double kd_nm_s_per_rad = 0.0;
  double torque_low_nm = 0.0;   // most negative torque (forcerange[0])
  double torque_high_nm = 0.0;  // most positive torque (forcerange[1])
};

// How one skeleton joint is realized in the model.
struct BoundJoint {
  JointType type = JointType::kFixed;
  int body_id = -1;
  int first_hinge = -1;  // index into Character::hinges(); -1 if none
  // Revolute only: MJCF hinge angle = sign x angle about the skeleton axis.
  double revolute_sign = 1.0;
};

// A free body that is not part of the character (e.g. the soccer ball).
struct FreeObject {
  std::string name;
  int body_id = -1;
  int qpos_address = -1;
  int dof_address = -1;
  double radius_m = 0.0;  // its first sphere geom's; 0 without one
};

// A character in a compiled scene: the MuJoCo model plus every id and
// address the simulation needs, resolved once so that stepping does no name
// lookups. Immutable after loading; share one between many Simulations.
class Character {
 public:
  // Loads the config at `config_path`, its skeleton and keypoint map, and
  // compiles scene `scene_name` with the given physics time step.
  static std::shared_ptr<const Character> Load(const std::string& config_path,
                                               const std::string& scene_name,
                                               double physics_timestep_s);
  static std::shared_ptr<const Character> Build(const CharacterConfig& config,
                                                const std::string& scene_name,
                                                double physics_timestep_s);

  const std::string& name() const { return config_.name; }
  const CharacterConfig& config() const { return config_; }
  const std::string& model_path() const { return model_path_; }
  const mjModel* model() const { return model_.get(); }

  const Skeleton& skeleton() const { return *skeleton_; }
  std::shared_ptr<const Skeleton> shared_skeleton() const { return skeleton_; }
  const KeypointMap& keypoint_map() const { return keypoint_map_; }
  const KeypointLayout& keypoint_layout() const {
    return *keypoint_map_.layout;
  }

  int root_body() const { return root_body_; }
  int root_qpos_address() const { return root_qpos_address_; }
  int root_dof_address() const { return root_dof_address_; }
  // One entry per skeleton joint, in skeleton order.
  const std::vector<BoundJoint>& joints() const { return joints_; }
  // Actuated hinges in action order.
  const std::vector<ActuatedHinge>& hinges() const { return hinges_; }
  int num_actions() const { return static_cast<int>(hinges_.size()); }
  // Site ids in keypoint-layout order.
  const std::vector<int>& keypoint_sites() const { return keypoint_sites_; }
  // Model body ids of the character (the root's subtree), ascending.
  const std::vector<int>& bodies() const { return bodies_; }
  bool IsCharacterBody(int body_id) const;
  // Bodies allowed to touch the ground (the others touching it = a fall).
  const std::vector<int>& ground_contact_bodies() const {
    return ground_contact_bodies_;
  }
  const std::vector<FreeObject>& free_objects() const { return free_objects_; }

  // Model id of a body; InputError naming the model file if absent. For
  // setting up, not for per-step use.
  int BodyId(const std::string& body_name) const;

 private:
  Character() = default;
  void BindSkeleton();
  void BindActuators();
  void BindKeypointSites();
  void CollectBodies();

  CharacterConfig config_;
  std::string model_path_;
  MujocoModelPtr model_;
  std::shared_ptr<const Skeleton> skeleton_;
  KeypointMap keypoint_map_;
  int root_body_ = -1;
  int root_qpos_address_ = -1;
  int root_dof_address_ = -1;
  std::vector<BoundJoint> joints_;
  std::vector<ActuatedHinge> hinges_;
  std::vector<int> keypoint_sites_;
  std::vector<int> bodies_;
  std::vector<char> is_character_body_;
  std::vector<int> ground_contact_bodies_;
  std::vector<FreeObject> free_objects_;
};

}  // namespace m2d

#endif  // MIMIC2D_SIM_CHARACTER_H_
