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
      {11, 12}};
  return layout;
}

const KeypointLayout& PointLayout() {
  static const KeypointLayout layout = {"point", {"center"}, {}, {0}};
  return layout;
}

const KeypointLayout* FindLayout(const std::string& name) {
  if (name == "coco17") return &Coco17Layout();
  if (name == "point") return &PointLayout();
  return nullptr;
}

std::vector<std::string> LayoutNames() { return {"coco17", "point"}; }

}  // namespace m2d
