#include "app/log_file_check.hpp"

#include <filesystem>
#include <unistd.h>
#include <vector>

namespace morphogen {

namespace {

namespace fs = std::filesystem;

// Why `file` cannot be created or overwritten ("" if it can).
std::string unwritable(const std::string& file) {
  std::error_code ec;
  const fs::path p(file);
  if (fs::is_directory(p, ec)) return file + " is a directory";
  if (fs::exists(p, ec)) return access(file.c_str(), W_OK) == 0 ? "" : file + " is not writable";
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  if (!fs::exists(dir, ec)) return "directory " + dir.string() + " does not exist";
  if (!fs::is_directory(dir, ec)) return dir.string() + " is not a directory";
  if (access(dir.c_str(), W_OK | X_OK) != 0)
    return "directory " + dir.string() + " is not writable";
  return "";
}

std::vector<std::string> split_colons(const std::string& v) {
  std::vector<std::string> parts(1);
  for (char c : v)
    if (c == ':')
      parts.emplace_back();
    else
      parts.back() += c;
  return parts;
}

std::string log_view_problem(const std::string& value) {
  const std::string allowed = "; allowed: -log_view [ascii][:FILE[:FORMAT]], FILE in an existing "
                              "writable directory, FORMAT one of ascii_info, ascii_info_detail, "
                              "ascii_csv, ascii_xml, ascii_flamegraph";
  const auto parts = split_colons(value);
  if (parts[0] != "" && parts[0] != "ascii")
    return "viewer type '" + parts[0] + "' (the log is written by an ASCII viewer only)" + allowed;
  if (parts.size() > 2) {
    const std::string& f = parts[2];
    if (f != "" && f != "default" && f != "ascii_info" && f != "ascii_info_detail" &&
        f != "ascii_csv" && f != "ascii_xml" && f != "ascii_flamegraph")
      return "format '" + f + "' is not a log format" + allowed;
  }
  if (parts.size() < 2 || parts[1].empty()) return ""; // standard output
  const std::string why = unwritable(parts[1]);
  return why.empty() ? "" : why + allowed;
}

} // namespace

std::string log_file_problem(const std::string& option, const std::string& value) {
  std::string why;
  if (option == "-log_view") {
    why = log_view_problem(value);
  } else if (option == "-log_trace" && !value.empty()) {
    why = unwritable(value + ".0"); // every rank opens PREFIX.<rank> in the same directory
    if (!why.empty())
      why += "; allowed: -log_trace [PREFIX], PREFIX.<rank> in a writable directory";
  }
  return why.empty() ? "" : option + " " + value + ": " + why;
}

} // namespace morphogen
