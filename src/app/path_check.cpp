#include "app/path_check.hpp"

#include <climits>
#include <filesystem>
#include <unistd.h>

namespace morphogen {

namespace {

// NAME_MAX of the file system holding the nearest existing ancestor of p (255 if unknown).
long name_max_at(const std::filesystem::path& p) {
  std::error_code ec;
  std::filesystem::path q = std::filesystem::absolute(p, ec);
  while (!q.empty() && !std::filesystem::exists(q, ec) && q != q.parent_path())
    q = q.parent_path();
  const long n = q.empty() ? -1 : pathconf(q.c_str(), _PC_NAME_MAX);
  return n > 0 ? n : 255;
}

} // namespace

std::string directory_name_problem(const std::string& dir) {
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(dir, ec);
  const size_t limit = PATH_MAX - 256;
  if (abs.native().size() > limit)
    return "path of " + std::to_string(abs.native().size()) + " characters, allowed at most " +
           std::to_string(limit);
  const long name_max = name_max_at(abs);
  for (const auto& part : abs)
    if (static_cast<long>(part.native().size()) > name_max)
      return "a directory name of " + std::to_string(part.native().size()) +
             " characters, allowed at most " + std::to_string(name_max);
  return {};
}

} // namespace morphogen
