#pragma once
// Objectives and constraints written in Python: adapters that call a Python object from the C++ step, the per-call
// views it sees (StepContext, StepQp), registration of Python classes in the C++ registries, and the conversions
// between Python values and TOML nodes that the typed plugin configurations go through.

#include <memory>
#include <stdexcept>
#include <string>

#include <pybind11/pybind11.h>

#include "redres/control/plugin.hpp"
#include "redres/control/task.hpp"

namespace redres::python {

namespace py = pybind11;

/// A Python object that C++ may keep beyond the interpreter: released with the GIL held, or leaked once the
/// interpreter has finalised (static registries outlive it).
using SharedObject = std::shared_ptr<py::object>;
SharedObject share(py::object object);

/// A Python exception raised inside a plugin, carried through the C++ step (which runs without the GIL) to the
/// Python caller, where it is raised again with its own type and value (a KeyboardInterrupt stays one), a note
/// naming the plugin added. what() is "<who>: <Type>: <message>" for C++ callers.
class PythonError : public std::runtime_error {
 public:
  /// Takes the exception out of `e`, with the GIL held.
  PythonError(py::error_already_set& e, const std::string& who);
  /// Raises it again in Python (the GIL held): the translator registered by bind_python_plugins calls this.
  void restore() const;

 private:
  SharedObject type_, value_, trace_;
};

/// A Python value (bool, int, float, str, a sequence or a dict of these, numpy scalars and arrays, pathlib paths) as
/// the TOML value stored under `key` of `table`; TypeError naming the key for anything else.
void put_value(toml::table& table, const std::string& key, py::handle value);
/// The table of a dict's entries.
toml::table to_table(const py::dict& values, const std::string& where);
/// A TOML node as a Python value (tables as dicts, arrays as lists).
py::object to_python(const toml::node& node);

/// A reader of `config` as the root table of a file named `where` (in messages: "where: key 'k': ...").
TableReader reader_of(const toml::table& config, const std::string& where);

/// An objective or constraint from its typed configuration: the TOML table `config` (with `type`) read by the
/// registry of `kind` ("objective" or "constraint") as if it were a [[objectives]] / [[constraints]] entry of a file
/// named `where`. Unknown keys and broken rules are ConfigErrors naming `where` and the key.
std::unique_ptr<Objective> make_objective_from(const toml::table& config, const std::string& where,
                                               const RobotModel& robot);
std::unique_ptr<Constraint> make_constraint_from(const toml::table& config, const std::string& where,
                                                 const RobotModel& robot);
/// A task from its typed configuration (a [[tasks]] entry; its mode, priority and weight among its keys).
std::unique_ptr<Task> make_task_from(const toml::table& config, const std::string& where, const RobotModel& robot);
/// Checks a configuration without a robot: the type exists, every key is one of its own or a common key, and every
/// value has its type and obeys its rule (checks that need the robot, such as one value per joint, wait for it).
void check_config(const std::string& kind, const toml::table& config, const std::string& where);

/// Wraps a Python objective instance (an object with contribute(ctx, qp), and optionally kinematics, potential(ctx),
/// name, weight, active) as a C++ Objective for `robot`.
std::unique_ptr<Objective> wrap_objective(py::object instance, const RobotModel& robot);
/// Wraps a Python constraint instance (contribute(ctx, qp), equality_rows / inequality_rows as ints or methods of
/// the robot, optionally describe_inequality_row(i), violated(), describe_violation()).
std::unique_ptr<Constraint> wrap_constraint(py::object instance, const RobotModel& robot);

/// Registers a Python plugin class under `type` in the registry of `kind` ("objective" or "constraint"), with its
/// keys as a dict of defaults (their types fix how TOML values are read) and a help text per key; instances are
/// made as cls(**config). The origin is "python:<module>.<qualname>". Returns the origin.
std::string register_class(const std::string& kind, const std::string& type, py::object cls, const py::dict& keys,
                           const py::dict& help, const std::string& summary);
/// Removes the plugins that one Python class registered (its origin).
void unregister(const std::string& origin);
/// Removes every plugin registered from Python (before the interpreter finalises).
void unregister_all();

/// Binds StepContext, StepQp and the functions above into module `m`.
void bind_python_plugins(py::module_& m);

}  // namespace redres::python
