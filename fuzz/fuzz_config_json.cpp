/** @file fuzz_config_json.cpp
 *  @brief libFuzzer harness of the CLI's config readers: `localize --config` (EkfParams, then validate()) and
 *         `simulate --config` (SimParams and TrajectoryParams, then validate()).
 */
#include "EkfConfig.h"
#include "FuzzInput.h"
#include "SimConfig.h"
#include "uwb/io/JsonFile.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  fuzz::expectCleanRejection([&] {
    const nlohmann::json j = parseJsonText(fuzz::asText(data, size), "fuzz-config.json", "config file");
    fuzz::expectCleanRejection([&] {
      EkfParams params;
      app::applyEkfConfig(j, "fuzz-config.json", params);
      params.validate();
    });
    sim::SimParams sp;
    sim::TrajectoryParams tp;
    app::applySimConfig(j, &sp, &tp);
    sp.validate();
    tp.validate();
  });
  return 0;
}
