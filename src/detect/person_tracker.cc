#include "detect/person_tracker.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace m2d {
namespace {

Eigen::Vector2d Centre(const Box& box) {
  return {0.5 * (box.x0_px + box.x1_px), 0.5 * (box.y0_px + box.y1_px)};
}

double Diagonal(const Box& box) {
  return std::hypot(box.width_px(), box.height_px());
}

}  // namespace

void PersonTrackerOptions::Validate() const {
  if (person_index < 0) throw ConfigError("tracker: person index must be >= 0");
  if (!(region_scale >= 1.0))
    throw ConfigError("tracker: region_scale must be >= 1");
  if (!(min_region_side_px > 0))
    throw ConfigError("tracker: min_region_side_px must be > 0");
  if (multipose_long_side_px < 32)
    throw ConfigError("tracker: multipose_long_side_px must be >= 32");
}

PersonTracker::PersonTracker(const MoveNet& movenet,
                             const PersonTrackerOptions& options)
    : movenet_(movenet), options_(options) {
  options_.Validate();
}

DetectedPerson PersonTracker::Refine(const RgbImage& frame,
                                     const Box& box) const {
  const Eigen::Vector2d centre = Centre(box);
  const double side = std::max(
      options_.min_region_side_px,
      options_.region_scale * std::max(box.width_px(), box.height_px()));
  return movenet_.DetectInRegion(frame, centre.x(), centre.y(), side);
}

std::optional<DetectedPerson> ChoosePerson(
    const std::vector<DetectedPerson>& people,
    const std::optional<Box>& last_box, const PersonTrackerOptions& options) {
  if (people.empty()) return std::nullopt;
  if (options.choice == PersonChoice::kLargest) {
    return *std::max_element(
        people.begin(), people.end(),
        [](const DetectedPerson& a, const DetectedPerson& b) {
          return a.box.area_px2() < b.box.area_px2();
        });
  }
  if (!last_box) {
    // The first sighting: the best-scoring person, or the N-th from the left.
    if (options.choice == PersonChoice::kTrack) return people.front();
    std::vector<DetectedPerson> by_x = people;
    std::sort(by_x.begin(), by_x.end(),
              [](const DetectedPerson& a, const DetectedPerson& b) {
                return Centre(a.box).x() < Centre(b.box).x();
              });
    if (options.person_index >= static_cast<int>(by_x.size()))
      return std::nullopt;
    return by_x[options.person_index];
  }
  // Again after a loss: the detection that overlaps the last box most, or
  // whose centre is nearest to it, within the limits.
  const DetectedPerson* best = nullptr;
  double best_iou = 0.0, best_distance = INFINITY;
  for (const DetectedPerson& person : people) {
    const double iou = BoxIou(person.box, *last_box);
    const double distance =
        (Centre(person.box) - Centre(*last_box)).norm() / Diagonal(*last_box);
    if (iou > best_iou ||
        (best_iou == 0.0 && iou == 0.0 && distance < best_distance)) {
      best = &person;
      best_iou = iou;
      best_distance = distance;
    }
  }
  if (best == nullptr) return std::nullopt;
  if (best_iou >= options.reacquire_min_iou ||
      best_distance <= options.reacquire_max_centre_diagonals)
    return *best;
  return std::nullopt;
}

TrackedFrame PersonTracker::Next(const RgbImage& frame) {
  // Outline: follow with single pose around the last box while its score
  // holds; otherwise run MultiPose, choose the person (first sighting or
  // re-acquisition) and refine them with single pose.
  TrackedFrame result;
  if (ended_) return result;
  if (following_ && options_.choice != PersonChoice::kLargest) {
    DetectedPerson followed = Refine(frame, *last_box_);
    if (followed.score >= options_.min_track_score &&
        followed.box.area_px2() > 0) {
      result.found = true;
      result.person = followed;
      last_box_ = followed.box;
      return result;
    }
    following_ = false;  // lost: look for them again below
  }
  ++multipose_runs_;
  std::optional<DetectedPerson> chosen =
      ChoosePerson(movenet_.DetectPeople(frame, options_.multipose_long_side_px,
                                         options_.min_person_score),
                   last_box_, options_);
  if (!chosen) {
    // Gone for too long: whoever appears there later is someone else.
    if (last_box_ && options_.choice != PersonChoice::kLargest &&
        options_.max_lost_frames > 0 &&
        ++lost_frames_ > options_.max_lost_frames) {
      ended_ = true;
    }
    return result;
  }
  lost_frames_ = 0;
  DetectedPerson refined = Refine(frame, chosen->box);
  result.found = true;
  result.reacquired = true;
  result.person = refined.score >= chosen->score ? refined : *chosen;
  const Box box = KeypointBox(result.person, options_.min_box_score);
  last_box_ = box.area_px2() > 0 ? box : chosen->box;
  following_ = true;
  return result;
}

}  // namespace m2d
