/** @file BiasModelOutputsTest.cpp
 *  @brief What a bias model hands out besides its GP: the named GP input columns (for `train --dump-arrays`) and
 *         the factor on its mean (docs/math/gp.md P44), kept through the model file.
 */
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>

#include "uwb/eval/BiasModel.h"

namespace uwb {
namespace {

TEST(BiasModelOutputs, EveryFeatureMapNamesEachOfItsColumnsOnce) {
  for (const auto& preset : BiasPreset::names()) {
    SCOPED_TRACE(preset);
    const FeatureMap map = BiasPreset::byName(preset).features;
    const std::vector<std::string> names = featureColumnNames(map);
    EXPECT_EQ(static_cast<int>(names.size()), featureDim(map));
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  }
  EXPECT_EQ(featureColumnNames(FeatureMap::kBodyPositions).front(), "b_p_a_x_m");
  EXPECT_EQ(featureColumnNames(FeatureMap::kYawAngles).back(), "yaw_b_rad");
}

TEST(BiasModelOutputs, MeanScaleShrinksTheMeanAndSurvivesTheModelFile) {
  // GIVEN a global yaw-angle model with a non-zero mean
  gp::Svgp svgp(gp::Kernel::preset("z1"), MatX::Random(4, 2));
  svgp.setMean(0.2);
  BiasModel model("z1", FeatureMap::kYawAngles, {{-1, -1, svgp}});
  TdoaFeature f;
  f.id_a = 1;
  f.id_b = 2;
  f.yaw_a_rad = 0.4;
  const double full = model.predict(f).mean_m;
  // WHEN its mean is scaled by w = 0.25
  model.setMeanScale(0.25);
  // THEN the filter's and the calibration's mean are w µ, the variance is unchanged, and the file keeps w
  EXPECT_NEAR(model.predict(f).mean_m, 0.25 * full, 1e-15);
  EXPECT_NEAR(model.predictive(f).mean_m, 0.25 * full, 1e-15);
  const BiasModel back = BiasModel::fromJson(model.toJson());
  EXPECT_DOUBLE_EQ(back.meanScale(), 0.25);
  EXPECT_NEAR(back.predict(f).mean_m, 0.25 * full, 1e-15);
  EXPECT_THROW(model.setMeanScale(1.5), std::invalid_argument);
  EXPECT_THROW(model.setMeanScale(-0.1), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
