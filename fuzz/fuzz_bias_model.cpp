/** @file fuzz_bias_model.cpp
 *  @brief libFuzzer harness of the bias-model JSON reader (the text → JSON → uwb::BiasModel path of
 *         BiasModel::load), then one prediction with the accepted model, which must be finite.
 */
#include <cmath>

#include "FuzzInput.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/io/JsonFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  fuzz::expectCleanRejection([&] {
    const nlohmann::json j = parseJsonText(fuzz::asText(data, size), "fuzz-model.json", "bias model");
    const BiasModel model = BiasModel::fromJson(j);
    const TdoaFeature f = makeTdoaFeature(0, 1, Vec3(0.5, 0.2, 1.0), Quat::Identity(), Vec3(-3, -4, 0.2), Vec3(-3, 4, 3));
    const BiasPrediction p = model.predict(f);
    if (!std::isfinite(p.mean_m) || !(p.variance_m2 >= 0)) throw std::invalid_argument("non-finite prediction");
  });
  return 0;
}
