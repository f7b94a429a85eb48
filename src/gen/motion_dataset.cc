#include "gen/motion_dataset.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "common/error.h"
#include "motion/bundle.h"

namespace m2d {

int CanonicalFrameSize(const KeypointLayout& layout) {
  return 2 * layout.num_keypoints() + 3;
}

std::vector<float> CanonicalFeatures(const CanonicalClip& canonical) {
  const int num_frames = canonical.num_frames();
  const int num_keypoints = canonical.local_pose.num_keypoints();
  const int frame_size = 2 * num_keypoints + 3;
  std::vector<float> rows(static_cast<size_t>(num_frames) * frame_size);
  // Outline: per keypoint, its first present value seeds the frames before
  // it; afterwards each missing frame holds the last present value.
  for (int j = 0; j < num_keypoints; ++j) {
    float held_x = 0.0f, held_y = 0.0f;
    for (int t = 0; t < num_frames; ++t) {
      const Keypoint2D& point = canonical.local_pose.at(t, j);
      if (point.IsPresent()) {
        held_x = static_cast<float>(point.x_px);
        held_y = static_cast<float>(point.y_px);
        break;
      }
    }
    for (int t = 0; t < num_frames; ++t) {
      const Keypoint2D& point = canonical.local_pose.at(t, j);
      if (point.IsPresent()) {
        held_x = static_cast<float>(point.x_px);
        held_y = static_cast<float>(point.y_px);
      }
      float* row = rows.data() + static_cast<size_t>(t) * frame_size;
      row[2 * j] = held_x;
      row[2 * j + 1] = held_y;
    }
  }
  for (int t = 0; t < num_frames; ++t) {
    float* row = rows.data() + static_cast<size_t>(t) * frame_size;
    row[2 * num_keypoints] = static_cast<float>(canonical.delta_root[t].x());
    row[2 * num_keypoints + 1] =
        static_cast<float>(canonical.delta_root[t].y());
    row[2 * num_keypoints + 2] =
        static_cast<float>(canonical.delta_log_scale[t]);
  }
  return rows;
}

CanonicalClip CanonicalFromFeatures(const float* rows, int num_frames,
                                    const KeypointLayout& layout, double fps,
                                    Eigen::Vector2d first_root_px,
                                    double first_scale_px) {
  const int num_keypoints = layout.num_keypoints();
  const int frame_size = CanonicalFrameSize(layout);
  CanonicalClip canonical;
  canonical.layout = &layout;
  canonical.fps = fps;
  canonical.local_pose = KeypointTrack(num_frames, num_keypoints);
  canonical.delta_root.resize(num_frames);
  canonical.delta_log_scale.resize(num_frames);
  for (int t = 0; t < num_frames; ++t) {
    const float* row = rows + static_cast<size_t>(t) * frame_size;
    for (int j = 0; j < num_keypoints; ++j)
      canonical.local_pose.at(t, j) = {row[2 * j], row[2 * j + 1], 1.0};
    canonical.delta_root[t] = {row[2 * num_keypoints],
                               row[2 * num_keypoints + 1]};
    canonical.delta_log_scale[t] = row[2 * num_keypoints + 2];
  }
  // FromCanonical applies deltas from the second frame on; fold the first
  // row's into the placement.
  canonical.first_scale_px =
      first_scale_px * std::exp(canonical.delta_log_scale[0]);
  canonical.first_root_px =
      first_root_px + canonical.first_scale_px * canonical.delta_root[0];
  canonical.delta_root[0].setZero();
  canonical.delta_log_scale[0] = 0.0;
  return canonical;
}

double GenViewOptions::azimuth_deg(int view) const {
  return RigOptions().first_azimuth_deg +
         (view % num_azimuths) * 360.0 / num_azimuths;
}

double GenViewOptions::elevation_deg(int view) const {
  return elevations_deg.at(view / num_azimuths);
}

int GenViewOptions::NearestView(double azimuth_deg,
                                double elevation_deg) const {
  auto direction = [](double azimuth, double elevation) {
    const double a = azimuth * M_PI / 180.0, e = elevation * M_PI / 180.0;
    return Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a),
                           std::sin(e));
  };
  const Eigen::Vector3d wanted = direction(azimuth_deg, elevation_deg);
  int nearest = 0;
  double best_cosine = -2.0;
  for (int v = 0; v < num_views(); ++v) {
    const double cosine =
        wanted.dot(direction(this->azimuth_deg(v), this->elevation_deg(v)));
    if (cosine > best_cosine + 1e-12) {
      best_cosine = cosine;
      nearest = v;
    }
  }
  return nearest;
}

void GenViewOptions::Validate() const {
  if (num_azimuths < 1 || num_azimuths > 360)
    throw ConfigError("views: num_azimuths must be in [1, 360]");
  if (elevations_deg.empty())
    throw ConfigError("views: elevations_deg needs at least one elevation");
  for (double elevation : elevations_deg) {
    if (!(elevation > -80.0 && elevation < 80.0))
      throw ConfigError("views: elevations_deg must lie in (-80, 80)");
  }
  if (!(follow_smoothing_s >= 0.0 && follow_smoothing_s <= 60.0))
    throw ConfigError("views: follow_smoothing_s must be in [0, 60] s");
  RigOptions rig;
  rig.distance_m = distance_m;
  rig.focal_px = focal_px;
  rig.width_px = width_px;
  rig.height_px = height_px;
  rig.Validate();
}

int64_t GenDataset::num_frames() const {
  int64_t frames = 0;
  for (const GenSequence& sequence : sequences) frames += sequence.num_frames;
  return frames;
}

namespace {

// Frames [begin, end) of `sequence` as a sequence of their own.
GenSequence FramesOf(const GenSequence& sequence, int frame_size, int begin,
                     int end, std::string name) {
  const auto rows = sequence.features.begin();
  return {std::move(name),
          end - begin,
          {rows + static_cast<size_t>(begin) * frame_size,
           rows + static_cast<size_t>(end) * frame_size},
          sequence.view,
          sequence.motion};
}

}  // namespace

std::vector<GenSequence> CutSequenceInTime(const GenSequence& sequence,
                                           int frame_size, int num_parts) {
  if (num_parts < 1 || num_parts > sequence.num_frames) {
    throw ConfigError("cannot cut " + std::to_string(sequence.num_frames) +
                      " frames of " + sequence.name + " into " +
                      std::to_string(num_parts) + " parts");
  }
  std::vector<GenSequence> parts;
  int start = 0;
  for (int k = 0; k < num_parts; ++k) {
    // Part k ends at floor((k + 1) n / parts): the shorter parts first.
    const int end = static_cast<int>(static_cast<int64_t>(k + 1) *
                                     sequence.num_frames / num_parts);
    parts.push_back(FramesOf(sequence, frame_size, start, end,
                             sequence.name + "/" + std::to_string(k + 1)));
    start = end;
  }
  return parts;
}

std::pair<GenSequence, GenSequence> SplitSequenceInTime(
    const GenSequence& sequence, int frame_size) {
  std::vector<GenSequence> halves = CutSequenceInTime(sequence, frame_size, 2);
  halves[0].name = sequence.name + "/first";
  halves[1].name = sequence.name + "/second";
  return {std::move(halves[0]), std::move(halves[1])};
}

PlacementDrift PlacementDriftOf(const GenSequence& sequence, int frame_size) {
  const int root = RootStepColumn(frame_size);
  const int log_scale = LogScaleStepColumn(frame_size);
  PlacementDrift drift;
  for (int t = 1; t < sequence.num_frames; ++t) {
    const float* row =
        sequence.features.data() + static_cast<size_t>(t) * frame_size;
    drift.log_scale_change += row[log_scale];
    drift.root_displacement += std::exp(drift.log_scale_change) *
                               Eigen::Vector2d(row[root], row[root + 1]);
  }
  return drift;
}

std::vector<double> LargestPoseSteps(const GenSequence& sequence,
                                     int frame_size) {
  const int keypoints = RootStepColumn(frame_size) / 2;
  std::vector<double> steps;
  for (int t = 1; t < sequence.num_frames; ++t) {
    const float* row =
        sequence.features.data() + static_cast<size_t>(t) * frame_size;
    const float* before = row - frame_size;
    double largest = 0.0;
    for (int j = 0; j < keypoints; ++j)
      largest = std::max(
          largest, std::hypot(static_cast<double>(row[2 * j] - before[2 * j]),
                              row[2 * j + 1] - before[2 * j + 1]));
    steps.push_back(largest);
  }
  return steps;
}

PlacementAnchor::PlacementAnchor(double return_time_s, double fps) {
  if (!(return_time_s >= 0.0 && std::isfinite(return_time_s)) || !(fps > 0))
    throw ConfigError(
        "placement return time (--placement-return) must be >= 0 s (0: off)");
  return_per_frame_ = return_time_s > 0 ? 1.0 / (return_time_s * fps) : 0.0;
}

void PlacementAnchor::Apply(float* rows, int num_frames, int frame_size) {
  if (return_per_frame_ == 0.0) return;
  const int root = RootStepColumn(frame_size);
  const int log_scale = LogScaleStepColumn(frame_size);
  for (int t = 0; t < num_frames; ++t) {
    float* row = rows + static_cast<size_t>(t) * frame_size;
    // Outline: the scale step gives back its share of the log scale; the
    // root step (in this frame's scale) its share of the displacement.
    row[log_scale] -= static_cast<float>(return_per_frame_ * log_scale_);
    log_scale_ += row[log_scale];
    const double scale = std::exp(log_scale_);
    row[root] -=
        static_cast<float>(return_per_frame_ * displacement_.x() / scale);
    row[root + 1] -=
        static_cast<float>(return_per_frame_ * displacement_.y() / scale);
    displacement_ += scale * Eigen::Vector2d(row[root], row[root + 1]);
  }
}

std::vector<GenSequence> DrawRealStretches(
    const std::vector<GenSequence>& sequences, int frame_size,
    int stretch_frames, int num_stretches, int min_frames, uint64_t seed) {
  std::vector<size_t> drawable;  // sequences of at least min_frames
  for (size_t i = 0; i < sequences.size(); ++i)
    if (sequences[i].num_frames >= std::max(1, min_frames))
      drawable.push_back(i);
  if (drawable.empty() || stretch_frames < 1 || num_stretches < 1) {
    throw ConfigError(
        "cannot draw " + std::to_string(num_stretches) + " stretches of " +
        std::to_string(stretch_frames) + " from " +
        std::to_string(sequences.size()) + " sequences: " +
        (drawable.empty() ? "none has " + std::to_string(min_frames) + " frames"
                          : "count and length must be positive"));
  }
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<size_t> pick(0, drawable.size() - 1);
  std::vector<GenSequence> stretches;
  for (int k = 0; k < num_stretches; ++k) {
    // Outline: a sequence, a start that leaves a whole stretch when the
    // sequence holds one, the rows from there.
    const GenSequence& sequence = sequences[drawable[pick(random)]];
    const int length = std::min(stretch_frames, sequence.num_frames);
    const int start = std::uniform_int_distribution<int>(
        0, sequence.num_frames - length)(random);
    stretches.push_back(FramesOf(sequence, frame_size, start, start + length,
                                 sequence.name + "@" + std::to_string(start)));
  }
  return stretches;
}

void FeatureStatistics(const std::vector<GenSequence>& sequences,
                       int frame_size, std::vector<float>* mean,
                       std::vector<float>* std) {
  std::vector<double> sum(frame_size, 0.0), squares(frame_size, 0.0);
  int64_t count = 0;
  for (const GenSequence& sequence : sequences) {
    for (int t = 0; t < sequence.num_frames; ++t) {
      const float* row =
          sequence.features.data() + static_cast<size_t>(t) * frame_size;
      for (int c = 0; c < frame_size; ++c) {
        sum[c] += row[c];
        squares[c] += static_cast<double>(row[c]) * row[c];
      }
    }
    count += sequence.num_frames;
  }
  mean->assign(frame_size, 0.0f);
  std->assign(frame_size, 1.0f);
  if (count == 0) return;
  for (int c = 0; c < frame_size; ++c) {
    const double m = sum[c] / count;
    const double variance = std::max(0.0, squares[c] / count - m * m);
    (*mean)[c] = static_cast<float>(m);
    (*std)[c] =
        std::max(kMinFeatureStd, static_cast<float>(std::sqrt(variance)));
  }
}

GenDataset BuildGenDataset(const std::vector<GenMotionSource>& motions,
                           const GenViewOptions& views, double fps,
                           double loop_to_s, LoopHeading loop_heading) {
  views.Validate();
  GenDataset dataset;
  dataset.fps = fps;
  dataset.frame_size = CanonicalFrameSize(*dataset.layout);
  dataset.num_views = views.num_views();
  for (size_t motion_index = 0; motion_index < motions.size(); ++motion_index) {
    const GenMotionSource& source = motions[motion_index];
    int view_index = 0;  // the order of GenViewOptions::azimuth_deg
    for (double elevation : views.elevations_deg) {
      BundleFromMotionOptions options;
      options.fps = fps;
      if (source.motion.loops)
        options.duration_s = std::max(source.motion.duration_s(), loop_to_s);
      options.loop_heading = loop_heading;
      options.follow = CameraFollow::kRootDolly;
      options.follow_smoothing_s = views.follow_smoothing_s;
      options.rig.num_views = views.num_azimuths;
      options.rig.elevation_deg = elevation;
      options.rig.distance_m = views.distance_m;
      options.rig.focal_px = views.focal_px;
      options.rig.width_px = views.width_px;
      options.rig.height_px = views.height_px;
      const ReferenceBundle bundle = MakeBundleFromMotion(
          source.motion, source.keypoint_map, options, source.name);
      for (const ReferenceView& view : bundle.views) {
        const CanonicalClip canonical = ToCanonical(view.clip, source.name);
        GenSequence sequence;
        sequence.name =
            source.name + "/" + view.name + "_el" +
            std::to_string(static_cast<int>(std::lround(elevation)));
        sequence.num_frames = canonical.num_frames();
        sequence.features = CanonicalFeatures(canonical);
        sequence.view = view_index++;
        sequence.motion = static_cast<int>(motion_index);
        dataset.sequences.push_back(std::move(sequence));
      }
    }
  }
  FeatureStatistics(dataset.sequences, dataset.frame_size, &dataset.mean,
                    &dataset.std);
  return dataset;
}

}  // namespace m2d
