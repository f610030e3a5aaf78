// A sweep over the rows of a CSV file: see point_list.hpp.
#include "sweep/point_list.hpp"

#include "app/simulation.hpp"
#include "core/user_error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace morphogen::sweep {

namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  size_t pos = 0;
  while (true) {
    const size_t c = line.find(',', pos);
    out.push_back(trim(line.substr(pos, c - pos)));
    if (c == std::string::npos) return out;
    pos = c + 1;
  }
}

// The axes of a screen's file: the columns between "index" and "wavelength".
std::vector<std::string> screen_axes(const std::string& where,
                                     const std::vector<std::string>& header) {
  const auto w = std::find(header.begin(), header.end(), "wavelength");
  if (header.empty() || header[0] != "index" || w == header.end() || w == header.begin() + 1)
    throw UserError(where + ": not a screen's file (index,<varied...>,wavelength,...); name the "
                            "columns to sweep with -sweep_axes");
  std::vector<std::string> axes;
  for (auto c = header.begin() + 1; c != w; ++c)
    axes.push_back(c->rfind("D_", 0) == 0 ? *c : "params_" + *c);
  return axes;
}

// Column of axis `option`: its own name, or <p> for params_<p>.
size_t column_of(const std::string& where, const std::vector<std::string>& header,
                 const std::string& option) {
  for (size_t c = 0; c < header.size(); ++c)
    if (header[c] == option || (option.rfind("params_", 0) == 0 && header[c] == option.substr(7)))
      return c;
  std::string names;
  for (const auto& h : header)
    names += (names.empty() ? "" : ",") + h;
  throw UserError(where + ": no column for sweep axis " + option + " (columns: " + names + ")");
}

double number(const std::string& where, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw UserError(where + ": '" + text + "' is not a finite number");
  return v;
}

// The file's non-empty lines (header first).
std::vector<std::string> read_lines(const std::string& where, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError(where + ": cannot open the file");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!trim(line).empty()) lines.push_back(std::move(line));
  if (in.bad()) throw UserError(where + ": read error");
  if (lines.size() < 2) throw UserError(where + ": needs a header line and at least one row");
  return lines;
}

} // namespace

SweepSpec read_point_list(const std::string& key, const std::string& path,
                          const std::vector<std::string>& axes_in, long long max_points) {
  const std::string where = "-" + key + " " + path;
  const std::vector<std::string> lines = read_lines(where, path);
  const std::vector<std::string> header = split(lines[0]);
  const std::vector<std::string> axes = axes_in.empty() ? screen_axes(where, header) : axes_in;
  SweepSpec spec;
  spec.listed = true;
  spec.points_file = path;
  std::vector<size_t> cols;
  for (const auto& a : axes) {
    cols.push_back(column_of(where, header, a));
    spec.axes.push_back(Axis{a, {}, {}});
  }
  const auto index_col = std::find(header.begin(), header.end(), "index") - header.begin();
  const long long rows = static_cast<long long>(lines.size()) - 1;
  const long long n = max_points > 0 ? std::min(rows, max_points) : rows;
  for (long long i = 0; i < n; ++i) {
    const long long row = i * rows / n;
    const std::string at = where + ": line " + std::to_string(row + 2);
    const auto f = split(lines[static_cast<size_t>(row) + 1]);
    if (f.size() != header.size())
      throw UserError(at + ": " + std::to_string(f.size()) + " fields, the header has " +
                      std::to_string(header.size()));
    for (size_t a = 0; a < axes.size(); ++a) {
      spec.axes[a].values.push_back(f[cols[a]]);
      spec.axes[a].numbers.push_back(number(at, f[cols[a]]));
    }
    spec.source.push_back(
        index_col < static_cast<long>(header.size())
            ? static_cast<long long>(number(at, f[static_cast<size_t>(index_col)]))
            : row);
  }
  return spec;
}

std::vector<std::string> screen_mismatches(const SweepSpec& spec, const Simulation& sim) {
  namespace fs = std::filesystem;
  const fs::path file(spec.points_file);
  std::ifstream in(file.parent_path() / "screen.json");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  std::vector<std::string> out;
  if (!in || j.is_discarded() || j.value("table", "") != file.filename().string()) return out;
  const ModelEntry& m = sim.model();
  if (j.value("model", "") != m.name)
    return {"the screen's model is " + j.value("model", "") + ", this sweep's " + m.name};
  auto compare = [&](const char* group, const std::string& name, const std::string& option,
                     double have) {
    if (!j[group].contains(name)) return;
    const double want = j[group][name].get<double>();
    if (std::fabs(want - have) > 1e-12 * std::max(1.0, std::fabs(want)))
      out.push_back("-" + option + " is " + format_double(have) + " here, " + format_double(want) +
                    " in the screen");
  };
  for (int q = 0; q < m.nparams; ++q)
    compare("params", m.params[q].name, std::string("params_") + m.params[q].name,
            sim.params().scalar[static_cast<size_t>(q)]);
  for (int s = 0; s < m.nspecies; ++s)
    compare("D", m.species[s].name, std::string("D_") + m.species[s].name,
            sim.diffusion()[static_cast<size_t>(s)]);
  return out;
}

} // namespace morphogen::sweep
