#include "random_chain.hpp"

#include "redres/config/toml_reader.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"

namespace redres::testing {

std::shared_ptr<const VelocityLimitLaw> constant_law(double limit) {
  const std::string text =
      "type = \"constant\"\nlower = " + std::to_string(-limit) + "\nupper = " + std::to_string(limit) + "\n";
  const auto file = parse_toml_string(text, "<test>");
  return velocity_limit_registry().create(TableReader::root(file));
}

RobotSpec random_planar(int n, TaskRows task) {
  RobotSpec spec;
  spec.name = "random_planar";
  spec.kind = ChainKind::kPlanar;
  spec.task = task;
  for (int j = 0; j < n; ++j) {
    JointSpec jt;
    jt.name = "j" + std::to_string(j + 1);
    jt.length = draw(0.05, 1.0);
    jt.lower = -draw(0.2, 3.0);
    jt.upper = draw(0.2, 3.0);
    jt.velocity_limit = constant_law(1.0);
    spec.joints.push_back(jt);
  }
  if (*rc::gen::inRange(0, 2) == 1) {
    spec.end_effector.translation() = Eigen::Vector3d(draw(-0.2, 0.2), draw(-0.2, 0.2), 0.0);
    spec.end_effector.rotate(Eigen::AngleAxisd(draw(-1.0, 1.0), Eigen::Vector3d::UnitZ()));
  }
  if (*rc::gen::inRange(0, 2) == 1) {  // a base moved and turned in the plane
    spec.base.translation() = Eigen::Vector3d(draw(-0.5, 0.5), draw(-0.5, 0.5), 0.0);
    spec.base.rotate(Eigen::AngleAxisd(draw(-3.0, 3.0), Eigen::Vector3d::UnitZ()));
  }
  return spec;
}

RobotSpec random_spatial(int n, TaskRows task) {
  RobotSpec spec;
  spec.name = "random_spatial";
  spec.kind = ChainKind::kSpatial;
  spec.task = task;
  const int convention = *rc::gen::inRange(0, 3);
  spec.convention = convention == 0   ? DhConvention::kStandard
                    : convention == 1 ? DhConvention::kModified
                                      : DhConvention::kJointFrames;
  for (int j = 0; j < n; ++j) {
    JointSpec jt;
    jt.name = "j" + std::to_string(j + 1);
    jt.type = *rc::gen::inRange(0, 4) == 0 ? JointType::kPrismatic : JointType::kRevolute;
    if (spec.convention == DhConvention::kJointFrames) {
      // A random origin (offset and turn) and a random axis, as a URDF joint has.
      jt.origin.translation() = Eigen::Vector3d(draw(-0.4, 0.4), draw(-0.4, 0.4), draw(-0.4, 0.4));
      jt.origin.rotate(Eigen::AngleAxisd(draw(-3.14, 3.14), Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(draw(-3.14, 3.14), Eigen::Vector3d::UnitY()) *
                       Eigen::AngleAxisd(draw(-3.14, 3.14), Eigen::Vector3d::UnitX()));
      jt.axis = Eigen::Vector3d(draw(-1.0, 1.0), draw(-1.0, 1.0), draw(-1.0, 1.0));
      if (jt.axis.norm() < 0.1) jt.axis = Eigen::Vector3d::UnitY();
      jt.axis.normalize();
    } else {
      jt.a = draw(-0.4, 0.4);
      jt.alpha = draw(-3.14, 3.14);
      jt.d = draw(-0.4, 0.4);
      jt.theta_offset = draw(-3.14, 3.14);
    }
    if (jt.type == JointType::kRevolute) {
      jt.lower = -draw(0.2, 3.0);
      jt.upper = draw(0.2, 3.0);
    } else {
      jt.lower = -draw(0.05, 0.5);
      jt.upper = draw(0.05, 0.5);
    }
    jt.velocity_limit = constant_law(1.0);
    spec.joints.push_back(jt);
  }
  spec.end_effector.translation() = Eigen::Vector3d(draw(-0.2, 0.2), draw(-0.2, 0.2), draw(0.0, 0.2));
  spec.end_effector.rotate(Eigen::AngleAxisd(draw(-1.0, 1.0), Eigen::Vector3d::UnitX()));
  if (*rc::gen::inRange(0, 2) == 1) {  // a base placed anywhere, turned any way
    spec.base.translation() = Eigen::Vector3d(draw(-0.5, 0.5), draw(-0.5, 0.5), draw(-0.5, 0.5));
    spec.base.rotate(Eigen::AngleAxisd(draw(-3.0, 3.0), Eigen::Vector3d(draw(-1, 1), draw(-1, 1), 1.0).normalized()));
  }
  return spec;
}

Eigen::VectorXd random_theta(const RobotModel& model) {
  Eigen::VectorXd theta(model.dof());
  for (int j = 0; j < model.dof(); ++j) {
    const double margin = 1e-3 * (model.upper_limits()(j) - model.lower_limits()(j));
    theta(j) = draw(model.lower_limits()(j) + margin, model.upper_limits()(j) - margin);
  }
  return theta;
}

}  // namespace redres::testing
