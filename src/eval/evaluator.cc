#include "eval/evaluator.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "common/error.h"
#include "eval/metrics.h"

namespace m2d {
namespace {

// The view sets rolled out: {v} per view for K = 1; otherwise per bundle
// with at least K views, each view v with the K - 1 next views of its
// bundle (wrapping).
std::vector<std::vector<int>> ViewSets(const TrackingReference& reference,
                                       int num_views) {
  const std::vector<TrackedView>& views = reference.views();
  std::vector<std::vector<int>> sets;
  for (size_t b = 0; b < reference.bundles().size(); ++b) {
    std::vector<int> bundle_views;
    for (size_t v = 0; v < views.size(); ++v) {
      if (views[v].bundle == static_cast<int>(b))
        bundle_views.push_back(static_cast<int>(v));
    }
    const int count = static_cast<int>(bundle_views.size());
    if (count < num_views) continue;
    for (int first = 0; first < count; ++first) {
      std::vector<int> set;
      for (int k = 0; k < num_views; ++k)
        set.push_back(bundle_views[(first + k) % count]);
      sets.push_back(set);
    }
  }
  return sets;
}

RolloutEnd EndOf(const StepOutcome& outcome) {
  if (outcome.diverged) return RolloutEnd::kDiverged;
  if (outcome.terminated) return RolloutEnd::kEarlyExit;
  return outcome.reference_ended ? RolloutEnd::kClipEnd
                                 : RolloutEnd::kTimeLimit;
}

}  // namespace

TrackingEnvOptions JudgedEnvOptions(const TrackingEnvOptions& trained,
                                    const EvalOptions& options) {
  TrackingEnvOptions judged = trained;
  // The early exit exactly at the success rule.
  judged.early_exit = true;
  judged.early_exit_max_error_px = options.success_threshold_px;
  judged.early_exit_measure = options.success_measure;
  judged.max_episode_s = options.episode_s;
  // Every policy is judged by the same 2D criterion, whatever it was
  // trained to follow (a 3D baseline's own 3D exit is off).
  judged.reward_3d.early_exit_max_error_m = 0.0;
  judged.pushes = options.pushes;
  judged.object_start_square_m = options.object_start_square_m;
  if (options.camera) judged.camera = *options.camera;
  return judged;
}

const char* RolloutEndName(RolloutEnd end) {
  switch (end) {
    case RolloutEnd::kEarlyExit:
      return "early_exit";
    case RolloutEnd::kDiverged:
      return "diverged";
    case RolloutEnd::kClipEnd:
      return "clip_end";
    case RolloutEnd::kTimeLimit:
      return "time_limit";
  }
  return "?";
}

void EvalOptions::Validate() const {
  if (episodes_per_view < 1)
    throw ConfigError("eval: episodes_per_view must be >= 1");
  if (!(episode_s > 0)) throw ConfigError("eval: episode_s must be > 0");
  if (!(success_threshold_px > 0))
    throw ConfigError("eval: success_threshold_px must be > 0");
  if (num_views < 1 || num_views > kMaxObservedViews) {
    throw ConfigError("eval: the number of views must be in [1, " +
                      std::to_string(kMaxObservedViews) + "]");
  }
  pushes.Validate();
  if (!(object_start_square_m >= 0 && std::isfinite(object_start_square_m)))
    throw ConfigError(
        "eval: the object start square must be finite and >= 0 m");
}

std::vector<EvalRow> EvaluatePolicy(
    Policy& policy, std::shared_ptr<const Character> character,
    std::shared_ptr<const TrackingReference> reference,
    std::shared_ptr<const InitialStates> initial_states,
    const TrackingEnvOptions& env_options, const EvalOptions& options,
    const std::vector<std::optional<GroundTruth3D>>& truth) {
  options.Validate();
  if (!truth.empty() && truth.size() != reference->bundles().size()) {
    throw InputError("evaluation",
                     "3D truth for " + std::to_string(truth.size()) +
                         " bundles, the reference has " +
                         std::to_string(reference->bundles().size()));
  }
  // Global positions compare only in the true cameras' world.
  const bool same_world = reference->sources().cameras == CameraSource::kTruth;
  // K views of one motion must share a world: the true cameras, or a rig's
  // estimate (`fit --rig`); a view fitted alone lives in its own.
  bool views_share_world = same_world;
  if (reference->sources().cameras == CameraSource::kEstimate) {
    views_share_world = true;
    for (const ReferenceBundle& bundle : reference->bundles())
      views_share_world = views_share_world && bundle.estimate_one_world;
  }
  if (options.num_views > 1 && !views_share_world) {
    throw ConfigError(
        "eval: tracking " + std::to_string(options.num_views) +
        " views at once needs their cameras in one world: the true cameras "
        "(a calibrated rig; --cameras truth) or a rig's estimate (`mimic2d "
        "fit --rig`), not views fitted alone");
  }
  const std::vector<std::vector<int>> view_sets =
      ViewSets(*reference, options.num_views);
  if (view_sets.empty()) {
    throw InputError("evaluation", "no bundle has " +
                                       std::to_string(options.num_views) +
                                       " views to track at once");
  }
  // Episodes start from the given initial states (noise-free ones for
  // evaluation: callers build them with sigma 0).
  const TrackingEnvOptions eval_env = JudgedEnvOptions(env_options, options);
  if (options.object_start_square_m > 0 &&
      reference->num_object_points() == 0) {
    throw InputError("evaluation",
                     "moving the objects' starts needs bundles that track an "
                     "object (a ball); these track none");
  }
  // The environment's seed draws the push directions and the objects'
  // offsets (Reset, which would also draw from it, is not used here).
  TrackingEnv env(character, reference, initial_states, eval_env,
                  options.perturbation_seed, options.num_views);
  if (env.observation_size() != policy.observation_size() ||
      env.action_size() != policy.action_size()) {
    throw InputError("policy", "expects " +
                                   std::to_string(policy.observation_size()) +
                                   " observations and " +
                                   std::to_string(policy.action_size()) +
                                   " actions; the environment has " +
                                   std::to_string(env.observation_size()) +
                                   " and " + std::to_string(env.action_size()));
  }
  std::vector<float> observation(env.observation_size()),
      action(env.action_size());
  const int episode_frames = eval_env.max_episode_steps();
  const KeypointLayout& layout = character->keypoint_layout();
  std::vector<EvalRow> rows;

  for (const std::vector<int>& view_set : view_sets) {
    const int v = view_set.front();
    const TrackedView& view = reference->views()[v];
    const ReferenceBundle& bundle = reference->bundles()[view.bundle];
    const GroundTruth3D* bundle_truth =
        truth.empty() || !truth[view.bundle] ? nullptr : &*truth[view.bundle];
    const bool has_truth =
        bundle_truth != nullptr &&
        bundle_truth->layout == &character->keypoint_layout();
    EvalRow row;
    row.bundle = bundle.name;
    for (int index : view_set) {
      if (!row.view.empty()) row.view += "+";
      row.view += bundle.views[reference->views()[index].view].name;
    }
    double succ = 0, e2d = 0, eo2d = 0, e3d = 0, e3d_root = 0, e3d_pa = 0,
           jitter = 0, frames = 0;
    // Rollouts that measured anything: one that diverged on its first step
    // (a start below the floor) has no error to average, not an error of 0.
    int measured_2d = 0, measured_3d = 0;
    const int last_start = std::max(0, view.num_frames - 1 - episode_frames);
    for (int e = 0; e < options.episodes_per_view; ++e) {
      int start = options.episodes_per_view == 1
                      ? 0
                      : last_start * e / (options.episodes_per_view - 1);
      const StateBuffer& buffer = initial_states->BufferOfView(v);
      const SimState& start_state =
          buffer.entry(start, buffer.Best(start)).state;
      env.ResetToViews(view_set, start, start_state, observation.data());
      KeypointFrames simulated, true_keypoints;
      double object_error = 0.0;
      int object_frames = 0;
      std::vector<EvalFrame> trace;
      StepOutcome outcome;
      for (;;) {
        policy.Act(observation.data(), 1, action.data());
        outcome = env.Step(action.data(), observation.data());
        if (!outcome.diverged) {
          simulated.push_back(SimulatedKeypoints(env.simulation()));
          if (has_truth)
            true_keypoints.push_back(bundle_truth->keypoints_m[env.frame()]);
        }
        if (options.record_frames) {
          EvalFrame record;
          record.frame = env.frame();
          if (!outcome.diverged) {
            record.keypoints_present = outcome.error.num_present;
            record.mean_px = outcome.error.mean_px;
            record.worst_px = outcome.error.max_px;
            record.worst_keypoint = outcome.error.worst_keypoint;
            record.worst_view = outcome.error.worst_view;
            if (has_truth) {
              record.pa_mm =
                  1000.0 * ProcrustesAlignedError({simulated.back()},
                                                  {true_keypoints.back()});
            }
          }
          trace.push_back(record);
        }
        if (reference->num_object_points() > 0 && !outcome.diverged) {
          const int num_keypoints = layout.num_keypoints();
          double sum = 0;
          int present = 0;
          for (int o = 0; o < reference->num_object_points(); ++o) {
            const Keypoint2D& target =
                view.frame(env.frame())[num_keypoints + o];
            if (!target.IsPresent()) continue;
            const double* xy =
                env.projected_px().data() + 2 * (num_keypoints + o);
            sum += std::hypot(xy[0] - target.x_px, xy[1] - target.y_px);
            ++present;
          }
          if (present > 0) {
            object_error += sum / present;
            ++object_frames;
          }
        }
        if (outcome.terminated || outcome.truncated) break;
      }
      const EpisodeStats& stats = env.episode();
      // A rollout succeeds when no frame failed and most of its frames
      // could be judged: a reference missing its keypoints is no success.
      const bool succeeded = !stats.failed &&
                             2 * stats.measured_steps >= stats.steps &&
                             stats.measured_steps > 0;
      row.rollouts.push_back(
          {start, stats.steps, succeeded, stats.mean_error_px(), EndOf(outcome),
           outcome.diverged ? -1 : outcome.error.worst_keypoint,
           std::move(trace)});
      succ += succeeded ? 1.0 : 0.0;
      frames += stats.steps;
      if (stats.measured_steps > 0) {
        e2d += stats.mean_error_px();
        ++measured_2d;
      }
      if (object_frames > 0) eo2d += object_error / object_frames;
      if (simulated.empty()) continue;
      ++measured_3d;
      jitter += MeanJerk(simulated, eval_env.simulation.control_hz);
      if (has_truth) {
        e3d += 1000.0 * MeanPositionError(simulated, true_keypoints);
        e3d_root +=
            1000.0 * (same_world ? RootRelativePositionError(
                                       simulated, true_keypoints, layout)
                                 : YawAlignedRootRelativeError(
                                       simulated, true_keypoints, layout));
        e3d_pa += 1000.0 * ProcrustesAlignedError(simulated, true_keypoints);
      }
    }
    const double n = options.episodes_per_view;
    row.episodes = options.episodes_per_view;
    row.succ = succ / n;
    row.e2d_px = measured_2d > 0 ? e2d / measured_2d : -1.0;
    row.jitter = measured_3d > 0 ? jitter / measured_3d : -1.0;
    row.mean_frames = frames / n;
    if (reference->num_object_points() > 0) row.eo2d_px = eo2d / n;
    if (has_truth && measured_3d > 0) {
      if (same_world) row.e3d_mm = e3d / measured_3d;
      row.e3d_root_mm = e3d_root / measured_3d;
      row.e3d_pa_mm = e3d_pa / measured_3d;
    }
    rows.push_back(row);
  }
  return rows;
}

EvalRow AggregateRows(const std::vector<EvalRow>& rows) {
  EvalRow all;
  all.bundle = "all";
  all.view = "all";
  double weight = 0;
  for (const EvalRow& row : rows) weight += row.episodes;
  if (weight == 0) return all;
  auto average = [&](double EvalRow::*field) {
    double sum = 0;
    for (const EvalRow& row : rows) {
      if (row.*field < 0) return -1.0;
      sum += row.*field * row.episodes;
    }
    return sum / weight;
  };
  all.episodes = static_cast<int>(weight);
  all.succ = average(&EvalRow::succ);
  all.e2d_px = average(&EvalRow::e2d_px);
  all.eo2d_px = average(&EvalRow::eo2d_px);
  all.e3d_mm = average(&EvalRow::e3d_mm);
  all.e3d_root_mm = average(&EvalRow::e3d_root_mm);
  all.e3d_pa_mm = average(&EvalRow::e3d_pa_mm);
  all.jitter = average(&EvalRow::jitter);
  all.mean_frames = average(&EvalRow::mean_frames);
  return all;
}

}  // namespace m2d
