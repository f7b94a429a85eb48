#include "motion/layout.h"

namespace m2d {

int KeypointLayout::IndexOf(const std::string& keypoint_name) const {
  for (int i = 0; i < num_keypoints(); ++i) {
    if (keypoint_names[i] == keypoint_name) return i;
  }
  return -1;
}

const KeypointLayout& Coco17Layout() {
  static const KeypointLayout layout = {
      "coco17",
      {"nose", "left_eye", "right_eye", "left_ear", "right_ear",
       "left_shoulder", "right_shoulder", "left_elbow", "right_elbow",
       "left_wrist", "right_wrist", "left_hip", "right_hip", "left_knee",
       "right_knee", "left_ankle", "right_ankle"},
      // The COCO drawing skeleton (0-based).
      {{15, 13},
       {13, 11},
       {16, 14},
       {14, 12},
       {11, 12},
       {5, 11},
       {6, 12},
       {5, 6},
       {5, 7},
       {6, 8},
       {7, 9},
       {8, 10},
       {1, 2},
       {0, 1},
       {0, 2},
       {1, 3},
       {2, 4},
       {3, 5},
       {4, 6}},
      {11, 12},
      {15, 16}};
  return layout;
}

// AP-10K's 17 animal keypoints (MMPose's ap10k order; ViTPose+ and MMPose
// animal models write it). The subject's root is the mean of the hips, as
// COCO-17's.
const KeypointLayout& Ap10kLayout() {
  static const KeypointLayout layout = {
      "ap10k",
      {"left_eye", "right_eye", "nose", "neck", "root_of_tail", "left_shoulder",
       "left_elbow", "left_front_paw", "right_shoulder", "right_elbow",
       "right_front_paw", "left_hip", "left_knee", "left_back_paw", "right_hip",
       "right_knee", "right_back_paw"},
      // MMPose's ap10k drawing skeleton (0-based).
      {{0, 1},
       {0, 2},
       {1, 2},
       {2, 3},
       {3, 4},
       {3, 5},
       {5, 6},
       {6, 7},
       {3, 8},
       {8, 9},
       {9, 10},
       {4, 11},
       {11, 12},
       {12, 13},
       {4, 14},
       {14, 15},
       {15, 16}},
      {11, 14},
      // No foot keypoints: the fit's stance cues, made for two feet that
      // take turns, read from the four paws made the dog's fits worse
      // (the trot's pitch 4.2 -> 9.2 deg, roll 2.3 -> 9.9; docs/quadruped.md).
      {}};
  return layout;
}

const KeypointLayout& PointLayout() {
  static const KeypointLayout layout = {"point", {"center"}, {}, {0}, {}};
  return layout;
}

const KeypointLayout* FindLayout(const std::string& name) {
  if (name == "coco17") return &Coco17Layout();
  if (name == "ap10k") return &Ap10kLayout();
  if (name == "point") return &PointLayout();
  return nullptr;
}

std::vector<std::string> LayoutNames() { return {"coco17", "ap10k", "point"}; }

}  // namespace m2d
