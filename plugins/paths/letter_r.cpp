#include "redres/paths/letter_r.hpp"

#include <numbers>

namespace redres {

const Schema<LetterRConfig>& LetterRConfig::schema() {
  static const Schema<LetterRConfig> s{{field("height", &LetterRConfig::height, "m", "letter height h", greater(0.0))}};
  return s;
}

namespace {

std::unique_ptr<PathGeometry> make_letter_r(const LetterRConfig& config, const PathContext& /*ctx*/) {
  const double h = config.height;
  const double c = h / 6.0, rho = h / 4.0;
  auto g = std::make_unique<PathGeometry>();
  g->rotation_deg = 180.0;
  g->strokes.push_back({PathSegment::line({0, 0, 0}, {0, h, 0})});
  g->strokes.push_back({PathSegment::line({0, h, 0}, {c, h, 0}),
                        PathSegment::arc({c, 0.75 * h, 0}, rho, std::numbers::pi / 2.0, -std::numbers::pi),
                        PathSegment::line({c, h / 2.0, 0}, {0, h / 2.0, 0})});
  g->strokes.push_back({PathSegment::line({0, h / 2.0, 0}, {c + rho, 0, 0})});
  return g;
}

const bool kLetterRRegistered = path_registry().add<LetterRConfig>(
    "letter_r",
    "the letter R of the paper's experiment (stem, bowl, leg; docs/letter_r.md); rotated 180 deg by default",
    make_letter_r);

}  // namespace
}  // namespace redres
