#include "parsers/urdf_overlay.hpp"

#include <algorithm>
#include <map>
#include <memory>

#include "common/text.hpp"
#include "parsers/robot_toml_values.hpp"
#include "redres/model/convex.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres {

namespace {

// The URDF's <limit velocity=...> as a `constant` law of +-limit, built by name from the registry the way a robot
// file's [joints.velocity_limit] table names it (the framework includes no plugin header).
std::unique_ptr<VelocityLimitLaw> symmetric_constant_law(double limit, const std::filesystem::path& file) {
  auto doc = std::make_shared<TomlFile>();
  doc->path = file;
  doc->root.insert("type", "constant");
  doc->root.insert("lower", -limit);
  doc->root.insert("upper", limit);
  return make_velocity_limit(TableReader::root(doc, "velocity_limit"));
}

// Runs f, keeping a ConfigError it throws among c.problems (so that the reading goes on to find the others).
template <class F>
void gather(RobotReading& c, F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    c.problems.push_back(e);
  }
}

// Throws the problems gathered, all in one error at the first one's place.
void throw_problems(const RobotReading& c) {
  if (c.problems.empty()) return;
  if (c.problems.size() == 1) throw c.problems.front();
  std::string all = std::to_string(c.problems.size()) + " problems in this robot file:";
  for (const ConfigError& e : c.problems) all += "\n  " + std::string(e.what());
  throw ConfigError(c.problems.front().where(), all);
}

}  // namespace

void read_urdf_joints(const TableReader& r, RobotReading& c) {
  const std::map<std::string, TableReader> overrides = named_entries(
      r, "joints",
      [&](const std::string& name) {
        return std::any_of(c.chain.joints.begin(), c.chain.joints.end(),
                           [&](const UrdfJoint& j) { return j.name == name; });
      },
      "joint", "moving joint", " between '" + c.base_link + "' and '" + c.tip_link + "' in " + c.urdf.string(),
      &c.problems);
  for (const UrdfJoint& uj : c.chain.joints) {
    JointSpec jt;
    jt.name = uj.name;
    jt.type = uj.prismatic ? JointType::kPrismatic : JointType::kRevolute;
    jt.origin = uj.origin;
    jt.axis = uj.axis;
    jt.lower = uj.lower;
    jt.upper = uj.upper;
    gather(c, [&] {
      const auto o = overrides.find(uj.name);
      const std::optional<TableReader> entry =
          o == overrides.end() ? std::nullopt
                               : std::optional<TableReader>(
                                     TableReader(o->second.file_ptr(), o->second.raw(), "joint '" + uj.name + "'"));
      if (entry) (void)entry->has("name");
      if (entry && entry->has("limits")) {
        read_limits(*entry, jt);
      } else if (uj.continuous) {
        r.fail("urdf", uj.where +
                           " is continuous, which gives it no position limits: give its `limits` in a "
                           "[[joints]] entry");
      } else if (!(uj.lower < uj.upper)) {
        r.fail("urdf", uj.where + " has limits lower " + num(uj.lower) + " >= upper " + num(uj.upper) +
                           ": fix the URDF or give its `limits` in a [[joints]] entry");
      }
      if (entry && entry->has("velocity_limit")) {
        read_velocity_law(*entry, jt);
      } else if (uj.velocity > 0.0) {
        jt.velocity_limit = symmetric_constant_law(uj.velocity, c.urdf);
      } else {
        r.fail("urdf", uj.where +
                           " has no velocity limit: give one in the URDF (<limit velocity=...>) or a `velocity_limit` "
                           "in a [[joints]] entry");
      }
      if (uj.effort > 0.0) jt.effort_limit = uj.effort;
      if (uj.damping >= 0.0) jt.damping = uj.damping;
      if (entry) read_motion_limits(*entry, jt);
      if (entry) entry->finish();
    });
    c.spec.joints.push_back(std::move(jt));
  }
}

const Schema<LinkEntry>& LinkEntry::schema() {
  using C = LinkEntry;
  static const Schema<C> s{{
      field("name", &C::name, "", "the URDF link's name").required(),
      field("replace", &C::replace, "", "the shapes replace the URDF's collision elements (false: add to them)"),
      field("collision", &C::collision, "", "the link's shapes, in the link's frame (capsules need `length`)")
          .listed_default("[] (none)"),
      field("collision_model", &C::collision_model, "",
            "what this link's mesh collision elements become: \"capsule\", \"hull\" or \"none\" (default: the "
            "robot's)",
            rule<std::string>("\"capsule\", \"hull\" or \"none\"",
                              [](const std::string& v) { return v == "capsule" || v == "hull" || v == "none"; }))
          .listed_default("the robot's `collision_model`"),
      entry<C>("inertia", "table {mass, com, ixx, iyy, izz, ixy, ixz, iyz}", "kg, m, kg m^2", "the URDF's <inertial>",
               "the link's mass properties, in the link's frame, replacing the URDF's (as a [[joints]] entry's "
               "`inertia`)",
               [](const TableReader& r, C& c) {
                 if (r.has("inertia")) c.inertia = read_inertia_table(r, "link '" + c.name + "'");
               }),
  }};
  return s;
}

void read_urdf_links(const TableReader& r, RobotReading& c) {
  std::string moving;  // the links that move with the chain, for the message naming a missing one
  for (const UrdfLink& l : c.chain.links) moving += (moving.empty() ? "'" : ", '") + l.name + "'";
  std::string all_links;
  for (const std::string& l : c.chain.all_links) all_links += (all_links.empty() ? "'" : ", '") + l + "'";
  const std::map<std::string, TableReader> link_entries = named_entries(
      r, "links",
      [&](const std::string& name) {
        return std::any_of(c.chain.links.begin(), c.chain.links.end(),
                           [&](const UrdfLink& l) { return l.name == name; });
      },
      "link", "link",
      " that moves with the chain from '" + c.base_link + "' to '" + c.tip_link + "' in " + c.urdf.string() +
          " (those are " + moving + "; the file's links are " + all_links + ")",
      &c.problems);
  std::vector<std::string> problems;  // every mesh that cannot be used, reported together
  const std::filesystem::path base_dir = c.urdf.parent_path();
  // The visual elements, for a viewer: a mesh that cannot be found is not drawn (and says why), never an error.
  const auto add_visual = [&](const UrdfVisual& v, int joint, const Eigen::Isometry3d& at) {
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
    if (v.kind == UrdfVisual::Kind::kMesh) {
      try {
        out.file = std::filesystem::absolute(resolve_mesh(v.filename, base_dir, c.packages));
      } catch (const std::exception& ex) {
        out.problem = ex.what();
      }
    }
    c.spec.visuals.push_back(std::move(out));
  };
  for (const UrdfVisual& v : c.chain.base_visuals) add_visual(v, -1, Eigen::Isometry3d::Identity());
  for (const UrdfLink& link : c.chain.links) {
    if (c.spec.joints.size() <= static_cast<std::size_t>(link.joint)) break;
    for (const UrdfVisual& v : link.visuals) add_visual(v, link.joint, link.pose);
  }
  for (const UrdfLink& link : c.chain.links) {
    if (c.spec.joints.size() <= static_cast<std::size_t>(link.joint)) break;
    JointSpec& jt = c.spec.joints[static_cast<std::size_t>(link.joint)];
    if (jt.link_name.empty()) jt.link_name = link.name;  // the first link met on a joint is the one it moves
    jt.frames.emplace_back(link.name, link.pose);        // every link: a frame tasks can name
    if (link.branch) jt.branch_links.push_back(link.name);
    const std::size_t first_shape = jt.collision.size();
    const auto e = link_entries.find(link.name);
    bool replace = false;
    std::string model = c.collision_model;
    std::optional<Inertia> given_inertia;
    if (e != link_entries.end())
      gather(c, [&] {
        const TableReader entry(e->second.file_ptr(), e->second.raw(), "link '" + link.name + "'");
        LinkEntry links;
        read_config(entry, LinkEntry::schema(), links);
        replace = links.replace;
        if (!links.collision_model.empty()) model = links.collision_model;
        given_inertia = links.inertia;
        for (std::size_t k = 0; k < links.collision.size(); ++k) {
          const ShapeSpec& shape = links.collision[k];
          if (shape.shape == ShapeSpec::Kind::kCapsule && !shape.length && !shape.from) {
            entry.fail("collision", "shape " + std::to_string(k + 1) +
                                        ": a capsule of a URDF link needs `length` (with `xyz`, `rpy`) or `from` and "
                                        "`to`, in the link's frame");
          }
          if (shape.velocity) {
            entry.fail("collision", "shape " + std::to_string(k + 1) + " has a velocity; only obstacles move");
          }
          jt.collision.push_back(shape.placed(link.pose));
        }
        entry.finish();
      });
    // The link's mass properties (the [[links]] entry's, else the URDF's), in the joint's link frame; a [[joints]]
    // entry's `inertia` replaces them all.
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
    for (const UrdfMesh& mesh : link.meshes) {
      try {
        const MeshData data =
            read_mesh(std::filesystem::absolute(resolve_mesh(mesh.filename, base_dir, c.packages)), mesh.scale);
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
        problems.push_back(link.where + ": " + ex.what());
      }
    }
    own();
  }
  if (!problems.empty()) {
    std::string all = std::to_string(problems.size()) + " mesh" + (problems.size() == 1 ? "" : "es") + " of " +
                      c.urdf.string() + " cannot be used:";
    for (const std::string& p : problems) all += "\n  " + p;
    all += "\n(give a link's shapes in a [[links]] entry, or set its `collision_model = \"none\"`)";
    gather(c, [&] { r.fail("urdf", all); });
  }
  throw_problems(c);
}

}  // namespace redres
