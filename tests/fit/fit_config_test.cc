// tests: FitOptions read from YAML (`fit --config`): keys set their fields,
// absent keys keep the defaults, and a typo, a wrong type or an invalid
// value is a named error.
#include "fit/fit_config.h"

#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/file_io.h"
#include "test_paths.h"

namespace m2d {
namespace {

std::string WriteYaml(const std::string& dir, const std::string& name,
                      const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// The message of the InputError that `read` throws ("" if none).
template <typename Read>
std::string InputErrorOf(Read read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FitConfig, KeysSetTheirFieldsAndTheRestKeepDefaults) {
  const std::string dir = testing::TempDir("fit_config");
  const std::string path =
      WriteYaml(dir, "fit.yaml",
                "camera_motion: moving\nfixed_focal_px: 1200\n"
                "pose_smooth_weight: 1.5\ncontact_rounds: 3\n");
  const FitOptions defaults;
  const FitOptions options = ReadFitOptions(path);
  EXPECT_EQ(options.camera_motion, CameraMotion::kMoving);
  EXPECT_EQ(options.fixed_focal_px, 1200.0);
  EXPECT_EQ(options.pose_smooth_weight, 1.5);
  EXPECT_EQ(options.contact_rounds, 3);
  EXPECT_EQ(options.ground_weight, defaults.ground_weight);
  EXPECT_EQ(options.num_facing_starts, defaults.num_facing_starts);
  // An empty file is the defaults.
  EXPECT_EQ(ReadFitOptions(WriteYaml(dir, "empty.yaml", "")).ground_weight,
            defaults.ground_weight);
}

TEST(FitConfig, BadFilesAreNamedErrors) {
  const std::string dir = testing::TempDir("fit_config_bad");
  const std::string typo =
      WriteYaml(dir, "typo.yaml", "pose_smoth_weight: 1\n");
  std::string message = InputErrorOf([&] { ReadFitOptions(typo); });
  EXPECT_NE(message.find(typo), std::string::npos) << message;
  EXPECT_NE(message.find("'pose_smoth_weight' is not a known setting"),
            std::string::npos)
      << message;

  const std::string type = WriteYaml(dir, "type.yaml", "contact_rounds: two\n");
  message = InputErrorOf([&] { ReadFitOptions(type); });
  EXPECT_NE(message.find("'contact_rounds' has the wrong type"),
            std::string::npos)
      << message;

  const std::string invalid =
      WriteYaml(dir, "invalid.yaml", "ground_weight: -1\n");
  message = InputErrorOf([&] { ReadFitOptions(invalid); });
  EXPECT_NE(message.find(invalid), std::string::npos) << message;
  EXPECT_NE(message.find("'ground_weight' must be in [0, inf)"),
            std::string::npos)
      << message;

  const std::string motion =
      WriteYaml(dir, "motion.yaml", "camera_motion: panning\n");
  message = InputErrorOf([&] { ReadFitOptions(motion); });
  EXPECT_NE(message.find("'camera_motion' must be one of static, moving"),
            std::string::npos)
      << message;

  const std::string list = WriteYaml(dir, "list.yaml", "- 1\n- 2\n");
  message = InputErrorOf([&] { ReadFitOptions(list); });
  EXPECT_NE(message.find("expected a map"), std::string::npos) << message;

  message = InputErrorOf([&] { ReadFitOptions(dir + "/absent.yaml"); });
  EXPECT_NE(message.find("cannot open"), std::string::npos) << message;
}

// The settings table in docs/fit.md is FitOptions::VisitFields' own.
TEST(FitConfig, DocsListEverySettingAsDeclared) {
  const std::string table = FitSettingsReference();
  EXPECT_NE(table.find("| `ground_weight` | `10` | [0, inf) |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| `camera_motion` | `static` | static, moving |"),
            std::string::npos)
      << table;
  const std::string docs =
      ReadFileText(std::string(MIMIC2D_SOURCE_DIR) + "/docs/fit.md");
  EXPECT_NE(docs.find(table), std::string::npos)
      << "docs/fit.md's settings table is stale: replace it with the output "
         "of `build/mimic2d fit --list-settings`";
}

}  // namespace
}  // namespace m2d
