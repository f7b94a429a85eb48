// camera: camera sets as documented JSON (docs/formats.md).
#ifndef MIMIC2D_CAMERA_CAMERA_IO_H_
#define MIMIC2D_CAMERA_CAMERA_IO_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "camera/rig.h"
#include "common/json_fields.h"

namespace m2d {

inline constexpr char kCameraSetFormat[] = "mimic2d.cameras";
inline constexpr int kCameraSetVersion = 1;

nlohmann::json CameraToJson(const PinholeCamera& camera);
// Validates shapes, finiteness, positive focal lengths and that the rotation
// is orthonormal with determinant +1.
PinholeCamera CameraFromJson(const JsonCursor& cursor);

std::vector<NamedCamera> ReadCameraSet(const std::string& path);
void WriteCameraSet(const std::string& path,
                    const std::vector<NamedCamera>& cameras);

}  // namespace m2d

#endif  // MIMIC2D_CAMERA_CAMERA_IO_H_
