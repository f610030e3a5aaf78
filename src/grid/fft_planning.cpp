#include "grid/fft_planning.hpp"

#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <fftw3.h>
#include <filesystem>
#include <set>
#include <sys/file.h>
#include <unistd.h>
#include <vector>

namespace morphogen {

namespace {

FftPlanning& planning() {
  static FftPlanning p{FftEffort::Measure, default_fft_wisdom_path()};
  return p;
}

std::set<std::string>& loaded_paths() {
  static std::set<std::string> s;
  return s;
}

// The process's wisdom as last merged into the file (to skip saves that add nothing).
std::string& saved_wisdom() {
  static std::string s;
  return s;
}

std::string current_wisdom() {
  char* w = fftw_export_wisdom_to_string();
  std::string s = w ? w : "";
  fftw_free(w);
  return s;
}

// Every rank's wisdom string on rank 0 (empty elsewhere).
std::vector<std::string> gather_strings(MPI_Comm comm, const std::string& mine) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int len = static_cast<int>(mine.size());
  std::vector<int> lens(static_cast<size_t>(size)), offs(static_cast<size_t>(size), 0);
  MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, comm);
  std::string all;
  if (rank == 0) {
    for (int r = 1; r < size; ++r)
      offs[static_cast<size_t>(r)] =
          offs[static_cast<size_t>(r - 1)] + lens[static_cast<size_t>(r - 1)];
    all.resize(static_cast<size_t>(offs.back() + lens.back()));
  }
  MPI_Gatherv(mine.data(), len, MPI_CHAR, all.data(), lens.data(), offs.data(), MPI_CHAR, 0, comm);
  std::vector<std::string> out;
  if (rank == 0)
    for (int r = 0; r < size; ++r)
      out.push_back(all.substr(static_cast<size_t>(offs[static_cast<size_t>(r)]),
                               static_cast<size_t>(lens[static_cast<size_t>(r)])));
  return out;
}

// Rank 0: file <- file's wisdom + each string, under an exclusive lock; false on failure.
bool merge_into_file(const std::string& path, const std::vector<std::string>& wisdom) {
  std::error_code ec;
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path(), ec);
  const int lock = open((path + ".lock").c_str(), O_CREAT | O_RDWR, 0644);
  if (lock < 0) return false;
  bool ok = flock(lock, LOCK_EX) == 0;
  if (ok) {
    fftw_import_wisdom_from_filename(path.c_str()); // absent or unreadable: nothing to add
    for (const std::string& w : wisdom)
      if (!w.empty()) fftw_import_wisdom_from_string(w.c_str());
    const std::string tmp = path + ".tmp." + std::to_string(getpid());
    ok = fftw_export_wisdom_to_filename(tmp.c_str()) != 0 &&
         std::rename(tmp.c_str(), path.c_str()) == 0;
    if (!ok) std::remove(tmp.c_str());
  }
  flock(lock, LOCK_UN);
  close(lock);
  return ok;
}

} // namespace

std::string default_fft_wisdom_path() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
    return std::string(x) + "/morphogen/fftw_wisdom";
  if (const char* h = std::getenv("HOME"); h && *h)
    return std::string(h) + "/.cache/morphogen/fftw_wisdom";
  return "";
}

void set_fft_planning(const FftPlanning& p) {
  planning() = p;
}

const FftPlanning& fft_planning() {
  return planning();
}

unsigned fft_planner_flags() {
  switch (planning().effort) {
  case FftEffort::Estimate:
    return FFTW_ESTIMATE;
  case FftEffort::Patient:
    return FFTW_PATIENT;
  default:
    return FFTW_MEASURE;
  }
}

void fft_wisdom_load() {
  const FftPlanning& p = planning();
  if (p.effort == FftEffort::Estimate) { // wisdom would let FFTW reuse timed plans
    fftw_forget_wisdom();
    loaded_paths().clear();
    saved_wisdom().clear();
    return;
  }
  if (p.wisdom.empty() || !loaded_paths().insert(p.wisdom).second) return;
  fftw_import_wisdom_from_filename(p.wisdom.c_str());
}

bool fft_wisdom_sync(MPI_Comm comm) {
  const FftPlanning& p = planning();
  if (p.effort == FftEffort::Estimate || p.wisdom.empty()) return false;
  const std::string mine = current_wisdom();
  int changed = mine != saved_wisdom(), any = 0;
  MPI_Allreduce(&changed, &any, 1, MPI_INT, MPI_MAX, comm);
  if (!any) return false;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const std::vector<std::string> all = gather_strings(comm, changed ? mine : std::string());
  std::string merged;
  if (rank == 0) {
    static bool warned = false;
    if (!merge_into_file(p.wisdom, all) && !warned) {
      warned = true;
      std::fprintf(stderr,
                   "morphogen: warning: cannot write the FFTW wisdom file %s (-fft_wisdom); "
                   "transform plans are timed again in every run\n",
                   p.wisdom.c_str());
    }
    merged = current_wisdom();
  }
  long long len = static_cast<long long>(merged.size());
  MPI_Bcast(&len, 1, MPI_LONG_LONG, 0, comm);
  merged.resize(static_cast<size_t>(len));
  MPI_Bcast(merged.data(), static_cast<int>(len), MPI_CHAR, 0, comm);
  fftw_forget_wisdom(); // every rank now plans from exactly the file's wisdom
  fftw_import_wisdom_from_string(merged.c_str());
  saved_wisdom() = current_wisdom();
  return true;
}

} // namespace morphogen
