#include "sim/character.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>

#include "common/error.h"
#include "common/file_io.h"
#include "common/yaml_fields.h"

namespace m2d {
namespace {

// Tolerance for checking that the MJCF geometry matches the skeleton and
// keypoint-map files (they are written with 6 decimals).
constexpr double kGeometryTolerance_m = 1e-6;

// A path relative to the config file, without "dir/../" detours.
std::string ResolvePath(const std::string& config_path,
                        const std::string& relative) {
  return std::filesystem::path(ResolveRelative(config_path, relative))
      .lexically_normal()
      .string();
}

std::string Names(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    text += (text.empty() ? "" : ", ") + name;
  }
  return text;
}

std::string FormatVector(const double* v) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "[%.6f, %.6f, %.6f]", v[0], v[1], v[2]);
  return buffer;
}

bool NearVector(const double* a, const Eigen::Vector3d& b) {
  return std::abs(a[0] - b[0]) <= kGeometryTolerance_m &&
         std::abs(a[1] - b[1]) <= kGeometryTolerance_m &&
         std::abs(a[2] - b[2]) <= kGeometryTolerance_m;
}

bool IsIdentityQuaternion(const double* q) {
  return std::abs(std::abs(q[0]) - 1.0) < 1e-9;
}

}  // namespace

void CharacterConfig::Validate() const {
  const std::string& source = source_path;
  if (name.empty()) throw InputError(source, "missing 'name'");
  if (skeleton_path.empty()) throw InputError(source, "missing 'skeleton'");
  if (keypoint_map_path.empty()) {
    throw InputError(source, "missing 'keypoint_map'");
  }
  if (scene_paths.empty()) throw InputError(source, "'scenes' lists no scene");
  if (joints.empty()) throw InputError(source, "'joints' binds no joint");
  std::set<std::string> bound;
  for (const JointBinding& binding : joints) {
    if (!bound.insert(binding.skeleton_joint).second) {
      throw InputError(
          source, "joints: '" + binding.skeleton_joint + "' is bound twice");
    }
    if (binding.body.empty()) {
      throw InputError(source,
                       "joints." + binding.skeleton_joint + ": missing 'body'");
    }
    if (binding.hinges.size() > 3) {
      throw InputError(source, "joints." + binding.skeleton_joint +
                                   ": at most 3 hinges per joint");
    }
  }
  if (!(std::isfinite(action_range_scale) && action_range_scale > 0.0)) {
    throw InputError(source, "action_range_scale must be a positive number");
  }
}

CharacterConfig LoadCharacterConfig(const std::string& yaml_path) {
  YamlSection root(ReadYamlFile(yaml_path), yaml_path, "");
  CharacterConfig config;
  config.source_path = yaml_path;
  std::string skeleton, keypoint_map, pose_prior;
  std::map<std::string, std::string> scenes;
  std::map<std::string, YAML::Node> joints;
  root.Optional("name", &config.name);
  root.Optional("skeleton", &skeleton);
  root.Optional("keypoint_map", &keypoint_map);
  root.Optional("keypoint_site_prefix", &config.keypoint_site_prefix);
  root.Optional("pose_prior", &pose_prior);
  root.Optional("scenes", &scenes);
  root.Optional("joints", &joints);
  root.Optional("ground_contact_bodies", &config.ground_contact_bodies);
  root.Optional("action_range_scale", &config.action_range_scale);
  root.RejectUnknownKeys();

  if (!skeleton.empty())
    config.skeleton_path = ResolvePath(yaml_path, skeleton);
  if (!keypoint_map.empty()) {
    config.keypoint_map_path = ResolvePath(yaml_path, keypoint_map);
  }
  if (!pose_prior.empty())
    config.pose_prior_path = ResolvePath(yaml_path, pose_prior);
  for (const auto& [scene, path] : scenes) {
    config.scene_paths[scene] = ResolvePath(yaml_path, path);
  }
  for (const auto& [joint, node] : joints) {
    YamlSection entry(node, yaml_path, "joints." + joint);
    JointBinding binding;
    binding.skeleton_joint = joint;
    entry.Optional("body", &binding.body);
    entry.Optional("hinges", &binding.hinges);
    entry.RejectUnknownKeys();
    config.joints.push_back(binding);
  }
  config.Validate();
  return config;
}

std::shared_ptr<const Character> Character::Load(const std::string& config_path,
                                                 const std::string& scene_name,
                                                 double physics_timestep_s) {
  return Build(LoadCharacterConfig(config_path), scene_name,
               physics_timestep_s);
}

std::shared_ptr<const Character> Character::Build(const CharacterConfig& config,
                                                  const std::string& scene_name,
                                                  double physics_timestep_s) {
  // Outline: read the kinematic files, compile the scene, then bind the
  // skeleton, actuators and keypoint sites to model ids, checking that the
  // MJCF agrees with the skeleton and keypoint map.
  config.Validate();
  if (!(std::isfinite(physics_timestep_s) && physics_timestep_s > 0.0)) {
    throw ConfigError("physics time step must be positive, got " +
                      std::to_string(physics_timestep_s));
  }
  std::shared_ptr<Character> character(new Character());
  character->config_ = config;
  auto skeleton =
      std::make_shared<Skeleton>(LoadSkeleton(config.skeleton_path));
  character->skeleton_ = skeleton;
  character->keypoint_map_ =
      LoadKeypointMap(config.keypoint_map_path, *skeleton);

  auto scene = config.scene_paths.find(scene_name);
  if (scene == config.scene_paths.end()) {
    std::vector<std::string> known;
    for (const auto& entry : config.scene_paths) known.push_back(entry.first);
    throw InputError(config.source_path, "unknown scene '" + scene_name +
                                             "' (known: " + Names(known) + ")");
  }
  character->model_path_ = scene->second;
  character->model_ = LoadMujocoModel(scene->second);
  character->model_->opt.timestep = physics_timestep_s;

  character->BindSkeleton();
  character->BindActuators();
  character->BindKeypointSites();
  character->CollectBodies();
  return character;
}

bool Character::IsCharacterBody(int body_id) const {
  return body_id >= 0 &&
         body_id < static_cast<int>(is_character_body_.size()) &&
         is_character_body_[body_id];
}

int Character::BodyId(const std::string& body_name) const {
  int id = mj_name2id(model_.get(), mjOBJ_BODY, body_name.c_str());
  if (id < 0) throw InputError(model_path_, "no body '" + body_name + "'");
  return id;
}

void Character::BindSkeleton() {
  const mjModel* m = model_.get();
  const std::string& source = config_.source_path;
  std::map<std::string, const JointBinding*> bindings;
  for (const JointBinding& binding : config_.joints) {
    if (skeleton_->IndexOf(binding.skeleton_joint) < 0) {
      throw InputError(source, "joints: '" + binding.skeleton_joint +
                                   "' is not a joint of skeleton " +
                                   config_.skeleton_path);
    }
    bindings[binding.skeleton_joint] = &binding;
  }
  joints_.resize(skeleton_->num_joints());
  for (int j = 0; j < skeleton_->num_joints(); ++j) {
    const SkeletonJoint& joint = skeleton_->joints[j];
    auto found = bindings.find(joint.name);
    if (found == bindings.end()) {
      throw InputError(source, "joints: skeleton joint '" + joint.name +
                                   "' is not bound to a body");
    }
    const JointBinding& binding = *found->second;
    const std::string where = "joints." + joint.name;
    BoundJoint& bound = joints_[j];
    bound.type = joint.type;
    bound.body_id = mj_name2id(m, mjOBJ_BODY, binding.body.c_str());
    if (bound.body_id < 0) {
      throw InputError(source, where + ": no body '" + binding.body +
                                   "' in model " + model_path_);
    }
    const int body = bound.body_id;

    // The body must sit where the skeleton puts the joint, unrotated, under
    // the parent joint's body, so that MuJoCo and the skeleton FK agree.
    if (j > 0) {
      const int parent_body = joints_[joint.parent].body_id;
      if (m->body_parentid[body] != parent_body) {
        throw InputError(model_path_,
                         "body '" + binding.body +
                             "' must be a child of body '" +
                             mj_id2name(m, mjOBJ_BODY, parent_body) +
                             "' (skeleton joint " + joint.name + ")");
      }
      if (!NearVector(m->body_pos + 3 * body, joint.offset_m) ||
          !IsIdentityQuaternion(m->body_quat + 4 * body)) {
        throw InputError(model_path_, "body '" + binding.body + "' is at " +
                                          FormatVector(m->body_pos + 3 * body) +
                                          " (or rotated); skeleton joint " +
                                          joint.name + " puts it at " +
                                          FormatVector(joint.offset_m.data()));
      }
    }

    size_t expected_hinges = 0;
    if (joint.type == JointType::kSpherical) expected_hinges = 3;
    if (joint.type == JointType::kRevolute) expected_hinges = 1;
    if (binding.hinges.size() != expected_hinges) {
      throw InputError(source, where + ": a joint of this type needs " +
                                   std::to_string(expected_hinges) +
                                   " hinges, got " +
                                   std::to_string(binding.hinges.size()));
    }
    if (joint.type == JointType::kFree) {
      const int first_joint = m->body_jntadr[body];
      if (m->body_jntnum[body] != 1 || m->jnt_type[first_joint] != mjJNT_FREE) {
        throw InputError(model_path_, "root body '" + binding.body +
                                          "' needs exactly one freejoint");
      }
      root_body_ = body;
      root_qpos_address_ = m->jnt_qposadr[first_joint];
      root_dof_address_ = m->jnt_dofadr[first_joint];
      continue;
    }
    if (m->body_jntnum[body] != static_cast<int>(expected_hinges)) {
      throw InputError(model_path_, "body '" + binding.body + "' has " +
                                        std::to_string(m->body_jntnum[body]) +
                                        " joints; " + where + " in " + source +
                                        " binds " +
                                        std::to_string(expected_hinges));
    }
    if (expected_hinges == 0) continue;

    bound.first_hinge = static_cast<int>(hinges_.size());
    for (size_t k = 0; k < binding.hinges.size(); ++k) {
      const std::string& hinge_name = binding.hinges[k];
      const int id = mj_name2id(m, mjOBJ_JOINT, hinge_name.c_str());
      if (id < 0) {
        throw InputError(source, where + ": no joint '" + hinge_name +
                                     "' in model " + model_path_);
      }
      if (m->jnt_type[id] != mjJNT_HINGE || m->jnt_bodyid[id] != body) {
        throw InputError(source, where + ": joint '" + hinge_name +
                                     "' must be a hinge of body '" +
                                     binding.body + "'");
      }
      if (m->body_jntadr[body] + static_cast<int>(k) != id) {
        throw InputError(source, where +
                                     ": list the hinges in the order the "
                                     "model declares them");
      }
      const double* pos = m->jnt_pos + 3 * id;
      if (std::abs(pos[0]) + std::abs(pos[1]) + std::abs(pos[2]) > 0.0) {
        throw InputError(model_path_, "hinge '" + hinge_name +
                                          "' must turn about its body origin");
      }
      if (!m->jnt_limited[id]) {
        throw InputError(model_path_, "hinge '" + hinge_name +
                                          "' needs a range (actions are "
                                          "normalized to it)");
      }
      Eigen::Vector3d axis(m->jnt_axis + 3 * id);
      if (joint.type == JointType::kSpherical) {
        // Hinges about x, y, z compose as R = Rx Ry Rz (MuJoCo multiplies a
        // body's joint rotations in declaration order).
        if ((axis - Eigen::Vector3d::Unit(static_cast<int>(k))).norm() > 1e-9) {
          throw InputError(model_path_, "hinge '" + hinge_name +
                                            "' of spherical joint " +
                                            joint.name + " must have axis " +
                                            (k == 0   ? "x"
                                             : k == 1 ? "y"
                                                      : "z"));
        }
      } else {
        const double alignment = axis.dot(joint.axis);
        if (std::abs(std::abs(alignment) - 1.0) > 1e-9) {
          throw InputError(model_path_, "hinge '" + hinge_name +
                                            "' is not parallel to the skeleton "
                                            "axis of joint " +
                                            joint.name);
        }
        bound.revolute_sign = alignment > 0 ? 1.0 : -1.0;
      }
      ActuatedHinge hinge;
      hinge.joint_id = id;
      hinge.qpos_address = m->jnt_qposadr[id];
      hinge.dof_address = m->jnt_dofadr[id];
      hinge.range_low_rad = m->jnt_range[2 * id];
      hinge.range_high_rad = m->jnt_range[2 * id + 1];
      hinge.target_mid_rad = 0.5 * (hinge.range_low_rad + hinge.range_high_rad);
      hinge.target_half_range_rad =
          0.5 * (hinge.range_high_rad - hinge.range_low_rad) *
          config_.action_range_scale;
      hinges_.push_back(hinge);
    }
  }
}

void Character::BindActuators() {
  // Each hinge needs exactly one position servo: force = kp (ctrl - q),
  // i.e. fixed gain kp and affine bias (0, -kp, 0), gear 1.
  const mjModel* m = model_.get();
  for (ActuatedHinge& hinge : hinges_) {
    const char* hinge_name = mj_id2name(m, mjOBJ_JOINT, hinge.joint_id);
    for (int a = 0; a < m->nu; ++a) {
      if (m->actuator_trntype[a] != mjTRN_JOINT ||
          m->actuator_trnid[2 * a] != hinge.joint_id) {
        continue;
      }
      if (hinge.actuator_id >= 0) {
        throw InputError(model_path_, std::string("hinge '") + hinge_name +
                                          "' has more than one actuator");
      }
      hinge.actuator_id = a;
    }
    if (hinge.actuator_id < 0) {
      throw InputError(model_path_, std::string("hinge '") + hinge_name +
                                        "' has no actuator");
    }
    const int a = hinge.actuator_id;
    const double kp = m->actuator_gainprm[a * mjNGAIN];
    const double* bias = m->actuator_biasprm + a * mjNBIAS;
    const bool is_servo = m->actuator_gaintype[a] == mjGAIN_FIXED &&
                          m->actuator_biastype[a] == mjBIAS_AFFINE && kp > 0 &&
                          bias[0] == 0.0 && bias[1] == -kp && bias[2] == 0.0 &&
                          m->actuator_gear[6 * a] == 1.0 &&
                          m->actuator_dyntype[a] == mjDYN_NONE;
    if (!is_servo) {
      throw InputError(model_path_,
                       std::string("actuator of hinge '") + hinge_name +
                           "' must be a <position> servo (kp > 0, gear 1)");
    }
    hinge.kp_nm_per_rad = kp;
    hinge.kd_nm_s_per_rad = m->dof_damping[hinge.dof_address];
    const bool limited = m->actuator_forcelimited[a];
    const double infinity = std::numeric_limits<double>::infinity();
    hinge.torque_low_nm = limited ? m->actuator_forcerange[2 * a] : -infinity;
    hinge.torque_high_nm =
        limited ? m->actuator_forcerange[2 * a + 1] : infinity;
    if (!(hinge.torque_low_nm < 0.0 && hinge.torque_high_nm > 0.0)) {
      throw InputError(model_path_, std::string("actuator of hinge '") +
                                        hinge_name +
                                        "' needs a forcerange around 0");
    }
  }
}

void Character::BindKeypointSites() {
  const mjModel* m = model_.get();
  const KeypointLayout& layout = *keypoint_map_.layout;
  for (int k = 0; k < layout.num_keypoints(); ++k) {
    const std::string& keypoint = layout.keypoint_names[k];
    const std::string site_name = config_.keypoint_site_prefix + keypoint;
    const int site = mj_name2id(m, mjOBJ_SITE, site_name.c_str());
    if (site < 0) {
      throw InputError(model_path_, "no site '" + site_name +
                                        "' for keypoint '" + keypoint +
                                        "' (keypoint_site_prefix in " +
                                        config_.source_path + ")");
    }
    const KeypointAnchor& anchor = keypoint_map_.anchors[k];
    const int anchor_body = joints_[anchor.joint].body_id;
    if (m->site_bodyid[site] != anchor_body ||
        !NearVector(m->site_pos + 3 * site, anchor.offset_m)) {
      throw InputError(model_path_,
                       "site '" + site_name + "' must be on body '" +
                           mj_id2name(m, mjOBJ_BODY, anchor_body) + "' at " +
                           FormatVector(anchor.offset_m.data()) +
                           " as in keypoint map " + config_.keypoint_map_path);
    }
    keypoint_sites_.push_back(site);
  }
}

void Character::CollectBodies() {
  const mjModel* m = model_.get();
  // Parents precede children in MuJoCo's body order.
  is_character_body_.assign(m->nbody, 0);
  for (int b = 1; b < m->nbody; ++b) {
    if (b == root_body_ || is_character_body_[m->body_parentid[b]]) {
      is_character_body_[b] = 1;
      bodies_.push_back(b);
    }
  }
  for (const std::string& name : config_.ground_contact_bodies) {
    const int id = mj_name2id(m, mjOBJ_BODY, name.c_str());
    if (!IsCharacterBody(id)) {
      throw InputError(config_.source_path,
                       "ground_contact_bodies: '" + name +
                           "' is not a body of the character in " +
                           model_path_);
    }
    ground_contact_bodies_.push_back(id);
  }
  for (int j = 0; j < m->njnt; ++j) {
    const int body = m->jnt_bodyid[j];
    if (m->jnt_type[j] != mjJNT_FREE || IsCharacterBody(body)) continue;
    FreeObject object;
    object.name = mj_id2name(m, mjOBJ_BODY, body);
    object.body_id = body;
    object.qpos_address = m->jnt_qposadr[j];
    object.dof_address = m->jnt_dofadr[j];
    for (int g = m->ngeom - 1; g >= 0; --g) {
      if (m->geom_bodyid[g] == body && m->geom_type[g] == mjGEOM_SPHERE)
        object.radius_m = m->geom_size[3 * g];
    }
    free_objects_.push_back(object);
  }
}

}  // namespace m2d
