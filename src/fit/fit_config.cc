#include "fit/fit_config.h"

#include "common/file_io.h"
#include "common/yaml_fields.h"

namespace m2d {

FitOptions ReadFitOptions(const std::string& path, const FitOptions& defaults) {
  const YAML::Node root = ReadYamlFile(path);
  if (root && !root.IsNull() && !root.IsMap())
    throw InputError(path, "expected a map of FitOptions fields");
  FitOptions options = defaults;
  YamlSection section(root, path, "");
  std::string camera_motion = CameraMotionName(options.camera_motion);
  section.Optional("camera_motion", &camera_motion);
  if (!ParseCameraMotion(camera_motion, &options.camera_motion))
    section.Fail("camera_motion", "must be static or moving");
  section.Optional("fixed_focal_px", &options.fixed_focal_px);
  section.Optional("min_confidence", &options.min_confidence);
  section.Optional("reprojection_sigma", &options.reprojection_sigma);
  section.Optional("pose_prior_weight", &options.pose_prior_weight);
  section.Optional("pose_smooth_weight", &options.pose_smooth_weight);
  section.Optional("root_smooth_weight", &options.root_smooth_weight);
  section.Optional("turn_smooth_weight", &options.turn_smooth_weight);
  section.Optional("ground_weight", &options.ground_weight);
  section.Optional("penetration_weight", &options.penetration_weight);
  section.Optional("foot_slide_weight", &options.foot_slide_weight);
  section.Optional("camera_smooth_weight", &options.camera_smooth_weight);
  section.Optional("camera_speed_weight", &options.camera_speed_weight);
  section.Optional("focal_prior_weight", &options.focal_prior_weight);
  section.Optional("upright_weight", &options.upright_weight);
  section.Optional("camera_height_prior_m", &options.camera_height_prior_m);
  section.Optional("camera_height_prior_weight",
                   &options.camera_height_prior_weight);
  section.Optional("moving_camera_height_prior_weight",
                   &options.moving_camera_height_prior_weight);
  section.Optional("contact_height_m", &options.contact_height_m);
  section.Optional("contact_speed_mps", &options.contact_speed_mps);
  section.Optional("contact_rounds", &options.contact_rounds);
  section.Optional("num_facing_starts", &options.num_facing_starts);
  section.Optional("root_stage_iterations", &options.root_stage_iterations);
  section.Optional("screening_iterations", &options.screening_iterations);
  section.Optional("pose_stage_iterations", &options.pose_stage_iterations);
  section.Optional("num_threads", &options.num_threads);
  section.Optional("function_tolerance", &options.function_tolerance);
  section.Optional("unconverged_residual_scale",
                   &options.unconverged_residual_scale);
  section.Optional("min_frames", &options.min_frames);
  section.Optional("min_keypoints_per_frame", &options.min_keypoints_per_frame);
  section.Optional("min_person_scale_px", &options.min_person_scale_px);
  section.Optional("min_usable_fraction", &options.min_usable_fraction);
  section.RejectUnknownKeys();
  try {
    options.Validate();
  } catch (const ConfigError& e) {
    throw InputError(path, e.what());
  }
  return options;
}

}  // namespace m2d
