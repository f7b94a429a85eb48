#include "render/training_plot.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "common/error.h"
#include "common/file_io.h"
#include "media/image.h"
#include "render_test_util.h"

namespace m2d {
namespace {

constexpr char kHeader[] =
    "iteration,samples,wall_time_s,samples_per_s,mean_return,"
    "mean_episode_length,succ,e2d_px,policy_loss,value_loss,entropy,"
    "learning_rate\n";

// A plausible run: return and Succ rise, E2D falls; Succ is evaluated
// every 5th iteration only (empty cells in between).
std::string SampleLog(int iterations, double speed) {
  std::ostringstream csv;
  csv << kHeader;
  for (int i = 0; i < iterations; ++i) {
    const double samples = 4096.0 * (i + 1);
    const double progress = i / static_cast<double>(iterations);
    csv << i << "," << samples << "," << samples / speed << "," << speed << ","
        << 20 + 180 * progress << "," << 30 + 200 * progress << ",";
    if (i % 5 == 4) csv << progress;
    csv << "," << 80 * (1 - progress) + 5 << ",0.01,0.5,1.2,3e-4\n";
  }
  return csv.str();
}

int CountColor(const RgbImage& image, Rgb color) {
  int count = 0;
  for (int y = 0; y < image.height_px(); ++y) {
    for (int x = 0; x < image.width_px(); ++x) count += image.at(x, y) == color;
  }
  return count;
}

TEST(TrainingPlot, ReadsTheTrainerSchemaWithMissingValues) {
  const std::string path = testing::TempDir("plot_read") + "/train.csv";
  WriteFileAtomic(path, SampleLog(20, 1500.0));
  const TrainingCurves log = ReadTrainingLog(path);
  EXPECT_EQ(log.name, "train");
  EXPECT_EQ(log.num_rows(), 20);
  EXPECT_EQ(log.columns.size(), 12u);
  EXPECT_DOUBLE_EQ(log.columns.at("samples")[2], 3 * 4096.0);
  EXPECT_TRUE(std::isnan(log.columns.at("succ")[0]));
  EXPECT_DOUBLE_EQ(log.columns.at("succ")[4], 0.2);
}

TEST(TrainingPlot, DrawsBothFiguresAsPngs) {
  const std::string folder = testing::TempDir("plot_draw");
  WriteFileAtomic(folder + "/a/train.csv", SampleLog(40, 1500.0));
  WriteFileAtomic(folder + "/b/train.csv", SampleLog(25, 900.0));
  const std::vector<TrainingCurves> logs = {
      ReadTrainingLog(folder + "/a/train.csv"),
      ReadTrainingLog(folder + "/b/train.csv")};
  PlotOptions options;
  options.width_px = 1000;
  options.height_px = 700;
  const PlotFiles files = PlotTrainingCurves(logs, folder + "/plots", options);
  for (const std::string& png :
       {files.vs_samples_png, files.vs_wall_time_png}) {
    ASSERT_TRUE(std::filesystem::exists(png)) << png;
    EXPECT_GT(std::filesystem::file_size(png), 10000u);
    const testing::PngSize size = testing::ReadPngSize(png);
    EXPECT_EQ(size.width_px, 1000);
    EXPECT_EQ(size.height_px, 700);
    // gnuplot's first two line colours (dark violet, teal) draw the runs.
    const RgbImage image = ReadPng(png);
    EXPECT_GT(CountColor(image, {148, 0, 211}), 500) << png;
    EXPECT_GT(CountColor(image, {0, 158, 115}), 500) << png;
  }
}

TEST(TrainingPlot, MetricNeverLoggedGetsAnEmptyPanel) {
  const std::string folder = testing::TempDir("plot_empty");
  std::string csv = std::string(kHeader) +
                    "0,4096,2.0,2048,10,30,,,0,0,0,0\n"
                    "1,8192,4.0,2048,12,31,,,0,0,0,0\n";
  WriteFileAtomic(folder + "/train.csv", csv);
  const PlotFiles files = PlotTrainingCurves(
      {ReadTrainingLog(folder + "/train.csv")}, folder, PlotOptions());
  EXPECT_EQ(testing::ReadPngSize(files.vs_samples_png).width_px, 1400);
}

TEST(TrainingPlot, MalformedLogsNameTheLineAndColumn) {
  const std::string folder = testing::TempDir("plot_bad");
  auto error_for = [&](const std::string& text) -> std::string {
    WriteFileAtomic(folder + "/bad.csv", text);
    try {
      ReadTrainingLog(folder + "/bad.csv");
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(error_for("iteration,samples,wall_time_s\n1,2,3\n")
                .find("missing column 'samples_per_s'"),
            std::string::npos);
  EXPECT_NE(error_for(std::string(kHeader) + "0,1,2,3,4,5,6,7,8,9,10,11\n"
                                             "1,2,3,4,x5,6,7,8,9,10,11,12\n")
                .find("line 3, column 'mean_return': 'x5' is not a number"),
            std::string::npos);
  EXPECT_NE(error_for(std::string(kHeader) + "0,1,2\n").find("line 2"),
            std::string::npos);
  EXPECT_NE(error_for(kHeader).find("no data rows"), std::string::npos);
  EXPECT_THROW(ReadTrainingLog(folder + "/absent.csv"), InputError);
}

}  // namespace
}  // namespace m2d
