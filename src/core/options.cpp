#include "core/options.hpp"

#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace morphogen {

std::string format_double(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  // Prefer the shortest representation that round-trips.
  // Numbers of ordinary size are written without an exponent (20, not 2e+01).
  const bool plain = std::abs(v) >= 1e-4 && std::abs(v) < 1e7;
  for (int prec = 1; prec <= 17; ++prec) {
    char b2[64];
    std::snprintf(b2, sizeof b2, "%.*g", prec, v);
    if (std::strtod(b2, nullptr) == v && !(plain && std::strchr(b2, 'e'))) return b2;
  }
  return buf;
}

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  if (v == std::floor(v) && std::abs(v) < 1e7)
    std::snprintf(buf, sizeof buf, "%.0f", v); // 1000000, not 1e+06
  else
    std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string allowed_range(double lo, double hi) {
  constexpr double big = std::numeric_limits<double>::max();
  const bool no_lo = lo <= -big, no_hi = hi >= big;
  if (no_lo && no_hi) return "any number";
  if (no_hi) return "allowed >= " + format_number(lo);
  if (no_lo) return "allowed <= " + format_number(hi);
  return "allowed [" + format_number(lo) + ", " + format_number(hi) + "]";
}

std::string one_line(const std::string& text) {
  std::string out;
  bool space = false;
  for (char c : text) {
    if (c == '\n' || c == '\r' || c == '\t' || c == ' ') {
      space = true;
      continue;
    }
    if (space && !out.empty()) out += ' ';
    space = false;
    out += c;
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> all_petsc_options() {
  char* text = nullptr;
  if (PetscOptionsGetAll(nullptr, &text) || !text) return {};
  std::stringstream ss(text);
  PetscFree(text);
  std::vector<std::pair<std::string, std::string>> all;
  std::string tok;
  while (ss >> tok) {
    if (tok.size() > 1 && tok[0] == '-' && std::isalpha(static_cast<unsigned char>(tok[1])))
      all.emplace_back(tok.substr(1), "");
    else if (!all.empty())
      all.back().second += (all.back().second.empty() ? "" : " ") + tok;
  }
  return all;
}

std::string lower_case(std::string text) {
  for (char& c : text)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string shown(const std::string& value) {
  bool plain = !value.empty();
  for (unsigned char c : value)
    plain = plain && c > ' ' && c != 127 && c != '"';
  return plain ? value : "\"" + value + "\"";
}

std::string name_petsc_option_error(const std::string& prefix, const std::string& petsc_message) {
  const std::string msg = one_line(petsc_message);
  for (const auto& [name, value] : all_petsc_options()) {
    if (name.compare(0, prefix.size(), prefix) != 0 || value.empty()) continue;
    if (msg.find(" " + value + " ") == std::string::npos &&
        msg.find(": " + value) == std::string::npos)
      continue;
    const char* what = msg.find("numeric value") != std::string::npos   ? "not a number"
                       : msg.find("integer value") != std::string::npos ? "not an integer"
                       : msg.find("logical value") != std::string::npos ? "not true or false"
                                                                        : "refused";
    return "-" + name + " " + shown(value) + ": " + what + " (PETSc: " + msg + ")";
  }
  return {};
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j)
    prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

namespace {

// "allowed [lo, hi]", or "allowed >= lo" when hi is the largest value of its type.
std::string int_range(PetscInt lo, PetscInt hi) {
  if (hi == std::numeric_limits<PetscInt>::max()) return "allowed >= " + std::to_string(lo);
  return "allowed [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
}

} // namespace

Options::Options(MPI_Comm comm) : comm_(comm) {
  PetscBool h = PETSC_FALSE;
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-help", &h));
  help_ = h || help_everywhere_;
}

void Options::record(const std::string& name, const std::string& value, const std::string& help) {
  for (auto& r : records_)
    if (r.name == name) {
      r.value = value;
      return;
    }
  records_.push_back({name, value, help});
}

std::optional<std::string> Options::get(const std::string& name, const std::string& help) {
  // The value as stored (no fixed-size buffer: values of any length are read whole).
  const char* value = nullptr;
  PetscBool set = PETSC_FALSE;
  const std::string key = "-" + name;
  MG_PETSC(PetscOptionsFindPair(nullptr, nullptr, key.c_str(), &value, &set));
  if (!set) {
    known_.push_back(name);
    return std::nullopt;
  }
  const std::string v = value ? value : "";
  record(name, v, help);
  return v;
}

bool Options::is_set(const std::string& name) const {
  PetscBool set = PETSC_FALSE;
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, ("-" + name).c_str(), &set));
  return set;
}

double Options::parse_real(const std::string& name, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const bool none = end == text.c_str(); // nothing read: "", " ", "abc"
  while (end && *end == ' ')
    ++end;
  // (no hexadecimal "0x10", which strtod would take: integers and expressions refuse it too;
  // an underflow, 1e-320 or 1e-400, reads as the subnormal or 0 that strtod gives, for the
  // option's range to judge; an overflow is no number)
  if (none || !end || *end != '\0' || (errno == ERANGE && std::isinf(v)) || std::isnan(v) ||
      text.find_first_of("xX") != std::string::npos)
    throw UserError("-" + name + " " + shown(text) + ": not a number");
  return v;
}

PetscInt Options::parse_int(const std::string& name, const std::string& text, PetscInt lo,
                            PetscInt hi) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  const bool none = end == text.c_str(); // nothing read: "", " ", "abc"
  while (end && *end == ' ')
    ++end;
  if (none || !end || *end != '\0')
    throw UserError("-" + name + " " + shown(text) + ": not an integer");
  if (errno == ERANGE || v > std::numeric_limits<PetscInt>::max() ||
      v < std::numeric_limits<PetscInt>::min())
    throw UserError("-" + name + " " + shown(text) + ": out of range, " + int_range(lo, hi));
  return static_cast<PetscInt>(v);
}

double Options::real(const std::string& name, double def, double lo, double hi,
                     const std::string& help) {
  const std::string h = help + " (" + allowed_range(lo, hi) + ")";
  auto s = get(name, h);
  const double v = s ? parse_real(name, *s) : def;
  if (!(v >= lo && v <= hi))
    throw UserError("-" + name + " " + (s ? shown(*s) : format_number(v)) + ": out of range, " +
                    allowed_range(lo, hi));
  record(name, format_double(v), h);
  return v;
}

PetscInt Options::integer(const std::string& name, PetscInt def, PetscInt lo, PetscInt hi,
                          const std::string& help) {
  const std::string h = help + " (" + int_range(lo, hi) + ")";
  auto s = get(name, h);
  const PetscInt v = s ? parse_int(name, *s, lo, hi) : def;
  if (v < lo || v > hi)
    throw UserError("-" + name + " " + (s ? shown(*s) : std::to_string(v)) + ": out of range, " +
                    int_range(lo, hi));
  record(name, std::to_string(v), h);
  return v;
}

bool Options::flag(const std::string& name, bool def, const std::string& help) {
  const std::string h = help + " (true/false)";
  auto s = get(name, h);
  bool v = def;
  if (s) {
    const std::string t = lower_case(*s);
    if (t.empty() || t == "true" || t == "1" || t == "yes" || t == "on")
      v = true;
    else if (t == "false" || t == "0" || t == "no" || t == "off")
      v = false;
    else
      throw UserError("-" + name + " " + shown(*s) + ": not a boolean, allowed true or false");
  }
  record(name, v ? "true" : "false", h);
  return v;
}

std::string Options::string(const std::string& name, const std::string& def,
                            const std::string& help) {
  auto s = get(name, help);
  const std::string v = s ? *s : def;
  record(name, v, help);
  return v;
}

std::string Options::choice(const std::string& name, const std::string& def,
                            const std::vector<std::string>& allowed, const std::string& help) {
  std::string all;
  for (auto& a : allowed)
    all += (all.empty() ? "" : ", ") + a;
  const std::string h = help + " (" + all + ")";
  auto s = get(name, h);
  const std::string v = s ? *s : def;
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
    std::string best;
    size_t bd = 4;
    for (auto& a : allowed)
      if (size_t d = edit_distance(v, a); d < bd) bd = d, best = a;
    throw UserError("-" + name + " " + shown(v) + ": unknown, allowed " + all +
                    (best.empty() ? "" : " (did you mean " + best + "?)"));
  }
  record(name, v, h);
  return v;
}

std::vector<std::string> Options::list(const std::string& name, const std::vector<std::string>& def,
                                       size_t min_count, size_t max_count,
                                       const std::string& help) {
  auto s = get(name, help);
  std::vector<std::string> v;
  if (s) {
    std::stringstream ss(*s);
    std::string item;
    while (std::getline(ss, item, ',')) {
      const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
      v.push_back(b == std::string::npos ? "" : item.substr(b, e - b + 1));
    }
    // "16,16," has an empty last value (getline drops it): refused like "16,,16" by the caller.
    const auto last = s->find_last_not_of(" \t");
    if (last != std::string::npos && (*s)[last] == ',') v.push_back("");
  } else {
    v = def;
  }
  if (v.size() < min_count || v.size() > max_count)
    throw UserError("-" + name + " " + shown(s ? *s : "") + ": expected " +
                    (min_count == max_count
                         ? std::to_string(min_count)
                         : std::to_string(min_count) + " to " + std::to_string(max_count)) +
                    " comma-separated values, got " + std::to_string(v.size()));
  std::string joined;
  for (auto& x : v)
    joined += (joined.empty() ? "" : ",") + x;
  record(name, joined, help);
  return v;
}

void Options::check_unused(const std::string& prefix) const {
  PetscInt n = 0;
  char** names = nullptr;
  char** values = nullptr;
  MG_PETSC(PetscOptionsLeftGet(nullptr, &n, &names, &values));
  std::string msg;
  for (PetscInt i = 0; i < n && msg.empty(); ++i) {
    const std::string name = names[i];
    if (name == "help" || name == "h") continue;
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    // Consumed later by a PETSc object (e.g. -diffusion_ksp_converged_reason at the first solve).
    if (std::find(known_.begin(), known_.end(), name) != known_.end()) continue;
    // PETSc's diagnostics (-*_view, -*_converged_reason, -*_monitor*) are read when a solve
    // ends; accept them for solver prefixes that this run has (diffusion_, ts_, snes_, ksp_).
    const auto ends_with = [&](const char* suffix) {
      const std::string sfx = suffix;
      return name.size() >= sfx.size() &&
             name.compare(name.size() - sfx.size(), sfx.size(), sfx) == 0;
    };
    const bool diagnostic = ends_with("_view") || ends_with("_converged_reason") ||
                            name.find("_monitor") != std::string::npos;
    bool prefix_known = false;
    for (const char* pre : {"diffusion_", "ts_", "snes_", "ksp_", "pc_"}) {
      const std::string p = pre;
      if (name.compare(0, p.size(), p) != 0) continue;
      for (const auto& k : known_)
        if (k.compare(0, p.size(), p) == 0) prefix_known = true;
    }
    if (diagnostic && prefix_known) continue;
    std::string best;
    size_t bd = std::max<size_t>(3, name.size() / 3) + 1;
    auto consider = [&](const std::string& cand) {
      if (size_t d = edit_distance(name, cand); d < bd) bd = d, best = cand;
    };
    for (auto& r : records_)
      consider(r.name);
    for (auto& k : known_)
      consider(k);
    msg = "-" + name;
    if (values[i]) msg.append(" ").append(values[i]);
    msg.append(": unknown option (nothing read it)");
    const std::string hint = hint_ ? hint_(name) : std::string();
    if (!hint.empty())
      msg.append("; ").append(hint);
    else if (best.empty())
      msg.append("; see -help");
    else
      msg.append("; did you mean -").append(best).append("?");
  }
  MG_PETSC(PetscOptionsLeftRestore(nullptr, &n, &names, &values));
  if (!msg.empty()) throw UserError(msg);
}

std::string Options::to_yaml(const std::string& header) const {
  std::string out = header;
  // morphogen's own options with their resolved values, then every other option that was set
  // (PETSc solver options such as -diffusion_pc_type or -ts_adapt_type), as given.
  std::vector<Record> all = records_;
  char* text = nullptr;
  MG_PETSC(PetscOptionsGetAll(nullptr, &text));
  std::stringstream ss(text ? text : "");
  MG_PETSC(PetscFree(text));
  std::string tok, name, value;
  const auto flush = [&] {
    if (name.empty() || name == "help" || name == "options_file" || name == "options_file_yaml" ||
        name == "options_left")
      return;
    for (const auto& r : all)
      if (r.name == name) return;
    // Only options something read (a "-x" inside an expression value is not an option).
    PetscBool used = PETSC_FALSE;
    MG_PETSC(PetscOptionsUsed(nullptr, ("-" + name).c_str(), &used));
    if (used) all.push_back({name, value, ""});
  };
  while (ss >> tok) {
    if (tok.size() > 1 && tok[0] == '-' && std::isalpha(static_cast<unsigned char>(tok[1]))) {
      flush();
      name = tok.substr(1);
      value.clear();
    } else {
      value += (value.empty() ? "" : " ") + tok;
    }
  }
  flush();
  for (auto& r : all) {
    std::string v;
    for (char c : r.value) {
      if (c == '"' || c == '\\') v += '\\';
      v += c;
    }
    out += r.name + ": \"" + v + "\"\n";
  }
  return out;
}

} // namespace morphogen
