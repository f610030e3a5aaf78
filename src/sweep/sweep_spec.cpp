#include "sweep/sweep_spec.hpp"

#include "core/options.hpp"
#include "core/user_error.hpp"

#include <cmath>
#include <cstdio>
#include <regex>

namespace morphogen::sweep {

namespace {

// Computed values (linspace, ...) rounded to 12 significant digits: 0.022, not
// 0.022000000000000002.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

} // namespace

long long SweepSpec::points() const {
  if (listed) return axes.empty() ? 0 : static_cast<long long>(axes[0].values.size());
  long long n = 1;
  for (const auto& a : axes)
    n *= static_cast<long long>(a.values.size());
  return n;
}

std::vector<long long> SweepSpec::indices(long long p) const {
  if (listed) return std::vector<long long>(axes.size(), p);
  std::vector<long long> idx;
  for (const auto& a : axes) {
    const long long n = static_cast<long long>(a.values.size());
    idx.push_back(p % n);
    p /= n;
  }
  return idx;
}

std::vector<std::pair<std::string, std::string>> SweepSpec::assignment(long long p) const {
  std::vector<std::pair<std::string, std::string>> out;
  const auto idx = indices(p);
  for (size_t a = 0; a < axes.size(); ++a)
    out.emplace_back(axes[a].option, axes[a].values[static_cast<size_t>(idx[a])]);
  return out;
}

std::vector<double> SweepSpec::numbers(long long p) const {
  std::vector<double> out;
  const auto idx = indices(p);
  for (size_t a = 0; a < axes.size(); ++a)
    out.push_back(axes[a].numbers[static_cast<size_t>(idx[a])]);
  return out;
}

std::vector<std::string> parse_axis_values(const std::string& key, const std::string& text) {
  static const std::regex fn(R"(^\s*(linspace|logspace|range)\s*\(([^)]*)\)\s*$)");
  const std::string allowed =
      "allowed: linspace(a, b, n), logspace(a, b, n), range(a, b, step) or a list v1,v2,...";
  std::smatch m;
  std::vector<std::string> out;
  if (std::regex_match(text, m, fn)) {
    std::vector<double> arg;
    std::string rest = m[2].str();
    size_t pos = 0;
    while (true) {
      const size_t c = rest.find(',', pos);
      arg.push_back(Options::parse_real(key, trim(rest.substr(pos, c - pos))));
      if (c == std::string::npos) break;
      pos = c + 1;
    }
    if (arg.size() != 3)
      throw UserError("-" + key + " " + text + ": needs 3 arguments; " + allowed);
    const std::string f = m[1].str();
    if (f == "range") {
      if (!(arg[2] > 0) || !(arg[1] > arg[0]))
        throw UserError("-" + key + " " + text + ": range(a, b, step) needs a < b and step > 0");
      const double n = std::ceil((arg[1] - arg[0]) / arg[2] - 1e-9);
      if (n > 1e6) throw UserError("-" + key + " " + text + ": more than 10^6 values");
      for (long long i = 0; i < static_cast<long long>(n); ++i)
        out.push_back(num(arg[0] + static_cast<double>(i) * arg[2]));
    } else {
      const double n = arg[2];
      if (!(n >= 1) || n != std::floor(n) || n > 1e6)
        throw UserError("-" + key + " " + text + ": the count n must be an integer in [1, 10^6]");
      for (long long i = 0; i < static_cast<long long>(n); ++i) {
        const double s = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
        const double v = arg[0] + s * (arg[1] - arg[0]);
        out.push_back(num(f == "logspace" ? std::pow(10.0, v) : v));
      }
    }
  } else {
    size_t pos = 0;
    while (true) {
      const size_t c = text.find(',', pos);
      const std::string v = trim(text.substr(pos, c - pos));
      (void)Options::parse_real(key, v); // every value must be a number
      out.push_back(v);
      if (c == std::string::npos) break;
      pos = c + 1;
    }
  }
  if (out.empty()) throw UserError("-" + key + " " + text + ": no values; " + allowed);
  return out;
}

} // namespace morphogen::sweep
