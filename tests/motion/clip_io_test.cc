#include "motion/clip_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/file_io.h"
#include "test_paths.h"

namespace m2d {
namespace {

using nlohmann::json;

constexpr int kJ = 17;

// A 4-frame COCO-17 clip with a few missing keypoints and a ball track.
Clip2D SampleClip() {
  Clip2D clip;
  clip.fps = 25.0;
  clip.image_width_px = 1280;
  clip.image_height_px = 720;
  clip.keypoints = KeypointTrack(4, kJ);
  for (int t = 0; t < 4; ++t) {
    for (int j = 0; j < kJ; ++j) {
      clip.keypoints.at(t, j) = {100.0 + 10.3 * j + 0.1 * t,
                                 200.0 + 7.7 * j - 0.2 * t, 0.5 + 0.025 * j};
    }
  }
  clip.keypoints.at(1, 3) = {NAN, NAN, 0.0};
  clip.keypoints.at(2, 16) = {NAN, NAN, 0.0};
  ObjectTrack2D ball{"ball", {}};
  for (int t = 0; t < 4; ++t) ball.points.push_back({640.0 + t, 700.5, 0.9});
  ball.points[2] = {NAN, NAN, 0.0};
  clip.objects.push_back(ball);
  return clip;
}

void ExpectSamePoint(const Keypoint2D& a, const Keypoint2D& b) {
  ASSERT_EQ(a.IsPresent(), b.IsPresent());
  EXPECT_EQ(a.confidence, b.confidence);
  if (!a.IsPresent()) return;
  EXPECT_EQ(a.x_px, b.x_px);
  EXPECT_EQ(a.y_px, b.y_px);
}

void ExpectSameClip(const Clip2D& a, const Clip2D& b) {
  EXPECT_EQ(a.layout, b.layout);
  EXPECT_EQ(a.fps, b.fps);
  EXPECT_EQ(a.image_width_px, b.image_width_px);
  EXPECT_EQ(a.image_height_px, b.image_height_px);
  ASSERT_EQ(a.num_frames(), b.num_frames());
  ASSERT_EQ(a.keypoints.num_keypoints(), b.keypoints.num_keypoints());
  for (int t = 0; t < a.num_frames(); ++t) {
    for (int j = 0; j < a.keypoints.num_keypoints(); ++j) {
      SCOPED_TRACE("frame " + std::to_string(t) + " keypoint " +
                   std::to_string(j));
      ExpectSamePoint(a.keypoints.at(t, j), b.keypoints.at(t, j));
    }
  }
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].name, b.objects[i].name);
    ASSERT_EQ(a.objects[i].points.size(), b.objects[i].points.size());
    for (size_t t = 0; t < a.objects[i].points.size(); ++t) {
      ExpectSamePoint(a.objects[i].points[t], b.objects[i].points[t]);
    }
  }
}

std::string WriteText(const std::string& dir, const std::string& name,
                      const std::string& text) {
  std::string path = dir + "/" + name;
  WriteFileAtomic(path, text);
  return path;
}

// Runs `read` and returns the InputError's message ("" if none was thrown).
template <typename Read>
std::string InputErrorOf(Read read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// ---------------------------------------------------------------------------
// Our format.

TEST(ClipIo, WriteThenReadGivesTheSameClip) {
  std::string dir = testing::TempDir("clip_roundtrip");
  std::string path = dir + "/clip.json";
  Clip2D clip = SampleClip();
  WriteClip(path, clip);
  ExpectSameClip(ReadClip(path), clip);
  // Nothing but the clip is left in the folder (the temp file was renamed).
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            1);
}

TEST(ClipIo, PointLayoutRoundTrips) {
  Clip2D clip;
  clip.layout = &PointLayout();
  clip.keypoints = KeypointTrack(2, 1);
  clip.keypoints.at(0, 0) = {1.5, 2.5, 1.0};
  clip.keypoints.at(1, 0) = {NAN, NAN, 0.0};
  json text = ClipToJson(clip);
  ExpectSameClip(ClipFromJson(JsonCursor(text, "mem")), clip);
}

// Animal keypoints (MMPose's AP-10K, the dog's layout): written and read
// under their name, hips as the root like COCO-17's.
TEST(ClipIo, Ap10kLayoutRoundTrips) {
  Clip2D clip = SampleClip();
  clip.layout = FindLayout("ap10k");
  ASSERT_NE(clip.layout, nullptr);
  EXPECT_EQ(clip.layout, &Ap10kLayout());
  EXPECT_EQ(clip.layout->num_keypoints(), 17);
  EXPECT_EQ(clip.layout->keypoint_names[4], "root_of_tail");
  EXPECT_EQ(clip.layout->root_keypoints,
            (std::vector<int>{clip.layout->IndexOf("left_hip"),
                              clip.layout->IndexOf("right_hip")}));
  json text = ClipToJson(clip);
  EXPECT_EQ(text["layout"], "ap10k");
  ExpectSameClip(ClipFromJson(JsonCursor(text, "mem")), clip);
}

TEST(ClipIo, MissingKeypointIsWrittenAsNullNullZero) {
  json text = ClipToJson(SampleClip());
  EXPECT_EQ(text["format"], "mimic2d.clip");
  EXPECT_EQ(text["version"], 1);
  EXPECT_EQ(text["layout"], "coco17");
  EXPECT_EQ(text["keypoints"][1][3], json::parse("[null, null, 0]"));
  EXPECT_EQ(text["objects"][0]["points"][2], json::parse("[null, null, 0]"));
  EXPECT_EQ(text["keypoints"][0][0], json::parse("[100.0, 200.0, 0.5]"));
}

class ClipIoBadInput : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::TempDir("clip_bad"); }

  // Writes the sample clip with `edit` applied and returns ReadClip's error.
  template <typename Edit>
  std::string ErrorAfterEdit(const std::string& name, Edit edit) {
    json text = ClipToJson(SampleClip());
    edit(text);
    std::string path = WriteText(dir_, name, text.dump());
    std::string message = InputErrorOf([&] { ReadClip(path); });
    EXPECT_NE(message.find(path), std::string::npos) << message;
    return message;
  }

  std::string dir_;
};

TEST_F(ClipIoBadInput, MalformedJson) {
  std::string path = WriteText(dir_, "broken.json", "{\"format\": [1, 2");
  std::string message = InputErrorOf([&] { ReadClip(path); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("malformed JSON"), std::string::npos) << message;
}

TEST_F(ClipIoBadInput, WrongFormatString) {
  std::string message = ErrorAfterEdit(
      "format.json", [](json& text) { text["format"] = "mimic2d.cameras"; });
  EXPECT_NE(message.find("format"), std::string::npos) << message;
  EXPECT_NE(message.find("mimic2d.clip"), std::string::npos) << message;
}

TEST_F(ClipIoBadInput, WrongVersion) {
  std::string message =
      ErrorAfterEdit("version.json", [](json& text) { text["version"] = 2; });
  EXPECT_NE(message.find("unsupported version 2"), std::string::npos)
      << message;
}

TEST_F(ClipIoBadInput, UnknownLayoutListsTheKnownOnes) {
  std::string message = ErrorAfterEdit(
      "layout.json", [](json& text) { text["layout"] = "body25"; });
  EXPECT_NE(message.find("unknown layout 'body25'"), std::string::npos)
      << message;
  for (const std::string& name : LayoutNames()) {
    EXPECT_NE(message.find(name), std::string::npos) << message;
  }
}

TEST_F(ClipIoBadInput, FrameWithTooFewKeypoints) {
  std::string message = ErrorAfterEdit("shape.json", [](json& text) {
    text["keypoints"][3].erase(text["keypoints"][3].size() - 1);
  });
  EXPECT_NE(message.find("frame 3 has 16 keypoints, layout coco17 has 17"),
            std::string::npos)
      << message;
}

TEST_F(ClipIoBadInput, KeypointThatIsNotATriple) {
  std::string message = ErrorAfterEdit("triple.json", [](json& text) {
    text["keypoints"][2][5] = json::parse("[1.0, 2.0]");
  });
  EXPECT_NE(message.find("keypoints[2][5]"), std::string::npos) << message;
}

TEST_F(ClipIoBadInput, NullCoordinateWithPositiveConfidence) {
  std::string message = ErrorAfterEdit("nan.json", [](json& text) {
    text["keypoints"][1][4] = json::parse("[null, 3.0, 0.7]");
  });
  EXPECT_NE(message.find("frame 1 keypoint 'right_ear'"), std::string::npos)
      << message;
  EXPECT_NE(message.find("NaN"), std::string::npos) << message;
}

TEST_F(ClipIoBadInput, NullObjectPointWithPositiveConfidence) {
  std::string message = ErrorAfterEdit("nan_ball.json", [](json& text) {
    text["objects"][0]["points"][0] = json::parse("[null, null, 0.4]");
  });
  EXPECT_NE(message.find("object 'ball' frame 0"), std::string::npos)
      << message;
}

TEST_F(ClipIoBadInput, EmptyClip) {
  std::string message = ErrorAfterEdit("empty.json", [](json& text) {
    text["keypoints"] = json::array();
    text["objects"] = json::array();
  });
  EXPECT_NE(message.find("no frames"), std::string::npos) << message;
}

TEST_F(ClipIoBadInput, NonPositiveFps) {
  std::string message =
      ErrorAfterEdit("fps.json", [](json& text) { text["fps"] = 0; });
  EXPECT_NE(message.find("fps"), std::string::npos) << message;
}

// Found by fuzzing: absurd rates were accepted, and an image side past 2^31
// wrapped into a plausible one.
TEST_F(ClipIoBadInput, AbsurdFpsOrImageSize) {
  for (double fps : {1e-320, 0.5, 1e308}) {
    const std::string message = ErrorAfterEdit(
        "fps_absurd.json", [fps](json& text) { text["fps"] = fps; });
    EXPECT_NE(message.find("is outside [1"), std::string::npos) << message;
  }
  for (long side : {4294968296L, 100000L, -5L}) {
    const std::string message = ErrorAfterEdit(
        "side.json", [side](json& text) { text["image_width_px"] = side; });
    EXPECT_NE(message.find("image size must be in [1, 65536]"),
              std::string::npos)
        << message;
  }
}

TEST_F(ClipIoBadInput, ObjectTrackOfWrongLength) {
  std::string message = ErrorAfterEdit(
      "ball.json", [](json& text) { text["objects"][0]["points"].erase(0); });
  EXPECT_NE(message.find("object 'ball' has 3 frames, clip has 4"),
            std::string::npos)
      << message;
}

TEST(ClipIo, EmbeddedClipErrorsNameTheirPosition) {
  json bundle = {{"views", json::array({ClipToJson(SampleClip())})}};
  bundle["views"][0]["fps"] = -5;
  JsonCursor cursor = JsonCursor(bundle, "bundle.json").Field("views").At(0);
  std::string message = InputErrorOf([&] { ClipFromJson(cursor); });
  EXPECT_NE(message.find("bundle.json: views[0]: fps"), std::string::npos)
      << message;
}

// ---------------------------------------------------------------------------
// COCO-style detector output.

// A person whose 17 keypoints spread over `width` × `height` pixels from
// (x0, y0), with confidence `score` except keypoint `missing` (score 0).
struct Person {
  double x0, y0, width, height, score;
  int missing = -1;

  Keypoint2D Point(int j) const {
    return {x0 + width * j / (kJ - 1.0), y0 + height * ((j * 7) % kJ) / 16.0,
            j == missing ? 0.0 : score};
  }
  json Pairs() const {
    json list = json::array();
    for (int j = 0; j < kJ; ++j) list.push_back({Point(j).x_px, Point(j).y_px});
    return list;
  }
  json Scores() const {
    json list = json::array();
    for (int j = 0; j < kJ; ++j) list.push_back(Point(j).confidence);
    return list;
  }
  json Flat() const {
    json list = json::array();
    for (int j = 0; j < kJ; ++j) {
      list.push_back(Point(j).x_px);
      list.push_back(Point(j).y_px);
      list.push_back(Point(j).confidence);
    }
    return list;
  }
  json Triples() const {
    json list = json::array();
    for (int j = 0; j < kJ; ++j) {
      list.push_back({Point(j).x_px, Point(j).y_px, Point(j).confidence});
    }
    return list;
  }
};

const Person kSmall{100, 100, 50, 120, 0.8};
const Person kLarge{600, 200, 150, 400, 0.9, 5};

void ExpectFrameIs(const Clip2D& clip, int t, const Person& person) {
  for (int j = 0; j < kJ; ++j) {
    SCOPED_TRACE("frame " + std::to_string(t) + " keypoint " +
                 std::to_string(j));
    const Keypoint2D& read = clip.keypoints.at(t, j);
    Keypoint2D expected = person.Point(j);
    ASSERT_EQ(read.IsPresent(), j != person.missing);
    if (!read.IsPresent()) continue;
    EXPECT_DOUBLE_EQ(read.x_px, expected.x_px);
    EXPECT_DOUBLE_EQ(read.y_px, expected.y_px);
    EXPECT_DOUBLE_EQ(read.confidence, expected.confidence);
  }
}

void ExpectFrameMissing(const Clip2D& clip, int t) {
  for (int j = 0; j < kJ; ++j)
    EXPECT_FALSE(clip.keypoints.at(t, j).IsPresent());
}

// Shape (a): MMPose-style per-frame instance lists, in the variants
// MMPose/ViTPose write. Frame 0: small (id 1) + large (id 2) with boxes;
// frame 1: an object with "instances", flat 51 keypoints, no boxes;
// frame 2: "predictions" nested per batch, 17 × 3 keypoints; frame 3: empty.
json PerFrameDocument() {
  json frames = json::array();
  frames.push_back(json::array({{{"keypoints", kSmall.Pairs()},
                                 {"keypoint_scores", kSmall.Scores()},
                                 {"bbox", {{95, 95, 155, 225}}},
                                 {"track_id", 1}},
                                {{"keypoints", kLarge.Pairs()},
                                 {"keypoint_scores", kLarge.Scores()},
                                 {"bbox", {590, 190, 760, 610}},
                                 {"track_id", 2}}}));
  frames.push_back({{"frame_id", 1},
                    {"instances",
                     {{{"keypoints", kLarge.Flat()}, {"id", 2}},
                      {{"keypoints", kSmall.Flat()}, {"id", 1}}}}});
  frames.push_back(
      {{"predictions",
        json::array({json::array(
            {{{"keypoints", kSmall.Triples()}, {"track_id", 1}},
             {{"keypoints", kLarge.Triples()}, {"track_id", 2}}})})}});
  frames.push_back(json::array());
  return frames;
}

TEST(CocoReader, PerFrameInstancesTakesTheLargestPerson) {
  Clip2D clip = CocoKeypointsFromJson(PerFrameDocument(), "vitpose.json", {});
  ASSERT_EQ(clip.num_frames(), 4);
  EXPECT_EQ(clip.layout, &Coco17Layout());
  for (int t = 0; t < 3; ++t) ExpectFrameIs(clip, t, kLarge);
  ExpectFrameMissing(clip, 3);
}

TEST(CocoReader, PerFrameInstancesFollowsTheTrackId) {
  DetectionReadOptions options;
  options.track_id = 1;
  options.fps = 60.0;
  options.image_width_px = 640;
  options.image_height_px = 480;
  Clip2D clip =
      CocoKeypointsFromJson(PerFrameDocument(), "vitpose.json", options);
  ASSERT_EQ(clip.num_frames(), 4);
  for (int t = 0; t < 3; ++t) ExpectFrameIs(clip, t, kSmall);
  ExpectFrameMissing(clip, 3);
  EXPECT_EQ(clip.fps, 60.0);
  EXPECT_EQ(clip.image_width_px, 640);
  EXPECT_EQ(clip.image_height_px, 480);
}

TEST(CocoReader, MmposeDemoInstanceInfoWrapper) {
  json document = {{"meta_info", {{"dataset_name", "coco"}}},
                   {"instance_info", PerFrameDocument()}};
  Clip2D clip = CocoKeypointsFromJson(document, "demo.json", {});
  ASSERT_EQ(clip.num_frames(), 4);
  ExpectFrameIs(clip, 0, kLarge);
}

TEST(CocoReader, BoxDecidesOverKeypointExtent) {
  // The small person's box is declared huge: the box wins.
  json frames = PerFrameDocument();
  frames[0][0]["bbox"] = {0, 0, 1000, 1000};
  Clip2D clip = CocoKeypointsFromJson(frames, "vitpose.json", {});
  ExpectFrameIs(clip, 0, kSmall);
  ExpectFrameIs(clip, 1, kLarge);  // no boxes there: extent decides
}

TEST(CocoReader, ScoresAboveOneAreClamped) {
  json frames =
      json::array({json::array({{{"keypoints", kSmall.Pairs()},
                                 {"keypoint_scores", kSmall.Scores()}}})});
  frames[0][0]["keypoint_scores"][0] = 1.07;
  Clip2D clip = CocoKeypointsFromJson(frames, "vitpose.json", {});
  EXPECT_EQ(clip.keypoints.at(0, 0).confidence, 1.0);
}

// Shape (b): COCO results, image ids out of order and not contiguous.
json CocoResultsDocument() {
  json results = json::array();
  auto add = [&](long image_id, const Person& person, long track_id,
                 bool with_box) {
    json entry = {{"image_id", image_id},
                  {"category_id", 1},
                  {"keypoints", person.Flat()},
                  {"score", 0.95},
                  {"track_id", track_id}};
    if (with_box) {
      entry["bbox"] = {person.x0, person.y0, person.width, person.height};
    }
    results.push_back(entry);
  };
  add(20, kSmall, 7, true);
  add(5, kLarge, 3, true);
  add(5, kSmall, 7, true);
  add(20, kLarge, 3, false);
  add(12, kSmall, 7, false);
  return results;
}

TEST(CocoReader, ResultsListGroupsByImageIdAndTakesTheLargest) {
  Clip2D clip = CocoKeypointsFromJson(CocoResultsDocument(), "res.json", {});
  ASSERT_EQ(clip.num_frames(), 3);  // image ids 5, 12, 20
  ExpectFrameIs(clip, 0, kLarge);
  ExpectFrameIs(clip, 1, kSmall);  // the only one there
  ExpectFrameIs(clip, 2, kLarge);
}

TEST(CocoReader, ResultsListFollowsTheTrackId) {
  DetectionReadOptions options;
  options.track_id = 3;
  Clip2D clip =
      CocoKeypointsFromJson(CocoResultsDocument(), "res.json", options);
  ASSERT_EQ(clip.num_frames(), 3);
  ExpectFrameIs(clip, 0, kLarge);
  ExpectFrameMissing(clip, 1);
  ExpectFrameIs(clip, 2, kLarge);
}

TEST(CocoReader, UnknownTrackIdIsAnError) {
  DetectionReadOptions options;
  options.track_id = 9;
  std::string message = InputErrorOf([&] {
    CocoKeypointsFromJson(CocoResultsDocument(), "res.json", options);
  });
  EXPECT_NE(message.find("res.json: track id 9 is in no frame (ids present: "
                         "3, 7)"),
            std::string::npos)
      << message;
}

TEST(CocoReader, BadInstancesNameTheirPosition) {
  json frames = PerFrameDocument();
  frames[1]["instances"][1]["keypoints"].erase(0);
  std::string message =
      InputErrorOf([&] { CocoKeypointsFromJson(frames, "vitpose.json", {}); });
  EXPECT_NE(message.find("vitpose.json: [1].instances[1].keypoints: expected "
                         "17 keypoints"),
            std::string::npos)
      << message;

  frames = PerFrameDocument();
  frames[0][1].erase("keypoint_scores");
  message =
      InputErrorOf([&] { CocoKeypointsFromJson(frames, "vitpose.json", {}); });
  EXPECT_NE(message.find("'keypoint_scores' is missing"), std::string::npos)
      << message;

  message = InputErrorOf(
      [&] { CocoKeypointsFromJson(json::array(), "vitpose.json", {}); });
  EXPECT_NE(message.find("vitpose.json: no frames"), std::string::npos)
      << message;
}

TEST(DetectionReadOptions, ValidateRejectsBadSettings) {
  DetectionReadOptions options;
  EXPECT_NO_THROW(options.Validate());
  options.track_id = -2;
  EXPECT_THROW(options.Validate(), ConfigError);
  options = {};
  options.fps = 0.0;
  EXPECT_THROW(options.Validate(), ConfigError);
  options = {};
  options.image_height_px = 0;
  EXPECT_THROW(options.Validate(), ConfigError);
}

// ---------------------------------------------------------------------------
// OpenPose.

// BODY_25 person: keypoint k at (1000 + 10 k, 500 + 3 k) scaled by `size`
// around that origin, confidence 0.5 + k / 100; k = `missing` undetected.
json Body25Person(double size, long person_id, int missing = -1) {
  json values = json::array();
  for (int k = 0; k < 25; ++k) {
    bool detected = k != missing;
    values.push_back(detected ? 1000 + size * 10 * k : 0.0);
    values.push_back(detected ? 500 + size * 3 * k : 0.0);
    values.push_back(detected ? 0.5 + k / 100.0 : 0.0);
  }
  return {{"person_id", json::array({person_id})},
          {"pose_keypoints_2d", values},
          {"face_keypoints_2d", json::array()}};
}

std::string WriteOpenPoseFolder() {
  std::string dir = testing::TempDir("openpose");
  auto frame = [](json people) {
    return json{{"version", 1.3}, {"people", people}}.dump();
  };
  // Names sort as frame 0, 1, 2; a stray file must be ignored.
  WriteText(dir, "clip_000000000000_keypoints.json",
            frame({Body25Person(1.0, 0, 5), Body25Person(2.0, 1)}));
  WriteText(dir, "clip_000000000001_keypoints.json",
            frame({Body25Person(2.0, 1, 11), Body25Person(1.0, 0)}));
  WriteText(dir, "clip_000000000002_keypoints.json", frame(json::array()));
  WriteText(dir, "notes.json", "{}");
  return dir;
}

void ExpectBody25Mapped(const Clip2D& clip, int t, double size,
                        int missing_body25) {
  const std::array<int, 17>& to_body25 = Body25ToCoco17();
  for (int j = 0; j < kJ; ++j) {
    const int k = to_body25[j];
    const Keypoint2D& read = clip.keypoints.at(t, j);
    ASSERT_EQ(read.IsPresent(), k != missing_body25) << "coco " << j;
    if (!read.IsPresent()) continue;
    EXPECT_DOUBLE_EQ(read.x_px, 1000 + size * 10 * k);
    EXPECT_DOUBLE_EQ(read.y_px, 500 + size * 3 * k);
    EXPECT_DOUBLE_EQ(read.confidence, 0.5 + k / 100.0);
  }
}

TEST(OpenPoseReader, Body25MapsToCoco17ByName) {
  const std::array<int, 17>& map = Body25ToCoco17();
  const KeypointLayout& coco = Coco17Layout();
  EXPECT_EQ(map[coco.IndexOf("nose")], 0);
  EXPECT_EQ(map[coco.IndexOf("left_eye")], 16);
  EXPECT_EQ(map[coco.IndexOf("right_ear")], 17);
  EXPECT_EQ(map[coco.IndexOf("left_shoulder")], 5);
  EXPECT_EQ(map[coco.IndexOf("right_wrist")], 4);
  EXPECT_EQ(map[coco.IndexOf("left_hip")], 12);
  EXPECT_EQ(map[coco.IndexOf("right_hip")], 9);
  EXPECT_EQ(map[coco.IndexOf("right_ankle")], 11);
  EXPECT_EQ(map[coco.IndexOf("left_ankle")], 14);
}

TEST(OpenPoseReader, FolderTakesTheLargestPerson) {
  std::string dir = WriteOpenPoseFolder();
  Clip2D clip = ReadOpenPoseFolder(dir, {});
  ASSERT_EQ(clip.num_frames(), 3);
  ExpectBody25Mapped(clip, 0, 2.0, -1);
  ExpectBody25Mapped(clip, 1, 2.0, 11);  // right ankle undetected
  ExpectFrameMissing(clip, 2);
}

TEST(OpenPoseReader, FolderFollowsThePersonId) {
  std::string dir = WriteOpenPoseFolder();
  DetectionReadOptions options;
  options.track_id = 0;
  Clip2D clip = ReadOpenPoseFolder(dir, options);
  ASSERT_EQ(clip.num_frames(), 3);
  ExpectBody25Mapped(clip, 0, 1.0, 5);  // left shoulder undetected
  ExpectBody25Mapped(clip, 1, 1.0, -1);
}

TEST(OpenPoseReader, BadFoldersAreReported) {
  std::string empty = testing::TempDir("openpose_empty");
  std::string message = InputErrorOf([&] { ReadOpenPoseFolder(empty, {}); });
  EXPECT_NE(message.find(empty + ": no *_keypoints.json files"),
            std::string::npos)
      << message;

  std::string dir = testing::TempDir("openpose_bad");
  std::string path = WriteText(
      dir, "a_keypoints.json",
      R"({"people": [{"pose_keypoints_2d": [1, 2, 0.5, 3, 4, 0.5]}]})");
  message = InputErrorOf([&] { ReadOpenPoseFolder(dir, {}); });
  EXPECT_NE(message.find(path + ": people[0].pose_keypoints_2d: expected 75 "
                                "values (BODY_25)"),
            std::string::npos)
      << message;
}

// ---------------------------------------------------------------------------
// Dispatch.

TEST(ReadClipAuto, DispatchesOnWhatThePathIs) {
  std::string dir = testing::TempDir("clip_auto");
  std::string ours = dir + "/ours.json";
  WriteClip(ours, SampleClip());
  ExpectSameClip(ReadClipAuto(ours, {}), SampleClip());

  std::string coco = WriteText(dir, "coco.json", CocoResultsDocument().dump());
  Clip2D from_coco = ReadClipAuto(coco, {});
  EXPECT_EQ(from_coco.num_frames(), 3);
  ExpectFrameIs(from_coco, 0, kLarge);

  Clip2D from_openpose = ReadClipAuto(WriteOpenPoseFolder(), {});
  EXPECT_EQ(from_openpose.num_frames(), 3);
  ExpectBody25Mapped(from_openpose, 0, 2.0, -1);

  std::string single = WriteText(dir, "one_keypoints.json",
                                 json{{"people", json::array()}}.dump());
  std::string message = InputErrorOf([&] { ReadClipAuto(single, {}); });
  EXPECT_NE(message.find("pass the folder"), std::string::npos) << message;

  std::string cameras = WriteText(
      dir, "cameras.json", R"({"format": "mimic2d.cameras", "version": 1})");
  message = InputErrorOf([&] { ReadClipAuto(cameras, {}); });
  EXPECT_NE(message.find(cameras + ": format: expected \"mimic2d.clip\""),
            std::string::npos)
      << message;
}

// A 10 fps clip at 30 fps: the same span, originals on every third frame,
// straight lines between them, a keypoint missing on one side taken from
// the nearer side only.
TEST(ResampleClip, InterpolatesOverTheSameSpan) {
  Clip2D clip;
  clip.fps = 10.0;
  clip.keypoints = KeypointTrack(3, 17);
  for (int t = 0; t < 3; ++t)
    for (int j = 0; j < 17; ++j)
      clip.keypoints.at(t, j) = {10.0 * t + j, 5.0 * t, 0.9 - 0.1 * t};
  clip.keypoints.at(1, 4) = Keypoint2D{std::nan(""), std::nan(""), 0.0};
  Clip2D fast = ResampleClip(clip, 30.0);
  EXPECT_DOUBLE_EQ(fast.fps, 30.0);
  ASSERT_EQ(fast.num_frames(), 7);  // 0.2 s at 30 Hz, both ends
  EXPECT_DOUBLE_EQ(fast.keypoints.at(3, 0).x_px, 10.0);
  EXPECT_NEAR(fast.keypoints.at(1, 0).x_px, 10.0 / 3, 1e-12);
  EXPECT_NEAR(fast.keypoints.at(1, 0).y_px, 5.0 / 3, 1e-12);
  EXPECT_NEAR(fast.keypoints.at(1, 0).confidence, 0.8, 1e-12);
  // Keypoint 4 is missing at source frame 1 (fast frame 3).
  EXPECT_DOUBLE_EQ(fast.keypoints.at(1, 4).x_px, 4.0);  // nearer: frame 0
  EXPECT_FALSE(fast.keypoints.at(2, 4).IsPresent());    // nearer: missing
  EXPECT_FALSE(fast.keypoints.at(3, 4).IsPresent());
  EXPECT_DOUBLE_EQ(fast.keypoints.at(6, 16).x_px, 36.0);
  ValidateClip(fast, "resampled");
  EXPECT_THROW(ResampleClip(clip, 0.0), ConfigError);
}

// A stretch of a clip, to fit again alone: its frames and objects in
// order; a stretch past the clip's end refused.
TEST(ClipFrames, KeepsTheStretchsFramesAndObjects) {
  Clip2D clip;
  clip.keypoints = KeypointTrack(10, 17);
  for (int t = 0; t < 10; ++t)
    for (int j = 0; j < 17; ++j)
      clip.keypoints.at(t, j) = {100.0 * t + j, 1.0 * t, 1.0};
  clip.objects.push_back({"ball", {}});
  for (int t = 0; t < 10; ++t)
    clip.objects[0].points.push_back({5.0 * t, 0.0, 1.0});
  const Clip2D part = ClipFrames(clip, 3, 4);
  ASSERT_EQ(part.num_frames(), 4);
  EXPECT_DOUBLE_EQ(part.keypoints.at(0, 0).x_px, 300.0);
  EXPECT_DOUBLE_EQ(part.keypoints.at(3, 16).x_px, 616.0);
  ASSERT_EQ(part.objects[0].points.size(), 4u);
  EXPECT_DOUBLE_EQ(part.objects[0].points[3].x_px, 30.0);
  EXPECT_DOUBLE_EQ(part.fps, clip.fps);
  ValidateClip(part, "part");
  EXPECT_THROW(ClipFrames(clip, 8, 3), std::out_of_range);
  EXPECT_THROW(ClipFrames(clip, -1, 2), std::out_of_range);
}

}  // namespace
}  // namespace m2d
