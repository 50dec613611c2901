#pragma once
// Python-side handles shared by the binding's translation units.

#include <memory>

#include <pybind11/numpy.h>
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

/// A read-only numpy view of an Eigen matrix (column-major) or vector, kept alive by `base`; no copy.
inline py::array view(const Eigen::MatrixXd& m, py::handle base) {
  py::array a(py::dtype::of<double>(), {m.rows(), m.cols()},
              {static_cast<py::ssize_t>(sizeof(double)), static_cast<py::ssize_t>(sizeof(double) * m.rows())}, m.data(),
              base);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}
inline py::array view(const Eigen::VectorXd& v, py::handle base) {
  py::array a(py::dtype::of<double>(), {v.size()}, {static_cast<py::ssize_t>(sizeof(double))}, v.data(), base);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

}  // namespace redres::python
