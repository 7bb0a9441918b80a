/** @file UmbrellaHeadersTest.cpp
 *  @brief The eight module umbrella headers compile together in one translation unit and give each module's API.
 */
#include <gtest/gtest.h>

#include "uwb/core.h"
#include "uwb/eval.h"
#include "uwb/filter.h"
#include "uwb/gp.h"
#include "uwb/graph.h"
#include "uwb/io.h"
#include "uwb/model.h"
#include "uwb/sim.h"

namespace uwb {
namespace {

TEST(UmbrellaHeaders, GiveEachModuleTogether) {
  // GIVEN only the umbrella includes, WHEN a type of each module is used, THEN it is there and behaves
  const Vec3 tag = tagPosition(Vec3(1, 2, 3), Quat::Identity(), kUtilTagOffset_b);  // model
  EXPECT_NEAR((tag - Vec3(1, 2, 3)).norm(), kUtilTagOffset_b.norm(), 1e-15);
  EXPECT_EQ(gp::Kernel::preset("tdoa").inputDim(), 6);                                   // gp
  EXPECT_NO_THROW(EkfParams::defaults().validate());                                     // filter
  AnchorTable anchors;                                                                   // filter
  anchors.set(3, Vec3(1, 0, 0));
  EXPECT_NE(anchors.find(3), nullptr);
  EXPECT_TRUE(Flight{}.tdoa.empty());                                                    // io
  EXPECT_NO_THROW((void)BiasDatasetParams{});                                                  // eval
  EXPECT_GT(sim::SimParams{}.imu.rate_hz, 0.0);                                          // sim
}

}  // namespace
}  // namespace uwb
