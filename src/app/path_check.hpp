// Checks of a directory name before anything is created under it.
#pragma once

#include <string>

namespace morphogen {

// "" when `dir` can be created whole, else why not (a name longer than the file system's
// NAME_MAX, 255 here, or a path longer than PATH_MAX - 256, left for the file names inside).
// Run before create_directories, so that a name that cannot work creates no truncated parents.
std::string directory_name_problem(const std::string& dir);

} // namespace morphogen
