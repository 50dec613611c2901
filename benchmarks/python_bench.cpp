// build/<preset>/bin/redres-bench-python: what an objective written in Python costs per control step, against the
// same objective in C++, in the same run. The program embeds Debian's Python, imports the build's redres package,
// and times Scenario.run() of the paper's R (4000 steps) with
//   - min_velocity_norm in C++ against the same objective in Python (qp.add_identity: the call itself), and
//   - manipulability (constant p = 1, det) in C++ against a Python objective that adds -p grad w from ctx.grad_w
//     (the call plus a numpy view and an array argument),
// each with the paper's engine (projection) and with newton. The counter per_step is the time per step (s); the
// difference of a pair is the Python objective's overhead per step.

#include <string>

#include <benchmark/benchmark.h>
#include <pybind11/embed.h>

#include "bench_counters.hpp"

namespace py = pybind11;

namespace {

const char* kSetup = R"PY(
import sys
sys.path.insert(0, BUILD_PYTHON_DIR)
import redres

class PyMinVelocityNorm(redres.Objective):
    type = "py_min_velocity_norm"
    kinematics = "position"
    def contribute(self, ctx, qp):
        qp.add_identity(1.0)

class PyManipulability(redres.Objective):
    type = "py_manipulability"
    keys = {"p": 1.0}
    kinematics = "manipulability"
    def contribute(self, ctx, qp):
        qp.add_linear(-self.p * ctx.grad_w)

redres.register(PyMinVelocityNorm)
redres.register(PyManipulability)

def scenario(objective, engine):
    sets = {"solver.engine": engine}
    if objective == "py_mvn":
        sets["objectives.0.type"] = "py_min_velocity_norm"
    if objective in ("cpp_manipulability", "py_manipulability"):
        sets["objectives.1"] = ({"type": "manipulability", "schedule": "constant", "p": 1.0}
                                if objective == "cpp_manipulability" else {"type": "py_manipulability", "p": 1.0})
    config = SOURCE_DIR + ("/configs/paper_r_mvn.toml" if objective in ("cpp_mvn", "py_mvn")
                           else "/configs/paper_r_tvcmm.toml")
    return redres.Scenario.load(config, overrides=sets)
)PY";

py::object& scenarios() {
  static py::scoped_interpreter interpreter;
  static py::object module = [] {
    py::dict globals = py::globals();
    globals["BUILD_PYTHON_DIR"] = REDRES_BUILD_PYTHON_DIR;
    globals["SOURCE_DIR"] = REDRES_SOURCE_DIR;
    py::exec(kSetup, globals);
    return globals["scenario"];
  }();
  return module;
}

void BM_PaperRun(benchmark::State& state, const char* objective, const char* engine) {
  py::object s = scenarios()(objective, engine);
  const int steps = s.attr("steps").cast<int>() + 1;
  for (auto _ : state) {
    py::object result = s.attr("run")();
    if (result.attr("failures").cast<int>() != 0) state.SkipWithError("the run has failed steps");
    benchmark::DoNotOptimize(result.ptr());
  }
  redres::set_per_step(state, static_cast<double>(steps));
}

}  // namespace

BENCHMARK_CAPTURE(BM_PaperRun, cpp_mvn_projection, "cpp_mvn", "projection")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun, py_mvn_projection, "py_mvn", "projection")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun, cpp_mvn_newton, "cpp_mvn", "newton")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun, py_mvn_newton, "py_mvn", "newton")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun, cpp_manipulability_newton, "cpp_manipulability", "newton")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PaperRun, py_manipulability_newton, "py_manipulability", "newton")->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  // Plugins registered from Python go before the interpreter does.
  py::module_::import("redres").attr("_redres").attr("_unregister_all")();
  return 0;
}
