// gen: generating 2D motion — the dataset of canonical 2D sequences, the
// VQ-VAE tokenizer, the GPT prior over its tokens and streaming generation
// (docs/generation.md). LibTorch is confined to the .cc files and to the
// model headers (vqvae.h, gpt.h); this header does not include it.
#ifndef MIMIC2D_GEN_MOTION_DATASET_H_
#define MIMIC2D_GEN_MOTION_DATASET_H_

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "camera/rig.h"
#include "motion/canonical.h"
#include "motion/motion3d.h"
#include "motion/skeleton.h"

namespace m2d {

// One frame of X^can as numbers: x̄ (J × 2, x then y per keypoint), then
// delta_root (2), then delta_log_scale (1).
int CanonicalFrameSize(const KeypointLayout& layout);
// Where a row's root step (2 numbers) and log-scale step (1) sit.
inline int RootStepColumn(int frame_size) { return frame_size - 3; }
inline int LogScaleStepColumn(int frame_size) { return frame_size - 1; }

// Frame-major rows of X^can. A missing keypoint (its local coordinates are
// NaN) repeats its last present value in the clip (its first present value
// before that; 0 when it is never present): the networks need numbers
// everywhere, and a held value is what a tracker would follow.
std::vector<float> CanonicalFeatures(const CanonicalClip& canonical);

// The inverse of CanonicalFeatures: `num_frames` rows of `rows` as a
// CanonicalClip with every keypoint present (confidence 1), placed by
// `first_root_px` / `first_scale_px` like ToCanonical's first frame (the
// first row's deltas are applied on top of them, as FromCanonical does for
// later frames; they are 0 for a clip's own first frame).
CanonicalClip CanonicalFromFeatures(const float* rows, int num_frames,
                                    const KeypointLayout& layout, double fps,
                                    Eigen::Vector2d first_root_px,
                                    double first_scale_px);

// The views a 3D motion is seen from: every azimuth at every elevation, the
// camera dollying with the subject so that long walks stay in frame. The
// representation is 2D; views are data augmentation.
struct GenViewOptions {
  int num_azimuths = 8;                          // spread over 360°
  std::vector<double> elevations_deg = {0, 20};  // camera elevations
  double distance_m = 4.5;                       // camera to subject
  double focal_px = 1000.0;
  // The dolly follows the subject's ground path averaged over this window
  // (s). 0: the root itself, so the subject's image root stays where it
  // started, as under a camera that follows a simulated character
  // (`generate --policy`).
  double follow_smoothing_s = 1.0;
  int width_px = 1920;
  int height_px = 1080;

  int num_views() const {
    return num_azimuths * static_cast<int>(elevations_deg.size());
  }
  // View v of the data is seen from elevation v / num_azimuths and azimuth
  // v % num_azimuths (the rig's azimuths, camera/rig.h, from its first):
  // its angles in degrees.
  double azimuth_deg(int view) const;
  double elevation_deg(int view) const;
  // The view nearest to a camera at `azimuth_deg`, `elevation_deg`
  // (angular distance of the directions to the subject).
  int NearestView(double azimuth_deg, double elevation_deg) const;
  void Validate() const;  // throws ConfigError
};

// A named 3D motion with the keypoint map that places COCO-17 on it.
struct GenMotionSource {
  std::string name;
  Motion3D motion;
  KeypointMap keypoint_map;
};

// One sequence of the dataset: a motion seen from one view.
struct GenSequence {
  std::string name;  // "<motion>/<view>"
  int num_frames = 0;
  std::vector<float> features;  // num_frames rows of CanonicalFrameSize
  int view = 0;    // which of GenViewOptions' views it is seen from
  int motion = 0;  // which of the dataset's motions it shows
};

struct GenDataset {
  const KeypointLayout* layout = &Coco17Layout();
  double fps = 30.0;
  int frame_size = 0;
  int num_views = 0;  // the GenViewOptions it was seen from
  std::vector<GenSequence> sequences;
  // Per-channel statistics over every frame, for normalization; std has a
  // floor (kMinFeatureStd) so that a constant channel does not blow up.
  std::vector<float> mean, std;

  int64_t num_frames() const;
};

inline constexpr float kMinFeatureStd = 1e-3f;

// Projects every motion into every view (motion/bundle.h's
// MakeBundleFromMotion at `fps`; a looping motion repeated to at least
// `loop_to_s`, its heading turn per `loop_heading`) and stores each view's
// canonical features; then the normalization statistics. Throws InputError
// naming a motion whose projection has no usable frame.
GenDataset BuildGenDataset(const std::vector<GenMotionSource>& motions,
                           const GenViewOptions& views, double fps,
                           double loop_to_s,
                           LoopHeading loop_heading = LoopHeading::kAccumulate);

// `sequence` cut in time into `num_parts` consecutive parts of equal
// length (the last ones a frame longer when it does not divide), named
// "<name>/<k>" from 1; rows as they are. ConfigError if a part would be
// empty.
std::vector<GenSequence> CutSequenceInTime(const GenSequence& sequence,
                                           int frame_size, int num_parts);

// `sequence` cut at its middle frame into its first and second half
// ("<name>/first", "<name>/second"; rows as they are).
std::pair<GenSequence, GenSequence> SplitSequenceInTime(
    const GenSequence& sequence, int frame_size);

// Stretches of real motion standing in for a generator's output, so that a
// floor is measured on as many independent draws as there are
// generations: `num_stretches` sequences drawn at random (with
// replacement, `seed`) among those of at least `min_frames` frames (a
// feature window: shorter ones hold no window), each read from a random
// start for up to `stretch_frames` frames (all of a shorter one). Named
// "<name>@<start>". A generator that replayed real motion would be scored
// on such draws: the FID of their windows against all real windows is the
// floor it reaches with this many generations. ConfigError when no
// sequence is long enough or on a non-positive count or length.
std::vector<GenSequence> DrawRealStretches(
    const std::vector<GenSequence>& sequences, int frame_size,
    int stretch_frames, int num_stretches, int min_frames, uint64_t seed);

// How far a sequence's placement moves from its first frame: the change of
// log scale, log(s_end / s_0) (the sum of the log-scale steps), and the
// root's displacement in units of the first frame's scale (each root step
// times its frame's scale). The first row's steps (from before the
// sequence) are not counted. A camera that follows the subject, as the
// data's do, keeps both near 0; a generator whose steps are biased drifts,
// and a tracker behind a following camera cannot follow that.
struct PlacementDrift {
  double log_scale_change = 0.0;
  Eigen::Vector2d root_displacement = Eigen::Vector2d::Zero();
};
PlacementDrift PlacementDriftOf(const GenSequence& sequence, int frame_size);

// Each frame's largest keypoint step from the frame before, in the local
// pose x̄ (body scales; the first frame has none, so num_frames - 1
// values): how fast the 2D a tracker follows moves. Real motion has few
// large ones; a generator that jumps where the motion does not (the seams
// between its decodings, gen/motion_stream.h) asks a limb to teleport.
std::vector<double> LargestPoseSteps(const GenSequence& sequence,
                                     int frame_size);

// Holds a stream's placement near its start, as the data's following
// cameras do: each frame's log-scale and root steps give back
// 1 / (return_time_s * fps) of the log scale and root displacement
// accumulated before it (PlacementDriftOf's quantities, counted from the
// stream's first row). A prior over steps sees 4 s of context and cannot
// keep what the steps add up to over minutes near 0; this restores the
// mean reversion a following camera gives real motion. Rows are changed
// in place, in stream order, across calls.
class PlacementAnchor {
 public:
  // return_time_s: time constant of the return (s); 0 leaves rows as they
  // are. ConfigError when negative or not finite.
  PlacementAnchor(double return_time_s, double fps);
  void Apply(float* rows, int num_frames, int frame_size);

 private:
  double return_per_frame_ = 0.0;
  double log_scale_ = 0.0;                                  // log(s / s_0)
  Eigen::Vector2d displacement_ = Eigen::Vector2d::Zero();  // s_0 units
};

// Per-channel mean and std (floored) of every row of `sequences`.
void FeatureStatistics(const std::vector<GenSequence>& sequences,
                       int frame_size, std::vector<float>* mean,
                       std::vector<float>* std);

}  // namespace m2d

#endif  // MIMIC2D_GEN_MOTION_DATASET_H_
