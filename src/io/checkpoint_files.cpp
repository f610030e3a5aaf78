#include "io/checkpoint_files.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace morphogen::io {

namespace fs = std::filesystem;

std::string checkpoint_file_name(long long step) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "checkpoint_%07lld.vtkhdf", step);
  return buf;
}

std::vector<std::pair<long long, std::string>> list_checkpoints(const std::string& dir) {
  std::vector<std::pair<long long, std::string>> out;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    const std::string pre = "checkpoint_", suf = ".vtkhdf";
    if (f.size() <= pre.size() + suf.size() || f.compare(0, pre.size(), pre) != 0 ||
        f.compare(f.size() - suf.size(), suf.size(), suf) != 0)
      continue;
    const std::string digits = f.substr(pre.size(), f.size() - pre.size() - suf.size());
    if (digits.empty() || digits.size() > 18 ||
        !std::all_of(digits.begin(), digits.end(), ::isdigit))
      continue;
    out.emplace_back(std::stoll(digits), it->path().string());
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  return out;
}

std::vector<std::string> prune_checkpoints(const std::string& dir, int keep) {
  std::vector<std::string> removed;
  const auto all = list_checkpoints(dir);
  for (size_t i = static_cast<size_t>(std::max(keep, 1)); i < all.size(); ++i) {
    std::error_code ec;
    if (fs::remove(all[i].second, ec)) removed.push_back(all[i].second);
  }
  return removed;
}

std::vector<std::string> retire_checkpoints_after(const std::string& dir, long long step) {
  std::vector<std::string> renamed;
  for (const auto& [s, path] : list_checkpoints(dir)) {
    if (s <= step) continue;
    std::error_code ec;
    std::string stale = path + ".stale";
    for (int k = 1; fs::exists(stale, ec); ++k) // never overwrite an earlier stale file
      stale = path + ".stale" + std::to_string(k);
    fs::rename(path, stale, ec);
    if (!ec) renamed.push_back(path);
  }
  return renamed;
}

} // namespace morphogen::io
