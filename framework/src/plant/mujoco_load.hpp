#pragma once
// Loading MJCF text with MuJoCo (private to src/plant/, for the files compiled with MuJoCo: REDRES_HAVE_MUJOCO).

#include <mujoco/mujoco.h>

#include <string>

namespace redres::plant_detail {

/// The model of `xml`, loaded through MuJoCo's virtual file system (no file is written); the caller owns it
/// (mj_deleteModel). std::runtime_error with MuJoCo's message when MuJoCo refuses it.
[[nodiscard]] mjModel* load_mjcf(const std::string& xml);

}  // namespace redres::plant_detail
