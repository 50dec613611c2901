#pragma once
/// @file
/// The robot file (TOML) parser: fills a RobotSpec from a robot file or table, joining in a URDF chain where the
/// file names one (`urdf = "..."`), and builds the RobotModel. Keys: docs/robot_format.md.

#include <filesystem>
#include <string>

#include "redres/config/config.hpp"
#include "redres/model/robot.hpp"

namespace redres {

/// Loads a bare URDF file as a robot: the chain from `base_link` to `tip_link`, by default from the root link to the
/// link below it with the most revolute joints (default_urdf_chain: a gripper's fingers are left out), its meshes
/// fitted with capsules, everything else as a robot file with only `urdf`, `base_link` and `tip_link` would give
/// (docs/robot_format.md).
[[nodiscard]] RobotModel load_urdf_robot(const std::filesystem::path& urdf, const std::string& base_link = "",
                                         const std::string& tip_link = "");

/// Loads a robot TOML file. Every problem is a ConfigError starting "file:line:col:".
[[nodiscard]] RobotModel load_robot(const std::filesystem::path& file);

/// Loads a robot from a table (the root of a robot file, or a table embedded in another file).
[[nodiscard]] RobotModel load_robot(const TableReader& table);

/// Reads the key `task` of a robot or scenario table into spec.task and spec.task_axes: "position", "pose", or an
/// array naming a subset of the pose's rows in order (e.g. ["x", "y", "z", "wz"]). spec.kind must be set.
void read_task(const TableReader& table, RobotSpec& spec);

/// Every table of a robot file with its keys (from the schemas the reader reads them with), for `redres keys` and
/// docs/robot_format.md.
[[nodiscard]] const std::vector<KeyTable>& robot_key_tables();

}  // namespace redres
