#include "app/run_output.hpp"

#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/stop_signal.hpp"
#include "core/user_error.hpp"
#include "io/checkpoint_files.hpp"

#include <hdf5.h>

#include <csignal>
#include <sys/statvfs.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace morphogen {

namespace {

enum : int { kSigUsr1 = 1, kSigTerm = 2, kWallCheckpoint = 4, kWallBudget = 8 };

std::string library_versions(std::string& hdf5) {
  char petsc[256];
  PetscGetVersion(petsc, sizeof petsc);
  std::string v = petsc;
  while (!v.empty() && v.back() == ' ')
    v.pop_back();
  unsigned maj = 0, min = 0, rel = 0;
  H5get_libversion(&maj, &min, &rel);
  hdf5 = std::to_string(maj) + "." + std::to_string(min) + "." + std::to_string(rel);
  return v;
}

// The velocity's components as ghosted local Vecs (owned cells set) named velocity_x,
// velocity_y[, velocity_z], for snapshots (ParaView shows the flow beside the pattern): the
// advection stage's (-advect), else the fluid's (-fluid without -advect: `fields` gets the
// fluid's own Vecs); nothing with neither.
void velocity_fields(const Simulation& sim, std::vector<std::string>& names,
                     std::vector<VecH>& vecs, std::vector<Vec>& fields) {
  const AdvectionStage* adv = sim.advection();
  if (!adv && sim.fluid()) {
    for (const auto& [name, vec] : sim.fluid()->state())
      if (name.rfind("velocity_", 0) == 0) {
        names.push_back(name);
        fields.push_back(vec);
      }
    return;
  }
  if (!adv) return;
  const Grid& grid = sim.grid();
  const Box& ob = grid.owned();
  std::vector<double> v(static_cast<size_t>(ob.size()));
  const char* axis[3] = {"x", "y", "z"};
  for (int d = 0; d < grid.dim(); ++d) {
    adv->owned_velocity(d, v.data());
    vecs.push_back(grid.create_local());
    PetscScalar* a;
    MG_PETSC(VecGetArray(vecs.back(), &a));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
          a[grid.local_index(i, j, k)] = v[static_cast<size_t>(grid.owned_index(i, j, k))];
    MG_PETSC(VecRestoreArray(vecs.back(), &a));
    names.push_back(std::string("velocity_") + axis[d]);
    fields.push_back(vecs.back());
  }
}

// Next multiple of `every` strictly after t (with a relative tolerance for rounding).
double next_multiple(double t, double every) {
  return (std::floor(t / every * (1 + 1e-12) + 1e-9) + 1) * every;
}

std::string step_file(const std::string& name, long long step) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "_%07lld.vtkhdf", step);
  return name + buf;
}

} // namespace

RunOutput::RunOutput(MPI_Comm comm, const Options& opt, double wall_start)
    : comm_(comm), opt_(opt), wall_start_(wall_start) {
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
}

RunOutput::~RunOutput() {
  if (committed_ || options_tmp_.empty()) return;
  std::error_code ec;
  std::filesystem::remove(options_tmp_, ec);
}

void RunOutput::prepare(const Simulation& sim) {
  const std::string& dir = sim.output().dir;
  dir_ = dir;
  std::string err;
  if (rank_ == 0) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) err = "-output_dir " + dir + ": cannot create directory (" + ec.message() + ")";
  }
  throw_if_any(comm_, err);
  if (rank_ != 0) return;
  const std::string path = dir + "/options_used.yaml";
  const std::string text = opt_.to_yaml(
      "# Options of this run, resolved (morphogen " MORPHOGEN_VERSION "). Rerun with: morphogen " +
      path + "\n");
  options_tmp_ = path + ".tmp";
  std::FILE* f = std::fopen(options_tmp_.c_str(), "w");
  const bool ok = f && std::fwrite(text.data(), 1, text.size(), f) == text.size() &&
                  std::fflush(f) == 0 && fsync(fileno(f)) == 0;
  const int errnum = errno;
  if (f) std::fclose(f);
  if (!ok) {
    std::error_code rm;
    std::filesystem::remove(options_tmp_, rm);
    options_tmp_.clear();
    write_failed("options", path, std::strerror(errnum));
  }
}

void RunOutput::commit() {
  if (committed_) return;
  committed_ = true;
  if (rank_ != 0) return;
  if (!options_tmp_.empty()) {
    const std::string path = options_tmp_.substr(0, options_tmp_.size() - 4);
    std::error_code ec;
    std::filesystem::rename(options_tmp_, path, ec);
    if (ec) write_failed("options", path, "rename: " + ec.message());
  }
  if (retire_pending_) {
    retire_pending_ = false;
    for (const auto& p : io::retire_checkpoints_after(dir_, retire_after_))
      std::printf("note: %s is %s: renamed to %s.stale*\n", p.c_str(),
                  retire_after_ < 0 ? "from an earlier run" : "newer than the restart point",
                  p.c_str());
    std::fflush(stdout);
  }
}

void RunOutput::check_finite(const Simulation& sim) const {
  try {
    sim.check_finite();
  } catch (const UserError& e) {
    throw UserError(std::string(e.what()) + "; last good checkpoint: " +
                    (last_checkpoint_.empty() ? "none written by this run" : last_checkpoint_));
  }
}

void RunOutput::images_failed(const std::string& err) const {
  if (rank_ == 0) write_failed("images into", dir_ + "/", err);
  MPI_Barrier(comm_); // rank 0 aborts the job
  MPI_Abort(comm_, kExitWriteFailed);
  std::abort();
}

void RunOutput::begin(Simulation& sim, long long restart_step, PetscInt end_step) {
  const auto& out = sim.output();
  grid_ = &sim.grid();
  dir_ = out.dir;
  io_ = std::make_unique<io::VtkHdfIO>(sim.grid());
  if (!series_) {
    series_ = std::make_unique<io::SeriesIndex>(out.dir, out.name);
    if (rank_ == 0) {
      // Temporary files of a killed earlier run: never complete, remove them.
      std::error_code ec;
      for (std::filesystem::directory_iterator it(out.dir, ec), end; !ec && it != end;
           it.increment(ec)) {
        const std::string f = it->path().filename().string();
        if (f.find(".vtkhdf.tmp") != std::string::npos || f.find(".tmp.") != std::string::npos) {
          std::error_code rm;
          std::filesystem::remove(it->path(), rm);
        }
      }
      // Checkpoints of an earlier run (or newer than the restart point) are retired when this
      // run writes its first file (commit()), not before: a run that fails first leaves them.
      retire_pending_ = true;
      retire_after_ = restart_step;
      if (restart_step >= 0) {
        series_->load_existing(restart_step);
        const std::string from = out.dir + "/" + io::checkpoint_file_name(restart_step);
        std::error_code ec;
        if (std::filesystem::is_regular_file(from, ec)) last_checkpoint_ = from;
      }
      std::fflush(stdout);
    }
  }
  if (out.checkpoint_every_walltime > 0)
    next_wall_checkpoint_ = out.checkpoint_every_walltime * 60.0;
  if (out.snapshot_every_time > 0)
    next_snapshot_time_ = next_multiple(sim.time(), out.snapshot_every_time);
  if (out.checkpoint_every_time > 0)
    next_checkpoint_time_ = next_multiple(sim.time(), out.checkpoint_every_time);
  last_step_wall_ = MPI_Wtime();
  sampler_ = FieldSampler();
  // Up to 1000 samples per run; each sample ends a fused pass, so the cadence is a whole
  // number of explicit passes (a run of fused passes keeps its steps per pass).
  const PetscInt fuse = std::max<PetscInt>(1, sim.pass_depth());
  sample_every_ = std::max<PetscInt>(1, (end_step - sim.step_index()) / 1000);
  sample_every_ = (sample_every_ + fuse - 1) / fuse * fuse;
  if (out.summary) sampler_.take(sim);
  const bool periodic = out.snapshot_every > 0 || out.snapshot_every_time > 0;
  if (restart_step < 0 && sim.level() == 0 && periodic) write_snapshot(sim);
}

// Rank 0's clock decides the wall-time triggers; a signal on any rank counts. One allreduce.
int RunOutput::poll_stop_flags(const Simulation& sim) {
  const auto& out = sim.output();
  const double now = MPI_Wtime();
  const double step = now - last_step_wall_;
  last_step_wall_ = now;
  loop_seconds_ += step;
  cell_updates_ += static_cast<double>(sim.grid().global_cells());
  step_seconds_ = step_seconds_ == 0 ? step : 0.9 * step_seconds_ + 0.1 * step;
  int flags = 0;
  const int sig = stop_signal_received();
  if (sig == SIGUSR1) flags |= kSigUsr1;
  if (sig == SIGTERM) flags |= kSigTerm;
  if (rank_ == 0) {
    const double wall = now - wall_start_;
    if (out.checkpoint_every_walltime > 0 && wall >= next_wall_checkpoint_)
      flags |= kWallCheckpoint;
    // Stop while there is time for two more steps and a checkpoint write (before the first
    // write, estimated at 100 MB/s for the run's float64 fields).
    const double write = last_write_seconds_ > 0
                             ? last_write_seconds_
                             : 8.0 * static_cast<double>(sim.grid().global_cells()) *
                                   static_cast<double>(sim.species().size()) / 1e8;
    const double margin = 2 * step_seconds_ + 2 * write + 1.0;
    if (out.max_walltime > 0 && wall + margin >= out.max_walltime * 60.0) flags |= kWallBudget;
  }
  MPI_Allreduce(MPI_IN_PLACE, &flags, 1, MPI_INT, MPI_BOR, comm_);
  return flags;
}

bool RunOutput::quiet_at(const Simulation& sim, PetscInt n, double t) const {
  const auto& out = sim.output();
  const double tol = 1e-9 * sim.dt();
  if (out.snapshot_every > 0 && n % out.snapshot_every == 0) return false;
  if (out.snapshot_every_time > 0 && t >= next_snapshot_time_ - tol) return false;
  if (out.checkpoint_every > 0 && n % out.checkpoint_every == 0) return false;
  if (out.checkpoint_every_time > 0 && t >= next_checkpoint_time_ - tol) return false;
  return !(out.summary && n % sample_every_ == 0);
}

bool RunOutput::after_step(Simulation& sim) {
  const auto& out = sim.output();
  const long long n = sim.step_index();
  const double t = sim.time(), tol = 1e-9 * sim.dt();
  bool snap = out.snapshot_every > 0 && n % out.snapshot_every == 0;
  if (out.snapshot_every_time > 0 && t >= next_snapshot_time_ - tol) {
    snap = true;
    next_snapshot_time_ = next_multiple(t, out.snapshot_every_time);
  }
  bool check = out.checkpoint_every > 0 && n % out.checkpoint_every == 0;
  if (out.checkpoint_every_time > 0 && t >= next_checkpoint_time_ - tol) {
    check = true;
    next_checkpoint_time_ = next_multiple(t, out.checkpoint_every_time);
  }
  if (out.summary && n % sample_every_ == 0) sampler_.take(sim);
  const int flags = poll_stop_flags(sim);
  if (flags & kWallCheckpoint) {
    check = true;
    const double wall = MPI_Wtime() - wall_start_;
    next_wall_checkpoint_ = (std::floor(wall / (out.checkpoint_every_walltime * 60.0)) + 1) *
                            out.checkpoint_every_walltime * 60.0;
  }
  const bool stop = flags & (kSigUsr1 | kSigTerm | kWallBudget);
  if (snap) write_snapshot(sim);
  if (check || stop) write_checkpoint(sim);
  if (!stop) return false;
  stop_reason_ = (flags & kSigUsr1) ? "SIGUSR1"
                 : (flags & kSigTerm)
                     ? "SIGTERM"
                     : "the -max_walltime budget (" + format_double(out.max_walltime) + " min)";
  return true;
}

void RunOutput::print_output_times(double summary_seconds) const {
  if (rank_ != 0) return;
  std::printf("output: HDF5 snapshots %.3f s (%d file%s)\n", snapshot_seconds_, snapshots_,
              snapshots_ == 1 ? "" : "s");
  std::printf("output: PNG images %.3f s (%d file%s)\n", image_seconds_, image_files_,
              image_files_ == 1 ? "" : "s");
  if (summary_seconds >= 0) std::printf("output: summary.json %.3f s\n", summary_seconds);
  std::printf("output: checkpoints %.3f s (%d file%s)\n", checkpoint_seconds_, checkpoints_,
              checkpoints_ == 1 ? "" : "s");
  std::fflush(stdout);
}

// The class of every species, on rank 0 (null elsewhere). In rounds of up to `size` species,
// each species' field is gathered to rank s mod size (one field per rank at a time), then every
// rank classifies its own, side by side; the results go to rank 0 as JSON text (doubles
// round-trip exactly). Collective.
nlohmann::json RunOutput::classify_all(Simulation& sim) const {
  MPI_Comm comm = sim.grid().comm();
  const int ns = static_cast<int>(sim.species().size());
  std::vector<nlohmann::json> c(static_cast<size_t>(ns));
  std::string err;
  for (int first = 0; first < ns; first += size_) {
    std::vector<double> field;
    int mine = -1;
    for (int s = first; s < std::min(ns, first + size_); ++s) {
      std::vector<double> f = gather_species_slice(sim, s, s % size_);
      if (s % size_ == rank_) {
        field = std::move(f);
        mine = s;
      }
    }
    if (mine < 0) continue;
    const analysis::RunSamples* samples = sampler_.count() >= 4 ? &sampler_.samples(mine) : nullptr;
    try {
      c[static_cast<size_t>(mine)] = classify_slice(sim, field, samples, "");
    } catch (const std::exception& e) {
      err = e.what();
    }
  }
  throw_if_any(comm, err);
  collect_on_rank0(comm, c);
  if (rank_ != 0) return nullptr;
  nlohmann::json species = nlohmann::json::object();
  for (int s = 0; s < ns; ++s)
    species[sim.species()[static_cast<size_t>(s)]] = std::move(c[static_cast<size_t>(s)]);
  return species;
}

// c[s] computed on rank s mod size, moved to rank 0 as JSON text (tag s). Collective.
void RunOutput::collect_on_rank0(MPI_Comm comm, std::vector<nlohmann::json>& c) const {
  for (int s = 0; s < static_cast<int>(c.size()); ++s) {
    const int root = s % size_;
    if (root == 0 || (rank_ != 0 && rank_ != root)) continue;
    if (rank_ == root) {
      const std::string text =
          c[static_cast<size_t>(s)].dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, 0, s, comm);
      continue;
    }
    MPI_Status st;
    MPI_Probe(root, s, comm, &st);
    int len = 0;
    MPI_Get_count(&st, MPI_CHAR, &len);
    std::string text(static_cast<size_t>(len), '\0');
    MPI_Recv(text.data(), len, MPI_CHAR, root, s, comm, MPI_STATUS_IGNORE);
    c[static_cast<size_t>(s)] = nlohmann::json::parse(text);
  }
}

void RunOutput::finish(Simulation& sim) {
  write_snapshot(sim);
  if (sim.output().checkpoint_final) write_checkpoint(sim);
  if (!sim.output().summary) {
    print_output_times(-1);
    return;
  }
  const double t0 = MPI_Wtime();
  nlohmann::json species = classify_all(sim);
  nlohmann::json stability = stability_record(sim);
  if (rank_ != 0) {
    print_output_times(0);
    return;
  }
  nlohmann::json j = {
      {"model", sim.model().name},
      {"step", static_cast<long long>(sim.step_index())},
      {"time", sim.time()},
      {"species", species},
      {"stability", stability},
      {"run", run_record(MPI_Wtime() - wall_start_, cell_updates_, loop_seconds_, size_)}};
  commit();
  const std::string path = sim.output().dir + "/summary.json";
  const std::string err = io::write_file_atomically(
      path, j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  if (!err.empty()) write_failed("summary", path, err);
  std::string line;
  for (const auto& [name, c] : species.items())
    line += (line.empty() ? "" : ", ") + name + ": " + c["class"].get<std::string>();
  std::printf("pattern (summary.json): %s\n", line.c_str());
  print_output_times(MPI_Wtime() - t0);
}

void RunOutput::write_snapshot(Simulation& sim) {
  const long long n = sim.step_index();
  if (n == last_snapshot_step_) return;
  commit();
  LogScope log_scope(log_events().output);
  const double t0 = MPI_Wtime();
  const auto& out = sim.output();
  const std::string file = step_file(out.name, n);
  const std::string path = out.dir + "/" + file;
  io::H5Attributes attrs;
  attrs.reals = {{"time", sim.time()}};
  attrs.ints = {{"step", n}};
  attrs.strings = {{"model", sim.model().name}};
  std::vector<Vec> fields;
  for (auto& v : sim.state())
    fields.push_back(v);
  std::vector<std::string> names = sim.species();
  std::vector<VecH> velocity;
  velocity_fields(sim, names, velocity, fields);
  const std::string err = io_->write(path + ".tmp", names, fields, out.snapshot_single, attrs);
  if (!err.empty()) write_failed("snapshot", path, err);
  std::string index_err;
  if (rank_ == 0) {
    std::error_code ec;
    std::filesystem::rename(path + ".tmp", path, ec);
    if (ec) write_failed("snapshot", path, "rename: " + ec.message());
    std::string why;
    auto info = io::inspect_vtkhdf(path, why);
    if (!info) write_failed("snapshot", path, "cannot re-read it: " + why);
    series_->add({file, n, sim.time(), std::move(*info)});
    index_err = series_->write();
    if (!index_err.empty()) write_failed("snapshot index", series_->series_path(), index_err);
  }
  last_snapshot_step_ = n;
  snapshot_seconds_ += MPI_Wtime() - t0;
  ++snapshots_;
}

void RunOutput::write_checkpoint(Simulation& sim) {
  const long long n = sim.step_index();
  if (n == last_checkpoint_step_) return;
  check_finite(sim); // never checkpoint a diverged state as "good"
  commit();
  LogScope log_scope(log_events().output);
  const double t0 = MPI_Wtime();
  const auto& out = sim.output();
  const std::string path = out.dir + "/" + io::checkpoint_file_name(n);
  std::string hdf5;
  const std::string petsc = library_versions(hdf5);
  io::H5Attributes attrs;
  attrs.reals = {{"time", sim.time()}, {"dt", sim.dt()}};
  attrs.ints = {{"step", n},
                {"seed", static_cast<long long>(sim.seed())},
                {"nranks", size_},
                {"level", sim.level()},
                {"complete", 1}};
  attrs.strings = {{"model", sim.model().name},
                   {"options", opt_.to_yaml("# Options of the run that wrote this checkpoint\n")},
                   {"version", MORPHOGEN_VERSION},
                   {"petsc_version", petsc},
                   {"hdf5_version", hdf5}};
  std::vector<Vec> fields;
  for (auto& v : sim.state())
    fields.push_back(v);
  std::vector<std::string> names = sim.species();
  if (const FluidSolver* fluid = sim.fluid()) { // the flow, for a bitwise restart
    attrs.strings.emplace_back("fluid", fluid->kind_name());
    for (const auto& [name, vec] : fluid->state()) {
      names.push_back(name);
      fields.push_back(vec);
    }
  }
  const std::string err = io_->write(path + ".tmp", names, fields, false, attrs);
  if (!err.empty()) write_failed("checkpoint", path, err);
  if (rank_ == 0) {
    std::error_code ec;
    std::filesystem::rename(path + ".tmp", path, ec);
    if (ec) write_failed("checkpoint", path, "rename: " + ec.message());
    io::prune_checkpoints(out.dir, static_cast<int>(out.checkpoint_keep));
  }
  MPI_Barrier(comm_);
  last_checkpoint_ = path;
  last_checkpoint_step_ = n;
  last_write_seconds_ = MPI_Wtime() - t0;
  checkpoint_seconds_ += last_write_seconds_;
  ++checkpoints_;
}

void RunOutput::write_failed(const std::string& what, const std::string& path,
                             const std::string& err) const {
  std::error_code ec;
  std::filesystem::remove(path + ".tmp", ec);
  std::string msg = err;
  struct statvfs fs {};
  if (statvfs(grid_ ? std::filesystem::path(path).parent_path().c_str() : ".", &fs) == 0 &&
      fs.f_bavail * fs.f_frsize < (1u << 20))
    msg += "; " + std::to_string(fs.f_bavail * fs.f_frsize / 1024) + " KiB free on its device";
  while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' '))
    msg.pop_back();
  for (auto& c : msg)
    if (c == '\n') c = ' ';
  std::fprintf(stderr, "morphogen: error: writing %s %s failed (%s); %s\n", what.c_str(),
               path.c_str(), msg.c_str(),
               last_checkpoint_.empty()
                   ? "no checkpoint had been written"
                   : ("the last good checkpoint " + last_checkpoint_ + " is intact").c_str());
  std::fflush(stderr);
  MPI_Abort(comm_, kExitWriteFailed);
  std::abort();
}

} // namespace morphogen
