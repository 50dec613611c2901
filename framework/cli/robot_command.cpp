// `redres robot FILE`: the model's summary and its kinematics at theta (by default the home configuration).

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "redres/common/formula.hpp"
#include "redres/model/collision.hpp"
#include "redres/model/convex.hpp"
#include "redres/model/frames.hpp"
#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/ik.hpp"

namespace redres::cli {

namespace {

struct RobotOptions {
  std::string file;
  std::string base_link, tip_link;
  std::string theta;
  std::string ik, seed;
  bool json = false;
};

Eigen::VectorXd parse_theta(const std::string& text, const RobotModel& model, const std::string& option = "--theta") {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      values.push_back(evaluate_constant(item));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(option + ": " + e.what());
    }
  }
  if (static_cast<int>(values.size()) != model.dof()) {
    throw std::invalid_argument(option + ": expected " + std::to_string(model.dof()) +
                                " comma-separated values (one "
                                "per joint), got " +
                                std::to_string(values.size()));
  }
  Eigen::VectorXd theta = Eigen::Map<Eigen::VectorXd>(values.data(), model.dof());
  REDRES_REQUIRE(theta.allFinite(), option.c_str(), "every value is finite");
  for (int j = 0; j < model.dof(); ++j) {
    const JointSpec& jt = model.joint(j);
    if (theta(j) < jt.lower || theta(j) > jt.upper) {
      std::ostringstream m;
      m << option << ": joint " << j + 1 << " ('" << jt.name << "') = " << theta(j) << " is outside its limits ["
        << jt.lower << ", " << jt.upper << "]";
      throw std::invalid_argument(m.str());
    }
  }
  return theta;
}

std::vector<double> to_vector(const Eigen::Ref<const Eigen::VectorXd>& v) { return {v.data(), v.data() + v.size()}; }

// Roll, pitch, yaw of a pose's rotation, in the convention of robot files and URDFs (rpy_of).
Eigen::Vector3d rpy(const Eigen::Isometry3d& p) {
  const std::array<double, 3> a = rpy_of(p.linear());
  return {a[0], a[1], a[2]};
}

// The nearest distance of every self-collision pair of bodies (i < j, RobotModel::bodies()) at the kinematics in k:
// over their shapes, each placed at its link frame. Sorted nearest first.
struct PairDistance {
  int i = 0, j = 0;
  double distance = 0.0;
};
std::vector<PairDistance> self_distances(const RobotModel& model, const KinematicsData& k) {
  std::vector<ShapeSpec> specs;
  for (const auto& shape : model.link_shapes()) specs.push_back(shape.spec);
  std::vector<PairDistance> out;
  if (specs.empty()) return out;
  const DistanceQuery query(specs);
  const auto& shapes = model.link_shapes();
  std::map<std::pair<int, int>, double> nearest;
  for (std::size_t a = 0; a < shapes.size(); ++a) {
    for (std::size_t b = a + 1; b < shapes.size(); ++b) {
      const int i = std::min(shapes[a].body, shapes[b].body), j = std::max(shapes[a].body, shapes[b].body);
      if (!model.self_collision_bodies(i, j)) continue;
      const Eigen::Isometry3d Ta = k.link_frames[static_cast<std::size_t>(shapes[a].link)] * shapes[a].pose;
      const Eigen::Isometry3d Tb = k.link_frames[static_cast<std::size_t>(shapes[b].link)] * shapes[b].pose;
      const ShapeDistance d = query.distance(static_cast<int>(a), Ta, static_cast<int>(b), Tb);
      if (!d.ok) continue;
      const auto key = std::make_pair(i, j);
      const auto it = nearest.find(key);
      if (it == nearest.end() || d.distance < it->second) nearest[key] = d.distance;
    }
  }
  for (const auto& [key, d] : nearest) out.push_back({key.first, key.second, d});
  std::sort(out.begin(), out.end(),
            [](const PairDistance& a, const PairDistance& b) { return a.distance < b.distance; });
  return out;
}

nlohmann::json to_json(const RobotModel& model, const KinematicsData& k, const Eigen::VectorXd& lo,
                       const Eigen::VectorXd& hi) {
  nlohmann::json joints = nlohmann::json::array();
  for (int j = 0; j < model.dof(); ++j) {
    const JointSpec& jt = model.joint(j);
    joints.push_back({{"name", jt.name},
                      {"type", to_string(jt.type)},
                      {"limits", {jt.lower, jt.upper}},
                      {"velocity_law", jt.velocity_limit->describe()},
                      {"velocity_limits", {lo(j), hi(j)}}});
  }
  const auto pose = [](const Eigen::Isometry3d& p) {
    return nlohmann::json{{"xyz", to_vector(p.translation())}, {"rpy", to_vector(rpy(p))}};
  };
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& f : k.link_frames) frames.push_back(pose(f));
  nlohmann::json self_pairs = nlohmann::json::array();
  for (const PairDistance& p : self_distances(model, k)) {
    const auto& A = model.bodies()[static_cast<std::size_t>(p.i)];
    const auto& B = model.bodies()[static_cast<std::size_t>(p.j)];
    self_pairs.push_back({{"links", {A.name, B.name}}, {"joints", {A.link + 1, B.link + 1}}, {"distance", p.distance}});
  }
  nlohmann::json inertias = nlohmann::json::array();
  for (int j = 0; j < model.dof(); ++j) {
    const auto& in = model.joint(j).inertia;
    if (!in) {
      inertias.push_back(nullptr);
      continue;
    }
    const Eigen::Matrix3d& I = in->tensor;
    inertias.push_back({{"mass", in->mass},
                        {"com", to_vector(in->com)},
                        {"tensor", {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)}}});
  }
  nlohmann::json shapes = nlohmann::json::array();
  for (const auto& shape : model.link_shapes()) {
    shapes.push_back({{"joint", shape.link + 1},
                      {"joint_name", model.joint(shape.link).name},
                      {"link", model.bodies()[static_cast<std::size_t>(shape.body)].name},
                      {"side_branch", model.bodies()[static_cast<std::size_t>(shape.body)].branch},
                      {"shape", shape.spec.describe()},
                      {"position", to_vector(shape.pose.translation())},
                      {"rpy", rpy_of(shape.pose.linear())},
                      {"kind", std::string(config_io::enum_name(shape.spec.shape))}});
    if (!shape.spec.source.empty()) shapes.back()["source_mesh"] = shape.spec.source.string();
    if (shape.spec.hull) {
      shapes.back()["file"] = shape.spec.hull->source.string();
      shapes.back()["vertices"] = shape.spec.hull->vertices.size();
      shapes.back()["faces"] = shape.spec.hull->faces.size();
    }
  }
  nlohmann::json held = nlohmann::json::array();
  for (const auto& [name, value] : model.spec().held_joints) held.push_back({{"name", name}, {"value", value}});
  nlohmann::json visuals = nlohmann::json::array();
  for (const VisualSpec& v : model.visuals()) {
    static const char* const kinds[] = {"mesh", "box", "cylinder", "sphere"};
    visuals.push_back({{"link", v.link},
                       {"joint", v.joint + 1},
                       {"kind", kinds[static_cast<int>(v.kind)]},
                       {"position", to_vector(v.pose.translation())},
                       {"rpy", rpy_of(v.pose.linear())}});
    if (v.kind == VisualSpec::Kind::kMesh) {
      visuals.back()["file"] = v.file.string();
      visuals.back()["uri"] = v.uri;
      if (!v.problem.empty()) visuals.back()["problem"] = v.problem;
    }
  }
  nlohmann::json task_frames = nlohmann::json::array();  // the frames a frame task can name (docs/tasks.md)
  for (std::size_t f = 0; f < model.frames().size(); ++f) {
    const Eigen::Isometry3d at = frame_pose(model, k, static_cast<int>(f));
    task_frames.push_back({{"name", model.frames()[f].name},
                           {"joint", model.frames()[f].joint + 1},
                           {"position", to_vector(at.translation())},
                           {"rpy", rpy_of(at.linear())}});
  }
  nlohmann::json J = nlohmann::json::array();
  for (Eigen::Index r = 0; r < k.J.rows(); ++r) J.push_back(to_vector(k.J.row(r).transpose()));
  return {{"name", model.name()},
          {"kind", to_string(model.kind())},
          {"dof", model.dof()},
          {"task", model.task_names()},
          {"reference", model.reference_names()},
          {"source", model.source()},
          {"joints", joints},
          {"collision_shapes", shapes},
          {"visuals", visuals},
          {"held_joints", held},
          {"self_collision_distances", self_pairs},
          {"inertias", inertias},
          {"base_pose", pose(model.base())},
          {"end_effector_pose", pose(k.ee_pose)},
          {"link_frames", frames},
          {"frames", task_frames},
          {"theta", to_vector(k.theta)},
          {"f", to_vector(k.f)},
          {"J", J},
          {"manipulability", k.w},
          {"grad_manipulability", to_vector(k.grad_w)},
          {"yoshikawa", k.mu},
          {"grad_yoshikawa", to_vector(k.grad_mu)}};
}

std::string row(const Eigen::Ref<const Eigen::VectorXd>& v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(9) << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v(i);
  s << "]";
  return s.str();
}

void print_text(const RobotModel& model, const KinematicsData& k, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                bool at_home) {
  std::ostream& o = std::cout;
  std::string rows;
  for (const auto& n : model.task_names()) rows += (rows.empty() ? "" : ", ") + n;
  o << "robot   " << model.name() << " (" << to_string(model.kind()) << ", " << model.dof() << " joints, task rows "
    << rows << ")\n";
  if (!model.source().empty()) o << "source  " << model.source() << "\n";
  int width = 12;  // the name column fits the longest name (of a joint or a link)
  for (int j = 0; j < model.dof(); ++j) width = std::max(width, static_cast<int>(model.joint(j).name.size()));
  for (const auto& b : model.bodies()) width = std::max(width, static_cast<int>(b.name.size()));
  o << "\njoint  " << std::left << std::setw(width) << "name" << std::right
    << "  type        theta^-      theta^+      velocity-limit law\n";
  for (int j = 0; j < model.dof(); ++j) {
    const JointSpec& jt = model.joint(j);
    o << std::setw(5) << j + 1 << "  " << std::left << std::setw(width) << jt.name << "  " << std::setw(10)
      << to_string(jt.type) << std::right << std::fixed << std::setprecision(6) << std::setw(11) << jt.lower << "  "
      << std::setw(11) << jt.upper << "  " << jt.velocity_limit->describe() << "\n";
  }
  o << "\nat theta " << row(k.theta) << (at_home ? "  (home)" : "") << "\n";
  const auto pose = [](const Eigen::Isometry3d& p) { return "xyz " + row(p.translation()) + "  rpy " + row(rpy(p)); };
  o << "base          " << pose(model.base()) << "\n";
  o << "end effector  " << pose(k.ee_pose) << "\n";
  o << "link frames (joint j's frame after its motion, in the world)\n";
  for (int j = 0; j < model.dof(); ++j) {
    o << std::setw(5) << j + 1 << "  " << std::left << std::setw(width) << model.joint(j).name << std::right << "  "
      << pose(k.link_frames[static_cast<std::size_t>(j)]) << "\n";
  }
  o << "frames a task can name (frame = \"...\"; docs/tasks.md), riding on joint j\n";
  for (std::size_t f = 0; f < model.frames().size(); ++f) {
    const RobotModel::Frame& frame = model.frames()[f];
    o << std::setw(5) << frame.joint + 1 << "  " << std::left << std::setw(width) << frame.name << std::right << "  "
      << pose(frame_pose(model, k, static_cast<int>(f))) << "\n";
  }
  o << "f        " << row(k.f) << "\n";
  o << "J\n";
  for (Eigen::Index r = 0; r < k.J.rows(); ++r) o << "  " << row(k.J.row(r).transpose()) << "\n";
  o << std::setprecision(9) << "w = det(JJ')      " << k.w << "\n";
  o << "grad w            " << row(k.grad_w) << "\n";
  o << "sqrt(det(JJ'))    " << k.mu << "\n";
  o << "grad sqrt         " << row(k.grad_mu) << "\n";
  o << "\njoint  velocity limits at theta (lower, upper)\n";
  for (int j = 0; j < model.dof(); ++j) {
    o << std::setw(5) << j + 1 << "  " << std::setprecision(9) << std::setw(14) << lo(j) << "  " << std::setw(14)
      << hi(j) << "\n";
  }
  o << "\njoint  mass (kg)   centre of mass (m), inertia about it (kg m^2: ixx iyy izz ixy ixz iyz), link frame\n";
  int with_inertia = 0;
  for (int j = 0; j < model.dof(); ++j) {
    const auto& in = model.joint(j).inertia;
    if (!in) continue;
    ++with_inertia;
    const Eigen::Matrix3d& I = in->tensor;
    o << std::setw(5) << j + 1 << "  " << std::setprecision(6) << std::setw(9) << in->mass << "   " << row(in->com)
      << "  " << std::setprecision(6) << I(0, 0) << " " << I(1, 1) << " " << I(2, 2) << " " << I(0, 1) << " " << I(0, 2)
      << " " << I(1, 2) << "\n";
  }
  if (with_inertia == 0) o << "  none given\n";
  for (int j = 0; j < model.dof(); ++j) {
    if (!model.joint(j).inertia_warning.empty()) {
      o << "  warning: joint " << j + 1 << ": " << model.joint(j).inertia_warning << " (kept as given)\n";
    }
  }
  o << "\ncollision shapes (" << model.link_shapes().size() << "), in their joint's link frame\n";
  if (model.link_shapes().empty())
    o << "  none\n";
  else
    o << "joint  " << std::left << std::setw(width) << "joint name"
      << "  " << std::setw(width) << "link" << std::right << "  shape\n";
  for (const auto& shape : model.link_shapes()) {
    const auto& body = model.bodies()[static_cast<std::size_t>(shape.body)];
    o << std::setw(5) << shape.link + 1 << "  " << std::left << std::setw(width) << model.joint(shape.link).name << "  "
      << std::setw(width) << body.name << std::right << "  " << shape.spec.describe();
    {  // its pose in the link frame, and the mesh it was made from
      const Eigen::Vector3d p = shape.pose.translation();
      const auto rpy = rpy_of(shape.pose.linear());
      o << " at xyz " << p.x() << " " << p.y() << " " << p.z() << " rpy " << rpy[0] << " " << rpy[1] << " " << rpy[2];
      if (!shape.spec.source.empty() && shape.spec.shape != ShapeSpec::Kind::kConvex) {
        o << " from " << shape.spec.source.filename().string();
      }
    }
    o << (body.branch ? "  (side branch)" : "") << "\n";
  }
  if (!model.visuals().empty()) {
    // What `redres view` draws: one line per link, a mesh that was not found named with why.
    std::size_t meshes = 0, missing = 0;
    for (const VisualSpec& v : model.visuals()) {
      if (v.kind != VisualSpec::Kind::kMesh) continue;
      ++meshes;
      if (!v.problem.empty()) ++missing;
    }
    o << "\nvisual elements (" << model.visuals().size() << ", " << meshes << " meshes"
      << (missing > 0 ? ", " + std::to_string(missing) + " not found" : std::string()) << "; drawn by redres view)\n";
    for (const VisualSpec& v : model.visuals()) {
      static const char* const kinds[] = {"mesh", "box", "cylinder", "sphere"};
      o << "  " << std::left << std::setw(width) << v.link << "  " << std::setw(8)
        << (v.joint < 0 ? std::string("base") : "joint " + std::to_string(v.joint + 1)) << std::right << "  "
        << kinds[static_cast<int>(v.kind)];
      if (v.kind == VisualSpec::Kind::kMesh) {
        o << " " << (v.problem.empty() ? v.file.filename().string() : v.uri + ": " + v.problem);
      }
      o << "\n";
    }
  }
  if (!model.spec().held_joints.empty()) {
    o << "\nheld joints (side branches; `held_joints` in the robot file)\n";
    for (const auto& [name, value] : model.spec().held_joints) {
      o << "  " << std::left << std::setw(width) << name << std::right << "  " << std::setprecision(6) << value << "\n";
    }
  }
  const std::vector<PairDistance> pairs = self_distances(model, k);
  if (!pairs.empty()) {
    o << "\nself-collision pairs at theta, nearest first (m; < 0: overlapping)\n";
    for (const PairDistance& p : pairs) {
      o << "  " << std::left << std::setw(width) << model.bodies()[static_cast<std::size_t>(p.i)].name << "  "
        << std::setw(width) << model.bodies()[static_cast<std::size_t>(p.j)].name << std::right << "  "
        << std::setprecision(6) << p.distance << "\n";
    }
  }
}

// `--ik x,y,z[,r,p,y]` (planar: x,y[,phi]) from `--seed home|zeros|v1,v2,...`: the inverse kinematics (run/ik.hpp),
// clear of the robot's self-collision; prints the answer (or JSON) and returns 2 when it does not converge.
int print_ik(const RobotModel& model, const RobotOptions& opts) {
  std::vector<double> v;
  std::stringstream in(opts.ik);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      v.push_back(evaluate_constant(item));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--ik: ") + e.what());
    }
  }
  const bool planar = model.kind() == ChainKind::kPlanar;
  const std::size_t p = planar ? 2 : 3, pose = planar ? 3 : 6;
  if (v.size() != p && v.size() != pose) {
    throw std::invalid_argument(
        "--ik: expected " + std::string(planar ? "x,y or x,y,phi" : "x,y,z or x,y,z,roll,pitch,yaw") + " (" +
        model.name() + " is " + (planar ? "planar" : "spatial") + "), got " + std::to_string(v.size()) + " value(s)");
  }
  for (double x : v) REDRES_REQUIRE(std::isfinite(x), "--ik", "every value is finite");
  const IkTarget target =
      planar ? IkTarget::planar(v[0], v[1], v.size() == pose ? std::optional<double>(v[2]) : std::nullopt)
             : IkTarget::spatial(
                   {v[0], v[1], v[2]},
                   v.size() == pose ? std::optional<Eigen::Vector3d>(Eigen::Vector3d(v[3], v[4], v[5])) : std::nullopt);
  Eigen::VectorXd seed = model.home();
  const std::string seed_name = opts.seed.empty() ? "home" : opts.seed;
  if (seed_name == "zeros") {
    seed = Eigen::VectorXd::Zero(model.dof()).cwiseMax(model.lower_limits()).cwiseMin(model.upper_limits());
  } else if (seed_name != "home") {
    seed = parse_theta(seed_name, model, "--seed");
  }
  const IkResult r = solve_ik(model, target, seed);
  KinematicsData k(model);
  compute_kinematics(model, r.theta, k, KinematicsLevel::kPosition);
  const std::vector<PairDistance> pairs = self_distances(model, k);
  if (opts.json) {
    nlohmann::json limit_joints = nlohmann::json::array();
    for (int j : r.limit_joints) limit_joints.push_back(j + 1);
    nlohmann::json j{{"target", {{"xyz", std::vector<double>(v.begin(), v.begin() + static_cast<long>(p))}}},
                     {"seed", to_vector(seed)},
                     {"converged", r.converged},
                     {"theta", to_vector(r.theta)},
                     {"end_effector_pose", {{"xyz", to_vector(r.pose.translation())}, {"rpy", to_vector(rpy(r.pose))}}},
                     {"position_error", r.position_error},
                     {"orientation_error", r.orientation_error},
                     {"iterations", r.iterations},
                     {"seeds", r.seeds},
                     {"seconds", r.seconds},
                     {"failure", to_string(r.failure)},
                     {"limit_joints", limit_joints},
                     {"blocking_pair", r.blocking_pair},
                     {"diagnosis", r.diagnosis}};
    if (v.size() == pose) {
      j["target"][planar ? "phi" : "rpy"] =
          planar ? nlohmann::json(v[2]) : nlohmann::json(std::vector<double>(v.begin() + 3, v.end()));
    }
    j["min_self_collision_distance"] = pairs.empty() ? nlohmann::json(nullptr) : nlohmann::json(pairs[0].distance);
    if (!pairs.empty()) {
      j["nearest_self_collision_pair"] = {model.bodies()[static_cast<std::size_t>(pairs[0].i)].name,
                                          model.bodies()[static_cast<std::size_t>(pairs[0].j)].name};
    }
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "robot   " << model.name() << "\n";
    std::cout << "ik      to xyz " << row(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<long>(p)));
    if (v.size() == pose) {
      std::cout << (planar ? "  phi " : "  rpy ")
                << row(Eigen::Map<const Eigen::VectorXd>(v.data() + p, static_cast<long>(pose - p)));
    }
    std::cout << " from the seed '" << seed_name << "' " << row(seed) << "\n";
    std::cout << "        "
              << (r.converged ? r.summary() : "did not converge (" + std::string(to_string(r.failure)) + ")") << "\n";
    std::cout << "theta   " << row(r.theta) << "\n";
    std::cout << "end effector  xyz " << row(r.pose.translation()) << "  rpy " << row(rpy(r.pose)) << "\n";
    std::cout << std::setprecision(3) << "position error " << r.position_error << " m, orientation error "
              << r.orientation_error << " rad, " << r.iterations << " iterations, " << r.seeds << " seed"
              << (r.seeds == 1 ? "" : "s") << ", " << r.seconds * 1e3 << " ms\n";
    if (!pairs.empty()) {
      std::cout << std::setprecision(6) << "nearest self-collision pair "
                << model.bodies()[static_cast<std::size_t>(pairs[0].i)].name << " / "
                << model.bodies()[static_cast<std::size_t>(pairs[0].j)].name << " at " << pairs[0].distance << " m\n";
    }
  }
  if (!r.converged) {
    std::cerr << "error: --ik: the inverse kinematics " << r.summary() << "\n";
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace

void add_robot_command(CLI::App& app, Action& action) {
  auto opts = std::make_shared<RobotOptions>();
  CLI::App* cmd = app.add_subcommand("robot", "Print a robot model's summary and its kinematics at theta");
  cmd->add_option("FILE", opts->file, "robot TOML file, or a URDF file (*.urdf) read as it comes")->required();
  cmd->add_option("--base-link", opts->base_link, "with a URDF: the link the chain starts at (default: the root)");
  cmd->add_option("--tip-link", opts->tip_link,
                  "with a URDF: the link the chain ends at (default: the one with the most revolute joints above it, a "
                  "gripper's fingers left out)");
  cmd->add_option("--theta", opts->theta,
                  "joint positions, comma-separated (formulas allowed, e.g. pi/4,pi/12); default: the home "
                  "configuration");
  cmd->add_option("--ik", opts->ik,
                  "inverse kinematics: x,y,z[,roll,pitch,yaw] (planar: x,y[,phi]) in the world frame (m, rad); prints "
                  "the joint positions that reach it (exit code 2 when none is found)");
  cmd->add_option("--seed", opts->seed, "with --ik: where the iteration starts: home (default), zeros, or v1,v2,...");
  cmd->add_flag("--json", opts->json, "print JSON instead of text");
  cmd->callback([opts, &action] {
    action = [opts] {
      const bool urdf = std::filesystem::path(opts->file).extension() == ".urdf";
      if (!urdf && (!opts->base_link.empty() || !opts->tip_link.empty())) {
        throw std::invalid_argument(
            "--base-link and --tip-link are for a URDF file (*.urdf); a robot file names "
            "them itself");
      }
      const RobotModel model =
          urdf ? load_urdf_robot(opts->file, opts->base_link, opts->tip_link) : load_robot(opts->file);
      if (!opts->seed.empty() && opts->ik.empty()) throw std::invalid_argument("--seed is for --ik");
      if (!opts->ik.empty()) {
        if (!opts->theta.empty()) throw std::invalid_argument("--ik finds theta: give --ik or --theta, not both");
        return print_ik(model, *opts);
      }
      const bool at_home = opts->theta.empty();
      const Eigen::VectorXd theta = at_home ? model.home() : parse_theta(opts->theta, model);
      KinematicsData k(model);
      compute_kinematics(model, theta, k, KinematicsLevel::kAll);
      Eigen::VectorXd lo(model.dof()), hi(model.dof());
      model.velocity_limits(theta, lo, hi);
      if (opts->json) {
        std::cout << to_json(model, k, lo, hi).dump(2) << "\n";
      } else {
        print_text(model, k, lo, hi, at_home);
      }
      return kExitOk;
    };
  });
}

}  // namespace redres::cli
