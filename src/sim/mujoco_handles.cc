#include "sim/mujoco_handles.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <mutex>

#include "common/error.h"

namespace m2d {
namespace {

[[noreturn]] void ThrowMujocoError(const char* message) {
  throw MujocoError(std::string("MuJoCo error: ") + message);
}

void LogMujocoWarning(const char* message) {
  spdlog::warn("MuJoCo: {}", message);
}

// MuJoCo 2.2.2's XML parser and compiler keep global state.
std::mutex& CompilerMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

void InstallMujocoErrorHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = ThrowMujocoError;
    mju_user_warning = LogMujocoWarning;
  });
}

MujocoModelPtr LoadMujocoModel(const std::string& mjcf_path) {
  InstallMujocoErrorHandlers();
  // MuJoCo's own message for a missing file is vague; say it plainly.
  if (!std::filesystem::exists(mjcf_path)) {
    throw InputError(mjcf_path, "MJCF model file not found");
  }
  char error[1024] = "";
  mjModel* model = nullptr;
  {
    std::lock_guard<std::mutex> lock(CompilerMutex());
    try {
      model = mj_loadXML(mjcf_path.c_str(), nullptr, error, sizeof(error));
    } catch (const MujocoError& e) {
      throw InputError(mjcf_path, e.what());
    }
  }
  if (model == nullptr) {
    // MuJoCo's message spans lines; keep the error on one.
    std::string message = error;
    for (char& c : message) {
      if (c == '\n') c = ' ';
    }
    throw InputError(mjcf_path, "MuJoCo cannot load the model: " + message);
  }
  if (error[0] != '\0') spdlog::warn("{}: MuJoCo: {}", mjcf_path, error);
  return MujocoModelPtr(model);
}

MujocoDataPtr MakeMujocoData(const mjModel* model) {
  InstallMujocoErrorHandlers();
  return MujocoDataPtr(mj_makeData(model));
}

}  // namespace m2d
