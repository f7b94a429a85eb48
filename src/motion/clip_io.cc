#include "motion/clip_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "common/error.h"
#include "common/file_io.h"

namespace m2d {
namespace {

constexpr int kCocoKeypoints = 17;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

Keypoint2D MissingKeypoint() { return {kNan, kNan, 0.0}; }

std::string JoinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) {
    joined += (joined.empty() ? "" : ", ") + name;
  }
  return joined;
}

// ---------------------------------------------------------------------------
// Our own format.

nlohmann::json PointToJson(const Keypoint2D& point) {
  if (!point.IsPresent()) return {nullptr, nullptr, 0};
  return {point.x_px, point.y_px, point.confidence};
}

// [x, y, confidence]; null coordinates become NaN (ValidateClip later
// rejects them unless the confidence is 0).
Keypoint2D PointFromJson(const JsonCursor& cursor) {
  cursor.ArraySize(3);
  return {cursor.At(0).NumberOrNan(), cursor.At(1).NumberOrNan(),
          cursor.At(2).Number()};
}

void CheckFormatAndVersion(const JsonCursor& cursor) {
  JsonCursor format = cursor.Field("format");
  if (format.String() != kClipFormat) {
    format.Fail("expected \"" + std::string(kClipFormat) + "\", found \"" +
                format.String() + "\"");
  }
  JsonCursor version = cursor.Field("version");
  if (version.Integer() != kClipVersion) {
    version.Fail("unsupported version " + std::to_string(version.Integer()) +
                 " (this build reads version " + std::to_string(kClipVersion) +
                 ")");
  }
}

const KeypointLayout* LayoutFromJson(const JsonCursor& cursor) {
  std::string name = cursor.String();
  const KeypointLayout* layout = FindLayout(name);
  if (layout == nullptr) {
    cursor.Fail("unknown layout '" + name +
                "' (known: " + JoinNames(LayoutNames()) + ")");
  }
  return layout;
}

KeypointTrack KeypointsFromJson(const JsonCursor& cursor,
                                const KeypointLayout& layout) {
  const int num_frames = static_cast<int>(cursor.ArraySize());
  KeypointTrack track(num_frames, layout.num_keypoints());
  for (int t = 0; t < num_frames; ++t) {
    JsonCursor frame = cursor.At(t);
    const size_t count = frame.ArraySize();
    if (count != static_cast<size_t>(layout.num_keypoints())) {
      frame.Fail("frame " + std::to_string(t) + " has " +
                 std::to_string(count) + " keypoints, layout " + layout.name +
                 " has " + std::to_string(layout.num_keypoints()));
    }
    for (int j = 0; j < layout.num_keypoints(); ++j) {
      track.at(t, j) = PointFromJson(frame.At(j));
    }
  }
  return track;
}

ObjectTrack2D ObjectFromJson(const JsonCursor& cursor) {
  ObjectTrack2D object;
  object.name = cursor.Field("name").String();
  JsonCursor points = cursor.Field("points");
  const size_t count = points.ArraySize();
  for (size_t t = 0; t < count; ++t) {
    object.points.push_back(PointFromJson(points.At(t)));
  }
  return object;
}

// ---------------------------------------------------------------------------
// Detector outputs: per frame, a list of candidate people.

struct Detection {
  std::vector<Keypoint2D> keypoints;  // COCO-17 order
  double area_px2 = 0.0;              // bounding box, else keypoint extent
  std::optional<long> track_id;
};
using DetectionFrames = std::vector<std::vector<Detection>>;

// Detector scores are heatmap maxima that may slightly exceed 1; a score of
// 0 (or below) marks an undetected keypoint.
Keypoint2D DetectedKeypoint(double x_px, double y_px, double score) {
  if (!(score > 0.0)) return MissingKeypoint();
  return {x_px, y_px, std::min(score, 1.0)};
}

double ExtentArea(const std::vector<Keypoint2D>& points) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double min_x = kInf, min_y = kInf, max_x = -kInf, max_y = -kInf;
  int present = 0;
  for (const Keypoint2D& point : points) {
    if (!point.IsPresent()) continue;
    ++present;
    min_x = std::min(min_x, point.x_px);
    max_x = std::max(max_x, point.x_px);
    min_y = std::min(min_y, point.y_px);
    max_y = std::max(max_y, point.y_px);
  }
  return present < 2 ? 0.0 : (max_x - min_x) * (max_y - min_y);
}

// Index of the person to follow in one frame, or -1 when there is none.
int ChoosePerson(const std::vector<Detection>& people, int track_id) {
  int chosen = -1;
  for (size_t i = 0; i < people.size(); ++i) {
    if (track_id >= 0) {
      if (people[i].track_id == track_id) return static_cast<int>(i);
    } else if (chosen < 0 || people[i].area_px2 > people[chosen].area_px2) {
      chosen = static_cast<int>(i);
    }
  }
  return chosen;
}

void CheckTrackIdSeen(const DetectionFrames& frames, int track_id,
                      const std::string& source) {
  std::set<long> seen;
  for (const auto& people : frames) {
    for (const Detection& person : people) {
      if (person.track_id) seen.insert(*person.track_id);
    }
  }
  if (track_id < 0 || seen.count(track_id) > 0) return;
  std::vector<std::string> names;
  for (long id : seen) names.push_back(std::to_string(id));
  throw InputError(source, "track id " + std::to_string(track_id) +
                               " is in no frame (ids present: " +
                               (names.empty() ? "none" : JoinNames(names)) +
                               ")");
}

Clip2D ClipFromDetections(const DetectionFrames& frames,
                          const DetectionReadOptions& options,
                          const std::string& source) {
  options.Validate();
  if (frames.empty()) throw InputError(source, "no frames");
  CheckTrackIdSeen(frames, options.track_id, source);
  Clip2D clip;
  clip.layout = &Coco17Layout();
  clip.fps = options.fps;
  clip.image_width_px = options.image_width_px;
  clip.image_height_px = options.image_height_px;
  const int num_frames = static_cast<int>(frames.size());
  clip.keypoints = KeypointTrack(num_frames, kCocoKeypoints);
  for (int t = 0; t < num_frames; ++t) {
    const int chosen = ChoosePerson(frames[t], options.track_id);
    for (int j = 0; j < kCocoKeypoints; ++j) {
      clip.keypoints.at(t, j) =
          chosen < 0 ? MissingKeypoint() : frames[t][chosen].keypoints[j];
    }
  }
  ValidateClip(clip, source);
  return clip;
}

// An optional integer id; null or -1 (OpenPose's "no id") count as none.
std::optional<long> OptionalId(const JsonCursor& cursor) {
  if (cursor.value().is_null()) return std::nullopt;
  long id = cursor.Integer();
  if (id < 0) return std::nullopt;
  return id;
}

// --- COCO-style JSON. ---

// "keypoints": 17 × [x, y] or 17 × [x, y, score] or 51 flat numbers;
// scores from "keypoint_scores" when present, else from the triples.
std::vector<Keypoint2D> CocoKeypointsFromInstance(const JsonCursor& instance) {
  JsonCursor keypoints = instance.Field("keypoints");
  const size_t count = keypoints.ArraySize();
  std::vector<double> x(kCocoKeypoints), y(kCocoKeypoints),
      score(kCocoKeypoints, kNan);
  if (count == 3 * kCocoKeypoints && !keypoints.value()[0].is_array()) {
    for (int j = 0; j < kCocoKeypoints; ++j) {
      x[j] = keypoints.At(3 * j).Number();
      y[j] = keypoints.At(3 * j + 1).Number();
      score[j] = keypoints.At(3 * j + 2).Number();
    }
  } else if (count == kCocoKeypoints) {
    for (int j = 0; j < kCocoKeypoints; ++j) {
      JsonCursor point = keypoints.At(j);
      const size_t size = point.ArraySize();
      if (size != 2 && size != 3)
        point.Fail("expected [x, y] or [x, y, score]");
      x[j] = point.At(0).Number();
      y[j] = point.At(1).Number();
      if (size == 3) score[j] = point.At(2).Number();
    }
  } else {
    keypoints.Fail(
        "expected 17 keypoints ([x, y] or [x, y, score]) or 51 "
        "numbers, found " +
        std::to_string(count) + " elements");
  }
  if (instance.Has("keypoint_scores")) {
    JsonCursor scores = instance.Field("keypoint_scores");
    scores.ArraySize(kCocoKeypoints);
    for (int j = 0; j < kCocoKeypoints; ++j) score[j] = scores.At(j).Number();
  }
  std::vector<Keypoint2D> points(kCocoKeypoints);
  for (int j = 0; j < kCocoKeypoints; ++j) {
    if (std::isnan(score[j])) {
      keypoints.Fail(
          "keypoints are [x, y] pairs but 'keypoint_scores' is "
          "missing");
    }
    points[j] = DetectedKeypoint(x[j], y[j], score[j]);
  }
  return points;
}

// Four numbers, or MMPose's single box wrapped in a list ([[...]]).
std::array<double, 4> BoxNumbers(const JsonCursor& bbox) {
  if (bbox.ArraySize() == 1 && bbox.value()[0].is_array()) {
    return BoxNumbers(bbox.At(0));
  }
  bbox.ArraySize(4);
  return {bbox.At(0).Number(), bbox.At(1).Number(), bbox.At(2).Number(),
          bbox.At(3).Number()};
}

std::optional<long> CocoTrackId(const JsonCursor& instance) {
  if (instance.Has("track_id")) return OptionalId(instance.Field("track_id"));
  if (instance.Has("id")) return OptionalId(instance.Field("id"));
  return std::nullopt;
}

// MMPose instance: "bbox" is [x1, y1, x2, y2] (corners).
Detection DetectionFromMmposeInstance(const JsonCursor& instance) {
  Detection detection;
  detection.keypoints = CocoKeypointsFromInstance(instance);
  detection.area_px2 = ExtentArea(detection.keypoints);
  if (instance.Has("bbox")) {
    std::array<double, 4> box = BoxNumbers(instance.Field("bbox"));
    detection.area_px2 =
        std::max(0.0, box[2] - box[0]) * std::max(0.0, box[3] - box[1]);
  }
  detection.track_id = CocoTrackId(instance);
  return detection;
}

// COCO results entry: "bbox" is [x, y, width, height].
Detection DetectionFromCocoResult(const JsonCursor& entry) {
  Detection detection;
  detection.keypoints = CocoKeypointsFromInstance(entry);
  detection.area_px2 = ExtentArea(detection.keypoints);
  if (entry.Has("bbox")) {
    std::array<double, 4> box = BoxNumbers(entry.Field("bbox"));
    detection.area_px2 = std::max(0.0, box[2]) * std::max(0.0, box[3]);
  }
  detection.track_id = CocoTrackId(entry);
  return detection;
}

// One frame of shape (a): a list of instances, or an object holding them
// under "instances" or "predictions" (MMPose may nest the latter once more,
// one list per batch item).
JsonCursor InstancesOfFrame(const JsonCursor& frame) {
  if (frame.value().is_array()) return frame;
  if (frame.Has("instances")) return frame.Field("instances");
  if (frame.Has("predictions")) {
    JsonCursor predictions = frame.Field("predictions");
    if (predictions.ArraySize() > 0 && predictions.value()[0].is_array()) {
      if (predictions.ArraySize() != 1) {
        predictions.Fail("expected one list of instances per frame");
      }
      return predictions.At(0);
    }
    return predictions;
  }
  frame.Fail(
      "expected a list of instances or an object with 'instances' or "
      "'predictions'");
}

DetectionFrames PerFrameDetections(const JsonCursor& frames) {
  DetectionFrames detections(frames.ArraySize());
  for (size_t t = 0; t < detections.size(); ++t) {
    JsonCursor instances = InstancesOfFrame(frames.At(t));
    for (size_t i = 0; i < instances.ArraySize(); ++i) {
      detections[t].push_back(DetectionFromMmposeInstance(instances.At(i)));
    }
  }
  return detections;
}

// Shape (b): frames are the distinct image ids in increasing order.
DetectionFrames CocoResultDetections(const JsonCursor& results) {
  std::map<long, std::vector<Detection>> by_image;
  for (size_t i = 0; i < results.ArraySize(); ++i) {
    JsonCursor entry = results.At(i);
    long image_id = entry.Field("image_id").Integer();
    by_image[image_id].push_back(DetectionFromCocoResult(entry));
  }
  DetectionFrames detections;
  for (auto& [image_id, people] : by_image) {
    detections.push_back(std::move(people));
  }
  return detections;
}

// --- OpenPose. ---

std::vector<std::string> OpenPoseFrameFiles(const std::string& folder) {
  namespace fs = std::filesystem;
  const std::string suffix = "_keypoints.json";
  std::vector<std::string> files;
  std::error_code error;
  for (const fs::directory_entry& entry :
       fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() > suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      files.push_back(entry.path().string());
    }
  }
  if (error) throw InputError(folder, "cannot list folder: " + error.message());
  std::sort(files.begin(), files.end());
  return files;
}

Detection DetectionFromOpenPosePerson(const JsonCursor& person) {
  JsonCursor pose = person.Field("pose_keypoints_2d");
  const size_t count = pose.ArraySize();
  const std::array<int, 17>* to_coco = nullptr;
  if (count == 75) to_coco = &Body25ToCoco17();
  if (count == 54) to_coco = &OpenPoseCoco18ToCoco17();
  if (to_coco == nullptr) {
    pose.Fail("expected 75 values (BODY_25) or 54 (COCO-18), found " +
              std::to_string(count));
  }
  std::vector<Keypoint2D> all(count / 3);
  for (size_t k = 0; k < all.size(); ++k) {
    all[k] =
        DetectedKeypoint(pose.At(3 * k).Number(), pose.At(3 * k + 1).Number(),
                         pose.At(3 * k + 2).Number());
  }
  Detection detection;
  detection.area_px2 = ExtentArea(all);
  for (int index : *to_coco) detection.keypoints.push_back(all[index]);
  if (person.Has("person_id")) {
    JsonCursor id = person.Field("person_id");
    // OpenPose writes [-1] (a list) when tracking is off.
    if (id.value().is_array()) {
      if (id.ArraySize() > 0) detection.track_id = OptionalId(id.At(0));
    } else {
      detection.track_id = OptionalId(id);
    }
  }
  return detection;
}

std::vector<Detection> OpenPoseFramePeople(const std::string& path) {
  nlohmann::json json = ReadJsonFile(path);
  JsonCursor people = JsonCursor(json, path).Field("people");
  std::vector<Detection> detections;
  for (size_t i = 0; i < people.ArraySize(); ++i) {
    detections.push_back(DetectionFromOpenPosePerson(people.At(i)));
  }
  return detections;
}

}  // namespace

// ---------------------------------------------------------------------------

nlohmann::json ClipToJson(const Clip2D& clip) {
  nlohmann::json frames = nlohmann::json::array();
  for (int t = 0; t < clip.num_frames(); ++t) {
    nlohmann::json frame = nlohmann::json::array();
    for (int j = 0; j < clip.keypoints.num_keypoints(); ++j) {
      frame.push_back(PointToJson(clip.keypoints.at(t, j)));
    }
    frames.push_back(std::move(frame));
  }
  nlohmann::json objects = nlohmann::json::array();
  for (const ObjectTrack2D& object : clip.objects) {
    nlohmann::json points = nlohmann::json::array();
    for (const Keypoint2D& point : object.points) {
      points.push_back(PointToJson(point));
    }
    objects.push_back({{"name", object.name}, {"points", std::move(points)}});
  }
  return {{"format", kClipFormat},
          {"version", kClipVersion},
          {"layout", clip.layout->name},
          {"fps", clip.fps},
          {"image_width_px", clip.image_width_px},
          {"image_height_px", clip.image_height_px},
          {"keypoints", std::move(frames)},
          {"objects", std::move(objects)}};
}

Clip2D ClipFromJson(const JsonCursor& cursor) {
  CheckFormatAndVersion(cursor);
  Clip2D clip;
  clip.layout = LayoutFromJson(cursor.Field("layout"));
  clip.fps = cursor.Field("fps").Number();
  // Read wide and bounded before narrowing: a side past 2^31 must not wrap
  // into a plausible one.
  for (auto [key, side] :
       {std::pair{"image_width_px", &clip.image_width_px},
        std::pair{"image_height_px", &clip.image_height_px}}) {
    const long value = cursor.Field(key).Integer();
    *side =
        value >= 1 && value <= kMaxImageSidePx ? static_cast<int>(value) : -1;
  }
  clip.keypoints = KeypointsFromJson(cursor.Field("keypoints"), *clip.layout);
  if (cursor.Has("objects")) {
    JsonCursor objects = cursor.Field("objects");
    for (size_t i = 0; i < objects.ArraySize(); ++i) {
      clip.objects.push_back(ObjectFromJson(objects.At(i)));
    }
  }
  // Re-raise through the cursor so the message carries the position of an
  // embedded clip, not just the file.
  try {
    ValidateClip(clip, cursor.source());
  } catch (const InputError& error) {
    cursor.Fail(error.problem());
  }
  return clip;
}

Clip2D ReadClip(const std::string& path) {
  nlohmann::json json = ReadJsonFile(path);
  return ClipFromJson(JsonCursor(json, path));
}

void WriteClip(const std::string& path, const Clip2D& clip) {
  ValidateClip(clip, path);
  WriteJsonFileAtomic(path, ClipToJson(clip));
}

void DetectionReadOptions::Validate() const {
  if (track_id < -1) {
    throw ConfigError("track_id must be >= 0, or -1 for the largest person");
  }
  if (!(fps > 0.0 && std::isfinite(fps))) {
    throw ConfigError("fps must be a positive number");
  }
  if (image_width_px < 1 || image_height_px < 1) {
    throw ConfigError("image_width_px and image_height_px must be positive");
  }
}

Clip2D CocoKeypointsFromJson(const nlohmann::json& json,
                             const std::string& source,
                             const DetectionReadOptions& options) {
  JsonCursor root(json, source);
  if (json.is_object()) {
    if (!root.Has("instance_info")) {
      root.Fail(
          "expected a list of frames, a COCO results list, or an "
          "object with 'instance_info' (MMPose demo output)");
    }
    return ClipFromDetections(PerFrameDetections(root.Field("instance_info")),
                              options, source);
  }
  if (root.ArraySize() == 0) root.Fail("no frames");
  const bool coco_results = json[0].is_object() && json[0].contains("image_id");
  return ClipFromDetections(
      coco_results ? CocoResultDetections(root) : PerFrameDetections(root),
      options, source);
}

Clip2D ReadCocoKeypoints(const std::string& path,
                         const DetectionReadOptions& options) {
  return CocoKeypointsFromJson(ReadJsonFile(path), path, options);
}

const std::array<int, 17>& Body25ToCoco17() {
  // BODY_25: 0 nose, 1 neck, 2-4 right arm, 5-7 left arm, 8 mid-hip,
  // 9-11 right leg, 12-14 left leg, 15/16 right/left eye, 17/18 ears.
  static const std::array<int, 17> indices = {0, 16, 15, 18, 17, 5,  2,  6, 3,
                                              7, 4,  12, 9,  13, 10, 14, 11};
  return indices;
}

const std::array<int, 17>& OpenPoseCoco18ToCoco17() {
  // COCO-18: 0 nose, 1 neck, 2-4 right arm, 5-7 left arm, 8-10 right leg,
  // 11-13 left leg, 14/15 right/left eye, 16/17 ears.
  static const std::array<int, 17> indices = {0, 15, 14, 17, 16, 5, 2,  6, 3,
                                              7, 4,  11, 8,  12, 9, 13, 10};
  return indices;
}

Clip2D ReadOpenPoseFolder(const std::string& folder,
                          const DetectionReadOptions& options) {
  if (!std::filesystem::is_directory(folder)) {
    throw InputError(folder, "not a folder");
  }
  std::vector<std::string> files = OpenPoseFrameFiles(folder);
  if (files.empty()) {
    throw InputError(
        folder, "no *_keypoints.json files (OpenPose --write_json output)");
  }
  DetectionFrames frames;
  for (const std::string& file : files) {
    frames.push_back(OpenPoseFramePeople(file));
  }
  return ClipFromDetections(frames, options, folder);
}

Clip2D ReadClipAuto(const std::string& path,
                    const DetectionReadOptions& options) {
  if (std::filesystem::is_directory(path)) {
    return ReadOpenPoseFolder(path, options);
  }
  nlohmann::json json = ReadJsonFile(path);
  JsonCursor root(json, path);
  if (root.Has("format")) return ClipFromJson(root);
  if (root.Has("people")) {
    root.Fail(
        "this is one OpenPose frame; pass the folder holding the "
        "*_keypoints.json files");
  }
  return CocoKeypointsFromJson(json, path, options);
}

}  // namespace m2d
