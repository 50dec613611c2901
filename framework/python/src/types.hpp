#pragma once
// Python-side handles shared by the binding's translation units.

#include <memory>

#include <pybind11/pybind11.h>

#include <Eigen/Core>

#include "redres/model/robot.hpp"

namespace redres::python {

namespace py = pybind11;

/// redres.Robot: a robot model shared with whatever owns it (a scenario, a controller, or itself).
struct PyRobot {
  std::shared_ptr<const RobotModel> model;
};

/// A robot that C++ owns and that lives at least as long as the call in which Python sees it (no ownership).
inline PyRobot borrowed(const RobotModel& robot) {
  return PyRobot{std::shared_ptr<const RobotModel>(std::shared_ptr<void>(), &robot)};
}

/// A copy of an Eigen matrix or vector (what a plugin keeps stays as it was when read).
template <class Derived>
typename Derived::PlainObject copy_of(const Eigen::MatrixBase<Derived>& m) {
  return m;
}

}  // namespace redres::python
