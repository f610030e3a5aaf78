#include "sweep/point_record.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

namespace morphogen::sweep {

namespace {

std::string cell(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "1" : "0";
  if (v.is_number_float()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v.get<double>());
    return buf;
  }
  return v.dump();
}

const nlohmann::json& at(const nlohmann::json& j, const char* a, const char* b = nullptr) {
  static const nlohmann::json null;
  if (!j.contains(a)) return null;
  if (!b) return j[a];
  return j[a].contains(b) ? j[a][b] : null;
}

} // namespace

std::string csv_header(const std::vector<std::string>& axes, bool listed) {
  std::string h = listed ? "index,source_index" : "index";
  for (const auto& a : axes)
    h += "," + a;
  return h + ",class,wavelength,wavelength_cells,contrast,spots,holes,spot_area,euler,"
             "anisotropy,coherence,dynamics,period,turing_unstable,hopf,predicted_wavelength,"
             "runtime_s,file\n";
}

std::string csv_row(const nlohmann::json& r, const std::vector<std::string>& axes, bool listed) {
  std::string row = cell(r["index"]);
  if (listed) row += "," + cell(at(r, "source_index"));
  for (const auto& a : axes)
    row += "," + cell(at(r, "params").contains(a) ? r["params"][a] : nlohmann::json());
  const auto& m = at(r, "metrics");
  const auto& high = at(m, "high");
  const auto& low = at(m, "low");
  const std::vector<nlohmann::json> cols = {at(r, "class"),
                                            at(m, "wavelength"),
                                            at(m, "wavelength_cells"),
                                            at(m, "contrast"),
                                            at(high, "spots"),
                                            at(low, "spots"),
                                            at(high, "spot_area"),
                                            at(m, "euler"),
                                            at(m, "spectral_anisotropy"),
                                            at(m, "coherence"),
                                            at(r, "dynamics", "behaviour"),
                                            at(r, "dynamics", "period"),
                                            at(r, "stability", "turing_unstable"),
                                            at(r, "stability", "hopf"),
                                            at(r, "stability", "wavelength_allowed"),
                                            at(r, "runtime_s"),
                                            at(r, "file")};
  for (const auto& c : cols)
    row += "," + cell(c);
  return row + "\n";
}

nlohmann::json read_record(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return nlohmann::json(nlohmann::json::value_t::discarded);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  using Event = nlohmann::json::parse_event_t;
  auto no_series = [](int depth, Event e, nlohmann::json& parsed) {
    return !(depth == 1 && e == Event::key && parsed == "series");
  };
  return nlohmann::json::parse(text, no_series, false);
}

} // namespace morphogen::sweep
