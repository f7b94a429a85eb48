// sim: MuJoCo physics for characters — models, simulations, PD control,
// pose mapping, keypoints and contacts.
#ifndef MIMIC2D_SIM_MUJOCO_HANDLES_H_
#define MIMIC2D_SIM_MUJOCO_HANDLES_H_

#include <mujoco/mujoco.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace m2d {

// An error raised inside the MuJoCo engine (mju_error), e.g. a stack
// overflow caused by an absurd state. MuJoCo's default handler would exit the
// process; ours throws this instead (see InstallMujocoErrorHandlers).
class MujocoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Routes MuJoCo errors to MujocoError exceptions and warnings to the log
// (instead of exit() and MUJOCO_LOG.TXT). Idempotent and thread-safe; called
// by LoadMujocoModel and MakeMujocoData.
void InstallMujocoErrorHandlers();

struct MujocoModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
struct MujocoDataDeleter {
  void operator()(mjData* data) const { mj_deleteData(data); }
};

// Move-only owners of MuJoCo's model and data.
using MujocoModelPtr = std::unique_ptr<mjModel, MujocoModelDeleter>;
using MujocoDataPtr = std::unique_ptr<mjData, MujocoDataDeleter>;

// Compiles an MJCF file. InputError naming the file with MuJoCo's message
// when it is missing or malformed.
MujocoModelPtr LoadMujocoModel(const std::string& mjcf_path);

// Fresh data for `model` (state = the model's reference configuration).
MujocoDataPtr MakeMujocoData(const mjModel* model);

}  // namespace m2d

#endif  // MIMIC2D_SIM_MUJOCO_HANDLES_H_
