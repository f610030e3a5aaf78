// The record of one sweep point, as JSON (points/point_<index>.json) and as a row of the sweep
// table (sweep.csv): parameters, class, metrics, linear stability, run time, and the time
// series of cheap metrics sampled during the run.
#pragma once

#include "analysis/classify.hpp"
#include "analysis/linear_stability.hpp"
#include "analysis/pattern_metrics.hpp"
#include "analysis/time_series.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace morphogen::sweep {

nlohmann::json metrics_json(const analysis::PatternMetrics& m);
nlohmann::json verdict_json(const analysis::RunVerdict& v);
nlohmann::json stability_json(const analysis::StabilityResult& r,
                              const std::optional<analysis::AllowedMode>& mode);
nlohmann::json samples_json(const analysis::RunSamples& s);

// The CSV header and row of a record (columns: index, the axis options, class, the main
// metrics, stability, run time, file).
std::string csv_header(const std::vector<std::string>& axes);
std::string csv_row(const nlohmann::json& record, const std::vector<std::string>& axes);

} // namespace morphogen::sweep
