#include "sweep/point_runner.hpp"

#include "app/pattern_summary.hpp"
#include "app/simulation.hpp"
#include "core/stop_signal.hpp"
#include "core/user_error.hpp"
#include "io/vtkhdf_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace morphogen::sweep {

std::string point_file(long long p, const char* ext) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "point_%06lld.%s", p, ext);
  return buf;
}

namespace {

// The start of point p's record: its index (and, listed, its index in the points file) and the
// axis values.
nlohmann::json record_head(const SweepSpec& spec, long long p) {
  nlohmann::json r;
  r["index"] = p;
  if (spec.listed) r["source_index"] = spec.source[static_cast<size_t>(p)];
  nlohmann::json params = nlohmann::json::object();
  const std::vector<double> values = spec.numbers(p);
  for (size_t ax = 0; ax < spec.axes.size(); ++ax)
    params[spec.axes[ax].option] = values[ax];
  r["params"] = params;
  return r;
}

// A point's time loop after its first sample: passes each ending at the next sample (every
// `every` steps) or NaN check, in advances of up to fuse_steps() steps (-explicit_fuse_steps), so
// bitwise the results of single steps. After each pass the work queue is served and the group
// agrees on the stop signal and on the pass's wall time: the next pass holds twice as many
// advances while passes take under 1 ms (up to kMaxAdvances), half as many over 5 ms, so the
// queue is answered within milliseconds however cheap or costly a step is. A diverged run (the
// class blowup) sets `diverged`. Returns false when stopped by a signal.
bool run_passes(Simulation& sim, FieldSampler& sampler, PetscInt every, WorkQueue& q, MPI_Comm comm,
                std::string& diverged) {
  constexpr PetscInt kMaxAdvances = 32;
  const PetscInt steps = sim.steps(), nan_every = sim.output().nan_check_every;
  const PetscInt fuse = sim.fuse_steps();
  PetscInt advances = 1;
  for (PetscInt n = 0; n < steps && diverged.empty();) {
    const PetscInt k =
        std::min({advances * fuse, steps - n, every - n % every, nan_every - n % nan_every});
    const double t0 = MPI_Wtime();
    try {
      for (PetscInt done = 0; done < k;) {
        const PetscInt c = std::min(fuse, k - done);
        sim.advance(c);
        done += c;
      }
      n += k;
      if (n % nan_every == 0 || n == steps) sim.check_finite();
    } catch (const UserError& e) {
      diverged = e.what();
    }
    q.poll();
    double agreed[2] = {stop_signal_received() != 0 ? 1.0 : 0.0, MPI_Wtime() - t0};
    MPI_Allreduce(MPI_IN_PLACE, agreed, 2, MPI_DOUBLE, MPI_MAX, comm);
    if (agreed[0] != 0) return false;
    if (agreed[1] < 1e-3 && advances < kMaxAdvances)
      advances *= 2;
    else if (agreed[1] > 5e-3 && advances > 1)
      advances /= 2;
    if (diverged.empty() && (n % every == 0 || n == steps)) sampler.take(sim);
  }
  return true;
}

nlohmann::json run_point_impl(const SweepSpec& spec, long long p, const SweepSettings& set,
                              WorkQueue& q, bool& interrupted) {
  MPI_Comm comm = q.group();
  interrupted = false;
  const double t0 = MPI_Wtime();
  const auto assignment = spec.assignment(p);
  for (const auto& [k, v] : assignment)
    MG_PETSC(PetscOptionsSetValue(nullptr, ("-" + k).c_str(), v.c_str()));
  Options opt(comm);
  for (const auto& k : set.known)
    opt.known(k);
  Simulation sim(comm, opt, set.base_dir);
  const Grid& g = sim.grid();
  const auto& names = sim.species();
  const int sm =
      set.species.empty()
          ? 0
          : static_cast<int>(std::find(names.begin(), names.end(), set.species) - names.begin());

  // Time loop with sampling; a diverged run is the class blowup, not an error.
  FieldSampler sampler(sm);
  const PetscInt steps = sim.steps();
  const PetscInt every = std::max<PetscInt>(1, steps / std::max<long long>(1, set.samples));
  std::string diverged;
  sampler.take(sim);
  if (!run_passes(sim, sampler, every, q, comm, diverged)) {
    interrupted = true;
    return {};
  }
  nlohmann::json c = classify_species(sim, sm, &sampler.samples(sm), diverged);
  const nlohmann::json st = stability_record(sim);

  // Fields of every species, for thumbnails and later analysis.
  const std::string file = "points/" + point_file(p, "vtkhdf");
  const std::string path = set.dir + "/" + file;
  io::H5Attributes attrs;
  attrs.reals = {{"time", sim.time()}};
  attrs.ints = {{"step", static_cast<long long>(sim.step_index())}, {"point", p}};
  attrs.strings = {{"model", sim.model().name}};
  const std::vector<double> values = spec.numbers(p);
  for (size_t ax = 0; ax < assignment.size(); ++ax)
    attrs.reals.emplace_back(assignment[ax].first, values[ax]);
  std::vector<Vec> vecs;
  for (auto& v : sim.state())
    vecs.push_back(v);
  const std::string werr = io::VtkHdfIO(g).write(path + ".tmp", names, vecs, true, attrs);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (!werr.empty()) {
    std::fprintf(stderr, "morphogen: error: writing %s failed (%s)\n", path.c_str(), werr.c_str());
    MPI_Abort(MPI_COMM_WORLD, 4);
  }
  if (rank != 0) return {};
  std::error_code ec;
  std::filesystem::rename(path + ".tmp", path, ec);
  if (ec) {
    std::fprintf(stderr, "morphogen: error: renaming %s.tmp failed (%s)\n", path.c_str(),
                 ec.message().c_str());
    MPI_Abort(MPI_COMM_WORLD, 4);
  }

  nlohmann::json r = record_head(spec, p);
  r["species"] = names[static_cast<size_t>(sm)];
  r["model"] = sim.model().name;
  r["steps"] = static_cast<long long>(sim.step_index());
  r["time"] = sim.time();
  r["cells"] = static_cast<long long>(g.global_cells());
  r["ranks"] = [&] {
    int s = 1;
    MPI_Comm_size(comm, &s);
    return s;
  }();
  r["class"] = c["class"];
  r["reason"] = c["reason"];
  r["metrics"] = c["metrics"];
  if (c.contains("dynamics")) r["dynamics"] = c["dynamics"];
  if (!st.is_null()) r["stability"] = st;
  r["file"] = file;
  r["runtime_s"] = MPI_Wtime() - t0;
  r["series"] = samples_json(sampler.samples(sm));
  return r;
}

} // namespace

nlohmann::json run_point(const SweepSpec& spec, long long p, const SweepSettings& set, WorkQueue& q,
                         bool& interrupted) {
  const double t0 = MPI_Wtime();
  try {
    return run_point_impl(spec, p, set, q, interrupted);
  } catch (const UserError& e) {
    // A combination of axis values that cannot run (validated one axis at a time, so possible):
    // the error is collective on the group; record it and go on with the other points.
    int rank = 0;
    MPI_Comm_rank(q.group(), &rank);
    if (rank != 0) return {};
    std::fprintf(stderr, "morphogen: warning: sweep point %lld: %s\n", p, e.what());
    nlohmann::json r = record_head(spec, p);
    r["class"] = "error";
    r["reason"] = e.what();
    r["runtime_s"] = MPI_Wtime() - t0;
    return r;
  }
}

} // namespace morphogen::sweep
