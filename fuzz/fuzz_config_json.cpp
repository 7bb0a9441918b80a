/** @file fuzz_config_json.cpp
 *  @brief libFuzzer harness of the CLI's config readers: `localize --config` (EkfParams, then validate()) and
 *         `simulate --config` (SimParams and TrajectoryParams, then validate()).
 */
#include "FuzzConfig.h"
#include "SimConfig.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  fuzz::readConfigText(fuzz::asText(data, size), "fuzz-config.json", [](const nlohmann::json& j) {
    sim::SimParams sp;
    sim::TrajectoryParams tp;
    app::applySimConfig(j, &sp, &tp);
    sp.validate();
    tp.validate();
  });
  return 0;
}
