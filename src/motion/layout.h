// motion: 2D and 3D motion data — keypoint layouts, 2D clips and their
// readers/writers, the canonical representation, skeletons, 3D motions,
// forward kinematics and multi-view reference bundles.
#ifndef MIMIC2D_MOTION_LAYOUT_H_
#define MIMIC2D_MOTION_LAYOUT_H_

#include <string>
#include <utility>
#include <vector>

namespace m2d {

// A named set of keypoints with a drawing skeleton and the keypoints whose
// mean is the subject's root (used by the canonical representation).
struct KeypointLayout {
  std::string name;
  std::vector<std::string> keypoint_names;
  std::vector<std::pair<int, int>> bones;  // pairs of keypoint indices
  std::vector<int> root_keypoints;         // root = mean of these
  // The points the fit reads a foot's stance from in the 2D (a person's
  // ankles), each matched to the foot whose soles it is nearest.
  std::vector<int> foot_keypoints;

  int num_keypoints() const { return static_cast<int>(keypoint_names.size()); }
  // Index of `keypoint_name`, or -1.
  int IndexOf(const std::string& keypoint_name) const;
};

// COCO-17 keypoint indices, in the order of the COCO format.
enum class Coco17 : int {
  kNose = 0,
  kLeftEye,
  kRightEye,
  kLeftEar,
  kRightEar,
  kLeftShoulder,
  kRightShoulder,
  kLeftElbow,
  kRightElbow,
  kLeftWrist,
  kRightWrist,
  kLeftHip,
  kRightHip,
  kLeftKnee,
  kRightKnee,
  kLeftAnkle,
  kRightAnkle,
};

const KeypointLayout& Coco17Layout();
// AP-10K's 17 animal keypoints (left_eye, ..., right_back_paw).
const KeypointLayout& Ap10kLayout();
// A single point (e.g. a ball's centre), for object tracks.
const KeypointLayout& PointLayout();

// The layout registered under `name` ("coco17", "ap10k", "point"); nullptr
// if none.
const KeypointLayout* FindLayout(const std::string& name);
// Names of all registered layouts, for error messages.
std::vector<std::string> LayoutNames();

}  // namespace m2d

#endif  // MIMIC2D_MOTION_LAYOUT_H_
