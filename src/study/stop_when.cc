// The stop_when rule's JSON form (stopping.h). Apart from the evaluator so that the study-file
// reader needs neither the statistics nor the trial store (the fuzz targets link it alone).
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/study/stopping.h"

namespace lrcal {

Json StopWhen::ToJson() const {
  if (!enabled()) return nullptr;
  Json j = {{"block", block}};
  if (relative_se > 0) j["relative_se"] = relative_se;
  if (p95_relative_halfwidth > 0) j["p95_relative_halfwidth"] = p95_relative_halfwidth;
  return j;
}

StopWhen StopWhen::FromJson(const Json& j, const std::string& where) {
  StopWhen rule;
  if (j.is_null()) return rule;
  if (!j.is_object())
    throw InputError(where, "expected a mapping {block, relative_se, p95_relative_halfwidth}");
  const auto number = [&](const char* key, double* out) {
    if (!j.contains(key)) return;
    if (!j[key].is_number() || !(j[key].get<double>() > 0) || !std::isfinite(j[key].get<double>()))
      throw InputError(where + "." + key, "expected a number > 0, got " + j[key].dump() +
                                              " (leave the key out to "
                                              "drop this criterion)");
    *out = j[key].get<double>();
  };
  if (!j.contains("block") || !j["block"].is_number_integer() || j["block"].get<long long>() < 2)
    throw InputError(where + ".block",
                     "expected a whole number of trials per block, at least 2 (e.g. 1000), got " +
                         (j.contains("block") ? j["block"].dump() : std::string("nothing")));
  rule.block = j["block"].get<long long>();
  number("relative_se", &rule.relative_se);
  number("p95_relative_halfwidth", &rule.p95_relative_halfwidth);
  if (rule.relative_se == 0 && rule.p95_relative_halfwidth == 0)
    throw InputError(where,
                     "expected at least one criterion: relative_se (e.g. 0.01) and/or "
                     "p95_relative_halfwidth (e.g. 0.05)");
  return rule;
}

}  // namespace lrcal
