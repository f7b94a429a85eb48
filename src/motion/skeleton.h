// motion: kinematic skeletons and keypoint maps (which keypoint sits where on
// which joint), loaded from YAML files under assets/skeletons/.
#ifndef MIMIC2D_MOTION_SKELETON_H_
#define MIMIC2D_MOTION_SKELETON_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "motion/layout.h"

namespace m2d {

enum class JointType {
  kFree,       // the root: 3D position + orientation
  kSpherical,  // 3 rotational DoF (a quaternion)
  kRevolute,   // 1 rotational DoF about `axis`
  kFixed,      // no DoF (e.g. a wrist or a BVH end site)
};

// Parses "free", "spherical", "revolute", "fixed"; false when unknown.
bool ParseJointType(const std::string& text, JointType* type);

struct SkeletonJoint {
  std::string name;
  int parent = -1;  // -1 for the root
  JointType type = JointType::kSpherical;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  // in the parent frame
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();     // unit; revolute only
};

// A joint tree in the world convention (Z up, metres). Joint 0 is the free
// root; every parent precedes its children.
struct Skeleton {
  std::string name;
  std::vector<SkeletonJoint> joints;

  int num_joints() const { return static_cast<int>(joints.size()); }
  // Index of the joint called `joint_name`, or -1.
  int IndexOf(const std::string& joint_name) const;
};

// Checks the invariants above; throws InputError naming `source`.
void ValidateSkeleton(const Skeleton& skeleton, const std::string& source);

// Reads a skeleton YAML file (docs/formats.md).
Skeleton LoadSkeleton(const std::string& yaml_path);

// Where one keypoint of a layout sits: a point fixed in a joint's frame.
struct KeypointAnchor {
  int joint = 0;
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  // in the joint frame
};

// One anchor per keypoint of `layout`, in layout order.
struct KeypointMap {
  const KeypointLayout* layout = &Coco17Layout();
  std::vector<KeypointAnchor> anchors;
};

// Reads a keypoint map YAML file whose joint names refer to `skeleton`.
// Every keypoint of the layout must be mapped; unknown keypoint or joint
// names are errors naming the file.
KeypointMap LoadKeypointMap(const std::string& yaml_path,
                            const Skeleton& skeleton);

}  // namespace m2d

#endif  // MIMIC2D_MOTION_SKELETON_H_
