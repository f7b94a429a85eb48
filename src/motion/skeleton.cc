#include "motion/skeleton.h"

#include <set>

#include "common/error.h"
#include "common/file_io.h"

namespace m2d {
namespace {

Eigen::Vector3d ReadVector3(const YAML::Node& node, const std::string& source,
                            const std::string& where) {
  if (!node || !node.IsSequence() || node.size() != 3) {
    throw InputError(source, where + ": expected a list of 3 numbers");
  }
  Eigen::Vector3d v;
  try {
    for (int i = 0; i < 3; ++i) v[i] = node[i].as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(source, where + ": expected a list of 3 numbers");
  }
  if (!v.allFinite()) throw InputError(source, where + ": not finite");
  return v;
}

std::string ReadString(const YAML::Node& node, const std::string& key,
                       const std::string& source, const std::string& where) {
  if (!node[key] || !node[key].IsScalar()) {
    throw InputError(source, where + ": missing '" + key + "'");
  }
  return node[key].as<std::string>();
}

}  // namespace

bool ParseJointType(const std::string& text, JointType* type) {
  if (text == "free")
    *type = JointType::kFree;
  else if (text == "spherical")
    *type = JointType::kSpherical;
  else if (text == "revolute")
    *type = JointType::kRevolute;
  else if (text == "fixed")
    *type = JointType::kFixed;
  else
    return false;
  return true;
}

int Skeleton::IndexOf(const std::string& joint_name) const {
  for (int i = 0; i < num_joints(); ++i) {
    if (joints[i].name == joint_name) return i;
  }
  return -1;
}

void ValidateSkeleton(const Skeleton& skeleton, const std::string& source) {
  if (skeleton.joints.empty())
    throw InputError(source, "skeleton has no joints");
  if (skeleton.joints[0].type != JointType::kFree ||
      skeleton.joints[0].parent != -1) {
    throw InputError(source, "joint 0 must be the free root with no parent");
  }
  std::set<std::string> names;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const SkeletonJoint& joint = skeleton.joints[j];
    if (!names.insert(joint.name).second) {
      throw InputError(source, "duplicate joint name '" + joint.name + "'");
    }
    if (j > 0 && (joint.parent < 0 || joint.parent >= j)) {
      throw InputError(source, "joint '" + joint.name +
                                   "' must name a parent listed before it");
    }
    if (j > 0 && joint.type == JointType::kFree) {
      throw InputError(source,
                       "only the root may be free ('" + joint.name + "')");
    }
    if (joint.type == JointType::kRevolute &&
        std::abs(joint.axis.norm() - 1.0) > 1e-6) {
      throw InputError(source, "joint '" + joint.name + "' axis is not unit");
    }
  }
}

Skeleton LoadSkeleton(const std::string& yaml_path) {
  YAML::Node root = ReadYamlFile(yaml_path);
  Skeleton skeleton;
  skeleton.name = ReadString(root, "name", yaml_path, "skeleton");
  YAML::Node joints = root["joints"];
  if (!joints || !joints.IsSequence()) {
    throw InputError(yaml_path, "missing list 'joints'");
  }
  for (size_t i = 0; i < joints.size(); ++i) {
    const YAML::Node& node = joints[i];
    std::string where = "joints[" + std::to_string(i) + "]";
    SkeletonJoint joint;
    joint.name = ReadString(node, "name", yaml_path, where);
    where += " ('" + joint.name + "')";
    std::string type = ReadString(node, "type", yaml_path, where);
    if (!ParseJointType(type, &joint.type)) {
      throw InputError(yaml_path, where + ": unknown joint type '" + type +
                                      "' (free, spherical, revolute, fixed)");
    }
    if (node["parent"]) {
      std::string parent = node["parent"].as<std::string>();
      joint.parent = skeleton.IndexOf(parent);
      if (joint.parent < 0) {
        throw InputError(yaml_path, where + ": unknown parent '" + parent +
                                        "' (parents must be listed first)");
      }
    }
    joint.offset_m =
        ReadVector3(node["offset_m"], yaml_path, where + ".offset_m");
    if (joint.type == JointType::kRevolute) {
      joint.axis = ReadVector3(node["axis"], yaml_path, where + ".axis");
      joint.axis.normalize();
    }
    skeleton.joints.push_back(joint);
  }
  ValidateSkeleton(skeleton, yaml_path);
  return skeleton;
}

KeypointMap LoadKeypointMap(const std::string& yaml_path,
                            const Skeleton& skeleton) {
  YAML::Node root = ReadYamlFile(yaml_path);
  std::string layout_name =
      ReadString(root, "layout", yaml_path, "keypoint map");
  KeypointMap map;
  map.layout = FindLayout(layout_name);
  if (map.layout == nullptr) {
    throw InputError(yaml_path, "unknown layout '" + layout_name + "'");
  }
  YAML::Node keypoints = root["keypoints"];
  if (!keypoints || !keypoints.IsMap()) {
    throw InputError(yaml_path, "missing map 'keypoints'");
  }
  for (const auto& entry : keypoints) {
    std::string name = entry.first.as<std::string>();
    if (map.layout->IndexOf(name) < 0) {
      throw InputError(yaml_path, "unknown keypoint '" + name +
                                      "' for layout " + layout_name);
    }
  }
  for (const std::string& name : map.layout->keypoint_names) {
    YAML::Node node = keypoints[name];
    if (!node)
      throw InputError(yaml_path, "keypoint '" + name + "' is not mapped");
    KeypointAnchor anchor;
    std::string joint = ReadString(node, "joint", yaml_path, name);
    anchor.joint = skeleton.IndexOf(joint);
    if (anchor.joint < 0) {
      throw InputError(yaml_path, name + ": unknown joint '" + joint +
                                      "' in skeleton " + skeleton.name);
    }
    anchor.offset_m =
        ReadVector3(node["offset_m"], yaml_path, name + ".offset_m");
    map.anchors.push_back(anchor);
  }
  return map;
}

}  // namespace m2d
