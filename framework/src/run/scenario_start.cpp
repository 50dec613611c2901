// A scenario's start configuration: theta0 as joint positions, or theta0 = { ik, seed } and the inverse kinematics
// that finds it (docs/ik.md).

#include "run/scenario_reading.hpp"

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "redres/control/collision_rows.hpp"

namespace redres::scenario_detail {

namespace {

// An array of joint positions at `key` (numbers or formulas, one per joint, within the limits).
// `label` starts the entries' messages ("" at the top level, "theta0: " in theta0's table).
Eigen::VectorXd read_joint_array(const TableReader& r, std::string_view key, const RobotModel& robot,
                                 const std::string& expected, const std::string& label = "") {
  const toml::node& node = *r.raw().get(key);
  const toml::array* arr = node.as_array();
  if (arr == nullptr || static_cast<int>(arr->size()) != robot.dof()) r.fail(key, expected);
  const std::string what = label + "key '" + std::string(key) + "'";
  Eigen::VectorXd theta(robot.dof());
  for (int j = 0; j < robot.dof(); ++j) {
    const toml::node& el = (*arr)[static_cast<std::size_t>(j)];
    double v = 0.0;
    bool number = false;
    try {
      number = read_number_or_formula(el, v);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(location_of(r.file(), el), what + ": entry " + std::to_string(j + 1) + ": " + e.what());
    }
    if (!number) {
      throw ConfigError(location_of(r.file(), el), what + ": entry " + std::to_string(j + 1) +
                                                       ": expected a number or a formula string, got " +
                                                       describe_type(el));
    }
    if (!std::isfinite(v)) {
      std::ostringstream s;
      s << what << ": entry " << j + 1 << ": expected a finite number, got " << v;
      throw ConfigError(location_of(r.file(), el), s.str());
    }
    const JointSpec& jt = robot.joint(j);
    if (v < jt.lower || v > jt.upper) {
      std::ostringstream s;
      s.precision(10);
      s << what << ": joint '" << jt.name << "' = " << v << " is outside its limits [" << jt.lower << ", " << jt.upper
        << "]";
      throw ConfigError(location_of(r.file(), el), s.str());
    }
    theta(j) = v;
  }
  return theta;
}

// The largest `margin` of the scheme's active joint_angle_margin constraints, per joint (zeros without one).
Eigen::VectorXd scheme_margin(const Scheme& scheme, int n) {
  Eigen::VectorXd margin = Eigen::VectorXd::Zero(n);
  for (const auto& c : scheme.constraints()) {
    if (!c->active() || c->type() != "joint_angle_margin") continue;
    const toml::table config = c->config();
    const toml::node* m = config.get("margin");
    if (m == nullptr) continue;
    if (const auto v = m->value<double>()) {
      margin = margin.cwiseMax(Eigen::VectorXd::Constant(n, *v));
    } else if (const toml::array* a = m->as_array(); a != nullptr && static_cast<int>(a->size()) == n) {
      for (int j = 0; j < n; ++j) margin(j) = std::max(margin(j), (*a)[static_cast<std::size_t>(j)].value_or(0.0));
    }
  }
  return margin;
}

std::string vector_text(const Eigen::Ref<const Eigen::VectorXd>& v) {
  std::ostringstream s;
  s.precision(6);
  s << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i > 0 ? ", " : "") << v(i);
  s << "]";
  return s.str();
}

}  // namespace

Eigen::VectorXd read_theta0(const TableReader& r, const RobotModel& robot) {
  if (!r.has("theta0")) return robot.home();
  return read_joint_array(r, "theta0", robot,
                          "expected an array of " + std::to_string(robot.dof()) +
                              " joint positions (numbers or formulas such as \"pi/4\"), or a table { ik = ..., seed = "
                              "... } (inverse kinematics, docs/ik.md)");
}

const Schema<IkTable>& IkTable::schema() {
  using C = IkTable;
  static const Schema<C> s{
      {entry<C>(
           "position", "array of 3 numbers (planar: 2), or \"path\"", "m", "",
           "where the end effector goes, in the world frame; \"path\": where the path starts (r_d(0))",
           [](const TableReader& r, C& c) {
             if (!r.has("position")) r.fail("missing required key 'position' (where the end effector goes)");
             if (const auto* text = r.raw().get("position")->as_string()) {
               if (text->get() != "path") {
                 r.fail("position", "expected an array of " + std::string(c.planar ? "2" : "3") +
                                        " numbers or \"path\" (the path's start), got \"" + text->get() + "\"");
               }
               c.from_path = true;
               return;
             }
             const std::vector<double> p = r.numbers("position", c.planar ? 2 : 3);
             for (std::size_t i = 0; i < p.size(); ++i) c.position(static_cast<Eigen::Index>(i)) = p[i];
             const double bound = *physical_bound("m");
             if (!(c.position.cwiseAbs().maxCoeff() <= bound)) {
               std::ostringstream m;
               m << "expected |x| <= " << bound << " m (a physical range), got " << c.position.cwiseAbs().maxCoeff();
               r.fail("position", m.str());
             }
           },
           "|x| <= 1000 m")
           .required(),
       entry<C>(
           "rpy", "array of 3 numbers", "rad", "none (position only, or the seed's orientation for a pose task)",
           "spatial robots: the end effector's roll, pitch, yaw, R = Rz(yaw) Ry(pitch) Rx(roll)",
           [](const TableReader& r, C& c) {
             if (!r.has("rpy")) return;
             if (c.planar) {
               r.fail("rpy", "a planar robot's end-effector orientation is `phi` (one angle about z)");
             }
             const std::vector<double> a = r.numbers("rpy", 3);
             c.rpy = Eigen::Vector3d(a[0], a[1], a[2]);
             if (!(c.rpy->cwiseAbs().maxCoeff() <= *physical_bound("rad"))) {
               r.fail("rpy", "expected |x| <= 1e6 rad (a physical range)");
             }
           },
           "|x| <= 1e+06 rad"),
       entry<C>(
           "phi", "number", "rad", "none (as rpy)", "planar robots: the end effector's angle about z",
           [](const TableReader& r, C& c) {
             if (!r.has("phi")) return;
             if (!c.planar) {
               r.fail("phi", "is for a planar robot; a spatial robot's orientation is `rpy = [roll, pitch, yaw]`");
             }
             c.phi = r.number("phi");
             if (!(std::abs(*c.phi) <= *physical_bound("rad"))) {
               r.fail("phi", "expected |x| <= 1e6 rad (a physical range)");
             }
           },
           "|x| <= 1e+06 rad")}};
  return s;
}

const Schema<Theta0Ik>& Theta0Ik::schema() {
  using C = Theta0Ik;
  static const Schema<C> s{
      {entry<C>("ik", "\"path\" or a table {position, rpy, phi}", "", "",
                "the end effector's target: \"path\" (where the path starts; the path's placement must be "
                "\"absolute\"), or a pose (below)",
                [](const TableReader& r, C& c) {
                  if (!r.has("ik")) {
                    r.fail("missing required key 'ik' (the target: \"path\", or { position = [...], rpy = [...] })");
                  }
                  const toml::node& n = *r.raw().get("ik");
                  if (const auto* text = n.as_string()) {
                    if (text->get() != "path") {
                      r.fail("ik",
                             "expected \"path\" (the path's start) or a table { position = [...], rpy = "
                             "[...] }, got \"" +
                                 text->get() + "\"");
                    }
                    c.ik.from_path = true;
                    return;
                  }
                  if (!n.is_table()) {
                    r.fail("ik",
                           "expected \"path\" or a table { position = [...], rpy = [...] }, got " + describe_type(n));
                  }
                  c.ik.planar = c.robot->kind() == ChainKind::kPlanar;
                  config_io::read(r, "ik", c.ik);
                })
           .required(),
       entry<C>(
           "seed", "\"home\", \"zeros\" or an array of numbers, one per joint", "rad or m", "\"home\"",
           "where the iteration starts: the robot's home, zeros (clamped into the limits), or these joint "
           "positions (within the limits)",
           [](const TableReader& r, C& c) {
             const RobotModel& model = *c.robot;
             c.seed = model.home();
             if (!r.has("seed")) return;
             const toml::node& n = *r.raw().get("seed");
             const std::string expected =
                 "expected \"home\", \"zeros\" or an array of " + std::to_string(model.dof()) + " joint positions";
             if (const auto* text = n.as_string()) {
               c.seed_name = text->get();
               if (c.seed_name == "zeros") {
                 c.seed =
                     Eigen::VectorXd::Zero(model.dof()).cwiseMax(model.lower_limits()).cwiseMin(model.upper_limits());
               } else if (c.seed_name != "home") {
                 r.fail("seed", expected + ", got \"" + c.seed_name + "\"");
               }
               return;
             }
             c.seed_name = "given";
             c.seed = read_joint_array(
                 r, "seed", model,
                 expected + ", got " + describe_type(n) +
                     (n.is_array() ? " of " + std::to_string(n.as_array()->size()) + " element(s)" : ""),
                 "theta0: ");
           })}};
  return s;
}

// theta0 = { ik = ... }: the IK from the seed, kept within the scheme's joint margins and clear of the bodies of its
// collision constraints; theta0 is its answer. A target it does not reach is a ConfigError at theta0.
void solve_start(Scenario& s, const Theta0Ik& req, const SourceLocation& where) {
  const RobotModel& robot = *s.robot;
  const bool planar = robot.kind() == ChainKind::kPlanar;
  const int p = robot.position_rows();
  KinematicsData k(robot);
  compute_kinematics(robot, req.seed, k, KinematicsLevel::kPosition);
  IkTarget target;
  std::ostringstream text;
  text.precision(6);
  if (req.ik.from_path) {
    Eigen::VectorXd r(p), r_dot(p);
    s.path->evaluate(0.0, r, r_dot);
    target.position.head(p) = r;
    text << "the path's start ";
  } else {
    target.position.head(p) = req.ik.position.head(p);
  }
  text << "xyz " << vector_text(target.position.head(p));
  bool held = false;  // a pose task without a given orientation keeps the seed's
  if (req.ik.rpy) {
    target.rotation = rpy_matrix({(*req.ik.rpy)(0), (*req.ik.rpy)(1), (*req.ik.rpy)(2)});
    text << " rpy " << vector_text(*req.ik.rpy);
  } else if (req.ik.phi) {
    target.rotation = Eigen::AngleAxisd(*req.ik.phi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    text << " phi " << *req.ik.phi;
  } else if (robot.has_orientation_rows()) {
    held = true;
    target.rotation = planar ? Eigen::AngleAxisd(k.f(2), Eigen::Vector3d::UnitZ()).toRotationMatrix()
                             : Eigen::Matrix3d(k.ee_pose.linear());
    text << " with the seed's orientation";
  }
  // From the path: the task's rows (and a given orientation in full); a given pose: every row.
  if (req.ik.from_path) {
    for (int r = 0; r < p; ++r) {
      if (robot.tracks(r)) target.rows.push_back(robot.reference_names()[static_cast<std::size_t>(r)]);
    }
    if (target.rotation) {
      const std::vector<std::string> names =
          planar ? std::vector<std::string>{"phi"} : std::vector<std::string>{"wx", "wy", "wz"};
      for (std::size_t i = 0; i < names.size(); ++i) {
        if (!held || robot.tracks(p + static_cast<int>(i))) target.rows.push_back(names[i]);
      }
    }
  }
  std::vector<const Constraint*> collision;
  for (const auto& c : s.scheme->constraints()) {
    if (!c->active()) continue;
    const std::unique_ptr<PluginData> data = c->make_data();
    if (dynamic_cast<const PairData*>(data.get()) != nullptr) collision.push_back(c.get());
  }
  IkOptions options;
  options.margin = scheme_margin(*s.scheme, robot.dof());
  IkResult result;
  try {
    result = solve_ik(robot, target, req.seed, collision, options);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(where, std::string("key 'theta0': the inverse kinematics cannot start: ") + e.what());
  }
  if (!result.converged) {
    throw ConfigError(where, "key 'theta0': the inverse kinematics to " + text.str() + " from the seed '" +
                                 req.seed_name + "' " + result.summary() +
                                 " (move the target, give another `seed`, or widen the limits)");
  }
  s.theta0 = result.theta;
  s.ik = result;
  s.ik_target = text.str() + " from the seed '" + req.seed_name + "'";
}

}  // namespace redres::scenario_detail
