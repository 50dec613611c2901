// Typed configurations: what the framework derives from a Config's one field list (strict TOML reading with
// file:line:col, write-back, listing with defaults, validation of Configs built in C++), and that the built-in
// plugins built from C++ behave exactly as the same plugins read from TOML.

#include <cmath>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "redres/config/config.hpp"
#include "redres/constraints/joint_angle_margin.hpp"
#include "redres/control/engine_registry.hpp"
#include "redres/control/path.hpp"
#include "redres/control/plugin.hpp"
#include "redres/control/scheme.hpp"
#include "redres/engines/newton.hpp"
#include "redres/model/velocity_limit.hpp"
#include "redres/objectives/manipulability.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/parsers/velocity_limit_registry.hpp"
#include "redres/paths/letter_r.hpp"
#include "redres/qp/lvi.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

enum class Colour { kRed, kGreen };
auto enum_names(Colour) {
  return std::array{std::pair{Colour::kRed, std::string_view("red")},
                    std::pair{Colour::kGreen, std::string_view("green")}};
}

struct Point {
  double x = 0.0;
  double y = 0.0;
  static const Schema<Point>& schema() {
    static const Schema<Point> s{{field("x", &Point::x, "m", "x"), field("y", &Point::y, "m", "y")}};
    return s;
  }
};

// One member of every supported kind.
struct Sample {
  double gain = 2.5;
  int count = 3;
  bool flag = true;
  std::string label = "abc";
  Colour colour = Colour::kGreen;
  std::vector<double> values = {1.0, 2.0};
  std::array<double, 3> axis = {0.0, 0.0, 1.0};
  PerJoint margin = 0.1;
  std::optional<double> extra;
  std::vector<Point> points;
  double needed = std::nan("");

  static const Schema<Sample>& schema() {
    using C = Sample;
    static const Schema<C> s{
        {field("gain", &C::gain, "1/s", "a gain", greater(0.0)),
         field("count", &C::count, "", "a count", at_least<int>(1)), field("flag", &C::flag, "", "a flag"),
         field("label", &C::label, "", "a label"), field("colour", &C::colour, "", "a colour"),
         field("values", &C::values, "", "some values"), field("axis", &C::axis, "", "an axis"),
         field("margin", &C::margin, "rad", "per joint", at_least<PerJoint>(0.0)),
         field("extra", &C::extra, "", "optional"), field("points", &C::points, "", "points"),
         field("needed", &C::needed, "", "must be given").required()},
        [](const C& c) {
          if (c.count > 10 && c.flag) throw FieldError("count", "expected count <= 10 while flag is true");
        },
        {}};
    return s;
  }
};

Sample read_sample(const std::string& text) {
  const auto file = parse_toml_string(text, "sample.toml");
  const TableReader r = TableReader::root(file, "sample");
  Sample s;
  read_config(r, Sample::schema(), s);
  r.finish();
  return s;
}

std::string error_of(const std::string& text) {
  try {
    (void)read_sample(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(accepted)";
}

std::string text_of(const toml::table& t) {
  std::ostringstream s;
  s << t;
  return s.str();
}

TEST(Config, ReadsEveryKindOfMemberAndKeepsDefaultsForAbsentKeys) {
  const Sample s = read_sample(
      "needed = \"pi/2\"\ngain = 4\ncolour = \"red\"\nmargin = [0.1, 0.2]\nextra = 7.5\n"
      "points = [{x = 1, y = 2}, {x = 3}]\n");
  EXPECT_DOUBLE_EQ(s.needed, std::acos(0.0));  // a constant formula
  EXPECT_EQ(s.gain, 4.0);
  EXPECT_EQ(s.colour, Colour::kRed);
  EXPECT_EQ(s.margin.values, (std::vector<double>{0.1, 0.2}));
  ASSERT_TRUE(s.extra.has_value());
  EXPECT_EQ(*s.extra, 7.5);
  ASSERT_EQ(s.points.size(), 2u);
  EXPECT_EQ(s.points[1].x, 3.0);
  EXPECT_EQ(s.points[1].y, 0.0);
  // Untouched: the struct's defaults.
  EXPECT_EQ(s.count, 3);
  EXPECT_EQ(s.label, "abc");
  EXPECT_EQ(s.axis[2], 1.0);
}

TEST(Config, ErrorsNameTheFileTheLineTheKeyAndWhatWasExpected) {
  EXPECT_EQ(error_of("needed = 1\ngain = -1\n").rfind("sample.toml:2:8: sample: key 'gain': expected > 0, got -1.0", 0),
            0u)
      << error_of("needed = 1\ngain = -1\n");
  EXPECT_NE(error_of("gain = 1\n").find("missing required key 'needed'"), std::string::npos);
  const std::string unknown = error_of("needed = 1\ncolor = \"red\"\n");
  EXPECT_EQ(unknown.rfind("sample.toml:2:1: unknown key 'color'", 0), 0u) << unknown;
  EXPECT_NE(unknown.find("known keys: axis, colour, count"), std::string::npos) << unknown;
  EXPECT_NE(error_of("needed = 1\ncolour = \"blue\"\n").find("expected one of 'red', 'green', got 'blue'"),
            std::string::npos);
  EXPECT_NE(error_of("needed = 1\ncount = 11\n").find("sample.toml:2:9: sample: key 'count': expected count <= 10"),
            std::string::npos)
      << error_of("needed = 1\ncount = 11\n");
  EXPECT_NE(error_of("needed = 1\ncount = 1.5\n").find("expected an integer, got a float"), std::string::npos);
  EXPECT_NE(error_of("needed = 1\ncount = 4294967297\n").find("expected an integer in [-2147483647, 2147483647]"),
            std::string::npos);
  EXPECT_NE(error_of("needed = 1\nmargin = [0.1, -0.2]\n").find("key 'margin': expected >= 0"), std::string::npos);
  EXPECT_NE(error_of("needed = \"pi/\"\n").find("expected a number or a constant formula"), std::string::npos);
  EXPECT_NE(error_of("needed = 1\npoints = [{x = 1, z = 2}]\n").find("unknown key 'z'"), std::string::npos);
}

TEST(Config, WriteBackReadsBackToTheSameConfig) {
  const Sample s = read_sample("needed = 1.25\nlabel = \"q\"\nextra = 2.0\npoints = [{x = 1, y = 2}]\n");
  toml::table out;
  write_config(s, Sample::schema(), out);
  const Sample again = read_sample(text_of(out));
  toml::table out2;
  write_config(again, Sample::schema(), out2);
  EXPECT_EQ(text_of(out2), text_of(out));
  EXPECT_EQ(again.label, "q");
  EXPECT_EQ(again.points.size(), 1u);
}

TEST(Config, ListingDerivesDefaultsAndPresenceFromTheStruct) {
  const std::vector<KeyInfo> keys = describe_keys(Sample::schema());
  ASSERT_EQ(keys.size(), Sample::schema().fields.size());
  const auto key = [&](const std::string& name) {
    for (const auto& k : keys) {
      if (k.name == name) return k;
    }
    ADD_FAILURE() << "no key " << name;
    return KeyInfo{};
  };
  EXPECT_EQ(key("gain").default_text, "2.5");
  EXPECT_EQ(key("gain").rule, "> 0; |x| <= 1e+06 1/s");  // the unit adds its physical range
  EXPECT_EQ(key("gain").unit, "1/s");
  EXPECT_EQ(key("colour").default_text, "'green'");
  EXPECT_EQ(key("colour").type, "one of 'red', 'green'");
  EXPECT_EQ(key("extra").default_text, "(none)");
  EXPECT_EQ(key("needed").presence, Presence::kRequired);
  EXPECT_EQ(key("needed").default_text, "");
}

TEST(Config, EveryRegisteredDefaultIsValidTomlThatReadsBackToItself) {
  // For every plugin of every kind: the listed default of each optional key, read back as that key, gives the
  // same listing, so the listing and the reader cannot disagree.
  int types = 0;
  const auto check = [&types](const auto& registry) {
    for (const auto* e : registry.entries()) {
      // A type with required keys cannot be read from one key alone; its optional keys are read with the
      // required ones in the path and law tests.
      bool required = false;
      for (const KeyInfo& k : e->keys) required = required || k.presence != Presence::kOptional;
      if (required) continue;
      ++types;
      for (const KeyInfo& k : e->keys) {
        if (k.presence != Presence::kOptional || k.default_text == "(none)") continue;
        SCOPED_TRACE(e->type + "." + k.name + " = " + k.default_text);
        const auto file = parse_toml_string(k.name + " = " + k.default_text + "\n", "<default>");
        const TableReader r = TableReader::root(file);
        EXPECT_NO_THROW((void)e->read(r)) << "the default does not read back";
      }
    }
  };
  check(objective_registry());
  check(constraint_registry());
  check(velocity_limit_registry());
  check(path_registry());
  check(engine_registry());
  EXPECT_GE(types, 12);
}

TEST(Config, ConfigsBuiltInCppAreValidatedWithTheKeyInTheMessage) {
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  try {
    (void)Manipulability(
        Manipulability::Config{.schedule = Manipulability::Schedule::kSmoothstep, .ramp_fraction = 0.7}, robot);
    ADD_FAILURE() << "accepted ramp_fraction = 0.7";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("manipulability: key 'ramp_fraction': expected in (0, 0.5], got 0.7"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)Manipulability(Manipulability::Config{.schedule = Manipulability::Schedule::kExpression}, robot),
               std::invalid_argument);
  // A robot-dependent rule: the margin must be less than half of every joint's range.
  EXPECT_THROW((void)JointAngleMargin(JointAngleMargin::Config{.margin = 3.0}, robot), FieldError);
  // By name: the Config must be the type's own.
  EXPECT_THROW((void)objective_registry().create("manipulability", JointAngleMargin::Config{}, robot),
               std::invalid_argument);
  EXPECT_THROW((void)objective_registry().create("no_such_objective", Manipulability::Config{}, robot),
               std::invalid_argument);
  EXPECT_THROW((void)make_engine("newton", SolverSettings{.tolerance = -1.0}), std::invalid_argument);
  EXPECT_THROW((void)engine_registry().create("newton", NewtonConfig{}, SolverSettings{.max_iterations = 0}),
               std::invalid_argument);
  PathContext ctx;
  ctx.duration = 10.0;
  try {
    (void)make_path("letter_r", LetterRConfig{.height = -0.15}, PathPlacement{}, ctx);
    ADD_FAILURE() << "a negative letter height was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("key 'height': expected > 0, got -0.15"), std::string::npos) << e.what();
  }
}

TEST(Config, APluginBuiltInCppContributesExactlyAsTheSamePluginReadFromToml) {
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  const auto file = parse_toml_string(
      "[[objectives]]\ntype = \"manipulability\"\nschedule = \"smoothstep\"\np = 1.5\nramp_fraction = 0.2\n"
      "weight = 0.5\n",
      "<scheme>");
  const Scheme from_toml = Scheme::from_toml(TableReader::root(file), robot);
  std::vector<std::unique_ptr<Objective>> objectives;
  objectives.push_back(objective_registry().create(
      "manipulability",
      Manipulability::Config{.p = 1.5, .schedule = Manipulability::Schedule::kSmoothstep, .ramp_fraction = 0.2},
      robot));
  objectives.back()->set_weight(0.5);
  const Scheme from_cpp(robot, std::move(objectives), {});
  EXPECT_EQ(text_of(from_cpp.objectives()[0]->config()), text_of(from_toml.objectives()[0]->config()));

  QpProblem a, b;
  SchemeData data_a = from_toml.make_data(), data_b = from_cpp.make_data();
  from_toml.setup(a, data_a);
  from_cpp.setup(b, data_b);
  KinematicsData kin(robot);
  Context ctx{0.0, 40.0, 0.01, &robot, &kin, nullptr, nullptr};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int rep = 0; rep < 10; ++rep) {
    Eigen::VectorXd theta = paper_theta0();
    for (int j = 0; j < 6; ++j) theta(j) += 0.2 * u(rng);
    ctx.t = 40.0 * (u(rng) + 0.5);
    compute_kinematics(robot, theta, kin, KinematicsLevel::kAll);
    from_toml.build(ctx, a, data_a);
    from_cpp.build(ctx, b, data_b);
    EXPECT_EQ(a.zeta, b.zeta);
    EXPECT_GT(a.zeta.norm(), 0.0);
  }
}

TEST(Config, ConstraintsRejectAWeightAndObjectivesCheckTheirs) {
  const RobotModel robot = load_robot(source_path("robots/paper_pushrod_6dof.toml"));
  const auto bad = parse_toml_string(
      "[[objectives]]\ntype = \"min_velocity_norm\"\n[[constraints]]\n"
      "type = \"task_tracking\"\nweight = 2.0\n",
      "w.toml");
  try {
    (void)Scheme::from_toml(TableReader::root(bad), robot);
    ADD_FAILURE() << "a constraint weight was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("w.toml:5:10: ", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("constraints are hard and have no weight"), std::string::npos) << e.what();
  }
  const auto negative = parse_toml_string("[[objectives]]\ntype = \"min_velocity_norm\"\nweight = -1\n", "n.toml");
  EXPECT_THROW((void)Scheme::from_toml(TableReader::root(negative), robot), ConfigError);
  auto p = objective_registry().create_default("min_velocity_norm", robot);
  EXPECT_THROW(p->set_weight(std::nan("")), std::invalid_argument);
}

TEST(Config, RobotFilesAcceptFormulasForNumbers) {
  const auto file = parse_toml_string(R"(
name = "f"
kind = "planar"
home = ["pi/8", 0]
[[joints]]
name = "j1"
length = "0.5/2"
limits = ["-pi/2", "pi/2"]
velocity_limit = { type = "constant", lower = "-2*pi", upper = "2*pi" }
[[joints]]
name = "j2"
length = 0.2
limits = [-1, 1]
velocity_limit = { type = "constant", lower = -1, upper = 1 }
)",
                                      "f.toml");
  const RobotModel robot = load_robot(TableReader::root(file, "robot"));
  EXPECT_DOUBLE_EQ(robot.joint(0).length, 0.25);
  EXPECT_DOUBLE_EQ(robot.upper_limits()(0), std::acos(0.0));
  EXPECT_DOUBLE_EQ(robot.home()(0), std::acos(0.0) / 4.0);
  EXPECT_DOUBLE_EQ(robot.joint(0).velocity_limit->bounds(0.0).upper, 4.0 * std::acos(0.0));
}

TEST(NumberOrFormula, OneReaderForNumbersAndConstantFormulas) {
  const auto file =
      parse_toml_string("a = 2\nb = 0.25\nc = \"pi/2\"\nd = true\ne = \"pi/\"\nf = \"1/0\"\n", "<numbers>");
  const toml::table& t = file->root;
  double v = -1.0;
  EXPECT_TRUE(read_number_or_formula(*t.get("a"), v));
  EXPECT_EQ(v, 2.0);
  EXPECT_TRUE(read_number_or_formula(*t.get("b"), v));
  EXPECT_EQ(v, 0.25);
  EXPECT_TRUE(read_number_or_formula(*t.get("c"), v));
  EXPECT_DOUBLE_EQ(v, std::acos(0.0));
  v = -1.0;
  EXPECT_FALSE(read_number_or_formula(*t.get("d"), v));  // a boolean is neither, and leaves v alone
  EXPECT_EQ(v, -1.0);
  EXPECT_THROW((void)read_number_or_formula(*t.get("e"), v), std::invalid_argument);
  // A formula may evaluate to inf: the reader returns it, and the callers refuse it where they say where.
  EXPECT_TRUE(read_number_or_formula(*t.get("f"), v));
  EXPECT_FALSE(std::isfinite(v));
  const TableReader r = TableReader::root(file, "numbers");
  try {
    (void)r.number("f");
    ADD_FAILURE() << "a non-finite formula was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'f': expected a finite number, got inf"), std::string::npos) << e.what();
  }
}

struct NothingToConfigure {
  static const Schema<NothingToConfigure>& schema() {
    static const Schema<NothingToConfigure> s{};
    return s;
  }
};

// A library that registers hundreds of plugins does not make every message about an unknown type list them all
// (`redres plugins --check` printed each failing plugin's message with every name, quadratic in the count): the
// message lists the 24 names closest to the one asked for, and how many more there are.
TEST(Registry, AnUnknownTypeListsTheClosestNamesAndHowManyMore) {
  Registry<Objective, const RobotModel&> registry("test objective");
  const auto make = [](const NothingToConfigure&, const RobotModel&) -> std::unique_ptr<Objective> { return nullptr; };
  for (int k = 0; k < 500; ++k) registry.add<NothingToConfigure>("bulk_" + std::to_string(k), "", make);
  registry.add<NothingToConfigure>("centering", "", make);
  try {
    (void)registry.at("centring");
    FAIL() << "found";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("unknown test objective type 'centring'; known types: "), std::string::npos) << m;
    EXPECT_NE(m.find("centering"), std::string::npos) << "the closest name is listed: " << m;
    EXPECT_NE(m.find(" and 477 more (`redres plugins` lists them all)"), std::string::npos) << m;
    EXPECT_LT(m.size(), 600u) << m;
  }
  // A few names are all listed.
  Registry<Objective, const RobotModel&> few("few");
  few.add<NothingToConfigure>("a", "", make);
  few.add<NothingToConfigure>("b", "", make);
  try {
    (void)few.at("c");
    FAIL() << "found";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("known types: a, b"), std::string::npos) << e.what();
  }
}
}  // namespace
}  // namespace redres
