#include "python_plugins.hpp"

#include <any>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "frame_access.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"
#include "redres/extend/conformance.hpp"
#include "redres/qp/lvi.hpp"
#include "types.hpp"

namespace redres::python {

SharedObject share(py::object object) {
  return SharedObject(new py::object(std::move(object)), [](py::object* p) {
    if (Py_IsInitialized() != 0) {
      py::gil_scoped_acquire gil;
      delete p;
    } else {
      (void)p->release();  // the interpreter is gone: nothing to release into
      delete p;
    }
  });
}

PythonError::PythonError(py::error_already_set& e, const std::string& who)
    : std::runtime_error(who + ": " + e.what()),
      type_(share(e.type())),
      value_(share(e.value())),
      trace_(share(e.trace())) {
  // Python 3.11 notes: the traceback then says which plugin raised.
  if (*value_ && py::hasattr(*value_, "add_note")) {
    try {
      value_->attr("add_note")("raised in " + who);
    } catch (py::error_already_set&) {
      // an exception whose add_note is not the standard one: it keeps what it has
    }
  }
}

void PythonError::restore() const {
  PyErr_Restore(py::object(*type_).release().ptr(), py::object(*value_).release().ptr(),
                py::object(*trace_).release().ptr());
}

namespace {

// Calls sink(value) with the TOML value of a Python value.
template <class Sink>
void convert(py::handle v, const std::string& key, Sink&& sink);

toml::array to_array(py::handle seq, const std::string& key) {
  toml::array out;
  for (py::handle item : seq) convert(item, key, [&out](auto&& x) { out.push_back(std::forward<decltype(x)>(x)); });
  return out;
}

template <class Sink>
void convert(py::handle v, const std::string& key, Sink&& sink) {
  if (py::isinstance<py::bool_>(v)) {
    sink(v.cast<bool>());
  } else if (py::isinstance<py::int_>(v)) {
    sink(v.cast<std::int64_t>());
  } else if (py::isinstance<py::float_>(v)) {
    sink(v.cast<double>());
  } else if (py::isinstance<py::str>(v)) {
    sink(v.cast<std::string>());
  } else if (py::isinstance<py::dict>(v)) {
    sink(to_table(py::reinterpret_borrow<py::dict>(v), key));
  } else if (py::hasattr(v, "__fspath__")) {
    sink(py::str(py::module_::import("os").attr("fspath")(v)).cast<std::string>());
  } else if (py::hasattr(v, "tolist") && py::hasattr(v, "dtype")) {
    convert(v.attr("tolist")(), key, std::forward<Sink>(sink));  // numpy scalars and arrays
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    sink(to_array(v, key));
  } else {
    throw py::type_error("key '" + key + "': cannot use a value of type '" +
                         py::str(v.get_type().attr("__name__")).cast<std::string>() +
                         "' (expected a number, bool, string, path, list or dict)");
  }
}

std::string type_text(const toml::node& node) {
  if (node.is_floating_point()) return "number";
  if (node.is_integer()) return "integer";
  if (node.is_boolean()) return "boolean";
  if (node.is_string()) return "string";
  const toml::array* a = node.as_array();
  if (a != nullptr && !a->empty() && (*a)[0].is_string()) return "array of strings";
  return "array of numbers";
}

// Reads `key` from `r` with the type of its default.
void read_like(const TableReader& r, const std::string& key, const toml::node& def, toml::table& out) {
  if (def.is_floating_point()) {
    out.insert_or_assign(key, r.number(key));
  } else if (def.is_integer()) {
    out.insert_or_assign(key, r.integer(key));
  } else if (def.is_boolean()) {
    out.insert_or_assign(key, r.boolean(key, false));
  } else if (def.is_string()) {
    out.insert_or_assign(key, r.string(key));
  } else if (type_text(def) == "array of strings") {
    toml::array a;
    for (const auto& s : r.strings(key)) a.push_back(s);
    out.insert_or_assign(key, std::move(a));
  } else {
    toml::array a;
    for (double x : r.numbers(key)) a.push_back(x);
    out.insert_or_assign(key, std::move(a));
  }
}

KinematicsLevel level_of(py::handle instance) {
  const std::string level =
      py::hasattr(instance, "kinematics") ? instance.attr("kinematics").cast<std::string>() : "all";
  if (level == "position") return KinematicsLevel::kPosition;
  if (level == "jacobian") return KinematicsLevel::kJacobian;
  if (level == "measure") return KinematicsLevel::kMeasure;
  if (level == "gradient") return KinematicsLevel::kGradient;
  if (level == "manipulability") return KinematicsLevel::kManipulability;
  if (level == "all") return KinematicsLevel::kAll;
  throw std::invalid_argument("kinematics = '" + level +
                              "': expected 'position', 'jacobian', 'measure', 'gradient', 'manipulability' or 'all'");
}

std::string type_of(py::handle instance) {
  if (py::hasattr(instance, "type") && py::isinstance<py::str>(instance.attr("type"))) {
    return instance.attr("type").cast<std::string>();
  }
  return py::str(instance.get_type().attr("__name__")).cast<std::string>();
}

// The keys of a registered class (its defaults, as its `keys`), or of an instance made in Python: their current
// values, for config().
toml::table own_keys(py::handle instance) {
  toml::table out;
  if (!py::hasattr(instance, "keys") || !py::isinstance<py::dict>(instance.attr("keys"))) return out;
  for (auto item : py::reinterpret_borrow<py::dict>(instance.attr("keys"))) {
    const std::string key = py::str(item.first).cast<std::string>();
    put_value(out, key, py::hasattr(instance, key.c_str()) ? instance.attr(key.c_str()) : item.second);
  }
  return out;
}

}  // namespace

void put_value(toml::table& table, const std::string& key, py::handle value) {
  convert(value, key, [&](auto&& x) { table.insert_or_assign(key, std::forward<decltype(x)>(x)); });
}

toml::table to_table(const py::dict& values, const std::string& where) {
  toml::table t;
  for (auto item : values) {
    if (!py::isinstance<py::str>(item.first)) throw py::type_error(where + ": keys are strings");
    put_value(t, item.first.cast<std::string>(), item.second);
  }
  return t;
}

py::object to_python(const toml::node& node) {
  if (const auto* v = node.as_floating_point()) return py::float_(v->get());
  if (const auto* v = node.as_integer()) return py::int_(v->get());
  if (const auto* v = node.as_boolean()) return py::bool_(v->get());
  if (const auto* v = node.as_string()) return py::str(v->get());
  if (const auto* a = node.as_array()) {
    py::list out;
    for (const auto& e : *a) out.append(to_python(e));
    return out;
  }
  if (const auto* t = node.as_table()) {
    py::dict out;
    for (const auto& [k, v] : *t) out[py::str(std::string(k.str()))] = to_python(v);
    return out;
  }
  return py::none();
}

namespace {

// --- what a Python plugin sees during contribute() ---------------------------------------------------------------

// The step's Context, valid only during the call (afterwards every accessor raises).
struct StepContext {
  const Context* ctx = nullptr;
  [[nodiscard]] const Context& get() const {
    if (ctx == nullptr) throw std::runtime_error("the step context is used outside contribute()");
    return *ctx;
  }
};

// The plugin's share of the step's QP, valid only during the call.
struct StepQp {
  QpBuilder* builder = nullptr;
  int n = 0, eq_rows = 0, in_rows = 0;
  std::string who;
  [[nodiscard]] QpBuilder& get() const {
    if (builder == nullptr) throw std::runtime_error(who + ": the QP is used outside contribute()");
    return *builder;
  }
  void need(Eigen::Index rows, Eigen::Index cols, Eigen::Index want_rows, Eigen::Index want_cols,
            const char* what) const {
    if (rows != want_rows || cols != want_cols) {
      throw std::invalid_argument(who + ": " + what + " is " + std::to_string(rows) + " x " + std::to_string(cols) +
                                  ", expected " + std::to_string(want_rows) + " x " + std::to_string(want_cols));
    }
  }
};

// Calls instance.contribute(ctx, qp), turning a Python exception into a C++ one that carries its text (nothing
// that needs the GIL crosses back into the C++ step).
void call_contribute(const py::object& instance, const Context& ctx, QpBuilder& builder, int n, int eq, int in,
                     const std::string& who) {
  py::gil_scoped_acquire gil;
  try {
    py::object c = py::cast(StepContext{&ctx});
    py::object q = py::cast(StepQp{&builder, n, eq, in, who});
    instance.attr("contribute")(c, q);
    c.cast<StepContext&>().ctx = nullptr;
    q.cast<StepQp&>().builder = nullptr;
  } catch (py::error_already_set& e) {
    throw PythonError(e, who);
  }
}

class PythonObjective final : public Objective {
 public:
  PythonObjective(const std::string& type, py::object instance, toml::table own)
      : Objective(type), own_(std::move(own)), level_(level_of(instance)) {
    has_potential_ = py::hasattr(instance, "potential");
    instance_ = share(std::move(instance));
  }
  [[nodiscard]] KinematicsLevel kinematics_level() const override { return level_; }
  [[nodiscard]] std::optional<double> potential(const Context& ctx) const override {
    if (!has_potential_) return std::nullopt;
    py::gil_scoped_acquire gil;
    try {
      py::object c = py::cast(StepContext{&ctx});
      py::object v = instance_->attr("potential")(c);
      c.cast<StepContext&>().ctx = nullptr;
      if (v.is_none()) return std::nullopt;
      return v.cast<double>();
    } catch (py::error_already_set& e) {
      throw PythonError(e, "python objective '" + name() + "': potential");
    }
  }

 private:
  // A Python plugin keeps its own state in its instance (the GIL serialises its calls); it makes no PluginData.
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* /*data*/) const override {
    call_contribute(*instance_, ctx, builder, ctx.robot->dof(), 0, 0, "python objective '" + name() + "'");
  }
  void write_config(toml::table& out) const override {
    for (const auto& [k, v] : own_) out.insert_or_assign(k, v);
  }
  SharedObject instance_;
  toml::table own_;
  KinematicsLevel level_;
  bool has_potential_ = false;
};

int rows_of(py::handle instance, const char* attr, const RobotModel& robot) {
  if (!py::hasattr(instance, attr)) return 0;
  py::object v = instance.attr(attr);
  if (PyCallable_Check(v.ptr()) != 0) v = v(borrowed(robot));
  const int rows = v.cast<int>();
  if (rows < 0) throw std::invalid_argument(std::string(attr) + " is " + std::to_string(rows) + ", expected >= 0");
  return rows;
}

class PythonConstraint final : public Constraint {
 public:
  PythonConstraint(const std::string& type, py::object instance, toml::table own, const RobotModel& robot)
      : Constraint(type),
        own_(std::move(own)),
        level_(level_of(instance)),
        eq_(rows_of(instance, "equality_rows", robot)),
        in_(rows_of(instance, "inequality_rows", robot)) {
    describes_ = py::hasattr(instance, "describe_inequality_row");
    checks_ = py::hasattr(instance, "violated");
    instance_ = share(std::move(instance));
  }
  [[nodiscard]] KinematicsLevel kinematics_level() const override { return level_; }
  [[nodiscard]] int equality_rows(const RobotModel&) const override { return eq_; }
  [[nodiscard]] int inequality_rows(const RobotModel&) const override { return in_; }
  [[nodiscard]] std::string describe_inequality_row(const PluginData* /*data*/, int row) const override {
    if (!describes_) return {};
    py::gil_scoped_acquire gil;
    try {
      return py::str(instance_->attr("describe_inequality_row")(row)).cast<std::string>();
    } catch (py::error_already_set& e) {
      return std::string("(describe_inequality_row raised: ") + e.what() + ")";
    }
  }
  [[nodiscard]] bool violated(const PluginData* /*data*/) const override {
    if (!checks_) return false;
    py::gil_scoped_acquire gil;
    try {
      return instance_->attr("violated")().cast<bool>();
    } catch (py::error_already_set& e) {
      throw PythonError(e, "python constraint '" + name() + "': violated");
    }
  }
  [[nodiscard]] std::string describe_violation(const PluginData* /*data*/) const override {
    py::gil_scoped_acquire gil;
    if (!py::hasattr(*instance_, "describe_violation")) return "violated";
    return py::str(instance_->attr("describe_violation")()).cast<std::string>();
  }

 private:
  void add_to(const Context& ctx, QpBuilder& builder, PluginData* /*data*/) const override {
    call_contribute(*instance_, ctx, builder, ctx.robot->dof(), eq_, in_, "python constraint '" + name() + "'");
  }
  void write_config(toml::table& out) const override {
    for (const auto& [k, v] : own_) out.insert_or_assign(k, v);
  }
  SharedObject instance_;
  toml::table own_;
  KinematicsLevel level_;
  int eq_ = 0, in_ = 0;
  bool describes_ = false, checks_ = false;
};

// Common keys of an instance made in Python (name, weight, active), as the registry path applies them from TOML.
template <class P>
void apply_common(py::handle instance, P& plugin) {
  if (py::hasattr(instance, "name") && !instance.attr("name").is_none()) {
    plugin.set_name(instance.attr("name").cast<std::string>());
  }
  if (py::hasattr(instance, "active")) plugin.set_active(instance.attr("active").cast<bool>());
  if constexpr (std::is_same_v<P, Objective>) {
    if (py::hasattr(instance, "weight")) plugin.set_weight(instance.attr("weight").cast<double>());
    if (py::hasattr(instance, "priority")) plugin.set_priority(instance.attr("priority").cast<int>());
  }
}

// --- registration -----------------------------------------------------------------------------------------------

struct PythonConfig {
  toml::table values;
};

std::set<std::string>& python_origins() {
  static std::set<std::string> origins;
  return origins;
}

template <class Base, class Reg, class Wrap>
void register_in(Reg& registry, const std::string& type, const SharedObject& cls, const toml::table& defaults,
                 std::vector<KeyInfo> keys, const std::string& summary, const std::string& origin, Wrap wrap) {
  typename Reg::Entry e;
  e.type = type;
  e.summary = summary;
  e.keys = std::move(keys);
  e.config_type = &typeid(PythonConfig);
  e.defaults = PythonConfig{defaults};
  e.read = [defaults](const TableReader& r) -> std::any {
    PythonConfig c{defaults};
    for (const auto& [k, v] : defaults) {
      const std::string key(k.str());
      if (r.has(key)) read_like(r, key, v, c.values);
    }
    return c;
  };
  e.write = [](const std::any& c, toml::table& out) {
    for (const auto& [k, v] : std::any_cast<const PythonConfig&>(c).values) out.insert_or_assign(k, v);
  };
  e.make = [cls, type, wrap](const std::any& c, const RobotModel& robot) -> std::unique_ptr<Base> {
    const PythonConfig& config = std::any_cast<const PythonConfig&>(c);
    py::gil_scoped_acquire gil;
    py::dict kwargs;
    for (const auto& [k, v] : config.values) kwargs[py::str(std::string(k.str()))] = to_python(v);
    py::object instance;
    try {
      instance = (*cls)(**kwargs);
    } catch (py::error_already_set& err) {
      throw std::invalid_argument(type + ": " + err.what());
    }
    return wrap(type, std::move(instance), config.values, robot);
  };
  registry.add_entry(std::move(e), origin);
}

}  // namespace

TableReader reader_of(const toml::table& config, const std::string& where) {
  auto file = std::make_shared<TomlFile>();
  file->path = where;
  file->root = config;
  return TableReader::root(std::move(file));
}

std::unique_ptr<Objective> make_objective_from(const toml::table& config, const std::string& where,
                                               const RobotModel& robot) {
  return make_objective(reader_of(config, where), robot);
}

std::unique_ptr<Constraint> make_constraint_from(const toml::table& config, const std::string& where,
                                                 const RobotModel& robot) {
  return make_constraint(reader_of(config, where), robot);
}

std::unique_ptr<Task> make_task_from(const toml::table& config, const std::string& where, const RobotModel& robot) {
  return make_task(reader_of(config, where), robot);
}

void check_config(const std::string& kind, const toml::table& config, const std::string& where) {
  const TableReader r = reader_of(config, where);
  if (kind == "engine") {
    (void)make_engine(r);  // an engine needs no robot: build it
    return;
  }
  std::set<std::string> allowed = {"type"};
  const auto allow = [&allowed](const std::vector<KeyInfo>& keys) {
    for (const auto& k : keys) allowed.insert(k.name);
  };
  const auto check = [&](const auto& registry, const std::vector<KeyInfo>& common) {
    const std::string type = r.string("type");
    const auto* e = registry.find(type);
    if (e == nullptr) r.fail("type", "unknown " + kind + " type '" + type + "'; known types: " + registry.names());
    allow(e->keys);
    allow(common);
    for (const auto& [k, v] : config) {
      const std::string key(k.str());
      if (allowed.count(key) == 0) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        r.fail(key, "unknown key for " + kind + " '" + type + "'; its keys are " + list);
      }
    }
    (void)e->read(r);
  };
  if (kind == "objective") {
    check(objective_registry(), objective_common_keys());
  } else if (kind == "constraint") {
    if (config.contains("weight")) r.fail("weight", "constraints are hard and have no weight");
    check(constraint_registry(), constraint_common_keys());
  } else if (kind == "task") {
    check(task_registry(), task_common_keys());
  } else if (kind == "path") {
    check(path_registry(), describe_keys(PathPlacement::schema()));
  } else {
    throw std::invalid_argument("check_config: unknown plugin kind '" + kind + "'");
  }
}

std::unique_ptr<Objective> wrap_objective(py::object instance, const RobotModel& robot) {
  (void)robot;
  const std::string type = type_of(instance);
  toml::table own = own_keys(instance);
  auto p = std::make_unique<PythonObjective>(type, instance, std::move(own));
  apply_common(instance, static_cast<Objective&>(*p));
  return p;
}

std::unique_ptr<Constraint> wrap_constraint(py::object instance, const RobotModel& robot) {
  const std::string type = type_of(instance);
  toml::table own = own_keys(instance);
  auto p = std::make_unique<PythonConstraint>(type, instance, std::move(own), robot);
  apply_common(instance, static_cast<Constraint&>(*p));
  return p;
}

std::string register_class(const std::string& kind, const std::string& type, py::object cls, const py::dict& keys,
                           const py::dict& help, const std::string& summary) {
  const std::string origin = "python:" + py::str(cls.attr("__module__")).cast<std::string>() + "." +
                             py::str(cls.attr("__qualname__")).cast<std::string>();
  const toml::table defaults = to_table(keys, type);
  std::vector<KeyInfo> infos;
  for (const auto& [k, v] : defaults) {
    if (v.is_table())
      throw std::invalid_argument(type + ": key '" + std::string(k.str()) + "': tables are not supported");
    KeyInfo info;
    info.name = std::string(k.str());
    info.default_text = toml_value_text(v);
    info.type = type_text(v);
    if (help.contains(info.name.c_str())) info.help = py::str(help[info.name.c_str()]).cast<std::string>();
    infos.push_back(std::move(info));
  }
  const SharedObject shared = share(std::move(cls));
  if (kind == "objective") {
    register_in<Objective>(
        objective_registry(), type, shared, defaults, std::move(infos), summary, origin,
        [](const std::string& t, py::object inst, const toml::table& own, const RobotModel&) {
          return std::unique_ptr<Objective>(std::make_unique<PythonObjective>(t, std::move(inst), own));
        });
  } else if (kind == "constraint") {
    register_in<Constraint>(
        constraint_registry(), type, shared, defaults, std::move(infos), summary, origin,
        [](const std::string& t, py::object inst, const toml::table& own, const RobotModel& r) {
          return std::unique_ptr<Constraint>(std::make_unique<PythonConstraint>(t, std::move(inst), own, r));
        });
  } else {
    throw std::invalid_argument("register: kind '" + kind + "': expected 'objective' or 'constraint'");
  }
  python_origins().insert(origin);
  return origin;
}

void unregister(const std::string& origin) {
  objective_registry().remove_origin(origin);
  constraint_registry().remove_origin(origin);
  python_origins().erase(origin);
}

void unregister_all() {
  for (const auto& origin : python_origins()) {
    objective_registry().remove_origin(origin);
    constraint_registry().remove_origin(origin);
  }
  python_origins().clear();
}

void bind_python_plugins(py::module_& m) {
  // A plugin's Python exception is raised again as itself at the Python call that ran the step.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const PythonError& e) {
      e.restore();
    }
  });
  py::class_<StepContext>(
      m, "StepContext",
      "What a Python plugin may read at one control step (valid during contribute() only).\n\n"
      "Arrays are copies of the step's values, taken when read: they stay as they were when kept past the call.")
      .def_property_readonly(
          "t", [](const StepContext& c) { return c.get().t; }, "time since the start (s)")
      .def_property_readonly(
          "T", [](const StepContext& c) { return c.get().T; }, "task duration (s)")
      .def_property_readonly(
          "tau", [](const StepContext& c) { return c.get().tau; }, "control step (s)")
      .def_property_readonly(
          "robot", [](const StepContext& c) { return borrowed(*c.get().robot); }, "the robot")
      .def_property_readonly(
          "theta", [](const StepContext& c) { return copy_of(c.get().theta()); }, "joint positions (n,)")
      .def_property_readonly(
          "f", [](const StepContext& c) { return copy_of(c.get().kinematics->f); },
          "task coordinates f(theta) (every reference row)")
      .def_property_readonly(
          "J", [](const StepContext& c) { return copy_of(c.get().kinematics->J); }, "task Jacobian (m, n)")
      .def_property_readonly(
          "w", [](const StepContext& c) { return c.get().kinematics->w; }, "w = det(J J')")
      .def_property_readonly(
          "grad_w", [](const StepContext& c) { return copy_of(c.get().kinematics->grad_w); }, "d w / d theta (n,)")
      .def_property_readonly(
          "mu", [](const StepContext& c) { return c.get().kinematics->mu; }, "Yoshikawa's sqrt(det(J J'))")
      .def_property_readonly(
          "grad_mu", [](const StepContext& c) { return copy_of(c.get().kinematics->grad_mu); }, "d mu / d theta (n,)")
      .def_property_readonly(
          "r_d", [](const StepContext& c) { return copy_of(*c.get().r_d); }, "desired task coordinates r_d(t)")
      .def_property_readonly(
          "r_d_dot", [](const StepContext& c) { return copy_of(*c.get().r_d_dot); }, "desired task velocity")
      .def_property_readonly(
          "ee_pose", [](const StepContext& c) { return Eigen::Matrix4d(c.get().kinematics->ee_pose.matrix()); },
          "end-effector pose in the world (4, 4), a copy")
      .def_property_readonly(
          "frame_names", [](const StepContext& c) { return frame_names(*c.get().robot); },
          "the robot's named frames (each joint's link, a URDF's other links, 'end_effector'), in order")
      .def(
          "frame_pose",
          [](const StepContext& c, const std::string& name) {
            return frame_pose_of(*c.get().robot, *c.get().kinematics, name, "StepContext.frame_pose");
          },
          py::arg("name"), "world pose (4, 4) of the named frame at theta, a copy; an unknown name raises ValueError")
      .def(
          "frame_jacobian",
          [](const StepContext& c, const std::string& name, const std::optional<Eigen::VectorXd>& point) {
            return frame_jacobian_of(*c.get().robot, *c.get().kinematics, name, point, "StepContext.frame_jacobian");
          },
          py::arg("name"), py::arg("point") = py::none(),
          "Jacobian (6, n) [v; omega] of the named frame, its origin moved by `point` (3,) in the frame's own axes "
          "(default: the origin)")
      .def_property_readonly(
          "link_frames", [](const StepContext& c) { return link_frames_of(*c.get().kinematics); },
          "each joint's link frame after its motion, in the world (list of (4, 4)), copies");

  py::class_<StepQp>(m, "StepQp",
                     "A plugin's share of the step's QP  min x'Wx/2 + zeta'x  s.t.  J x = d,  A x <= b,  lo <= x <= hi "
                     "(valid during contribute() only). Objective terms are scaled by the plugin's weight.")
      .def_property_readonly(
          "n", [](const StepQp& q) { return q.n; }, "number of joints")
      .def_property_readonly(
          "weight", [](const StepQp& q) { return q.get().weight(); }, "the objective's weight")
      .def_property_readonly(
          "equality_rows", [](const StepQp& q) { return q.eq_rows; }, "this constraint's equality rows (J x = d)")
      .def_property_readonly(
          "inequality_rows", [](const StepQp& q) { return q.in_rows; }, "this constraint's inequality rows (A x <= b)")
      .def(
          "add_identity", [](StepQp& q, double scale) { q.get().add_identity(scale); }, py::arg("scale") = 1.0,
          "W += weight * scale * I")
      .def(
          "add_diagonal",
          [](StepQp& q, const Eigen::VectorXd& d) {
            q.need(d.size(), 1, q.n, 1, "the diagonal");
            q.get().add_diagonal(d);
          },
          py::arg("diagonal"), "W += weight * diag(diagonal)")
      .def(
          "add_hessian",
          [](StepQp& q, const Eigen::MatrixXd& H) {
            q.need(H.rows(), H.cols(), q.n, q.n, "H");
            q.get().add_hessian(H);
          },
          py::arg("H"), "W += weight * H (H symmetric)")
      .def(
          "add_linear",
          [](StepQp& q, const Eigen::VectorXd& z) {
            q.need(z.size(), 1, q.n, 1, "the linear term");
            q.get().add_linear(z);
          },
          py::arg("zeta"), "zeta += weight * zeta_term")
      .def(
          "set_equality",
          [](StepQp& q, const Eigen::MatrixXd& J, const Eigen::VectorXd& d) {
            q.need(J.rows(), J.cols(), q.eq_rows, q.n, "the equality matrix");
            q.need(d.size(), 1, q.eq_rows, 1, "the equality right-hand side");
            q.get().equality_matrix() = J;
            q.get().equality_rhs() = d;
          },
          py::arg("J"), py::arg("d"), "this constraint's equality rows J x = d")
      .def(
          "set_inequality",
          [](StepQp& q, const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
            q.need(A.rows(), A.cols(), q.in_rows, q.n, "the inequality matrix");
            q.need(b.size(), 1, q.in_rows, 1, "the inequality right-hand side");
            q.get().inequality_matrix() = A;
            q.get().inequality_rhs() = b;
          },
          py::arg("A"), py::arg("b"), "this constraint's inequality rows A x <= b")
      .def(
          "intersect_bounds",
          [](StepQp& q, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi) {
            q.need(lo.size(), 1, q.n, 1, "the lower bounds");
            q.need(hi.size(), 1, q.n, 1, "the upper bounds");
            q.get().intersect_bounds(lo, hi);
          },
          py::arg("lower"), py::arg("upper"), "lo = max(lo, lower), hi = min(hi, upper)")
      .def(
          "intersect_bound",
          [](StepQp& q, int joint, double lo, double hi) {
            if (joint < 0 || joint >= q.n) {
              throw py::index_error(q.who + ": joint " + std::to_string(joint) + " is not in 0.." +
                                    std::to_string(q.n - 1));
            }
            q.get().intersect_bound(joint, lo, hi);
          },
          py::arg("joint"), py::arg("lower"), py::arg("upper"), "the same for one joint (0-based)");

  m.def("_register_class", &register_class, py::arg("kind"), py::arg("type"), py::arg("cls"), py::arg("keys"),
        py::arg("help"), py::arg("summary"));
  m.def("_unregister_all", &unregister_all);
  m.def("_unregister", &unregister, py::arg("origin"));
  m.def("_check_config", [](const std::string& kind, const py::dict& config, const std::string& where) {
    check_config(kind, to_table(config, where), where);
  });
  m.def(
      "check_plugins",
      [](const std::string& origin) {
        py::list out;
        for (const auto& r : check_registries(origin)) {
          py::dict d;
          d["kind"] = r.kind;
          d["type"] = r.type;
          d["check"] = r.check;
          d["ok"] = r.ok;
          d["detail"] = r.detail;
          out.append(d);
        }
        return out;
      },
      py::arg("origin") = "",
      "Runs the conformance checks of `redres plugins --check` on the registered plugins (those from `origin` "
      "only, e.g. 'python:mymodule.MyObjective', when given): defaults, configuration round trip, documented keys, "
      "finite contributions, and zeta against central differences of the objective's potential. Returns one dict "
      "per check: kind, type, check, ok, detail.");
}

}  // namespace redres::python
