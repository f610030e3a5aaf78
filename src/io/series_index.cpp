#include "io/series_index.hpp"

#include "core/options.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace morphogen::io {

namespace {

// Step number of "<name>_<digits>.vtkhdf", or -1.
long long step_of(const std::string& file, const std::string& name) {
  const std::string pre = name + "_", suf = ".vtkhdf";
  if (file.size() <= pre.size() + suf.size() || file.compare(0, pre.size(), pre) != 0 ||
      file.compare(file.size() - suf.size(), suf.size(), suf) != 0)
    return -1;
  const std::string digits = file.substr(pre.size(), file.size() - pre.size() - suf.size());
  if (digits.empty() || digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), ::isdigit))
    return -1;
  return std::stoll(digits);
}

// One grid of the temporal collection: a 3DCoRectMesh of the cell corners (n + 1 points per
// axis, 1 along z in 2-D: VTK's flat image of nx x ny cells) from the domain's corner, whose
// Center="Cell" attributes are the file's datasets, so the bounds are the domain. Either layout
// holds one value per cell: PointData (the cell centres, Origin h/2) or CellData (the cell
// corners, Origin 0).
std::string xmf_grid(const SeriesEntry& e) {
  const auto& n = e.info.n;
  const bool flat_z = n[2] == 1; // 2-D (a 3-D grid has >= 3 cells per axis)
  std::array<long long, 3> points{};
  std::array<double, 3> origin{};
  for (int d = 0; d < 3; ++d) {
    const bool flat = d == 2 && flat_z;
    points[d] = flat ? 1 : n[d] + 1;
    origin[d] = e.info.origin[d] - (e.info.cell_data || flat ? 0.0 : 0.5 * e.info.spacing[d]);
  }
  const std::string mesh =
      std::to_string(points[2]) + " " + std::to_string(points[1]) + " " + std::to_string(points[0]);
  const std::string data =
      std::to_string(n[2]) + " " + std::to_string(n[1]) + " " + std::to_string(n[0]);
  std::ostringstream x;
  x << "   <Grid Name=\"step_" << e.step << "\" GridType=\"Uniform\">\n"
    << "    <Time Value=\"" << format_double(e.time) << "\"/>\n"
    << "    <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" << mesh << "\"/>\n"
    << "    <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
    << "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
    << format_double(origin[2]) << " " << format_double(origin[1]) << " "
    << format_double(origin[0]) << "</DataItem>\n"
    << "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">"
    << format_double(e.info.spacing[2]) << " " << format_double(e.info.spacing[1]) << " "
    << format_double(e.info.spacing[0]) << "</DataItem>\n"
    << "    </Geometry>\n";
  for (const auto& a : e.info.arrays)
    x << "    <Attribute Name=\"" << a << "\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
      << "     <DataItem Dimensions=\"" << data << "\" NumberType=\"Float\" Precision=\""
      << e.info.precision << "\" Format=\"HDF\">" << e.file << ":/VTKHDF/" << e.info.group() << "/"
      << a << "</DataItem>\n"
      << "    </Attribute>\n";
  x << "   </Grid>\n";
  return x.str();
}

} // namespace

std::string write_file_atomically(const std::string& path, const std::string& text) {
  // A temporary name of this writer's own: chunks of a sweep may write the same file at once.
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  const std::string tmp = path + ".tmp." + host + "." + std::to_string(getpid());
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.flush();
    if (!f) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      return "cannot write " + tmp;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return "cannot rename " + tmp + " to " + path + " (" + ec.message() + ")";
  return {};
}

SeriesIndex::SeriesIndex(std::string dir, std::string name)
    : dir_(std::move(dir)), name_(std::move(name)) {}

size_t SeriesIndex::load_existing(long long max_step) {
  entries_.clear();
  std::ifstream f(series_path());
  if (!f) return 0;
  nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  if (j.is_discarded() || !j.contains("files") || !j["files"].is_array()) return 0;
  for (const auto& e : j["files"]) {
    if (!e.contains("name") || !e["name"].is_string() || !e.contains("time")) continue;
    SeriesEntry s;
    s.file = e["name"].get<std::string>();
    s.step = step_of(s.file, name_);
    if (s.step < 0 || s.step > max_step || !e["time"].is_number()) continue;
    s.time = e["time"].get<double>();
    std::string why;
    auto info = inspect_vtkhdf(dir_ + "/" + s.file, why);
    if (!info) continue;
    s.info = std::move(*info);
    add(std::move(s));
  }
  return entries_.size();
}

void SeriesIndex::add(SeriesEntry entry) {
  auto it = std::find_if(entries_.begin(), entries_.end(),
                         [&](const SeriesEntry& e) { return e.step == entry.step; });
  if (it != entries_.end())
    *it = std::move(entry);
  else
    entries_.push_back(std::move(entry));
  std::sort(entries_.begin(), entries_.end(),
            [](const SeriesEntry& a, const SeriesEntry& b) { return a.step < b.step; });
}

std::string SeriesIndex::write() const {
  nlohmann::json files = nlohmann::json::array();
  for (const auto& e : entries_)
    files.push_back({{"name", e.file}, {"time", e.time}});
  const nlohmann::json series = {{"file-series-version", "1.0"}, {"files", files}};
  std::string err = write_file_atomically(
      series_path(), series.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (!err.empty()) return err;

  std::ostringstream x;
  x << "<?xml version=\"1.0\" ?>\n"
    << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
    << "<Xdmf Version=\"3.0\">\n"
    << " <Domain>\n"
    << "  <Grid Name=\"" << name_ << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& e : entries_)
    x << xmf_grid(e);
  x << "  </Grid>\n"
    << " </Domain>\n"
    << "</Xdmf>\n";
  return write_file_atomically(xmf_path(), x.str());
}

} // namespace morphogen::io
