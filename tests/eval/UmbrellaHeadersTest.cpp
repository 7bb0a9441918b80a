/** @file UmbrellaHeadersTest.cpp
 *  @brief The eight module umbrella headers compile together in one translation unit, give each module's API, and
 *         list every public header of their module.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

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
  EXPECT_DOUBLE_EQ(residualStats({1.0, 4.0, 2.0}).median_m, 2.0);                       // io
  BiasDatasetParams bias_params;                                                         // eval
  EXPECT_NO_THROW(bias_params.validate());
  bias_params.min_z_m = std::nan("");
  EXPECT_THROW(bias_params.validate(), std::invalid_argument);
  EXPECT_GT(sim::SimParams{}.imu.rate_hz, 0.0);                                          // sim
}

TEST(UmbrellaHeaders, ListEveryPublicHeaderOfTheirModule) {
  // GIVEN each module's umbrella header and the headers in its folder
  namespace fs = std::filesystem;
  const fs::path include_dir = fs::path(UWB_SOURCE_DIR) / "include" / "uwb";
  ASSERT_TRUE(fs::is_directory(include_dir)) << include_dir;
  for (const char* module : {"core", "eval", "filter", "gp", "graph", "io", "model", "sim"}) {
    std::ifstream in(include_dir / (std::string(module) + ".h"));
    ASSERT_TRUE(in) << module;
    std::stringstream umbrella;
    umbrella << in.rdbuf();
    // THEN every header of the folder is included by the umbrella
    int n = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(include_dir / module)) {
      if (e.path().extension() != ".h") continue;
      ++n;
      const std::string line = "#include \"uwb/" + std::string(module) + "/" + e.path().filename().string() + "\"";
      EXPECT_NE(umbrella.str().find(line), std::string::npos) << module << ".h misses " << e.path().filename();
    }
    EXPECT_GT(n, 0) << module;
  }
}

}  // namespace
}  // namespace uwb
