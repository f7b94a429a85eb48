// Where cameras and initial states come from: Prepare keeps only what the
// sources allow (no truth in 2D-only mode), estimated cameras replace the
// true ones, an estimate fills one initial-state buffer per view, and every
// missing source is a named error. No shared data: a gliding standing pose.
#include "env/sources.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>

#include "common/error.h"
#include "env/task.h"
#include "env_fixture.h"

namespace m2d {
namespace {

using testing::WorldChange;

// Two views, each with its own estimated world frame: the truth turned and
// shifted differently per view.
const std::vector<WorldChange>& Changes() {
  static const std::vector<WorldChange> changes = {{0.7, {1.5, -2.0, 0.0}},
                                                   {-2.1, {-0.4, 3.0, 0.0}}};
  return changes;
}

struct Fixture {
  SimulationOptions simulation;
  std::shared_ptr<const Character> character;
  ReferenceBundle bundle;  // truth, true cameras and the estimate
};

Fixture MakeFixture() {
  Fixture fixture;
  fixture.character = testing::LoadHumanoid(fixture.simulation);
  fixture.bundle = testing::MakeGlidingBundle(*fixture.character, 1.0);
  fixture.bundle.estimate =
      testing::EstimateFromTruth(fixture.bundle, Changes());
  return fixture;
}

TrackingTask Build(const Fixture& fixture, const TaskSources& sources) {
  TrackingTaskOptions options;
  options.simulation = fixture.simulation;
  options.sources = sources;
  return BuildTrackingTask(fixture.character, {fixture.bundle}, options);
}

// The message of the InputError `call` throws (fails when it throws none).
template <typename Call>
std::string InputErrorOf(Call call) {
  try {
    call();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(Sources, ParseAndPrintRoundTrip) {
  for (InitialStateSource source :
       {InitialStateSource::kTruth, InitialStateSource::kEstimate,
        InitialStateSource::kDefault}) {
    EXPECT_EQ(ParseInitialStateSource(SourceName(source)), source);
  }
  for (CameraSource source : {CameraSource::kTruth, CameraSource::kEstimate})
    EXPECT_EQ(ParseCameraSource(SourceName(source)), source);
  EXPECT_THROW(ParseInitialStateSource("Truth"), ConfigError);
  EXPECT_THROW(ParseCameraSource("default"), ConfigError);
  // Poses and cameras of different world frames do not mix.
  EXPECT_THROW((TaskSources{InitialStateSource::kEstimate, CameraSource::kTruth}
                    .Validate()),
               ConfigError);
  EXPECT_THROW((TaskSources{InitialStateSource::kTruth, CameraSource::kEstimate}
                    .Validate()),
               ConfigError);
  EXPECT_NO_THROW(
      (TaskSources{InitialStateSource::kDefault, CameraSource::kEstimate}
           .Validate()));
}

TEST(Sources, EstimateSourcesUseTheEstimatedCamerasAndHoldNoTruth) {
  Fixture fixture = MakeFixture();
  TrackingTask task =
      Build(fixture, {InitialStateSource::kEstimate, CameraSource::kEstimate});
  const ReferenceBundle& prepared = task.reference->bundles()[0];
  EXPECT_FALSE(prepared.ground_truth.has_value());
  ASSERT_TRUE(prepared.estimate.has_value());
  for (size_t v = 0; v < prepared.views.size(); ++v) {
    const PinholeCamera& used = prepared.views[v].CameraAt(0);
    const PinholeCamera& estimated = (*fixture.bundle.estimate)[v].CameraAt(0);
    EXPECT_TRUE(used.rotation_world_to_camera().isApprox(
        estimated.rotation_world_to_camera()));
    EXPECT_TRUE(used.translation_m().isApprox(estimated.translation_m()));
    EXPECT_FALSE(used.translation_m().isApprox(
        fixture.bundle.views[v].CameraAt(0).translation_m()));
  }

  // Default starts keep neither the truth nor the estimate.
  TrackingTask placed =
      Build(fixture, {InitialStateSource::kDefault, CameraSource::kEstimate});
  EXPECT_FALSE(placed.reference->bundles()[0].ground_truth.has_value());
  EXPECT_FALSE(placed.reference->bundles()[0].estimate.has_value());
  EXPECT_EQ(placed.initial_states->num_buffers(), 1);

  // Truth keeps the truth and drops the estimate.
  TrackingTask truth = Build(fixture, TaskSources());
  EXPECT_TRUE(truth.reference->bundles()[0].ground_truth.has_value());
  EXPECT_FALSE(truth.reference->bundles()[0].estimate.has_value());
}

TEST(Sources, MissingSourcesAreNamedErrors) {
  Fixture fixture = MakeFixture();
  const TaskSources estimate{InitialStateSource::kEstimate,
                             CameraSource::kEstimate};

  Fixture stripped = fixture;
  stripped.bundle = StripBundle(fixture.bundle);
  std::string message =
      InputErrorOf([&] { Build(stripped, {InitialStateSource::kDefault}); });
  EXPECT_NE(message.find("gliding"), std::string::npos) << message;
  EXPECT_NE(message.find("stripped? use cameras: estimate"), std::string::npos)
      << message;

  message = InputErrorOf([&] { Build(stripped, estimate); });
  EXPECT_NE(message.find("gliding"), std::string::npos) << message;
  EXPECT_NE(message.find("run mimic2d fit"), std::string::npos) << message;

  Fixture no_truth = fixture;
  no_truth.bundle.ground_truth.reset();
  message = InputErrorOf([&] { Build(no_truth, TaskSources()); });
  EXPECT_NE(message.find("gliding"), std::string::npos) << message;
  EXPECT_NE(message.find("initial_states: truth needs ground-truth poses"),
            std::string::npos)
      << message;

  Fixture other_skeleton = fixture;
  (*other_skeleton.bundle.estimate)[1].skeleton_name = "smpl";
  message = InputErrorOf([&] { Build(other_skeleton, estimate); });
  EXPECT_NE(message.find("skeleton 'smpl'"), std::string::npos) << message;
  EXPECT_NE(message.find(fixture.bundle.views[1].name), std::string::npos)
      << message;

  // A stripped bundle with only an estimate is all 2D-only mode needs.
  Fixture fitted = fixture;
  fitted.bundle = StripBundle(fixture.bundle);
  fitted.bundle.estimate = fixture.bundle.estimate;
  EXPECT_NO_THROW(Build(fitted, estimate));
}

TEST(Sources, EstimatedInitialStatesAreEachViewsPosesInItsOwnFrame) {
  Fixture fixture = MakeFixture();
  TrackingTask task =
      Build(fixture, {InitialStateSource::kEstimate, CameraSource::kEstimate});
  const InitialStates& states = *task.initial_states;
  const int num_views = static_cast<int>(task.reference->views().size());
  ASSERT_EQ(num_views, 2);
  ASSERT_EQ(states.num_buffers(), num_views);
  EXPECT_NE(states.BufferOf(0), states.BufferOf(1));

  // With the truth: one buffer shared by the bundle's views.
  TrackingTask truth_task = Build(fixture, TaskSources());
  const InitialStates& truth_states = *truth_task.initial_states;
  ASSERT_EQ(truth_states.num_buffers(), 1);
  EXPECT_EQ(truth_states.BufferOf(0), truth_states.BufferOf(1));

  // Each view's buffer holds the truth's states moved into that view's
  // frame: same joints and speeds, the root turned and shifted.
  const int root = task.character->root_qpos_address();
  const int frames = fixture.bundle.num_frames();
  for (int v = 0; v < num_views; ++v) {
    const WorldChange& change = Changes()[v];
    for (int t = 0; t < frames; t += 5) {
      SCOPED_TRACE("view " + std::to_string(v) + " frame " + std::to_string(t));
      const SimState& state = states.BufferOfView(v).entry(t, 0).state;
      const SimState& truth = truth_states.BufferOfView(v).entry(t, 0).state;
      const Eigen::Vector3d truth_root(truth.qpos[root], truth.qpos[root + 1],
                                       truth.qpos[root + 2]);
      const Eigen::Vector3d root_m(state.qpos[root], state.qpos[root + 1],
                                   state.qpos[root + 2]);
      // Lifting out of the floor moves the root up only.
      EXPECT_TRUE(
          root_m.head<2>().isApprox(change.Point(truth_root).head<2>(), 1e-9));
      EXPECT_GE(root_m.z(), truth_root.z() - 1e-9);
      for (size_t k = root + 7; k < state.qpos.size(); ++k)
        EXPECT_NEAR(state.qpos[k], truth.qpos[k], 1e-9) << k;
      // Linear velocity turned with the world.
      const Eigen::Vector3d truth_velocity(truth.qvel[0], truth.qvel[1],
                                           truth.qvel[2]);
      const Eigen::Vector3d velocity(state.qvel[0], state.qvel[1],
                                     state.qvel[2]);
      EXPECT_TRUE(velocity.isApprox(change.rotation() * truth_velocity, 1e-6));
    }
  }

  // Episodes on a view start at that view's estimated poses, and project
  // onto its 2D as the truth did through the true cameras.
  TrackingEnvOptions env_options;
  env_options.simulation = fixture.simulation;
  TrackingEnv env(task.character, task.reference, task.initial_states,
                  env_options, 1);
  TrackingEnv truth_env(truth_task.character, truth_task.reference,
                        truth_task.initial_states, env_options, 1);
  std::vector<float> observation(env.observation_size());
  for (int v = 0; v < num_views; ++v) {
    env.ResetTo(v, 10, states.BufferOfView(v).entry(10, 0).state,
                observation.data());
    truth_env.ResetTo(v, 10, truth_states.BufferOfView(v).entry(10, 0).state,
                      observation.data());
    const std::vector<double>& projected = env.projected_px();
    const std::vector<double>& truth_projected = truth_env.projected_px();
    for (size_t i = 0; i < projected.size(); ++i)
      EXPECT_NEAR(projected[i], truth_projected[i], 0.05) << v << " " << i;
  }
  // Random episodes draw from their view's buffer.
  for (int e = 0; e < 20; ++e) {
    env.Reset(observation.data());
    const int v = env.episode().view_index;
    const SimState& expected =
        states.BufferOfView(v).entry(env.frame(), 0).state;
    const std::vector<double> qpos = env.simulation().Save().qpos;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(qpos[root + k], expected.qpos[root + k], 1e-12);
  }
}

TEST(Sources, NoisyStartsApplyOnTopOfTheEstimate) {
  Fixture fixture = MakeFixture();
  TrackingTaskOptions options;
  options.simulation = fixture.simulation;
  options.sources = {InitialStateSource::kEstimate, CameraSource::kEstimate};
  TrackingTask clean =
      BuildTrackingTask(fixture.character, {fixture.bundle}, options);
  options.initial_state_noise_rad = 0.3;
  options.noise_seed = 5;
  TrackingTask noisy =
      BuildTrackingTask(fixture.character, {fixture.bundle}, options);
  ASSERT_EQ(noisy.initial_states->num_buffers(), 2);
  const ActuatedHinge& hinge = fixture.character->hinges().front();
  int changed = 0;
  for (int v = 0; v < 2; ++v) {
    for (int t = 0; t < fixture.bundle.num_frames(); ++t) {
      changed += noisy.initial_states->buffer(v)
                     .entry(t, 0)
                     .state.qpos[hinge.qpos_address] !=
                 clean.initial_states->buffer(v)
                     .entry(t, 0)
                     .state.qpos[hinge.qpos_address];
    }
  }
  EXPECT_EQ(changed, 2 * fixture.bundle.num_frames());
}

// `mimic2d fit` fails on a view whose frames mostly did not converge but
// writes the estimate for inspection; a task built on it anyway warns,
// naming the view, and one on the truth does not read the estimate at all.
TEST(Sources, ATaskOnAnUnreliableFitWarns) {
  Fixture fixture = MakeFixture();
  FitSummary& fit = (*fixture.bundle.estimate)[1].summary;
  fit.num_frames = fixture.bundle.num_frames();
  EXPECT_FALSE(fit.Unreliable());
  for (int t = 0; t <= fit.num_frames / 4; ++t)
    fit.unconverged_frames.push_back(t);
  EXPECT_TRUE(fit.Unreliable());
  EXPECT_FALSE((*fixture.bundle.estimate)[0].summary.Unreliable());

  auto log = std::make_shared<std::ostringstream>();
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(*log);
  spdlog::default_logger()->sinks().push_back(sink);
  Build(fixture, {InitialStateSource::kEstimate, CameraSource::kEstimate});
  const std::string on_estimate = log->str();
  log->str("");
  Build(fixture, {InitialStateSource::kTruth, CameraSource::kTruth});
  const std::string on_truth = log->str();
  // Read from a file (train, eval), the warning names the file.
  log->str("");
  const std::string dir = testing::TempDir("unreliable_fit");
  const std::string path = dir + "/gliding.json";
  WriteBundle(path, fixture.bundle);
  TrackingTaskOptions options;
  options.simulation = fixture.simulation;
  options.sources = {InitialStateSource::kEstimate, CameraSource::kEstimate};
  BuildTrackingTask(testing::SourcePath("assets/characters/humanoid.yaml"),
                    "flat", {path}, options);
  const std::string from_file = log->str();
  spdlog::default_logger()->sinks().pop_back();
  EXPECT_NE(from_file.find(path + ": the fit of view " +
                           fixture.bundle.views[1].name + " did not converge"),
            std::string::npos)
      << from_file;
  std::filesystem::remove_all(dir);

  EXPECT_NE(on_estimate.find("the fit of view " + fixture.bundle.views[1].name +
                             " did not converge on " +
                             std::to_string(fit.unconverged_frames.size()) +
                             " of " + std::to_string(fit.num_frames) +
                             " frames (more than 25%)"),
            std::string::npos)
      << on_estimate;
  EXPECT_EQ(on_estimate.find("view " + fixture.bundle.views[0].name + " did"),
            std::string::npos)
      << on_estimate;
  EXPECT_EQ(on_truth.find("did not converge"), std::string::npos) << on_truth;
}

}  // namespace
}  // namespace m2d
