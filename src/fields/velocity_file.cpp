#include "fields/velocity_file.hpp"

#include "core/collective_error.hpp"
#include "core/user_error.hpp"
#include "io/h5_arrays.hpp"

#include <algorithm>
#include <cmath>

namespace morphogen {

namespace {

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v)
    s += (s.empty() ? "" : ",") + x;
  return s;
}

void bcast_strings(MPI_Comm comm, std::vector<std::string>& v) {
  int count = static_cast<int>(v.size());
  MPI_Bcast(&count, 1, MPI_INT, 0, comm);
  v.resize(static_cast<size_t>(count));
  for (auto& s : v) {
    int len = static_cast<int>(s.size());
    MPI_Bcast(&len, 1, MPI_INT, 0, comm);
    s.resize(static_cast<size_t>(len));
    MPI_Bcast(s.data(), len, MPI_CHAR, 0, comm);
  }
}

} // namespace

VelocityFile::VelocityFile(const Grid& grid, Options& opt, const std::string& text,
                           const std::string& base_dir)
    : grid_(grid), text_(text) {
  const char* axes[3] = {"x", "y", "z"};
  std::vector<std::string> def;
  for (int d = 0; d < grid.dim(); ++d)
    def.push_back(std::string("velocity_") + axes[d]);
  datasets_ = opt.list("velocity_datasets", def, static_cast<size_t>(grid.dim()),
                       static_cast<size_t>(grid.dim()),
                       "datasets of the -velocity_file components, one per axis: /full/path or a "
                       "name in /VTKHDF/PointData, /VTKHDF/CellData or /");
  frames_ = read_velocity_frames(grid.comm(), opt, text, base_dir);
  // Every frame's datasets checked on rank 0 (names, types, extents), paths broadcast.
  int rank = 0;
  MPI_Comm_rank(grid.comm(), &rank);
  std::string err;
  paths_.resize(frames_.size());
  for (size_t f = 0; f < frames_.size() && rank == 0 && err.empty(); ++f) {
    const std::string why =
        io::probe_h5_arrays(frames_[f].path, datasets_, grid.spec().n, paths_[f]);
    if (!why.empty())
      err = "-velocity_file " + text +
            (frames_.size() > 1 || frames_[f].name != text ? ": file " + frames_[f].name
                                                           : std::string()) +
            " (-velocity_datasets " + joined(datasets_) + "): " + why;
  }
  throw_if_any(grid.comm(), err);
  for (auto& p : paths_)
    bcast_strings(grid.comm(), p);
  // Every frame once: finite values, and the largest speed per axis over all frames.
  for (size_t f = 0; f < frames_.size(); ++f) {
    Slot& s = slots_[f % 2];
    read_frame(f, s);
    throw_if_any(grid.comm(), check_finite(f, s));
    for (int d = 0; d < grid.dim(); ++d)
      for (double v : s.u[static_cast<size_t>(d)])
        umax_[static_cast<size_t>(d)] = std::max(umax_[static_cast<size_t>(d)], std::fabs(v));
  }
  MPI_Allreduce(MPI_IN_PLACE, umax_.data(), 3, MPI_DOUBLE, MPI_MAX, grid.comm());
}

void VelocityFile::read_frame(size_t f, Slot& slot) const {
  const std::string why = io::read_h5_block(grid_.comm(), frames_[f].path, paths_[f],
                                            grid_.spec().n, grid_.owned(), slot.u);
  if (!why.empty())
    throw UserError("-velocity_file " + text_ + ": file " + frames_[f].name + ": " + why);
  slot.frame = static_cast<long long>(f);
}

// The first non-finite value of this rank's cells, as a message ("" when all are finite).
std::string VelocityFile::check_finite(size_t f, const Slot& slot) const {
  const Box& ob = grid_.owned();
  for (int d = 0; d < grid_.dim(); ++d) {
    const auto& u = slot.u[static_cast<size_t>(d)];
    const auto it = std::find_if(u.begin(), u.end(), [](double v) { return !std::isfinite(v); });
    if (it == u.end()) continue;
    const PetscInt o = static_cast<PetscInt>(it - u.begin());
    const PetscInt i = ob.s[0] + o % ob.m[0], j = ob.s[1] + (o / ob.m[0]) % ob.m[1],
                   k = ob.s[2] + o / (ob.m[0] * ob.m[1]);
    return "-velocity_file " + text_ + ": file " + frames_[f].name + ", dataset " +
           paths_[f][static_cast<size_t>(d)] + ": value " + format_number(*it) + " at cell (" +
           std::to_string(i) + "," + std::to_string(j) + "," + std::to_string(k) +
           "): a velocity must be finite";
  }
  return {};
}

// Frame f in a slot, reading it into the slot that does not hold frame `keep` if needed.
const VelocityFile::Slot& VelocityFile::frame(size_t f, size_t keep) {
  for (const Slot& s : slots_)
    if (s.frame == static_cast<long long>(f)) return s;
  Slot& target = slots_[0].frame == static_cast<long long>(keep) ? slots_[1] : slots_[0];
  read_frame(f, target);
  return target;
}

void VelocityFile::owned(int d, double t, double* out) {
  const FrameBracket b = bracket_time(frames_, t);
  const auto& u0 = frame(b.lo, b.lo + 1).u[static_cast<size_t>(d)];
  const size_t n = u0.size();
  if (b.w == 0.0) {
    std::copy(u0.begin(), u0.end(), out);
    return;
  }
  const auto& u1 = frame(b.lo + 1, b.lo).u[static_cast<size_t>(d)];
  const double w = b.w;
  for (size_t c = 0; c < n; ++c)
    out[c] = (1.0 - w) * u0[c] + w * u1[c];
}

std::string VelocityFile::describe() const {
  const std::string ds = joined(datasets_);
  if (frames_.size() == 1) return "velocity from " + option_text() + " (" + ds + ", steady)";
  return "velocity from " + option_text() + " (" + ds + ", " + std::to_string(frames_.size()) +
         " frames, t in [" + format_number(frames_.front().time) + ", " +
         format_number(frames_.back().time) +
         "], linear in t between frames, the first/last frame held outside)";
}

} // namespace morphogen
