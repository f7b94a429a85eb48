// detect: people's 2D keypoints from images and video — a TF.js graph-model
// interpreter on LibTorch, MoveNet on it, and a tracker that keeps one
// person across frames.
#ifndef MIMIC2D_DETECT_PERSON_TRACKER_H_
#define MIMIC2D_DETECT_PERSON_TRACKER_H_

#include <optional>
#include <string>
#include <vector>

#include "detect/movenet.h"

namespace m2d {

// Whom a video's clip follows.
enum class PersonChoice {
  kTrack,    // the best-scoring person of the first frame with anyone,
             // then that person
  kIndex,    // the N-th person from the left in that frame, then that person
  kLargest,  // every frame, the largest person (MultiPose every frame)
};

struct PersonTrackerOptions {
  PersonChoice choice = PersonChoice::kTrack;
  int person_index = 0;       // kIndex: N, from 0, left to right
  double region_scale = 1.6;  // single-pose region side / box's longer side
  double min_region_side_px = 96;  // regions never smaller (tiny people)
  double min_track_score = 0.3;    // mean keypoint score that keeps a track
  double min_box_score = 0.2;      // keypoints that make the track's box
  int multipose_long_side_px = 512;
  double min_person_score = 0.2;  // MultiPose detections kept
  // After a loss, a detection re-acquires the track when its box overlaps
  // the last one by this IoU, or its centre is within this many of the
  // last box's diagonals.
  double reacquire_min_iou = 0.1;
  double reacquire_max_centre_diagonals = 1.0;
  // kTrack and kIndex: a person lost for more than this many frames is
  // gone (left the scene): the track ends rather than continue with
  // whoever passes where they were. 0: never ends.
  int max_lost_frames = 10;
  void Validate() const;  // throws ConfigError
};

// The detection that starts a track (no `last_box`: first sighting by
// `options.choice`) or continues it after a loss (the one overlapping
// `last_box` most, else the nearest centre, within the re-acquisition
// limits); none when no detection qualifies. Pure: the tracker's rule.
std::optional<DetectedPerson> ChoosePerson(
    const std::vector<DetectedPerson>& people,
    const std::optional<Box>& last_box, const PersonTrackerOptions& options);

struct TrackedFrame {
  bool found = false;       // the person's keypoints are in `person`
  bool reacquired = false;  // found by MultiPose this frame (not followed)
  DetectedPerson person;
};

// Follows one person through a video's frames: single pose in a region
// around where the person was (fast), MultiPose to find them first and
// again after a loss (IoU and distance to where they were last seen).
class PersonTracker {
 public:
  PersonTracker(const MoveNet& movenet, const PersonTrackerOptions& options);
  TrackedFrame Next(const RgbImage& frame);

  int multipose_runs() const { return multipose_runs_; }
  // The followed person was lost for longer than max_lost_frames.
  bool ended() const { return ended_; }

 private:
  // Single pose in the region around `box`.
  DetectedPerson Refine(const RgbImage& frame, const Box& box) const;

  const MoveNet& movenet_;
  PersonTrackerOptions options_;
  std::optional<Box> last_box_;  // where the person was last seen
  bool following_ = false;       // the last frame found them
  int lost_frames_ = 0;          // frames since they were last found
  bool ended_ = false;
  int multipose_runs_ = 0;
};

}  // namespace m2d

#endif  // MIMIC2D_DETECT_PERSON_TRACKER_H_
