#include "sweep/point_runner.hpp"

#include "analysis/classify.hpp"
#include "analysis/linear_stability.hpp"
#include "app/simulation.hpp"
#include "core/stop_signal.hpp"
#include "core/user_error.hpp"
#include "io/slice_gather.hpp"
#include "io/vtkhdf_file.hpp"
#include "sweep/point_record.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace morphogen::sweep {

namespace {

// Spatial mean, standard deviation, relative L2 change since `prev` (updated), centre probe.
struct Sample {
  double mean, stddev, change, probe;
};

Sample sample(const Grid& g, Vec u, std::vector<double>& prev, MPI_Comm comm) {
  const Box& ob = g.owned();
  const auto& n = g.spec().n;
  const PetscInt ci = n[0] / 2, cj = n[1] / 2, ck = g.dim() == 3 ? n[2] / 2 : 0;
  const PetscScalar* a;
  MG_PETSC(VecGetArrayRead(u, &a));
  double acc[5] = {0, 0, 0, 0, 0}; // sum, sum of squares, sum of squared change, probe, count
  const bool first = prev.empty();
  if (first) prev.resize(static_cast<size_t>(ob.size()));
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        const double v = a[g.local_index(i, j, k)];
        double& p = prev[static_cast<size_t>(g.owned_index(i, j, k))];
        acc[0] += v;
        acc[1] += v * v;
        acc[2] += first ? 0.0 : (v - p) * (v - p);
        p = v;
        if (i == ci && j == cj && k == ck) acc[3] = v;
      }
  MG_PETSC(VecRestoreArrayRead(u, &a));
  MPI_Allreduce(MPI_IN_PLACE, acc, 4, MPI_DOUBLE, MPI_SUM, comm);
  const double cells = static_cast<double>(g.global_cells());
  const double mean = acc[0] / cells;
  const double var = std::max(0.0, acc[1] / cells - mean * mean);
  const double norm = std::sqrt(acc[1]);
  return {mean, std::sqrt(var), first ? std::nan("") : std::sqrt(acc[2]) / (norm + 1e-300), acc[3]};
}

} // namespace

std::string point_file(long long p, const char* ext) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "point_%06lld.%s", p, ext);
  return buf;
}

nlohmann::json run_point(const SweepSpec& spec, long long p, const SweepSettings& set, WorkQueue& q,
                         bool& interrupted) {
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
  analysis::RunSamples samples;
  std::vector<double> prev;
  const PetscInt steps = sim.steps();
  const PetscInt every = std::max<PetscInt>(1, steps / std::max<long long>(1, set.samples));
  std::string diverged;
  auto take = [&] {
    const Sample s = sample(g, sim.state()[sm], prev, comm);
    samples.t.push_back(sim.time());
    samples.mean.push_back(s.mean);
    samples.stddev.push_back(s.stddev);
    samples.change.push_back(s.change);
    samples.probe.push_back(s.probe);
  };
  take();
  for (PetscInt n = 1; n <= steps && diverged.empty(); ++n) {
    try {
      sim.step();
      if (n % sim.output().nan_check_every == 0 || n == steps) sim.check_finite();
    } catch (const UserError& e) {
      diverged = e.what();
    }
    q.poll();
    int stop = stop_signal_received() != 0;
    MPI_Allreduce(MPI_IN_PLACE, &stop, 1, MPI_INT, MPI_LOR, comm);
    if (stop) {
      interrupted = true;
      return {};
    }
    if (diverged.empty() && (n % every == 0 || n == steps)) take();
  }

  // The final field (or its middle z slice) on the leader.
  const PetscInt kz = g.dim() == 3 ? g.spec().n[2] / 2 : 0;
  const PetscScalar* a;
  MG_PETSC(VecGetArrayRead(sim.state()[sm], &a));
  std::vector<double> field = io::gather_xy_slice(g, a, kz);
  MG_PETSC(VecRestoreArrayRead(sim.state()[sm], &a));

  // Fields of every species, for thumbnails and later analysis.
  const std::string file = "points/" + point_file(p, "vtkhdf");
  const std::string path = set.dir + "/" + file;
  io::H5Attributes attrs;
  attrs.reals = {{"time", sim.time()}};
  attrs.ints = {{"step", static_cast<long long>(sim.step_index())}, {"point", p}};
  attrs.strings = {{"model", sim.model().name}};
  for (size_t ax = 0; ax < assignment.size(); ++ax)
    attrs.reals.emplace_back(assignment[ax].first,
                             spec.axes[ax].numbers[static_cast<size_t>(spec.indices(p)[ax])]);
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

  nlohmann::json r;
  r["index"] = p;
  nlohmann::json params = nlohmann::json::object();
  for (size_t ax = 0; ax < assignment.size(); ++ax)
    params[assignment[ax].first] = spec.axes[ax].numbers[static_cast<size_t>(spec.indices(p)[ax])];
  r["params"] = params;
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
  analysis::FieldShape2D shape;
  shape.nx = static_cast<int>(g.spec().n[0]);
  shape.ny = static_cast<int>(g.spec().n[1]);
  shape.hx = g.spec().h(0);
  shape.hy = g.spec().h(1);
  shape.periodic_x = g.spec().bc[0] == Boundary::Periodic;
  shape.periodic_y = g.spec().bc[1] == Boundary::Periodic;
  const analysis::PatternMetrics m = analysis::compute_pattern_metrics(field.data(), shape);
  const analysis::RunVerdict v = analysis::classify_run(samples);
  analysis::Classification c = analysis::classify(m, &v);
  if (!diverged.empty()) {
    c.cls = analysis::PatternClass::blowup;
    c.reason = diverged;
  }
  r["class"] = analysis::to_string(c.cls);
  r["reason"] = c.reason;
  r["metrics"] = metrics_json(m);
  r["dynamics"] = verdict_json(v);

  // Linear stability of the point's (constant) parameters on this grid.
  const auto& ps = sim.params();
  if (!ps.any_field()) {
    analysis::StabilityOptions so;
    analysis::DiscreteGrid dg;
    dg.dim = g.dim();
    for (int d = 0; d < 3; ++d) {
      dg.h[d] = g.spec().h(d);
      dg.n[d] = d < g.dim() ? g.spec().n[d] : 1;
      dg.periodic[d] = g.spec().bc[d] == Boundary::Periodic;
    }
    dg.stencil = sim.stencil().name;
    so.grid = dg;
    try {
      const auto st = analysis::analyse(sim.model(), ps.scalar, sim.diffusion(), so);
      std::optional<analysis::AllowedMode> mode;
      if (st.has_steady_state) mode = analysis::fastest_allowed_mode(st, dg);
      r["stability"] = stability_json(st, mode);
    } catch (const UserError& e) {
      r["stability"] = {{"error", e.what()}};
    }
  }
  r["file"] = file;
  r["runtime_s"] = MPI_Wtime() - t0;
  r["series"] = samples_json(samples);
  return r;
}

} // namespace morphogen::sweep
