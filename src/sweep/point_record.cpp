#include "sweep/point_record.hpp"

#include <cmath>
#include <cstdio>

namespace morphogen::sweep {

namespace {

// JSON has no infinities or NaN: store them as null.
nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

nlohmann::json phase_json(const analysis::PhaseMetrics& p) {
  return {{"area_fraction", num(p.area_fraction)},
          {"components", p.components},
          {"specks", p.specks},
          {"spots", p.spots},
          {"spot_area", num(p.spot_area)},
          {"spot_area_cells", num(p.spot_area_cells)},
          {"elongated", p.elongated},
          {"wrapping", p.wrapping},
          {"networks", p.networks},
          {"spot_area_fraction", num(p.spot_area_fraction)},
          {"elongated_area_fraction", num(p.elongated_area_fraction)},
          {"largest_fraction", num(p.largest_fraction)},
          {"median_elongation", num(p.median_elongation)},
          {"median_fill", num(p.median_fill)}};
}

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

nlohmann::json metrics_json(const analysis::PatternMetrics& m) {
  return {{"finite", m.finite},
          {"min", num(m.min)},
          {"max", num(m.max)},
          {"mean", num(m.mean)},
          {"stddev", num(m.stddev)},
          {"contrast", num(m.contrast)},
          {"wavelength", num(m.wavelength)},
          {"wavelength_cells", num(m.wavelength_cells)},
          {"peak_sharpness", num(m.peak_sharpness)},
          {"spectral_anisotropy", num(m.spectral_anisotropy)},
          {"coherence", num(m.coherence)},
          {"threshold", num(m.threshold)},
          {"euler", m.euler},
          {"high", phase_json(m.high)},
          {"low", phase_json(m.low)}};
}

nlohmann::json verdict_json(const analysis::RunVerdict& v) {
  return {{"behaviour", analysis::to_string(v.behaviour)},
          {"period", num(v.period)},
          {"moving", v.moving},
          {"late_change", num(v.late_change)}};
}

nlohmann::json stability_json(const analysis::StabilityResult& r,
                              const std::optional<analysis::AllowedMode>& mode) {
  nlohmann::json j = {{"has_steady_state", r.has_steady_state},
                      {"u_star", r.u_star},
                      {"stable_homogeneous", r.stable_homogeneous},
                      {"turing_unstable", r.turing_unstable},
                      {"hopf", r.hopf},
                      {"wave", r.oscillatory_fastest},
                      {"growth_fastest", num(r.growth_fastest)},
                      {"wavelength_fastest", num(r.wavelength_fastest)}};
  if (mode) { // the predicted pattern wavelength only where a pattern is predicted
    j["wavelength_allowed"] = r.turing_unstable ? num(mode->wavelength) : nlohmann::json();
    j["growth_allowed"] = num(mode->growth);
  }
  return j;
}

nlohmann::json samples_json(const analysis::RunSamples& s) {
  auto arr = [](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v)
      a.push_back(num(x));
    return a;
  };
  return {{"t", arr(s.t)},
          {"mean", arr(s.mean)},
          {"stddev", arr(s.stddev)},
          {"change", arr(s.change)},
          {"probe", arr(s.probe)}};
}

std::string csv_header(const std::vector<std::string>& axes) {
  std::string h = "index";
  for (const auto& a : axes)
    h += "," + a;
  return h + ",class,wavelength,wavelength_cells,contrast,spots,holes,spot_area,euler,"
             "anisotropy,coherence,dynamics,period,turing_unstable,hopf,predicted_wavelength,"
             "runtime_s,file\n";
}

std::string csv_row(const nlohmann::json& r, const std::vector<std::string>& axes) {
  std::string row = cell(r["index"]);
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

} // namespace morphogen::sweep
