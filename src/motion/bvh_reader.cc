// BVH motion capture files, read with libassimp and converted to the world
// convention (Z up, metres).
//
// Assimp parses the hierarchy and turns each frame's Euler channels into
// quaternions, but it trusts the MOTION section blindly: a frame line with a
// missing value silently shifts every later value into the wrong channel,
// and zero frames, a zero frame time or NaN values come back as a "valid"
// scene. It also drops position channels on joints that do not declare
// exactly six channels, and does not report which channels a joint declares.
// So a light scan of the file text (channel declarations, values per frame
// line) runs first and rejects what assimp would misread.
#include <assimp/MemoryIOWrapper.h>
#include <assimp/config.h>
#include <assimp/scene.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/file_io.h"
#include "motion/motion_io.h"

namespace m2d {
namespace {

// The channels one BVH joint declares, as listed in the file.
struct BvhJointChannels {
  std::string joint_name;
  std::vector<std::string> channel_names;  // e.g. "Xposition", "Zrotation"

  bool HasChannelEndingWith(const std::string& suffix) const {
    return std::any_of(channel_names.begin(), channel_names.end(),
                       [&](const std::string& name) {
                         return name.size() > 1 && name.substr(1) == suffix;
                       });
  }
  bool HasPositions() const { return HasChannelEndingWith("position"); }
  bool HasRotations() const { return HasChannelEndingWith("rotation"); }
};

// What the scan of the file text finds.
struct BvhTextLayout {
  std::vector<BvhJointChannels> joints;  // file order; the root first
  int num_channels = 0;                  // values per frame line
  int num_frames = 0;
  double frame_time_s = 0.0;
};

std::vector<std::string> SplitWhitespace(const std::string& text) {
  std::istringstream stream(text);
  std::vector<std::string> tokens;
  std::string token;
  while (stream >> token) tokens.push_back(token);
  return tokens;
}

bool ParseInteger(const std::string& text, long* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *value = std::strtol(text.c_str(), &end, 10);
  return errno == 0 && *end == '\0';
}

bool ParseDouble(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return *end == '\0';
}

bool IsChannelName(const std::string& name) {
  static const char* const kNames[] = {"Xposition", "Yposition", "Zposition",
                                       "Xrotation", "Yrotation", "Zrotation"};
  return std::find(std::begin(kNames), std::end(kNames), name) !=
         std::end(kNames);
}

// The joints and their channels, from the HIERARCHY text (which ends at the
// MOTION keyword). Syntax beyond that (braces, offsets) is left to assimp.
std::vector<BvhJointChannels> ScanHierarchy(const std::string& hierarchy,
                                            const std::string& path) {
  std::istringstream stream(hierarchy);
  std::string token;
  if (!(stream >> token) || token != "HIERARCHY") {
    throw InputError(path, "not a BVH file: it must start with HIERARCHY");
  }
  std::vector<BvhJointChannels> joints;
  while (stream >> token) {
    if (token == "ROOT" || token == "JOINT") {
      BvhJointChannels joint;
      if (!(stream >> joint.joint_name)) break;
      joints.push_back(joint);
    } else if (token == "CHANNELS") {
      if (joints.empty()) {
        throw InputError(path, "CHANNELS before any ROOT or JOINT");
      }
      BvhJointChannels& joint = joints.back();
      std::string count_text;
      long count = 0;
      if (!(stream >> count_text) || !ParseInteger(count_text, &count) ||
          count < 0 || count > 6) {
        throw InputError(path, "joint '" + joint.joint_name +
                                   "': bad channel count '" + count_text +
                                   "' (expected 0 to 6)");
      }
      for (long c = 0; c < count; ++c) {
        std::string name;
        if (!(stream >> name) || !IsChannelName(name)) {
          throw InputError(path, "joint '" + joint.joint_name +
                                     "': bad channel name '" + name + "'");
        }
        joint.channel_names.push_back(name);
      }
    }
  }
  if (joints.empty()) throw InputError(path, "hierarchy has no ROOT joint");
  return joints;
}

// Checks the MOTION section (the text after the MOTION keyword, starting on
// file line `first_line`): the frame count and time, then exactly one line
// of `num_channels` values per frame.
void ScanMotion(const std::string& motion, int first_line,
                const std::string& path, BvhTextLayout* layout) {
  std::istringstream stream(motion);
  std::string line;
  int line_number = first_line - 1;
  enum class Expect { kFrameCount, kFrameTime, kFrameValues };
  Expect expect = Expect::kFrameCount;
  long declared_frames = 0;
  int frame = 0;
  while (std::getline(stream, line)) {
    ++line_number;
    const std::vector<std::string> tokens = SplitWhitespace(line);
    if (tokens.empty()) continue;
    const std::string where = "line " + std::to_string(line_number);
    switch (expect) {
      case Expect::kFrameCount:
        if (tokens.size() != 2 || tokens[0] != "Frames:" ||
            !ParseInteger(tokens[1], &declared_frames) || declared_frames < 0) {
          throw InputError(path, where + ": expected 'Frames: <count>'");
        }
        if (declared_frames == 0) throw InputError(path, "BVH has no frames");
        expect = Expect::kFrameTime;
        break;
      case Expect::kFrameTime:
        if (tokens.size() != 3 || tokens[0] != "Frame" ||
            tokens[1] != "Time:" ||
            !ParseDouble(tokens[2], &layout->frame_time_s)) {
          throw InputError(path, where + ": expected 'Frame Time: <seconds>'");
        }
        if (!(layout->frame_time_s > 0.0 &&
              std::isfinite(layout->frame_time_s))) {
          throw InputError(path, where + ": Frame Time must be positive");
        }
        expect = Expect::kFrameValues;
        break;
      case Expect::kFrameValues:
        if (static_cast<int>(tokens.size()) != layout->num_channels) {
          throw InputError(
              path, where + " (frame " + std::to_string(frame) + ") has " +
                        std::to_string(tokens.size()) +
                        " values but the hierarchy declares " +
                        std::to_string(layout->num_channels) +
                        " channels (missing or extra channel values)");
        }
        ++frame;
        break;
    }
  }
  if (expect != Expect::kFrameValues) {
    throw InputError(path, "MOTION section lacks 'Frames:' or 'Frame Time:'");
  }
  if (frame < declared_frames) {
    throw InputError(path, "'Frames: " + std::to_string(declared_frames) +
                               "' but only " + std::to_string(frame) +
                               " frame lines (truncated file?)");
  }
  // Exporters sometimes write one frame more than they declare (Debian's
  // Boxing_Toes.bvh does); like assimp and other readers, keep the declared
  // count.
  if (frame > declared_frames) {
    spdlog::warn(
        "{}: ignoring {} frame line(s) after the {} declared by "
        "'Frames:'",
        path, frame - declared_frames, declared_frames);
  }
  layout->num_frames = static_cast<int>(declared_frames);
}

// Finds the MOTION keyword on a line of its own (after the hierarchy).
size_t FindMotionKeyword(const std::string& text) {
  size_t position = 0;
  while ((position = text.find("MOTION", position)) != std::string::npos) {
    const bool starts_token =
        position == 0 ||
        std::isspace(static_cast<unsigned char>(text[position - 1]));
    const size_t after = position + 6;
    const bool ends_token =
        after == text.size() ||
        std::isspace(static_cast<unsigned char>(text[after]));
    if (starts_token && ends_token) return position;
    position = after;
  }
  return std::string::npos;
}

BvhTextLayout ScanBvhText(const std::string& text, const std::string& path) {
  const size_t motion_start = FindMotionKeyword(text);
  BvhTextLayout layout;
  layout.joints = ScanHierarchy(text.substr(0, motion_start), path);
  if (motion_start == std::string::npos) {
    throw InputError(path,
                     "no MOTION section after the hierarchy (truncated file?)");
  }
  for (const BvhJointChannels& joint : layout.joints) {
    layout.num_channels += static_cast<int>(joint.channel_names.size());
  }
  const int motion_line =
      1 + static_cast<int>(
              std::count(text.begin(), text.begin() + motion_start, '\n'));
  ScanMotion(text.substr(motion_start + 6), motion_line, path, &layout);
  return layout;
}

// Assimp reports errors against its in-memory file name; say "line" instead.
std::string CleanAssimpError(const std::string& error) {
  const std::string prefix = std::string(AI_MEMORYIO_MAGIC_FILENAME) + ".bvh:";
  if (error.compare(0, prefix.size(), prefix) == 0) {
    return "line " + error.substr(prefix.size());
  }
  return error;
}

// The scene assimp builds from `text`; owned by `importer`.
const aiScene& ImportWithAssimp(const std::string& text,
                                const std::string& path,
                                Assimp::Importer* importer) {
  // No dummy skeleton mesh, and no post-processing that could reshape the
  // node tree: the hierarchy must stay one node per BVH joint or end site.
  importer->SetPropertyInteger(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, 1);
  const aiScene* scene = nullptr;
  try {
    scene = importer->ReadFileFromMemory(text.data(), text.size(), 0, "bvh");
  } catch (const std::exception& error) {
    throw InputError(path, std::string("BVH import failed: ") + error.what());
  }
  if (scene == nullptr) {
    throw InputError(path, "BVH import failed: " +
                               CleanAssimpError(importer->GetErrorString()));
  }
  if (scene->mRootNode == nullptr || scene->mNumAnimations != 1) {
    throw InputError(path, "BVH import produced no skeleton animation");
  }
  return *scene;
}

Eigen::Vector3d ToEigen(const aiVector3D& vector) {
  return Eigen::Vector3d(vector.x, vector.y, vector.z);
}

Eigen::Quaterniond ToEigen(const aiQuaternion& rotation) {
  return Eigen::Quaterniond(rotation.w, rotation.x, rotation.y, rotation.z);
}

bool IsFinite(const Eigen::Vector3d& vector) { return vector.allFinite(); }
bool IsFinite(const Eigen::Quaterniond& rotation) {
  return rotation.coeffs().allFinite();
}

// A skeleton joint and where its per-frame data comes from.
struct JointSource {
  const aiNodeAnim* track = nullptr;  // null for end sites
  const BvhJointChannels* channels = nullptr;
};

// Scales and turns file (Y-up) quantities into the world (Z-up) convention.
struct FrameConversion {
  double scale_m = 1.0;
  Eigen::Quaterniond y_up_to_z_up = YUpToZUp();

  Eigen::Vector3d Position(const Eigen::Vector3d& file_position) const {
    return scale_m * (y_up_to_z_up * file_position);
  }
  // A rotation about file axes becomes the same rotation about world axes.
  Eigen::Quaterniond Rotation(const Eigen::Quaterniond& file_rotation) const {
    return (y_up_to_z_up * file_rotation.normalized() *
            y_up_to_z_up.conjugate())
        .normalized();
  }
};

// A non-root joint's position channels replace its OFFSET (assimp's and the
// usual BVH reading); the skeleton holds fixed offsets, so they must not
// move over time.
Eigen::Vector3d ConstantPositionKey(const aiNodeAnim& track,
                                    const std::string& path) {
  const Eigen::Vector3d first = ToEigen(track.mPositionKeys[0].mValue);
  const double tolerance = 1e-4 * (1.0 + first.norm());
  for (unsigned int k = 0; k < track.mNumPositionKeys; ++k) {
    const Eigen::Vector3d position = ToEigen(track.mPositionKeys[k].mValue);
    if (!IsFinite(position)) {
      throw InputError(path, "frame " + std::to_string(k) + ": joint '" +
                                 std::string(track.mNodeName.C_Str()) +
                                 "' has NaN or infinite position values");
    }
    if ((position - first).norm() > tolerance) {
      throw InputError(path, "joint '" + std::string(track.mNodeName.C_Str()) +
                                 "' has animated position channels (frame " +
                                 std::to_string(k) +
                                 " moves it); only the root may translate");
    }
  }
  return first;
}

// Appends `node` and its subtree in depth-first order (parents first).
void AddJoints(const aiNode& node, int parent,
               const std::map<std::string, JointSource>& sources,
               const FrameConversion& conversion, const std::string& path,
               Skeleton* skeleton, std::vector<JointSource>* joint_sources) {
  const std::string node_name = node.mName.C_Str();
  auto found = sources.find(node_name);
  SkeletonJoint joint;
  joint.parent = parent;
  Eigen::Vector3d file_offset(node.mTransformation.a4, node.mTransformation.b4,
                              node.mTransformation.c4);
  if (found == sources.end()) {
    // Assimp names end sites "EndSite_<parent>"; only the scan's joints
    // carry channels, so anything else is an end site.
    if (parent < 0) {
      throw InputError(path, "assimp's root node '" + node_name +
                                 "' is not the BVH ROOT joint");
    }
    joint.name = skeleton->joints[parent].name + "_end";
    joint.type = JointType::kFixed;
    joint_sources->push_back(JointSource{});
  } else {
    const JointSource& source = found->second;
    joint.name = node_name;
    if (parent < 0) {
      joint.type = JointType::kFree;
      file_offset.setZero();  // the root's place comes from root_position_m
    } else {
      joint.type = source.channels->HasRotations() ? JointType::kSpherical
                                                   : JointType::kFixed;
      if (source.channels->HasPositions()) {
        file_offset = ConstantPositionKey(*source.track, path);
      }
    }
    joint_sources->push_back(source);
  }
  if (!IsFinite(file_offset)) {
    throw InputError(path,
                     "joint '" + joint.name + "' has a non-finite OFFSET");
  }
  joint.offset_m = conversion.Position(file_offset);
  skeleton->joints.push_back(joint);
  const int index = skeleton->num_joints() - 1;
  for (unsigned int c = 0; c < node.mNumChildren; ++c) {
    AddJoints(*node.mChildren[c], index, sources, conversion, path, skeleton,
              joint_sources);
  }
}

// Pairs each scanned joint with its assimp track, checking that assimp kept
// every channel: it reads positions only from 6-channel joints.
std::map<std::string, JointSource> MatchTracks(const aiAnimation& animation,
                                               const BvhTextLayout& layout,
                                               const std::string& path) {
  std::map<std::string, JointSource> sources;
  for (const BvhJointChannels& joint : layout.joints) {
    if (!sources.emplace(joint.joint_name, JointSource{nullptr, &joint})
             .second) {
      throw InputError(path, "duplicate joint name '" + joint.joint_name + "'");
    }
    if (joint.HasPositions() && joint.channel_names.size() != 6) {
      throw InputError(path, "joint '" + joint.joint_name + "' declares " +
                                 std::to_string(joint.channel_names.size()) +
                                 " channels including positions; assimp only "
                                 "reads positions of 6-channel joints");
    }
  }
  for (unsigned int t = 0; t < animation.mNumChannels; ++t) {
    const aiNodeAnim* track = animation.mChannels[t];
    auto found = sources.find(track->mNodeName.C_Str());
    if (found == sources.end()) {
      throw InputError(path, "assimp produced a track for unknown joint '" +
                                 std::string(track->mNodeName.C_Str()) + "'");
    }
    const unsigned int frames = static_cast<unsigned int>(layout.num_frames);
    const unsigned int positions =
        found->second.channels->HasPositions() ? frames : 1u;
    if (track->mNumRotationKeys != frames ||
        track->mNumPositionKeys != positions) {
      throw InputError(path,
                       "assimp returned an unexpected number of keys "
                       "for joint '" +
                           found->first + "'");
    }
    found->second.track = track;
  }
  for (const auto& [name, source] : sources) {
    if (source.track == nullptr) {
      throw InputError(path,
                       "assimp produced no track for joint '" + name + "'");
    }
  }
  return sources;
}

Pose3D ReadFrame(const Skeleton& skeleton,
                 const std::vector<JointSource>& joint_sources, int frame,
                 const FrameConversion& conversion, const std::string& path) {
  Pose3D pose;
  pose.local_rotations.assign(skeleton.num_joints(),
                              Eigen::Quaterniond::Identity());
  const std::string where = "frame " + std::to_string(frame) + ": ";
  const aiNodeAnim& root_track = *joint_sources[0].track;
  // Without position channels assimp's single key is the root's OFFSET.
  const unsigned int root_key =
      root_track.mNumPositionKeys > 1 ? static_cast<unsigned int>(frame) : 0u;
  pose.root_position_m =
      conversion.Position(ToEigen(root_track.mPositionKeys[root_key].mValue));
  if (!IsFinite(pose.root_position_m)) {
    throw InputError(path, where + "root position is NaN or infinite");
  }
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    if (skeleton.joints[j].type == JointType::kFixed) continue;
    const Eigen::Quaterniond file_rotation =
        ToEigen(joint_sources[j].track->mRotationKeys[frame].mValue);
    if (!IsFinite(file_rotation)) {
      throw InputError(path, where + "joint '" + skeleton.joints[j].name +
                                 "' has NaN or infinite rotation values");
    }
    pose.local_rotations[j] = conversion.Rotation(file_rotation);
  }
  return pose;
}

// BVH frame times are printed rounded (".0083333" for 120 Hz); recover the
// integer rate they stand for instead of carrying 120.0005 Hz around.
double RateFromFrameTime(double frame_time_s) {
  const double rate_hz = 1.0 / frame_time_s;
  const double nearest_hz = std::round(rate_hz);
  return nearest_hz > 0.0 && std::abs(rate_hz - nearest_hz) < 1e-4 * rate_hz
             ? nearest_hz
             : rate_hz;
}

}  // namespace

Motion3D ReadBvhMotion(const std::string& path, double scale_m, double fps) {
  if (!(scale_m > 0.0 && std::isfinite(scale_m))) {
    throw InputError(path,
                     "BVH scale must be a positive number of metres "
                     "per file unit, got " +
                         std::to_string(scale_m));
  }
  if (std::isnan(fps) || std::isinf(fps)) {
    throw InputError(path, "requested fps must be a number");
  }
  const std::string text = ReadFileText(path);
  const BvhTextLayout layout = ScanBvhText(text, path);
  Assimp::Importer importer;
  const aiScene& scene = ImportWithAssimp(text, path, &importer);
  const std::map<std::string, JointSource> sources =
      MatchTracks(*scene.mAnimations[0], layout, path);

  FrameConversion conversion;
  conversion.scale_m = scale_m;
  auto skeleton = std::make_shared<Skeleton>();
  skeleton->name = std::filesystem::path(path).stem().string();
  std::vector<JointSource> joint_sources;
  AddJoints(*scene.mRootNode, -1, sources, conversion, path, skeleton.get(),
            &joint_sources);
  ValidateSkeleton(*skeleton, path);

  Motion3D motion;
  motion.skeleton = skeleton;
  motion.fps = RateFromFrameTime(layout.frame_time_s);
  motion.loops = false;
  motion.frames.reserve(layout.num_frames);
  for (int frame = 0; frame < layout.num_frames; ++frame) {
    motion.frames.push_back(
        ReadFrame(*skeleton, joint_sources, frame, conversion, path));
  }
  return fps > 0.0 ? ResampleMotion(motion, fps) : motion;
}

}  // namespace m2d
