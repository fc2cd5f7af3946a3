// limn's own subdivision rules (render/rules) against OpenSubdiv on the shared corpus.
#include <gtest/gtest.h>

#include "render/rules/limit.h"
#include "render/rules/refine.h"
#include "render/rules/weights.h"

namespace limn::render::rules {
namespace {

TEST(LoopWeights, KnownBetas) {
  EXPECT_DOUBLE_EQ(loopBeta(3), 3.0 / 16.0);
  EXPECT_DOUBLE_EQ(loopBeta(6), 1.0 / 16.0);
}

}  // namespace
}  // namespace limn::render::rules
