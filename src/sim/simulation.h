// sim: MuJoCo physics for characters — models, simulations, PD control,
// pose mapping, keypoints and contacts.
#ifndef MIMIC2D_SIM_SIMULATION_H_
#define MIMIC2D_SIM_SIMULATION_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/settings.h"
#include "motion/motion3d.h"
#include "sim/character.h"
#include "sim/mujoco_handles.h"

namespace m2d {

// What a hinge's torque limit (its actuator's forcerange) bounds
// (docs/simulation.md, "What the torque limit bounds").
enum class TorqueLimit {
  // The servo's kp (q* - q) alone; the joint's damping -kd qdot acts on top,
  // unbounded. A joint then cannot be driven much faster than limit / kd
  // (2-2.5 rad/s at the humanoid's shoulders, elbows and ankles).
  kServo,
  // The whole PD torque kp (q* - q) - kd qdot, as DeepMimic's torque limit
  // and Isaac Gym's drive effort do: fast limbs stay within reach.
  kPd,
};
inline const char* SettingName(TorqueLimit limit) {
  return limit == TorqueLimit::kServo ? "servo" : "pd";
}
inline bool ParseSetting(const std::string& text, TorqueLimit* limit) {
  return ParseSettingByName(text, {TorqueLimit::kServo, TorqueLimit::kPd},
                            limit);
}
inline std::string SettingChoices(TorqueLimit) { return "servo, pd"; }

struct SimulationOptions {
  double control_hz = 30.0;  // policy rate: one Step() per control period
  // Physics steps per control period (physics at control_hz x substeps).
  // 2 (60 Hz) is the lowest stable count for the humanoid; 4 (120 Hz)
  // halves ground penetration and integration error (docs/simulation.md,
  // "Physics rate").
  int physics_substeps = 4;
  // Divergence limits: speeds no motion reaches unless the physics blew up
  // (a baseball pitch turns the shoulder at about 150 rad/s).
  double max_joint_speed_rad_s = 200.0;   // character rotational DoF
  double max_linear_speed_m_s = 50.0;     // every free body's translation
  double max_object_spin_rad_s = 1000.0;  // non-character free bodies
  // What the torque limits bound; servo is how every policy before
  // 2026-12-02 was trained.
  TorqueLimit torque_limit = TorqueLimit::kServo;

  // Every setting (common/settings.h); a training config's `env` section.
  template <typename Self, typename Visitor>
  static void VisitFields(Self& self, Visitor& v) {
    v("control_hz", self.control_hz, Range::Closed(1, 1000),
      "policy rate (Hz): one step per control period; bundles must be at "
      "this fps");
    v("physics_substeps", self.physics_substeps, Range::Closed(1, 100),
      "physics steps per control period (2 is the humanoid's stability "
      "limit, 4 halves ground penetration)");
    v("max_joint_speed_rad_s", self.max_joint_speed_rad_s, Range::Above(0),
      "divergence limit: any rotational DoF faster than this ends the "
      "episode as diverged");
    v("max_linear_speed_m_s", self.max_linear_speed_m_s, Range::Above(0),
      "divergence limit on every free body's translation");
    v("max_object_spin_rad_s", self.max_object_spin_rad_s, Range::Above(0),
      "divergence limit on non-character free bodies' spin");
    v("torque_limit", self.torque_limit, Range::Any(),
      "what the actuators' torque limits bound: servo (kp (q* - q) alone, "
      "joint damping on top, unbounded) or pd (the whole kp (q* - q) - kd "
      "qdot, as DeepMimic)");
  }

  double physics_timestep_s() const {
    return 1.0 / (control_hz * physics_substeps);
  }
  // Throws ConfigError when a field is outside its range.
  void Validate() const;
};

// Loads a character with the physics time step `options` asks for.
std::shared_ptr<const Character> LoadCharacterForSimulation(
    const std::string& config_path, const std::string& scene_name,
    const SimulationOptions& options);

enum class Divergence {
  kNone,
  kNonFinite,       // NaN or inf in qpos or qvel
  kExcessiveSpeed,  // a velocity beyond the SimulationOptions limits
  kBadPhysics,      // MuJoCo flagged a bad qpos/qvel/qacc and reset itself
  kEngineError,     // MuJoCo raised an error (e.g. stack overflow)
};
const char* DivergenceName(Divergence divergence);

struct StepResult {
  Divergence divergence = Divergence::kNone;
  bool diverged() const { return divergence != Divergence::kNone; }
  // Mean over the substeps of sum_i |qdot_i tau_i| over the actuated DoF,
  // tau = PD torque (servo + damping); the energy penalty's input.
  double mean_abs_power_w = 0.0;
};

// A snapshot of everything that determines the future trajectory: MuJoCo's
// integration state (time, qpos, qvel, act) plus the solver warm start and
// the inputs (ctrl, applied forces, mocap), so that Restore() + Step()
// reproduces the original trajectory bit for bit.
struct SimState {
  double time_s = 0.0;
  std::vector<double> qpos, qvel, act, qacc_warmstart, ctrl;
  std::vector<double> qfrc_applied, xfrc_applied, mocap_pos, mocap_quat;
};

// One simulated world (mjData) of a shared, immutable Character model.
// After construction and after every call that changes the state, MuJoCo's
// position and velocity stages have been computed for the current state, so
// keypoints and contacts describe it. Step() allocates nothing.
class Simulation {
 public:
  Simulation(std::shared_ptr<const Character> character,
             const SimulationOptions& options);

  const Character& character() const { return *character_; }
  const SimulationOptions& options() const { return options_; }
  const mjModel* model() const { return character_->model(); }
  const mjData* data() const { return data_.get(); }
  // For scene setup (e.g. placing the ball, applying perturbation forces);
  // call Refresh() after changing the state directly.
  mjData* mutable_data() { return data_.get(); }

  // Sets PD targets from `normalized_actions` (num_actions values, clipped
  // to [-1, 1]) and advances one control period. A diverged simulation
  // stops early, stays diverged and must be Reset/Restored/SetPose'd.
  StepResult Step(const float* normalized_actions);
  bool diverged() const { return divergence_ != Divergence::kNone; }
  Divergence divergence() const { return divergence_; }

  // The model's reference state (qpos0, zero velocity, time 0).
  void Reset();
  // Puts the character in `pose` with `qvel` (model->nv values, or null for
  // zero velocity) for its DoF; other bodies keep their state.
  void SetPose(const Pose3D& pose, const double* character_qvel = nullptr);
  // Recomputes the derived quantities after mutable_data() edits.
  void Refresh();

  SimState Save() const;
  void Save(SimState* state) const;  // reuses `state`'s buffers
  void Restore(const SimState& state);

  // World positions of the keypoint sites, layout order, 3 doubles each.
  void KeypointPositions(double* out_xyz) const;
  // PD target (rad) per action for `normalized_actions`.
  void ActionsToTargets(const float* normalized_actions,
                        double* targets_rad) const;
  // Mean PD torque per actuated hinge (N m) over the last Step.
  const std::vector<double>& mean_torques_nm() const { return mean_torques_; }

  // Contacts with the ground (geoms of the world body, e.g. the floor).
  bool BodyTouchesGround(int body_id) const;
  // Per model body: 1 if it touches the ground. Size model->nbody.
  void GroundContacts(std::vector<uint8_t>* touching) const;
  // True when a character body not listed in ground_contact_bodies touches
  // the ground (a fall).
  bool UnexpectedGroundContact() const;

 private:
  bool GeomIsGround(int geom) const;
  void CheckDivergence(const int* warnings_before);

  std::shared_ptr<const Character> character_;
  SimulationOptions options_;
  MujocoDataPtr data_;
  Divergence divergence_ = Divergence::kNone;
  std::vector<double> speed_limit_;  // per DoF
  // TorqueLimit::kPd: sets each hinge's servo target and applied torque
  // for the next substep so that the PD's whole torque keeps to its limit.
  void LimitWholePd(const double* targets_rad);

  std::vector<double> targets_rad_;      // per action: the step's PD targets
  std::vector<double> hinge_qvel_;       // scratch: qvel before a substep
  std::vector<double> mean_torques_;     // per action
  std::vector<uint8_t> allowed_ground_;  // per body
};

// The height (m) of the character's lowest colliding point in its current
// state: exact for spheres, capsules, cylinders and boxes, a bounding sphere
// for other shapes.
double LowestCharacterPointZ(const Simulation& simulation);
// The same for geom `g` of `m` placed as in `d` (after kinematics).
double LowestGeomPointZ(const mjModel* m, const mjData* d, int g);

// The keypoint sites' world positions as points (layout order).
std::vector<Eigen::Vector3d> SimulatedKeypoints(const Simulation& simulation);

}  // namespace m2d

#endif  // MIMIC2D_SIM_SIMULATION_H_
