// A sweep point's record (points/point_<index>.json: parameters, class, metrics, dynamics, linear
// stability, run time, the sampled time series) as a row of the sweep table sweep.csv.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace morphogen::sweep {

// The CSV header and row of a record (columns: index, for a listed sweep source_index (the
// point's index in the points file), the axis options, class, the main metrics, stability, run
// time, file).
std::string csv_header(const std::vector<std::string>& axes, bool listed);
std::string csv_row(const nlohmann::json& record, const std::vector<std::string>& axes,
                    bool listed);

// The record of a point file without its time series ("series": most of the file), as the table
// and the resume check read it: the file read whole, then parsed (nlohmann's stream input reads a
// character at a time). Discarded (is_discarded()) when the file is missing or not JSON.
nlohmann::json read_record(const std::string& path);

} // namespace morphogen::sweep
