#include "render/report.h"

#include <glib.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "common/error.h"
#include "common/file_io.h"
#include "media/image.h"
#include "media/video_writer.h"
#include "render_test_util.h"

namespace m2d {
namespace {

constexpr char kEval[] = R"({"rows": [
  {"clip": "walk", "view": "cam0", "succ": 1.0, "e2d_px": 4.25,
   "e3d_mm": 61.5, "jitter": 0.0123},
  {"view": "cam1", "clip": "walk <b>", "succ": false, "e2d_px": null,
   "notes": "fell", "rollouts": [{"start_frame": 0, "frames": 3}]}
]})";

struct ReportFiles {
  std::string folder, image, video, eval;
};

ReportFiles MakeFiles(const std::string& name) {
  ReportFiles files;
  files.folder = testing::TempDir(name);
  files.image = files.folder + "/curves.png";
  RgbImage image(200, 120, {255, 255, 255});
  for (int x = 20; x < 180; ++x) image.set(x, 60 + (x % 40) / 4, {148, 0, 211});
  WritePng(files.image, image);
  files.video = files.folder + "/episode.mp4";
  Mp4Writer writer(files.video, 160, 120, Mp4Options());
  for (int frame = 0; frame < 8; ++frame) {
    writer.Write(
        RgbImage(160, 120, {static_cast<uint8_t>(30 * frame), 90, 200}));
  }
  writer.Finish();
  files.eval = files.folder + "/eval.json";
  WriteFileAtomic(files.eval, kEval);
  return files;
}

size_t Count(const std::string& text, const std::string& part) {
  size_t count = 0;
  for (size_t at = text.find(part); at != std::string::npos;
       at = text.find(part, at + 1)) {
    ++count;
  }
  return count;
}

std::string Base64Decode(const std::string& text) {
  gsize length = 0;
  guchar* bytes = g_base64_decode(text.c_str(), &length);
  std::string decoded(reinterpret_cast<char*>(bytes), length);
  g_free(bytes);
  return decoded;
}

// (Nested detail such as eval's per-rollout list is not a column.)
TEST(EvalTable, KnownColumnsFirstThenTheRest) {
  const ReportFiles files = MakeFiles("eval_table");
  const EvalTable table = ReadEvalTable(files.eval);
  EXPECT_EQ(table.columns,
            (std::vector<std::string>{"clip", "view", "succ", "e2d_px",
                                      "e3d_mm", "jitter", "notes"}));
  ASSERT_EQ(table.rows.size(), 2u);
  EXPECT_EQ(table.rows[0][3], "4.25");
  EXPECT_EQ(table.rows[1][2], "no");
  EXPECT_EQ(table.rows[1][3], "\u2014");  // null
  EXPECT_EQ(table.rows[1][4], "");        // absent
  EXPECT_EQ(table.rows[1][6], "fell");
  EXPECT_EQ(EvalColumnHeading("e2d_px"), "E2D (px)");
}

TEST(EvalTable, MalformedFilesNameTheField) {
  const std::string folder = testing::TempDir("eval_bad");
  WriteFileAtomic(folder + "/a.json",
                  R"({"rows": [{"clip": "x"}, {"clip": {}}]})");
  try {
    ReadEvalTable(folder + "/a.json");
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rows[1].clip"), std::string::npos)
        << e.what();
  }
  WriteFileAtomic(folder + "/b.json", R"({"table": []})");
  EXPECT_THROW(ReadEvalTable(folder + "/b.json"), InputError);
}

TEST(Report, IsSelfContainedAndEmbedsEveryFile) {
  const ReportFiles files = MakeFiles("report_html");
  ReportContents contents;
  contents.title = "walk <run 3>";
  contents.eval = ReadEvalTable(files.eval);
  contents.image_paths = {files.image};
  contents.video_paths = {files.video};
  const std::string path = files.folder + "/report.html";
  WriteReport(path, contents);
  const std::string html = ReadFileText(path);

  EXPECT_NE(html.find("<title>walk &lt;run 3&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("<th>E2D (px)</th>"), std::string::npos);
  EXPECT_NE(html.find("walk &lt;b&gt;"), std::string::npos);
  // Nothing is fetched: no URLs, every src is a data URI.
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("file:"), std::string::npos);
  EXPECT_EQ(Count(html, "src=\""), Count(html, "src=\"data:"));
  EXPECT_EQ(Count(html, "src=\"data:image/png;base64,"), 1u);
  EXPECT_EQ(Count(html, "src=\"data:video/mp4;base64,"), 1u);
  // The embedded bytes are the files' bytes.
  int checked = 0;
  for (const auto& [type, file] :
       {std::pair<std::string, std::string>{"image/png", files.image},
        {"video/mp4", files.video}}) {
    const std::string prefix = "src=\"data:" + type + ";base64,";
    const size_t begin = html.find(prefix) + prefix.size();
    const size_t end = html.find('"', begin);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(Base64Decode(html.substr(begin, end - begin)),
              ReadFileText(file));
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

TEST(Report, MissingOrUnsupportedMediaAreInputErrors) {
  ReportContents contents;
  contents.image_paths = {"/nonexistent/curves.png"};
  EXPECT_THROW(MakeReportHtml(contents), InputError);
  const std::string folder = testing::TempDir("report_media");
  WriteFileAtomic(folder + "/notes.txt", "text");
  contents.image_paths = {folder + "/notes.txt"};
  EXPECT_THROW(MakeReportHtml(contents), InputError);
}

// The report in a real browser: headless Chromium loads it offline, every
// image and the video decode (the page's media check says so), and a
// screenshot shows the page. setup.sh installs Debian's chromium.
TEST(Report, OpensInHeadlessChromium) {
  if (!ProgramAvailable("chromium")) {
    GTEST_FAIL() << "chromium is not installed (setup.sh installs it: "
                    "apt-get install chromium)";
  }
  const ReportFiles files = MakeFiles("report_chromium");
  ReportContents contents;
  contents.eval = ReadEvalTable(files.eval);
  contents.image_paths = {files.image};
  contents.video_paths = {files.video};
  const std::string report = files.folder + "/report.html";
  WriteReport(report, contents);
  const std::vector<std::string> browser = {
      "timeout",
      "90",
      "chromium",
      "--headless",
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--no-first-run",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
      "--user-data-dir=" + files.folder + "/chromium",
      "--virtual-time-budget=5000"};

  std::vector<std::string> dump = browser;
  dump.push_back("--dump-dom");
  dump.push_back("file://" + report);
  const ProcessResult dom = RunProcess(dump);
  ASSERT_TRUE(dom.ok()) << dom.output;
  EXPECT_NE(dom.output.find("media check: 1/1 images, 1/1 videos decoded"),
            std::string::npos)
      << dom.output.substr(dom.output.rfind("media check"), 200);

  std::vector<std::string> shoot = browser;
  const std::string screenshot = files.folder + "/screenshot.png";
  shoot.push_back("--window-size=1200,1400");
  shoot.push_back("--screenshot=" + screenshot);
  shoot.push_back("file://" + report);
  const ProcessResult shot = RunProcess(shoot);
  ASSERT_TRUE(shot.ok()) << shot.output;
  const testing::PngSize size = testing::ReadPngSize(screenshot);
  EXPECT_EQ(size.width_px, 1200);
  EXPECT_EQ(size.height_px, 1400);
  // The embedded figure is on screen: its violet curve was painted.
  const RgbImage page = ReadPng(screenshot);
  int violet = 0;
  for (int y = 0; y < page.height_px(); ++y) {
    for (int x = 0; x < page.width_px(); ++x) {
      violet += testing::ColorDistance(page.at(x, y), {148, 0, 211}) < 30;
    }
  }
  EXPECT_GT(violet, 50);
}

}  // namespace
}  // namespace m2d
