#include "fields/velocity_series.hpp"

#include "core/collective_error.hpp"
#include "core/json_depth.hpp"
#include "core/user_error.hpp"
#include "io/h5_arrays.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace morphogen {

namespace {

bool ends_with(const std::string& a, const std::string& e) {
  return a.size() >= e.size() && a.compare(a.size() - e.size(), e.size(), e) == 0;
}

// Relative to the deck's directory when it exists there, else as given.
std::string resolve(const std::string& base_dir, const std::string& file) {
  namespace fs = std::filesystem;
  if (base_dir.empty() || file.empty() || file[0] == '/') return file;
  std::error_code ec;
  const fs::path alt = fs::path(base_dir) / file;
  return fs::exists(alt, ec) ? alt.string() : file;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    v.push_back(b == std::string::npos ? "" : item.substr(b, e - b + 1));
  }
  return v;
}

// Frames of a ParaView .series JSON file (rank 0). Throws UserError.
std::vector<VelocityFrame> series_frames(const std::string& opt_text, const std::string& path) {
  const std::string where = "-velocity_file " + opt_text + ": ";
  std::ifstream f(path);
  if (!f) throw UserError(where + "no such file");
  std::stringstream ss;
  ss << f.rdbuf();
  if (const int depth = json_nesting_depth(ss.str()); depth > kMaxJsonDepth)
    throw UserError(where + "not a valid .series JSON file (nested " + std::to_string(depth) +
                    " levels deep, allowed at most " + std::to_string(kMaxJsonDepth) + ")");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ss.str());
  } catch (const nlohmann::json::exception& e) {
    throw UserError(where + "not a valid .series JSON file (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("files") || !j["files"].is_array() || j["files"].empty())
    throw UserError(where + "a .series file needs a non-empty \"files\" list of "
                            "{\"name\": FILE, \"time\": T}");
  const auto dir = std::filesystem::path(path).parent_path();
  std::vector<VelocityFrame> frames;
  for (const auto& e : j["files"]) {
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("time") ||
        !e["time"].is_number())
      throw UserError(where + "entry " + e.dump() + " is not {\"name\": FILE, \"time\": NUMBER}");
    const std::string name = e["name"].get<std::string>();
    const auto p = name.size() && name[0] == '/' ? std::filesystem::path(name) : dir / name;
    frames.push_back({p.string(), name, e["time"].get<double>()});
  }
  return frames;
}

// Frames of a comma list; times from `times` or the attribute (rank 0). Throws UserError.
std::vector<VelocityFrame> list_frames(const std::string& text, const std::string& base_dir,
                                       const std::vector<double>& times,
                                       const std::string& attribute) {
  std::vector<VelocityFrame> frames;
  for (const auto& name : split(text)) {
    if (name.empty()) throw UserError("-velocity_file " + text + ": an empty file name");
    frames.push_back({resolve(base_dir, name), name, 0.0});
  }
  if (!times.empty() && times.size() != frames.size())
    throw UserError("-velocity_times: " + std::to_string(times.size()) + " times for " +
                    std::to_string(frames.size()) + " files of -velocity_file " + text +
                    " (one time per file)");
  for (size_t f = 0; f < frames.size(); ++f) {
    if (!times.empty()) {
      frames[f].time = times[f];
      continue;
    }
    const std::string why = io::read_h5_attribute(frames[f].path, attribute, frames[f].time);
    const bool attr = why.find("attribute") != std::string::npos;
    if (!why.empty())
      throw UserError("-velocity_file " + text + ": file " + frames[f].name + ": " + why +
                      (attr ? " (the frame's time: give -velocity_times T1,T2,... or "
                              "-velocity_time_attribute /object/name)"
                            : ""));
  }
  return frames;
}

void check_times(const std::string& text, const std::vector<VelocityFrame>& frames) {
  for (size_t f = 0; f < frames.size(); ++f) {
    if (!std::isfinite(frames[f].time))
      throw UserError("-velocity_file " + text + ": file " + frames[f].name + " has time " +
                      format_number(frames[f].time) + " (a finite number is needed)");
    if (f > 0 && !(frames[f].time > frames[f - 1].time))
      throw UserError("-velocity_file " + text + ": times not increasing (" + frames[f].name +
                      " at t = " + format_number(frames[f].time) + " after " + frames[f - 1].name +
                      " at t = " + format_number(frames[f - 1].time) +
                      "; allowed: strictly increasing times)");
  }
}

void bcast_string(MPI_Comm comm, std::string& s) {
  int len = static_cast<int>(s.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, comm);
  s.resize(static_cast<size_t>(len));
  MPI_Bcast(s.data(), len, MPI_CHAR, 0, comm);
}

// The position and length of a printf integer conversion (%d, %4d, %04d) in text; npos if none.
// Throws UserError for a '%' that is not one, or for more than one.
std::pair<size_t, size_t> pattern_conversion(const std::string& text) {
  size_t at = std::string::npos, len = 0;
  for (size_t i = text.find('%'); i != std::string::npos; i = text.find('%', i + 1)) {
    size_t j = i + 1;
    while (j < text.size() && j - i <= 3 && std::isdigit(static_cast<unsigned char>(text[j])))
      ++j;
    if (j >= text.size() || text[j] != 'd' || at != std::string::npos)
      throw UserError("-velocity_file " + text +
                      ": a file pattern takes one integer conversion (%d, %4d or %04d) and no "
                      "other '%'");
    at = i;
    len = j + 1 - i;
  }
  return {at, len};
}

// PATTERN -> the comma list of the files it names for 0, 1, 2, ... (or from 1 when 0 is
// missing), up to the first missing index (rank 0). Throws UserError when none exists.
std::string expand_pattern(const std::string& text, const std::string& base_dir,
                           std::pair<size_t, size_t> conv) {
  const std::string fmt = text.substr(conv.first, conv.second);
  auto name = [&](int i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, fmt.c_str(), i);
    return text.substr(0, conv.first) + buf + text.substr(conv.first + conv.second);
  };
  auto exists = [&](int i) {
    std::error_code ec;
    return std::filesystem::exists(resolve(base_dir, name(i)), ec);
  };
  const int first = exists(0) ? 0 : 1;
  std::string list;
  for (int i = first; i < first + 100000 && exists(i); ++i)
    list += (list.empty() ? "" : ",") + name(i);
  if (list.empty())
    throw UserError("-velocity_file " + text + ": no file matches (looked for " + name(0) +
                    " and " + name(1) + (base_dir.empty() ? "" : " in " + base_dir + " and") +
                    " in the working directory)");
  return list;
}

void bcast_frames(MPI_Comm comm, std::vector<VelocityFrame>& frames) {
  int count = static_cast<int>(frames.size());
  MPI_Bcast(&count, 1, MPI_INT, 0, comm);
  frames.resize(static_cast<size_t>(count));
  for (auto& f : frames) {
    bcast_string(comm, f.path);
    bcast_string(comm, f.name);
    MPI_Bcast(&f.time, 1, MPI_DOUBLE, 0, comm);
  }
}

} // namespace

std::vector<VelocityFrame> read_velocity_frames(MPI_Comm comm, Options& opt,
                                                const std::string& given,
                                                const std::string& base_dir) {
  const auto conv = pattern_conversion(given);
  std::string text = given;
  if (conv.first != std::string::npos) { // a numbered sequence of files
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    std::string err;
    if (rank == 0) try {
        text = expand_pattern(given, base_dir, conv);
      } catch (const UserError& e) {
        err = e.what();
      }
    throw_if_any(comm, err);
    bcast_string(comm, text);
  }
  const bool series = ends_with(text, ".series");
  const bool list = !series && text.find(',') != std::string::npos;
  if (!list)
    for (const char* k : {"velocity_times", "velocity_time_attribute"})
      if (opt.is_set(k))
        throw UserError(std::string("-") + k + ": applies to a comma list of files in " +
                        "-velocity_file (here " + text +
                        (series ? ", whose .series file gives "
                                  "the times)"
                                : ", one steady file)"));
  std::vector<double> times;
  std::string attribute;
  if (list) {
    if (const auto t = opt.get("velocity_times", "times of the -velocity_file files, one per file "
                                                 "(default: from -velocity_time_attribute)"))
      for (const auto& s : split(*t))
        times.push_back(Options::parse_real("velocity_times", s));
    if (!times.empty() && opt.is_set("velocity_time_attribute"))
      throw UserError("-velocity_time_attribute: the times are given by -velocity_times; "
                      "give one of them");
    if (times.empty())
      attribute = opt.string("velocity_time_attribute", "/morphogen/time",
                             "attribute /object/name holding each -velocity_file file's time");
  }
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<VelocityFrame> frames;
  std::string err;
  if (rank == 0) {
    try {
      frames = series ? series_frames(text, resolve(base_dir, text))
               : list ? list_frames(text, base_dir, times, attribute)
                      : std::vector<VelocityFrame>{{resolve(base_dir, text), text, 0.0}};
      check_times(text, frames);
    } catch (const UserError& e) {
      err = e.what();
    }
  }
  throw_if_any(comm, err);
  bcast_frames(comm, frames);
  return frames;
}

FrameBracket bracket_time(const std::vector<VelocityFrame>& frames, double t) {
  if (frames.size() < 2 || t <= frames.front().time) return {0, 0.0};
  if (t >= frames.back().time) return {frames.size() - 1, 0.0};
  const auto it = std::upper_bound(frames.begin(), frames.end(), t,
                                   [](double x, const VelocityFrame& f) { return x < f.time; });
  const size_t lo = static_cast<size_t>(it - frames.begin()) - 1;
  const double w = (t - frames[lo].time) / (frames[lo + 1].time - frames[lo].time);
  return {lo, w};
}

} // namespace morphogen
