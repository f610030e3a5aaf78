// A sweep over the rows of a CSV file: see point_list.hpp.
#include "sweep/point_list.hpp"

#include "app/simulation.hpp"
#include "core/user_error.hpp"
#include "io/h5_table.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
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

// The points file as a table: its header and the fields of any data row, as text.
struct PointTable {
  std::vector<std::string> header;
  long long rows = 0;
  std::function<std::vector<std::string>(long long row)> fields;
  std::function<std::string(long long row)> where; // "line 7" / "row 5"
};

// A CSV file: its non-empty lines, the first the header.
PointTable csv_table(const std::string& where, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UserError(where + ": cannot open the file");
  auto lines = std::make_shared<std::vector<std::string>>();
  for (std::string line; std::getline(in, line);)
    if (!trim(line).empty()) lines->push_back(std::move(line));
  if (in.bad()) throw UserError(where + ": read error");
  if (lines->size() < 2) throw UserError(where + ": needs a header line and at least one row");
  PointTable t;
  t.header = split((*lines)[0]);
  t.rows = static_cast<long long>(lines->size()) - 1;
  t.fields = [lines](long long r) { return split((*lines)[static_cast<size_t>(r) + 1]); };
  t.where = [](long long r) { return "line " + std::to_string(r + 2); };
  return t;
}

// An HDF5 table (io/h5_table.hpp, e.g. a screen's turing_sets.h5): numbers in shortest
// round-trip form.
PointTable h5_table(const std::string& where, const std::string& path) {
  auto values = std::make_shared<std::vector<std::vector<double>>>();
  PointTable t;
  const std::string err = io::read_h5_table(path, t.header, *values);
  if (!err.empty()) throw UserError(where + ": " + err);
  t.rows = static_cast<long long>((*values)[0].size());
  if (t.rows == 0) throw UserError(where + ": no rows");
  t.fields = [values](long long r) {
    std::vector<std::string> f;
    for (const auto& col : *values) {
      char buf[32];
      const auto res = std::to_chars(buf, buf + sizeof buf, col[static_cast<size_t>(r)]);
      f.emplace_back(buf, res.ptr);
    }
    return f;
  };
  t.where = [](long long r) { return "row " + std::to_string(r); };
  return t;
}

bool is_hdf5(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char sig[8] = {};
  return in.read(sig, 8) && std::string(sig, 8) == "\x89HDF\r\n\x1a\n";
}

} // namespace

SweepSpec read_point_list(const std::string& key, const std::string& path,
                          const std::vector<std::string>& axes_in, long long max_points) {
  const std::string where = "-" + key + " " + path;
  const PointTable t = is_hdf5(path) ? h5_table(where, path) : csv_table(where, path);
  const std::vector<std::string> axes = axes_in.empty() ? screen_axes(where, t.header) : axes_in;
  SweepSpec spec;
  spec.listed = true;
  spec.points_file = path;
  std::vector<size_t> cols;
  for (const auto& a : axes) {
    cols.push_back(column_of(where, t.header, a));
    spec.axes.push_back(Axis{a, {}, {}});
  }
  const auto index_col = std::find(t.header.begin(), t.header.end(), "index") - t.header.begin();
  const bool has_index = index_col < static_cast<long>(t.header.size());
  const long long n = max_points > 0 ? std::min(t.rows, max_points) : t.rows;
  for (long long i = 0; i < n; ++i) {
    const long long row = i * t.rows / n;
    const std::string at = where + ": " + t.where(row);
    const auto f = t.fields(row);
    if (f.size() != t.header.size())
      throw UserError(at + ": " + std::to_string(f.size()) + " fields, the header has " +
                      std::to_string(t.header.size()));
    for (size_t a = 0; a < axes.size(); ++a) {
      spec.axes[a].values.push_back(f[cols[a]]);
      spec.axes[a].numbers.push_back(number(at, f[cols[a]]));
    }
    spec.source.push_back(
        has_index ? static_cast<long long>(number(at, f[static_cast<size_t>(index_col)])) : row);
  }
  return spec;
}

std::vector<std::string> screen_mismatches(const SweepSpec& spec, const Simulation& sim) {
  namespace fs = std::filesystem;
  const fs::path file(spec.points_file);
  std::ifstream in(file.parent_path() / "screen.json");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  std::vector<std::string> out;
  const std::string name = file.filename().string();
  if (!in || j.is_discarded() || !j.is_object() ||
      (j.value("table", "") != name && j.value("table_h5", "") != name))
    return out;
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
