/** @file FilterOptions.cpp
 *  @brief The filter options of `localize` and `stream`.
 */
#include "FilterOptions.h"

#include <nlohmann/json.hpp>

#include "EkfConfig.h"
#include "uwb/core/Error.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/filter/EkfParamRegistry.h"
#include "uwb/io/JsonFile.h"

namespace uwb::app {

void addFilterOptions(CLI::App& sub, FilterOptionArgs& a) {
  sub.add_option("--config", a.config,
                 "JSON file with an object of EkfParams fields, e.g. {\"tdoa_sigma_m\": 0.3} (keys: uwbtdoa params); "
                 "flags override it");
  sub.add_option("--bias-model", a.bias_model, "Bias model JSON (GP) to correct the TDoA");
  for (const EkfParamInfo& info : ekfParamRegistry()) {
    const std::string names = info.flag() + (info.cli_alias.empty() ? "" : ",--" + info.cli_alias) +
                              (info.cli_negation.empty() ? "" : ",!--" + info.cli_negation);
    const std::string help = info.doc + " " + ekfParamHelpSuffix(info);
    a.param_text.emplace_back();
    a.param_flag.push_back(false);
    a.param_option.push_back(info.kind == EkfParamKind::kBool ? sub.add_flag(names, a.param_flag.back(), help)
                                                              : sub.add_option(names, a.param_text.back(), help));
    a.param_option.back()->group("Filter parameters");
    if (info.kind == EkfParamKind::kReal) a.param_option.back()->type_name("FLOAT");
    if (info.kind == EkfParamKind::kInteger) a.param_option.back()->type_name("INT");
    if (info.kind == EkfParamKind::kVec3) a.param_option.back()->type_name("X,Y,Z");
    if (info.kind == EkfParamKind::kChoice) {
      std::string choices;
      for (const std::string& c : info.choices) choices += (choices.empty() ? "" : "|") + c;
      a.param_option.back()->type_name(choices);
    }
  }
}

FilterSetup buildFilterParams(const FilterOptionArgs& a) {
  FilterSetup s;
  if (!a.config.empty()) {
    const nlohmann::json j = readJsonFile(a.config, "config file");
    applyEkfConfig(j, a.config, s.params);
    s.process_model_given = j.is_object() && j.contains("process_model");
    try {
      s.params.validate();
    } catch (const std::invalid_argument& e) {
      throw InputError(SourceLocation{a.config, 0, 0, ""}, e.what());
    }
  }
  // flags override the config file
  const std::vector<EkfParamInfo>& registry = ekfParamRegistry();
  for (std::size_t k = 0; k < registry.size(); ++k) {
    if (a.param_option[k]->count() == 0) continue;
    const EkfParamInfo& info = registry[k];
    if (info.name == "process_model") s.process_model_given = true;
    if (info.name == "start_w_p_b") s.start_flag = true;
    if (info.kind == EkfParamKind::kBool) setEkfParam(s.params, info, a.param_flag[k], info.flag());
    else setEkfParamFromText(s.params, info, a.param_text[k], info.flag());
  }
  s.params.validate();
  if (!s.params.b_t_tag.allFinite() || s.params.b_t_tag.norm() > 1.0)
    throw InputError("--tag-offset / b_t_tag: the tag must sit within 1 m of the body origin, got " +
                     std::to_string(s.params.b_t_tag.norm()) + " m");
  return s;
}

BiasPredictor loadBiasPredictor(const FilterOptionArgs& a, EkfParams* params) {
  if (a.bias_model.empty()) return {};
  const BiasModel model = BiasModel::load(a.bias_model);
  applyBiasModelLevel(model, params);                   // (F24b)
  return model.predictor();  // the GP as a plain BiasPredictor (the filter knows no GPs)
}

}  // namespace uwb::app
