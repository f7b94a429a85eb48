// motion: readers for 3D motion files (DeepMimic JSON, BVH).
#ifndef MIMIC2D_MOTION_MOTION_IO_H_
#define MIMIC2D_MOTION_MOTION_IO_H_

#include <memory>
#include <string>

#include "motion/motion3d.h"

namespace m2d {

// Reads a DeepMimic motion file ({"Loop": ..., "Frames": [[duration, root
// xyz, root quat wxyz, joints...]]}, Y up) for `skeleton`, whose non-root,
// non-fixed joints give the channel order (spherical: quaternion w,x,y,z;
// revolute: one angle about DeepMimic's z axis). The result is converted to
// the world convention (Z up) and resampled at `fps` (<= 0: the file's own
// rate, from its first frame's duration).
Motion3D ReadDeepMimicMotion(const std::string& path,
                             std::shared_ptr<const Skeleton> skeleton,
                             double fps = 0.0);

// Reads a BVH file via libassimp. Lengths are multiplied by `scale_m` (CMU
// captures converted by cgspeed use inches/0.45: 0.056444 m per unit); the
// file's Y-up frame is converted to Z up. The skeleton is built from the
// hierarchy (end sites become fixed joints named "<parent>_end").
Motion3D ReadBvhMotion(const std::string& path, double scale_m,
                       double fps = 0.0);

// The rotation taking Y-up motion-file coordinates to the Z-up world:
// (x, y, z) -> (x, -z, y), a +90° turn about x.
Eigen::Quaterniond YUpToZUp();

}  // namespace m2d

#endif  // MIMIC2D_MOTION_MOTION_IO_H_
