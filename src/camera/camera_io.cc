#include "camera/camera_io.h"

#include <Eigen/LU>

#include "common/file_io.h"

namespace m2d {

nlohmann::json CameraToJson(const PinholeCamera& camera) {
  const Intrinsics& k = camera.intrinsics();
  const Eigen::Matrix3d& r = camera.rotation_world_to_camera();
  const Eigen::Vector3d& t = camera.translation_m();
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) rows.push_back({r(i, 0), r(i, 1), r(i, 2)});
  return {{"fx_px", k.fx_px},
          {"fy_px", k.fy_px},
          {"cx_px", k.cx_px},
          {"cy_px", k.cy_px},
          {"width_px", k.width_px},
          {"height_px", k.height_px},
          {"rotation_world_to_camera", rows},
          {"translation_m", {t.x(), t.y(), t.z()}}};
}

PinholeCamera CameraFromJson(const JsonCursor& cursor) {
  Intrinsics k;
  k.fx_px = cursor.Field("fx_px").Number();
  k.fy_px = cursor.Field("fy_px").Number();
  k.cx_px = cursor.Field("cx_px").Number();
  k.cy_px = cursor.Field("cy_px").Number();
  k.width_px = static_cast<int>(cursor.Field("width_px").Integer());
  k.height_px = static_cast<int>(cursor.Field("height_px").Integer());
  if (k.fx_px <= 0 || k.fy_px <= 0) cursor.Fail("focal lengths must be > 0");
  if (k.width_px < 1 || k.height_px < 1) {
    cursor.Fail("image size must be positive");
  }
  JsonCursor rows = cursor.Field("rotation_world_to_camera");
  rows.ArraySize(3);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    JsonCursor row = rows.At(i);
    row.ArraySize(3);
    for (int j = 0; j < 3; ++j) r(i, j) = row.At(j).Number();
  }
  if (!(r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      r.determinant() < 0) {
    rows.Fail("not a rotation matrix (must be orthonormal, determinant +1)");
  }
  JsonCursor translation = cursor.Field("translation_m");
  translation.ArraySize(3);
  Eigen::Vector3d t(translation.At(0).Number(), translation.At(1).Number(),
                    translation.At(2).Number());
  return PinholeCamera(k, r, t);
}

std::vector<NamedCamera> ReadCameraSet(const std::string& path) {
  nlohmann::json json = ReadJsonFile(path);
  JsonCursor root(json, path);
  if (root.Field("format").String() != kCameraSetFormat) {
    root.Field("format").Fail(std::string("expected \"") + kCameraSetFormat +
                              "\"");
  }
  long version = root.Field("version").Integer();
  if (version != kCameraSetVersion) {
    root.Field("version").Fail("unsupported version " +
                               std::to_string(version));
  }
  JsonCursor list = root.Field("cameras");
  size_t count = list.ArraySize();
  if (count == 0) list.Fail("no cameras");
  std::vector<NamedCamera> cameras;
  for (size_t i = 0; i < count; ++i) {
    JsonCursor entry = list.At(i);
    cameras.push_back({entry.Field("name").String(), CameraFromJson(entry)});
  }
  return cameras;
}

void WriteCameraSet(const std::string& path,
                    const std::vector<NamedCamera>& cameras) {
  nlohmann::json list = nlohmann::json::array();
  for (const NamedCamera& named : cameras) {
    nlohmann::json entry = CameraToJson(named.camera);
    entry["name"] = named.name;
    list.push_back(entry);
  }
  WriteJsonFileAtomic(path,
                      {{"format", kCameraSetFormat},
                       {"version", kCameraSetVersion},
                       {"cameras", list}},
                      2);
}

}  // namespace m2d
