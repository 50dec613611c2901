// redres-baseline-process: the baseline of the whole-process figure. A program of its own, using no part of the
// framework, that runs the paper's TVCMM R on its arm (paper_baseline.cpp, with the letter evaluated in the loop)
// and writes the trajectory it recorded (t, theta, theta_dot, w of every step) as CSV, in the shortest form that
// reads back to the same doubles (std::to_chars). Its constants are those of robots/paper_pushrod_6dof.toml and
// configs/paper_r_tvcmm.toml: Table I of the paper, theta(0), T = 40 s.
//
//   redres-baseline-process OUT.csv [tau]     (tau defaults to 0.001 s)

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "paper_baseline.hpp"

namespace {

using redres::baseline::Joints;
using redres::baseline::kJoints;

redres::baseline::PaperArm paper_arm() {
  redres::baseline::PaperArm arm;
  arm.length = {0.301, 0.29, 0.23, 0.225, 0.214, 0.103};
  arm.lower = {-1.536, 0.052, 0.026, 0.066, 0.017, 0.009};
  arm.upper = {1.431, 0.785, 0.611, 0.576, 0.559, 0.445};
  arm.margin.fill(0.0349);
  arm.kappa = 4.0;
  arm.gain = 8.0;
  arm.p = 2.0;
  arm.joint1_speed = 25.0 * std::numbers::pi / 24.0;
  arm.a = {0.0, 0.25, 0.25, 0.19, 0.185, 0.174};
  arm.b = {0.0, 0.08, 0.08, 0.08, 0.08, 0.08};
  arm.s = 2.5e-3;
  arm.sigma_min = -10.0;
  arm.sigma_max = 10.0;
  return arm;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s OUT.csv [tau]\n", argv[0]);
    return 2;
  }
  const double tau = argc == 3 ? std::strtod(argv[2], nullptr) : 0.001;
  const double T = 40.0;
  const int steps = static_cast<int>(std::lround(T / tau));
  if (!(tau > 0.0) || steps < 1) {
    std::fprintf(stderr, "tau must be in (0, 40] s\n");
    return 2;
  }
  const double pi = std::numbers::pi;
  const Joints theta0 = {pi / 4, pi / 12, pi / 12, pi / 12, pi / 36, pi / 36};
  redres::baseline::LetterR letter;
  letter.height = 0.15;
  letter.psi = pi;
  redres::baseline::Record record;
  record.rows.resize(static_cast<std::size_t>(steps + 1) * 13);
  const Joints theta = redres::baseline::run_letter_r(paper_arm(), letter, theta0, steps, tau, record);

  std::FILE* out = std::fopen(argv[1], "wb");
  if (out == nullptr) {
    std::perror(argv[1]);
    return 1;
  }
  std::string header = "t";
  for (int j = 1; j <= kJoints; ++j) header += ",theta_" + std::to_string(j);
  for (int j = 1; j <= kJoints; ++j) header += ",theta_dot_" + std::to_string(j);
  header += ",manipulability\n";
  std::fputs(header.c_str(), out);
  std::vector<char> buffer(1 << 16);
  std::size_t used = 0;
  const auto put = [&](double v, char end) {
    if (buffer.size() - used < 32) {
      std::fwrite(buffer.data(), 1, used, out);
      used = 0;
    }
    char* p = std::to_chars(buffer.data() + used, buffer.data() + buffer.size(), v).ptr;
    *p++ = end;
    used = static_cast<std::size_t>(p - buffer.data());
  };
  for (int k = 0; k <= steps; ++k) {
    put(k == steps ? T : k * tau, ',');
    const double* row = record.rows.data() + static_cast<std::size_t>(k) * 13;
    for (int c = 0; c < 13; ++c) put(row[c], c == 12 ? '\n' : ',');
  }
  std::fwrite(buffer.data(), 1, used, out);
  if (std::fclose(out) != 0) {
    std::perror(argv[1]);
    return 1;
  }
  std::printf("theta(T) =");
  for (double v : theta) std::printf(" %.12g", v);
  std::printf("\nsolver failures: %d\n", record.failures);
  return record.failures == 0 ? 0 : 1;
}
