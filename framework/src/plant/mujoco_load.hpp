#pragma once
// Loading MJCF text with MuJoCo (private to src/plant/, for the files compiled with MuJoCo: REDRES_HAVE_MUJOCO).

#include <mujoco/mujoco.h>

#include <string>

namespace redres::plant_detail {

/// Makes MuJoCo's errors exceptions, for the whole process, from the first call on: MuJoCo reports a failure inside a
/// call (memory it cannot allocate, an offscreen buffer, an OpenGL too old) through mju_user_error, and without a
/// handler prints it and exits the process. The handler throws std::runtime_error("MuJoCo failed: ..."); it is set
/// once and never swapped back, so threads that use MuJoCo at once (a sweep's plants) share it without a race.
/// MuJoCo's warnings are not printed: mjData counts them, and MujocoPlant::advance() reports the ones that matter.
void throw_on_mujoco_errors();

/// The model of `xml`, loaded through MuJoCo's virtual file system (no file is written); the caller owns it
/// (mj_deleteModel). std::runtime_error with MuJoCo's message when MuJoCo refuses it.
[[nodiscard]] mjModel* load_mjcf(const std::string& xml);

}  // namespace redres::plant_detail
