// MujocoPlant: the controller's commands applied to the robot in MuJoCo (docs/plant.md, "The plant").

#include "redres/plant/mujoco_plant.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "redres/plant/mujoco_model.hpp"

#if REDRES_HAVE_MUJOCO
#include "plant/mujoco_load.hpp"
#endif

namespace redres {

namespace {

// The plant's timing (plant_timing()); a control period that is not positive is refused first.
PlantTiming resolve_timing(const PlantConfig& config, double control_period) {
  if (!(control_period > 0.0)) throw std::invalid_argument("MujocoPlant: the control period must be > 0");
  return plant_timing(config, control_period);
}

}  // namespace

#if REDRES_HAVE_MUJOCO

struct MujocoPlant::Impl {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  std::string xml;
  PlantConfig config;
  PlantTiming timing;
  int n = 0;
  Eigen::VectorXd kv, kp, kd, effort;  // effort: +inf where the joint has no limit
  std::vector<int> qadr, dofadr;       // joint j's qpos and dof addresses
  std::vector<char> robot_body;        // body b is the robot's (not the world, not a mocap obstacle)
  // The measured states of the last delay_steps + 1 MuJoCo steps (a ring; column `head` is the newest).
  Eigen::MatrixXd hist_q, hist_v;
  int head = 0;
  Eigen::VectorXd theta_m, theta_dot_m;
  Eigen::VectorXd q_ref, gravity, command_prev;
  std::vector<mjtNum> jacp;
  Eigen::VectorXd torque, torque_prev, max_torque, max_rate;
  bool have_torque = false;
  int contacts = 0;
  double penetration = 0.0;
  struct Pair {
    int a = 0, b = 0;  // owners: a body id, or nbody + geom id for a geom of the world body
    double first = 0.0, deepest = 0.0;
    long steps = 0;
    long last = -1;  // the last MuJoCo step (tick) that counted
  };
  long tick = 0;  // MuJoCo steps taken so far
  std::vector<std::string> joint_names;
  std::vector<Pair> pairs;
  long steps = 0;
  double seconds = 0.0;
  std::vector<ShapeSpec> obstacles;
  std::vector<int> mocap;  // obstacle k's mocap id, -1 when it is still

  ~Impl() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }

  [[nodiscard]] int owner(int geom) const {
    const int b = m->geom_bodyid[geom];
    return b == 0 ? m->nbody + geom : b;
  }
  [[nodiscard]] std::string owner_name(int o) const {
    const char* name = o < m->nbody ? mj_id2name(m, mjOBJ_BODY, o) : mj_id2name(m, mjOBJ_GEOM, o - m->nbody);
    return name ? name : "?";
  }

  void move_obstacles(double t) {
    for (std::size_t k = 0; k < obstacles.size(); ++k) {
      const int id = mocap[k];
      if (id < 0) continue;
      const Eigen::Vector3d p = obstacles[k].pose().translation();
      const std::array<double, 3>& v = *obstacles[k].velocity;
      for (int r = 0; r < 3; ++r) d->mocap_pos[3 * id + r] = p(r) + v[static_cast<std::size_t>(r)] * t;
    }
  }

  // The contacts of the current state (after the position stage) that involve the robot, at time t.
  void note_contacts(double t) {
    int count = 0;
    for (int i = 0; i < d->ncon; ++i) {
      const mjContact& c = d->contact[i];
      int a = owner(c.geom1), b = owner(c.geom2);
      const bool robot = (a < m->nbody && robot_body[static_cast<std::size_t>(a)] != 0) ||
                         (b < m->nbody && robot_body[static_cast<std::size_t>(b)] != 0);
      if (!robot) continue;
      ++count;
      const double depth = std::max(0.0, -c.dist);
      penetration = std::max(penetration, depth);
      if (a > b) std::swap(a, b);
      auto it = std::find_if(pairs.begin(), pairs.end(), [a, b](const Pair& p) { return p.a == a && p.b == b; });
      if (it == pairs.end()) {
        pairs.push_back({a, b, t, depth, 0, -1});  // storage reserved at setup
        it = pairs.end() - 1;
      }
      it->deepest = std::max(it->deepest, depth);
      if (it->last != tick) ++it->steps;  // a pair may touch at several points: one step
      it->last = tick;
    }
    ++tick;
    contacts = std::max(contacts, count);
  }

  // g(q): the joint torques that hold the robot against gravity (after mj_kinematics and mj_comPos).
  void gravity_torques() {
    gravity.setZero();
    const int nv = m->nv;
    const mjtNum* g = m->opt.gravity;
    for (int b = 1; b < m->nbody; ++b) {
      if (robot_body[static_cast<std::size_t>(b)] == 0) continue;
      mj_jacBodyCom(m, d, jacp.data(), nullptr, b);
      const double mass = m->body_mass[b];
      for (int j = 0; j < n; ++j) {
        const int dof = dofadr[static_cast<std::size_t>(j)];
        double s = 0.0;
        for (int r = 0; r < 3; ++r) s += jacp[static_cast<std::size_t>(r * nv + dof)] * g[r];
        gravity(j) -= mass * s;
      }
    }
  }

  void sample() {
    head = (head + 1) % static_cast<int>(hist_q.cols());
    for (int j = 0; j < n; ++j) {
      hist_q(j, head) = d->qpos[qadr[static_cast<std::size_t>(j)]];
      hist_v(j, head) = d->qvel[dofadr[static_cast<std::size_t>(j)]];
    }
    // The oldest column of the ring is the state delay_steps ago.
    const int oldest = (head + 1) % static_cast<int>(hist_q.cols());
    theta_m = hist_q.col(oldest);
    theta_dot_m = hist_v.col(oldest);
  }

  void note_torque() {
    for (int j = 0; j < n; ++j) {
      max_torque(j) = std::max(max_torque(j), std::abs(torque(j)));
      if (have_torque) max_rate(j) = std::max(max_rate(j), std::abs(torque(j) - torque_prev(j)) / timing.timestep);
    }
    torque_prev = torque;
    have_torque = true;
  }

  void step_actuated(const Eigen::Ref<const Eigen::VectorXd>& command, double t) {
    move_obstacles(t);
    // One whole mj_step (MuJoCo's split step1/step2 integrates with Euler whatever the model says, which a stiff servo
    // on a light link does not survive): g(q) from the kinematics at the current state first.
    if (config.gravity_compensation) {
      mj_kinematics(m, d);
      mj_comPos(m, d);
      gravity_torques();
    } else {
      gravity.setZero();
    }
    const bool servo = config.actuator == PlantActuator::kVelocityServo;
    for (int j = 0; j < n; ++j) {
      const double e = effort(j);
      const double gc = std::clamp(gravity(j), -e, e);
      d->qfrc_applied[dofadr[static_cast<std::size_t>(j)]] = gc;
      if (std::isfinite(e)) {  // the total torque stays within the effort limit
        m->actuator_forcerange[2 * j] = -e - gc;
        m->actuator_forcerange[2 * j + 1] = e - gc;
      }
      d->ctrl[j] = servo ? command(j) : kp(j) * q_ref(j) + kd(j) * command(j);
      gravity(j) = gc;
    }
    mj_step(m, d);
    note_contacts(t);  // the collisions of the step's position stage: the state at t
    for (int j = 0; j < n; ++j) {
      torque(j) = d->actuator_force[j] + gravity(j);
      q_ref(j) += timing.timestep * command(j);
    }
  }

  void step_ideal(const Eigen::Ref<const Eigen::VectorXd>& command, double t) {
    move_obstacles(t);
    for (int j = 0; j < n; ++j) {
      const int dof = dofadr[static_cast<std::size_t>(j)];
      d->qacc[dof] = (command(j) - command_prev(j)) / timing.timestep;
      d->qvel[dof] = command(j);
    }
    mj_inverse(m, d);  // the torques this motion takes, and the collisions at the current state
    note_contacts(t);
    for (int j = 0; j < n; ++j) torque(j) = d->qfrc_inverse[dofadr[static_cast<std::size_t>(j)]];
    mj_integratePos(m, d->qpos, d->qvel, timing.timestep);
    d->time += timing.timestep;
    command_prev = command;
  }
};

MujocoPlant::MujocoPlant(const RobotModel& robot, const PlantConfig& config, double control_period,
                         std::vector<ShapeSpec> obstacles, const Eigen::VectorXd& theta0)
    : impl_(std::make_unique<Impl>()) {
  Impl& p = *impl_;
  p.n = robot.dof();
  const int n = p.n;
  if (theta0.size() != n)
    throw std::invalid_argument("MujocoPlant: theta0 has " + std::to_string(theta0.size()) + " entries, expected " +
                                std::to_string(n));
  p.config = config;
  p.timing = resolve_timing(config, control_period);
  p.config.timestep = p.timing.timestep;
  p.kv = config.kv.resolve(n, "kv");
  p.kp = config.kp.resolve(n, "kp");
  p.kd = config.kd.resolve(n, "kd");
  MjcfOptions options;
  options.plant = p.config;
  options.obstacles = obstacles;
  p.xml = mjcf_from_robot(robot, options);
  p.m = plant_detail::load_mjcf(p.xml);
  p.d = mj_makeData(p.m);
  if (!p.d) throw std::runtime_error("MuJoCo: cannot make the model's data");
  p.obstacles = std::move(obstacles);
  for (std::size_t k = 0; k < p.obstacles.size(); ++k) {
    const int body = mj_name2id(p.m, mjOBJ_BODY, ("obstacle" + std::to_string(k)).c_str());
    p.mocap.push_back(body >= 0 ? p.m->body_mocapid[body] : -1);
  }
  p.effort = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  for (int j = 0; j < n; ++j) {
    const JointSpec& joint = robot.joint(j);
    if (joint.effort_limit) p.effort(j) = *joint.effort_limit;
    const int id = mj_name2id(p.m, mjOBJ_JOINT, joint.name.c_str());
    if (id < 0) throw std::logic_error("MujocoPlant: joint '" + joint.name + "' is not in the generated model");
    p.joint_names.push_back(joint.name);
    p.qadr.push_back(p.m->jnt_qposadr[id]);
    p.dofadr.push_back(p.m->jnt_dofadr[id]);
    p.d->qpos[p.qadr.back()] = theta0(j);
  }
  p.robot_body.assign(static_cast<std::size_t>(p.m->nbody), 0);
  for (int b = 1; b < p.m->nbody; ++b) p.robot_body[static_cast<std::size_t>(b)] = p.m->body_mocapid[b] < 0 ? 1 : 0;
  p.hist_q = theta0.replicate(1, p.timing.delay_steps + 1);
  p.hist_v = Eigen::MatrixXd::Zero(n, p.timing.delay_steps + 1);
  p.theta_m = theta0;
  p.theta_dot_m = Eigen::VectorXd::Zero(n);
  p.q_ref = theta0;
  p.gravity = Eigen::VectorXd::Zero(n);
  p.command_prev = Eigen::VectorXd::Zero(n);
  p.jacp.assign(static_cast<std::size_t>(3 * p.m->nv), 0.0);
  p.torque = p.torque_prev = p.max_torque = p.max_rate = Eigen::VectorXd::Zero(n);
  const std::size_t owners = static_cast<std::size_t>(p.m->nbody + p.m->ngeom);
  p.pairs.reserve(std::min<std::size_t>(owners * owners / 2 + 1, 1u << 16));
  p.move_obstacles(0.0);
  mj_forward(p.m, p.d);
}

MujocoPlant::~MujocoPlant() = default;

void MujocoPlant::advance(const Eigen::Ref<const Eigen::VectorXd>& command, double t) {
  Impl& p = *impl_;
  if (command.size() != p.n)
    throw std::invalid_argument("MujocoPlant::advance: the command has " + std::to_string(command.size()) +
                                " entries, expected " + std::to_string(p.n));
  if (!command.allFinite()) throw std::invalid_argument("MujocoPlant::advance: the command is not finite");
  const auto start = std::chrono::steady_clock::now();
  p.contacts = 0;
  p.penetration = 0.0;
  for (int s = 0; s < p.timing.substeps; ++s) {
    const double ts = t + s * p.timing.timestep;
    if (p.config.actuator == PlantActuator::kIdealVelocity) {
      p.step_ideal(command, ts);
    } else {
      p.step_actuated(command, ts);
    }
    p.note_torque();
    p.sample();
  }
  p.steps += p.timing.substeps;
  p.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // MuJoCo resets a state it finds bad (a non-finite or huge acceleration, velocity or position) and goes on with a
  // warning: a run on after that would be garbage. A full contact or constraint buffer drops contacts: the same.
  static constexpr std::pair<int, const char*> kFatal[] = {
      {mjWARN_BADQACC, "a bad acceleration (MuJoCo reset the state)"},
      {mjWARN_BADQVEL, "a bad velocity (MuJoCo reset the state)"},
      {mjWARN_BADQPOS, "a bad position (MuJoCo reset the state)"},
      {mjWARN_CONTACTFULL, "more contacts than its buffer holds"},
      {mjWARN_CNSTRFULL, "more constraints than its buffer holds"}};
  for (const auto& [warning, what] : kFatal) {
    if (p.d->warning[warning].number > 0) {
      throw std::runtime_error("MuJoCo's simulation failed between t = " + std::to_string(t) + " and " +
                               std::to_string(t + p.timing.substeps * p.timing.timestep) + " s: " + what +
                               "; try a smaller [plant] timestep, smaller gains, an `armature` on light joints, or "
                               "the implicit integrator");
    }
  }
  for (int j = 0; j < p.n; ++j) {
    if (!std::isfinite(p.d->qpos[p.qadr[static_cast<std::size_t>(j)]])) {
      throw std::runtime_error("MuJoCo's simulation diverged at t = " + std::to_string(t) + " s (joint '" +
                               p.joint_names[static_cast<std::size_t>(j)] +
                               "' is not finite): try a smaller [plant] timestep, smaller gains, or an armature");
    }
  }
}

const std::string& MujocoPlant::mjcf() const { return impl_->xml; }
double MujocoPlant::timestep() const { return impl_->timing.timestep; }
int MujocoPlant::substeps() const { return impl_->timing.substeps; }
const Eigen::VectorXd& MujocoPlant::theta() const { return impl_->theta_m; }
const Eigen::VectorXd& MujocoPlant::theta_dot() const { return impl_->theta_dot_m; }
const Eigen::VectorXd& MujocoPlant::torque() const { return impl_->torque; }
int MujocoPlant::contacts() const { return impl_->contacts; }
double MujocoPlant::penetration() const { return impl_->penetration; }
const Eigen::VectorXd& MujocoPlant::max_torque() const { return impl_->max_torque; }
const Eigen::VectorXd& MujocoPlant::max_torque_rate() const { return impl_->max_rate; }
long MujocoPlant::mujoco_steps() const { return impl_->steps; }
double MujocoPlant::mujoco_seconds() const { return impl_->seconds; }

std::vector<PlantContactPair> MujocoPlant::contact_pairs() const {
  std::vector<PlantContactPair> out;
  for (const Impl::Pair& p : impl_->pairs)
    out.push_back({impl_->owner_name(p.a), impl_->owner_name(p.b), p.first, p.deepest, p.steps});
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.first_time < y.first_time; });
  return out;
}

Eigen::Matrix3Xd MujocoPlant::mocap_positions(double t) const { return mjcf_mocap_positions(impl_->obstacles, t); }

#else  // without MuJoCo

struct MujocoPlant::Impl {};

MujocoPlant::MujocoPlant(const RobotModel&, const PlantConfig& config, double control_period, std::vector<ShapeSpec>,
                         const Eigen::VectorXd&) {
  (void)resolve_timing(config, control_period);
  throw std::runtime_error(mujoco_missing());
}
MujocoPlant::~MujocoPlant() = default;

namespace {
[[noreturn]] void unavailable() { throw std::logic_error("MujocoPlant: redres was built without MuJoCo"); }
}  // namespace

void MujocoPlant::advance(const Eigen::Ref<const Eigen::VectorXd>&, double) { unavailable(); }
const std::string& MujocoPlant::mjcf() const { unavailable(); }
double MujocoPlant::timestep() const { unavailable(); }
int MujocoPlant::substeps() const { unavailable(); }
const Eigen::VectorXd& MujocoPlant::theta() const { unavailable(); }
const Eigen::VectorXd& MujocoPlant::theta_dot() const { unavailable(); }
const Eigen::VectorXd& MujocoPlant::torque() const { unavailable(); }
int MujocoPlant::contacts() const { unavailable(); }
double MujocoPlant::penetration() const { unavailable(); }
const Eigen::VectorXd& MujocoPlant::max_torque() const { unavailable(); }
const Eigen::VectorXd& MujocoPlant::max_torque_rate() const { unavailable(); }
std::vector<PlantContactPair> MujocoPlant::contact_pairs() const { unavailable(); }
long MujocoPlant::mujoco_steps() const { unavailable(); }
double MujocoPlant::mujoco_seconds() const { unavailable(); }
Eigen::Matrix3Xd MujocoPlant::mocap_positions(double) const { unavailable(); }

#endif

}  // namespace redres
