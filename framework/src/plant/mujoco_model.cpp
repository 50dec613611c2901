// MujocoModel: a generated MJCF loaded with MuJoCo. The only file of redres that includes MuJoCo's headers; without
// MuJoCo (REDRES_HAVE_MUJOCO not set) loading throws.

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "redres/plant/mujoco_model.hpp"

#if REDRES_HAVE_MUJOCO
#include <cstring>
#include <mutex>

#include "plant/mujoco_load.hpp"
#endif

namespace redres {

std::string mujoco_missing() {
  return "redres was built without MuJoCo: install Debian's package libmujoco-dev (scripts/install_deps.sh installs "
         "it) and build again (CMake option REDRES_WITH_MUJOCO, on when MuJoCo is found)";
}

#if REDRES_HAVE_MUJOCO

bool mujoco_available() noexcept { return true; }

struct MujocoModel::Impl {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  ~Impl() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

namespace {
[[noreturn]] void throw_mujoco_error(const char* message) {
  throw std::runtime_error(std::string("MuJoCo failed: ") + message);
}
}  // namespace

void plant_detail::throw_on_mujoco_errors() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = throw_mujoco_error;
    // Warnings are counted in mjData, where the plant reads the ones that matter and says so in its own words.
    mju_user_warning = [](const char*) {};
  });
}

mjModel* plant_detail::load_mjcf(const std::string& xml) {
  throw_on_mujoco_errors();
  // MuJoCo 2.2 reads XML only from a file name; a virtual file holds the text. (mjVFS is megabytes: on the heap.)
  struct Vfs {
    mjVFS vfs;
    Vfs() { mj_defaultVFS(&vfs); }
    ~Vfs() { mj_deleteVFS(&vfs); }
  };
  auto vfs = std::make_unique<Vfs>();
  const char* name = "redres_model.xml";
  if (mj_makeEmptyFileVFS(&vfs->vfs, name, static_cast<int>(xml.size())) != 0)
    throw std::runtime_error("MuJoCo: cannot make a virtual file for the model");
  const int index = mj_findFileVFS(&vfs->vfs, name);
  std::memcpy(vfs->vfs.filedata[index], xml.data(), xml.size());
  char error[1000] = "";
  // One load at a time: MuJoCo 2.2's XML reader and compiler are not documented as safe to run in parallel (a sweep
  // loads its runs' plants from several threads). The models it makes are independent.
  static std::mutex loading;
  const std::lock_guard<std::mutex> lock(loading);
  mjModel* m = mj_loadXML(name, &vfs->vfs, error, sizeof error);
  if (!m) throw std::runtime_error(std::string("MuJoCo refused the model: ") + error);
  return m;
}

MujocoModel MujocoModel::from_xml(const std::string& xml) {
  mjModel* m = plant_detail::load_mjcf(xml);
  auto impl = std::make_unique<Impl>();
  impl->m = m;
  impl->d = mj_makeData(m);
  if (!impl->d) throw std::runtime_error("MuJoCo: cannot make the model's data");
  return MujocoModel(std::move(impl));
}

int MujocoModel::nq() const { return impl_->m->nq; }
int MujocoModel::nbody() const { return impl_->m->nbody; }
int MujocoModel::ngeom() const { return impl_->m->ngeom; }
int MujocoModel::nmesh() const { return impl_->m->nmesh; }
int MujocoModel::nexclude() const { return impl_->m->nexclude; }
int MujocoModel::body(const std::string& name) const { return mj_name2id(impl_->m, mjOBJ_BODY, name.c_str()); }
int MujocoModel::joint(const std::string& name) const { return mj_name2id(impl_->m, mjOBJ_JOINT, name.c_str()); }
int MujocoModel::site(const std::string& name) const { return mj_name2id(impl_->m, mjOBJ_SITE, name.c_str()); }
int MujocoModel::geom(const std::string& name) const { return mj_name2id(impl_->m, mjOBJ_GEOM, name.c_str()); }
double MujocoModel::body_mass(int b) const { return impl_->m->body_mass[b]; }
Eigen::Vector3d MujocoModel::body_com(int b) const { return Eigen::Vector3d(impl_->m->body_ipos + 3 * b); }

Eigen::Matrix3d MujocoModel::body_inertia(int b) const {
  const mjtNum* q = impl_->m->body_iquat + 4 * b;
  const Eigen::Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  const Eigen::Vector3d moments(impl_->m->body_inertia + 3 * b);
  return R * moments.asDiagonal() * R.transpose();
}

Eigen::Vector2d MujocoModel::joint_range(int j) const { return Eigen::Vector2d(impl_->m->jnt_range + 2 * j); }
bool MujocoModel::joint_limited(int j) const { return impl_->m->jnt_limited[j] != 0; }

bool MujocoModel::excluded(int body1, int body2) const {
  // MuJoCo 2.2 stores a pair as ((body1 + 1) << 16) + body2 + 1, in the order the <exclude> names them.
  const int forward = ((body1 + 1) << 16) + body2 + 1, backward = ((body2 + 1) << 16) + body1 + 1;
  for (int i = 0; i < impl_->m->nexclude; ++i)
    if (impl_->m->exclude_signature[i] == forward || impl_->m->exclude_signature[i] == backward) return true;
  return false;
}

void MujocoModel::kinematics(const Eigen::Ref<const Eigen::VectorXd>& q) {
  if (q.size() != impl_->m->nq)
    throw std::invalid_argument("MujocoModel::kinematics: q has " + std::to_string(q.size()) + " entries, nq is " +
                                std::to_string(impl_->m->nq));
  for (int i = 0; i < impl_->m->nq; ++i) impl_->d->qpos[i] = q(i);
  mj_kinematics(impl_->m, impl_->d);
}

namespace {
// MuJoCo's rotation matrices are row-major.
Eigen::Isometry3d pose_from(const mjtNum* pos, const mjtNum* mat) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(pos);
  T.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(mat);
  return T;
}
}  // namespace

Eigen::Isometry3d MujocoModel::site_pose(int s) const {
  return pose_from(impl_->d->site_xpos + 3 * s, impl_->d->site_xmat + 9 * s);
}
Eigen::Isometry3d MujocoModel::body_pose(int b) const {
  return pose_from(impl_->d->xpos + 3 * b, impl_->d->xmat + 9 * b);
}
Eigen::Isometry3d MujocoModel::geom_pose(int g) const {
  return pose_from(impl_->d->geom_xpos + 3 * g, impl_->d->geom_xmat + 9 * g);
}

Eigen::Matrix3Xd MujocoModel::mesh_vertices(int g) const {
  const mjModel* m = impl_->m;
  const int mesh = m->geom_dataid[g];
  if (m->geom_type[g] != mjGEOM_MESH || mesh < 0) return Eigen::Matrix3Xd(3, 0);
  const Eigen::Isometry3d T = geom_pose(g);
  Eigen::Matrix3Xd out(3, m->mesh_vertnum[mesh]);
  const float* v = m->mesh_vert + 3 * m->mesh_vertadr[mesh];
  for (int i = 0; i < m->mesh_vertnum[mesh]; ++i)
    out.col(i) = T * Eigen::Vector3d(static_cast<double>(v[3 * i]), static_cast<double>(v[3 * i + 1]),
                                     static_cast<double>(v[3 * i + 2]));
  return out;
}

#else  // without MuJoCo

bool mujoco_available() noexcept { return false; }

struct MujocoModel::Impl {};

MujocoModel MujocoModel::from_xml(const std::string&) { throw std::runtime_error(mujoco_missing()); }

namespace {
[[noreturn]] void unavailable() { throw std::logic_error("MujocoModel: redres was built without MuJoCo"); }
}  // namespace

int MujocoModel::nq() const { unavailable(); }
int MujocoModel::nbody() const { unavailable(); }
int MujocoModel::ngeom() const { unavailable(); }
int MujocoModel::nmesh() const { unavailable(); }
int MujocoModel::nexclude() const { unavailable(); }
int MujocoModel::body(const std::string&) const { unavailable(); }
int MujocoModel::joint(const std::string&) const { unavailable(); }
int MujocoModel::site(const std::string&) const { unavailable(); }
double MujocoModel::body_mass(int) const { unavailable(); }
Eigen::Vector3d MujocoModel::body_com(int) const { unavailable(); }
Eigen::Matrix3d MujocoModel::body_inertia(int) const { unavailable(); }
Eigen::Vector2d MujocoModel::joint_range(int) const { unavailable(); }
bool MujocoModel::joint_limited(int) const { unavailable(); }
bool MujocoModel::excluded(int, int) const { unavailable(); }
void MujocoModel::kinematics(const Eigen::Ref<const Eigen::VectorXd>&) { unavailable(); }
Eigen::Isometry3d MujocoModel::site_pose(int) const { unavailable(); }
Eigen::Isometry3d MujocoModel::body_pose(int) const { unavailable(); }
int MujocoModel::geom(const std::string&) const { unavailable(); }
Eigen::Isometry3d MujocoModel::geom_pose(int) const { unavailable(); }
Eigen::Matrix3Xd MujocoModel::mesh_vertices(int) const { unavailable(); }

#endif

MujocoModel::MujocoModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MujocoModel::MujocoModel(MujocoModel&&) noexcept = default;
MujocoModel& MujocoModel::operator=(MujocoModel&&) noexcept = default;
MujocoModel::~MujocoModel() = default;

}  // namespace redres
