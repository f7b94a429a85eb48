// motion: reading and writing 2D clips — our own JSON format, COCO-style
// keypoint JSON (ViTPose/MMPose) and OpenPose per-frame folders
// (docs/formats.md).
#ifndef MIMIC2D_MOTION_CLIP_IO_H_
#define MIMIC2D_MOTION_CLIP_IO_H_

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/json_fields.h"
#include "motion/clip2d.h"

namespace m2d {

inline constexpr char kClipFormat[] = "mimic2d.clip";
inline constexpr int kClipVersion = 1;

// --- Our own format: {"format": "mimic2d.clip", "version": 1, ...}. -------

// Missing keypoints are written as [null, null, 0].
nlohmann::json ClipToJson(const Clip2D& clip);
// Parses and validates (ValidateClip) a clip object; errors name the
// cursor's file and position, so clips embedded in other files (reference
// bundles) report e.g. "bundle.json: views[1].clip.keypoints[3]: ...".
Clip2D ClipFromJson(const JsonCursor& cursor);

Clip2D ReadClip(const std::string& path);
void WriteClip(const std::string& path, const Clip2D& clip);  // atomic

// --- Detector outputs (always COCO-17). ----------------------------------

// How to turn a detector's per-frame lists of people into one clip.
struct DetectionReadOptions {
  // The person to follow: the instance whose "track_id"/"id" (COCO) or
  // "person_id" (OpenPose) equals this; -1 takes the largest person in each
  // frame (bounding-box area, else the area of the keypoints' extent).
  int track_id = -1;
  double fps = 30.0;          // frames per second of the source video
  int image_width_px = 1920;  // size of the source video's frames
  int image_height_px = 1080;

  void Validate() const;  // throws ConfigError
};

// COCO-style keypoint JSON as written by ViTPose/MMPose; the accepted
// shapes are listed in docs/formats.md ("COCO keypoint JSON input").
Clip2D ReadCocoKeypoints(const std::string& path,
                         const DetectionReadOptions& options);
// Same, from an already parsed document; `source` names it in errors.
Clip2D CocoKeypointsFromJson(const nlohmann::json& json,
                             const std::string& source,
                             const DetectionReadOptions& options);

// An OpenPose --write_json folder: files "*_keypoints.json" in name order,
// one frame each; BODY_25 (75 values) or COCO-18 (54 values) bodies are
// mapped to COCO-17.
Clip2D ReadOpenPoseFolder(const std::string& folder,
                          const DetectionReadOptions& options);

// For each COCO-17 keypoint, its index in OpenPose's BODY_25 / COCO-18
// layouts (the feet and the neck/mid-hip are dropped).
const std::array<int, 17>& Body25ToCoco17();
const std::array<int, 17>& OpenPoseCoco18ToCoco17();

// What the CLI accepts: a folder is read as OpenPose, a JSON object with
// "format": "mimic2d.clip" as our clip (`options` unused: the file carries
// its own fps and image size), anything else as COCO-style keypoint JSON.
Clip2D ReadClipAuto(const std::string& path,
                    const DetectionReadOptions& options);

}  // namespace m2d

#endif  // MIMIC2D_MOTION_CLIP_IO_H_
