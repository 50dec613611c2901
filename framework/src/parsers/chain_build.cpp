#include "parsers/chain_build.hpp"

#include <filesystem>
#include <memory>
#include <utility>

#include "common/text.hpp"
#include "redres/model/convex.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres {

namespace {

// A velocity limit given as one number (a URDF's <limit velocity=...>) as a `constant` law of +-limit, built by name
// from the registry the way a robot file's [joints.velocity_limit] table names it (the framework includes no plugin
// header).
std::unique_ptr<VelocityLimitLaw> symmetric_constant_law(double limit, const std::filesystem::path& file) {
  auto doc = std::make_shared<TomlFile>();
  doc->path = file;
  doc->root.insert("type", "constant");
  doc->root.insert("lower", -limit);
  doc->root.insert("upper", limit);
  return make_velocity_limit(TableReader::root(doc, "velocity_limit"));
}

// Runs f, keeping a ConfigError it throws among `problems` (so that the reading goes on to find the others).
template <class F>
void gather(std::vector<ConfigError>& problems, F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    problems.push_back(e);
  }
}

// Throws the problems gathered, all in one error at the first one's place.
void throw_problems(const std::vector<ConfigError>& problems) {
  if (problems.empty()) return;
  if (problems.size() == 1) throw problems.front();
  std::string all = std::to_string(problems.size()) + " problems in this robot file:";
  for (const ConfigError& e : problems) all += "\n  " + std::string(e.what());
  throw ConfigError(problems.front().where(), all);
}

// The chain's joints, as amended, into spec.joints. Every joint's problems are gathered.
void build_joints(const ChainDescription& chain, ChainAmendments& amend, RobotSpec& spec,
                  std::vector<ConfigError>& problems) {
  amend.begin_joints(chain);
  for (const ChainJoint& cj : chain.joints) {
    JointSpec jt = cj.spec;
    gather(problems, [&] {
      amend.begin_joint(cj);
      if (amend.range(cj, jt)) {
      } else if (cj.continuous) {
        amend.fail(cj.where +
                   " is continuous, which gives it no position limits: give its `limits` in a [[joints]] entry");
      } else if (!(jt.lower < jt.upper)) {
        amend.fail(cj.where + " has limits lower " + num(jt.lower) + " >= upper " + num(jt.upper) +
                   ": fix the URDF or give its `limits` in a [[joints]] entry");
      }
      if (amend.velocity_limit(cj, jt)) {
      } else if (jt.velocity_limit) {  // the format's own law
      } else if (cj.velocity > 0.0) {
        jt.velocity_limit = symmetric_constant_law(cj.velocity, chain.file);
      } else {
        amend.fail(cj.where +
                   " has no velocity limit: give one in the URDF (<limit velocity=...>) or a `velocity_limit` in a "
                   "[[joints]] entry");
      }
      amend.end_joint(cj, jt);
    });
    spec.joints.push_back(std::move(jt));
  }
}

// The chain's links onto the joints they ride on, as amended: frames, collision shapes (meshes made capsules or hulls),
// inertias; and the visual elements into spec.visuals.
void build_links(const ChainDescription& chain, const ChainOptions& options, ChainAmendments& amend, RobotSpec& spec,
                 std::vector<ConfigError>& problems) {
  amend.begin_links(chain);
  std::vector<std::string> mesh_problems;  // every mesh that cannot be used, reported together
  const std::filesystem::path base_dir = chain.file.parent_path();
  // The visual elements, for a viewer: a mesh that cannot be found is not drawn (and says why), never an error.
  const auto add_visual = [&](const ChainVisual& v, int joint, const Eigen::Isometry3d& at) {
    VisualSpec out;
    out.kind = static_cast<VisualSpec::Kind>(static_cast<int>(v.kind));
    out.joint = joint;
    out.link = v.link;
    out.pose = at * v.pose;
    out.uri = v.filename;
    out.scale = v.scale;
    out.size = v.size;
    out.radius = v.radius;
    out.length = v.length;
    out.rgba = v.rgba;
    if (v.kind == ChainVisual::Kind::kMesh) {
      try {
        out.file = std::filesystem::absolute(resolve_mesh(v.filename, base_dir, options.packages));
      } catch (const std::exception& ex) {
        out.problem = ex.what();
      }
    }
    spec.visuals.push_back(std::move(out));
  };
  for (const ChainVisual& v : chain.base_visuals) add_visual(v, -1, Eigen::Isometry3d::Identity());
  for (const ChainLink& link : chain.links) {
    if (spec.joints.size() <= static_cast<std::size_t>(link.joint)) break;
    for (const ChainVisual& v : link.visuals) add_visual(v, link.joint, link.pose);
  }
  for (const ChainLink& link : chain.links) {
    if (spec.joints.size() <= static_cast<std::size_t>(link.joint)) break;
    JointSpec& jt = spec.joints[static_cast<std::size_t>(link.joint)];
    if (jt.link_name.empty()) jt.link_name = link.name;  // the first link met on a joint is the one it moves
    jt.frames.emplace_back(link.name, link.pose);        // every link: a frame tasks can name
    if (link.branch) jt.branch_links.push_back(link.name);
    const std::size_t first_shape = jt.collision.size();
    LinkAmendment given;
    gather(problems, [&] { amend.link(link, given); });
    const bool replace = given.replace;
    const std::string model = given.collision_model.empty() ? options.collision_model : given.collision_model;
    const std::optional<Inertia>& given_inertia = given.inertia;
    for (const ShapeSpec& shape : given.shapes) jt.collision.push_back(shape.placed(link.pose));
    // The link's mass properties (the amendment's, else the format's), in the joint's link frame; a joint's own
    // inertia given by the robot file replaces them all.
    const std::optional<Inertia>& body = given_inertia ? given_inertia : link.inertia;
    if (body && jt.inertia_source.empty()) {
      const Inertia placed = body->moved(link.pose);
      jt.inertia = jt.inertia ? jt.inertia->combined(placed) : placed;
      if (!given_inertia) {
        for (const std::string& w : link.warnings) jt.inertia_warning += (jt.inertia_warning.empty() ? "" : "; ") + w;
      }
    }
    // Every shape of this link belongs to it (a body of its own: RobotModel::bodies()).
    const auto own = [&] {
      for (std::size_t k = first_shape; k < jt.collision.size(); ++k) jt.collision[k].body = link.name;
    };
    if (replace) {
      own();
      continue;
    }
    for (const ShapeSpec& shape : link.shapes) jt.collision.push_back(shape.placed(link.pose));
    if (model == "none") {
      own();
      continue;
    }
    // Mesh collision elements: a capsule fitted to each mesh, every piece of it (a file's meshes, e.g. an OBJ's
    // material groups, or a convex decomposition's pieces) together; or ("hull") the convex hull of each piece.
    for (const ChainMesh& mesh : link.meshes) {
      try {
        const MeshData data =
            read_mesh(std::filesystem::absolute(resolve_mesh(mesh.filename, base_dir, options.packages)), mesh.scale);
        if (model == "hull") {
          const int pieces = static_cast<int>(data.pieces.size());
          for (int k = 0; k < pieces; ++k) {
            jt.collision.push_back(convex_shape(data.pieces[static_cast<std::size_t>(k)], data.file, k, pieces)
                                       .placed(link.pose * mesh.pose));
            jt.collision.back().source = data.file;
          }
          continue;
        }
        std::vector<Eigen::Vector3d> all;
        all.reserve(data.vertex_count());
        for (const auto& piece : data.pieces) all.insert(all.end(), piece.begin(), piece.end());
        jt.collision.push_back(fit_capsule(all).placed(link.pose * mesh.pose));
        jt.collision.back().source = data.file;
      } catch (const std::exception& ex) {
        mesh_problems.push_back(link.where + ": " + ex.what());
      }
    }
    own();
  }
  if (!mesh_problems.empty()) {
    std::string all = std::to_string(mesh_problems.size()) + " mesh" + (mesh_problems.size() == 1 ? "" : "es") +
                      " of " + chain.file.string() + " cannot be used:";
    for (const std::string& p : mesh_problems) all += "\n  " + p;
    all += "\n(give a link's shapes in a [[links]] entry, or set its `collision_model = \"none\"`)";
    gather(problems, [&] { amend.fail(all); });
  }
}

}  // namespace

void build_chain(const ChainDescription& chain, const ChainOptions& options, ChainAmendments& amend, RobotSpec& spec,
                 std::vector<ConfigError>& problems) {
  spec.end_effector = chain.tip;
  for (const HeldJoint& h : chain.held) spec.held_joints.emplace_back(h.name, h.value);
  build_joints(chain, amend, spec, problems);
  build_links(chain, options, amend, spec, problems);
  throw_problems(problems);
}

}  // namespace redres
