#include "app/pattern_summary.hpp"

#include "analysis/classify.hpp"
#include "analysis/linear_stability.hpp"
#include "analysis/pattern_metrics.hpp"
#include "core/user_error.hpp"
#include "io/slice_gather.hpp"

#include <hdf5.h>
#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

namespace morphogen {

namespace {

nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

nlohmann::json phase_json(const analysis::PhaseMetrics& p) {
  return {{"area_fraction", num(p.area_fraction)},
          {"components", p.components},
          {"specks", p.specks},
          {"spots", p.spots},
          {"spot_area", num(p.spot_area)},
          {"spot_area_cells", num(p.spot_area_cells)},
          {"elongated", p.elongated},
          {"wrapping", p.wrapping},
          {"networks", p.networks},
          {"spot_area_fraction", num(p.spot_area_fraction)},
          {"elongated_area_fraction", num(p.elongated_area_fraction)},
          {"largest_fraction", num(p.largest_fraction)},
          {"median_elongation", num(p.median_elongation)},
          {"median_fill", num(p.median_fill)}};
}

nlohmann::json metrics_json(const analysis::PatternMetrics& m) {
  return {{"finite", m.finite},
          {"min", num(m.min)},
          {"max", num(m.max)},
          {"mean", num(m.mean)},
          {"stddev", num(m.stddev)},
          {"contrast", num(m.contrast)},
          {"wavelength", num(m.wavelength)},
          {"wavelength_cells", num(m.wavelength_cells)},
          {"peak_sharpness", num(m.peak_sharpness)},
          {"spectral_anisotropy", num(m.spectral_anisotropy)},
          {"spectral_angle_deg", num(m.spectral_angle * 180.0 / M_PI)},
          {"coherence", num(m.coherence)},
          {"threshold", num(m.threshold)},
          {"euler", m.euler},
          {"high", phase_json(m.high)},
          {"low", phase_json(m.low)}};
}

nlohmann::json verdict_json(const analysis::RunVerdict& v) {
  return {{"behaviour", analysis::to_string(v.behaviour)},
          {"period", num(v.period)},
          {"moving", v.moving},
          {"late_change", num(v.late_change)}};
}

} // namespace

namespace {

// acc += (sum v, sum v^2, sum (v - prev)^2) over the n values of a row, prev <- v. Four
// interleaved partial sums held in one 4-wide vector each (GCC / Clang vector extensions: the
// compilers do not vectorise the interleaved form themselves), so the loop has no serial
// dependence chain per value; the same sums, in the same order, as four scalar accumulators.
void add_row_sums(const double* row, double* prev, PetscInt n, double* acc) {
  typedef double v4 __attribute__((vector_size(32)));
  v4 sv{}, qv{}, cv{};
  PetscInt i = 0;
  for (; i + 4 <= n; i += 4) {
    v4 v, p;
    std::memcpy(&v, row + i, sizeof v);
    std::memcpy(&p, prev + i, sizeof p);
    const v4 d = v - p;
    sv += v;
    qv += v * v;
    cv += d * d;
    std::memcpy(prev + i, &v, sizeof v);
  }
  double s[4], q[4], c[4];
  std::memcpy(s, &sv, sizeof s);
  std::memcpy(q, &qv, sizeof q);
  std::memcpy(c, &cv, sizeof c);
  for (; i < n; ++i) {
    const double v = row[i], d = v - prev[i];
    s[0] += v;
    q[0] += v * v;
    c[0] += d * d;
    prev[i] = v;
  }
  acc[0] += (s[0] + s[1]) + (s[2] + s[3]);
  acc[1] += (q[0] + q[1]) + (q[2] + q[3]);
  acc[2] += (c[0] + c[1]) + (c[2] + c[3]);
}

} // namespace

void FieldSampler::take(Simulation& sim) {
  const Grid& g = sim.grid();
  const size_t ns = sim.state().size();
  if (samples_.empty()) {
    samples_.resize(ns);
    prev_.resize(ns);
  }
  const Box& ob = g.owned();
  const auto& n = g.spec().n;
  // The probe sits off-centre: a spiral started at the centre rotates about it.
  const PetscInt ci = n[0] / 3, cj = n[1] / 3, ck = g.dim() == 3 ? n[2] / 3 : 0;
  // Per species: sum, sum of squares, sum of squared change, probe.
  std::vector<double> acc(4 * ns, 0.0);
  const size_t s0 = only_ >= 0 ? static_cast<size_t>(only_) : 0;
  const size_t s1 = only_ >= 0 ? s0 + 1 : ns;
  const bool first = prev_[s0].empty();
  for (size_t s = s0; s < s1; ++s) {
    auto& prev = prev_[s];
    if (first) prev.resize(static_cast<size_t>(ob.size()));
    double* a4 = &acc[4 * s];
    const PetscScalar* a;
    MG_PETSC(VecGetArrayRead(sim.state()[s], &a));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        add_row_sums(a + g.local_index(ob.s[0], j, k), prev.data() + g.owned_index(ob.s[0], j, k),
                     ob.m[0], a4);
    if (first) a4[2] = 0.0;
    if (ob.contains(ci, cj, ck)) a4[3] = a[g.local_index(ci, cj, ck)];
    MG_PETSC(VecRestoreArrayRead(sim.state()[s], &a));
  }
  MPI_Allreduce(MPI_IN_PLACE, acc.data(), static_cast<int>(acc.size()), MPI_DOUBLE, MPI_SUM,
                g.comm());
  const double cells = static_cast<double>(g.global_cells());
  for (size_t s = s0; s < s1; ++s) {
    const double* a4 = &acc[4 * s];
    const double mean = a4[0] / cells;
    auto& r = samples_[s];
    r.t.push_back(sim.time());
    r.mean.push_back(mean);
    r.stddev.push_back(std::sqrt(std::max(0.0, a4[1] / cells - mean * mean)));
    r.change.push_back(first ? std::nan("") : std::sqrt(a4[2] / cells)); // RMS change per cell
    r.probe.push_back(a4[3]);
  }
}

std::vector<double> gather_species_slice(Simulation& sim, int species, int root) {
  const Grid& g = sim.grid();
  const PetscInt kz = g.dim() == 3 ? g.spec().n[2] / 2 : 0;
  const PetscScalar* a;
  MG_PETSC(VecGetArrayRead(sim.state()[species], &a));
  std::vector<double> field = io::gather_xy_slice(g, a, kz, root);
  MG_PETSC(VecRestoreArrayRead(sim.state()[species], &a));
  return field;
}

nlohmann::json classify_species(Simulation& sim, int species, const analysis::RunSamples* samples,
                                const std::string& diverged) {
  const std::vector<double> field = gather_species_slice(sim, species, 0);
  int rank = 0;
  MPI_Comm_rank(sim.grid().comm(), &rank);
  if (rank != 0) return {};
  return classify_slice(sim, field, samples, diverged);
}

nlohmann::json classify_slice(const Simulation& sim, const std::vector<double>& field,
                              const analysis::RunSamples* samples, const std::string& diverged) {
  const Grid& g = sim.grid();
  analysis::FieldShape2D shape;
  shape.nx = static_cast<int>(g.spec().n[0]);
  shape.ny = static_cast<int>(g.spec().n[1]);
  shape.hx = g.spec().h(0);
  shape.hy = g.spec().h(1);
  shape.periodic_x = g.spec().bc[0] == Boundary::Periodic;
  shape.periodic_y = g.spec().bc[1] == Boundary::Periodic;
  const analysis::PatternMetrics m = analysis::compute_pattern_metrics(field.data(), shape);
  nlohmann::json r;
  analysis::Classification c;
  if (samples && samples->t.size() >= 4) {
    const analysis::RunVerdict v = analysis::classify_run(*samples);
    c = analysis::classify(m, &v);
    r["dynamics"] = verdict_json(v);
  } else {
    c = analysis::classify(m, nullptr);
  }
  if (!diverged.empty()) {
    c.cls = analysis::PatternClass::blowup;
    c.reason = diverged;
  }
  r["class"] = analysis::to_string(c.cls);
  r["reason"] = c.reason;
  r["metrics"] = metrics_json(m);
  return r;
}

nlohmann::json stability_record(const Simulation& sim) {
  const auto& ps = sim.params();
  const Grid& g = sim.grid();
  // A parameter that varies in space (a noisy value, a ramp) is analysed at its spatial mean.
  std::vector<double> p = ps.scalar;
  std::vector<std::string> averaged;
  for (size_t q = 0; q < p.size(); ++q) {
    if (!ps.field[q].get()) continue;
    PetscScalar sum = 0;
    MG_PETSC(VecSum(ps.field[q], &sum));
    p[q] = sum / static_cast<double>(g.global_cells());
    averaged.push_back(ps.names[q]);
  }
  analysis::DiscreteGrid dg;
  dg.dim = g.dim();
  for (int d = 0; d < 3; ++d) {
    dg.h[d] = g.spec().h(d);
    dg.n[d] = d < g.dim() ? g.spec().n[d] : 1;
    dg.periodic[d] = g.spec().bc[d] == Boundary::Periodic;
  }
  dg.stencil = sim.stencil().name;
  analysis::StabilityOptions so;
  so.grid = dg;
  // Diffusion maps and tensors: each species' operator at the spatial-mean coefficients.
  const bool mean_diffusion = !sim.all_constant_diffusion();
  if (mean_diffusion)
    for (const DiffusionOperator* op : sim.operators()) {
      const Stencil st = op->mean_stencil();
      analysis::SpeciesOperator so_op;
      for (int t = 0; t < st.nterms; ++t) {
        so_op.off.push_back({st.off[t][0], st.off[t][1], st.off[t][2]});
        so_op.w.push_back(st.w[t]);
      }
      so.operators.push_back(std::move(so_op));
    }
  try {
    int states = 0;
    const auto r = analyse_states(sim.model(), p, sim.diffusion(), so, &states);
    nlohmann::json j = {{"has_steady_state", r.has_steady_state},
                        {"u_star", r.u_star},
                        {"stable_homogeneous", r.stable_homogeneous},
                        {"turing_unstable", r.turing_unstable},
                        {"hopf", r.hopf},
                        {"wave", r.oscillatory_fastest},
                        {"growth_fastest", num(r.growth_fastest)},
                        {"wavelength_fastest", num(r.wavelength_fastest)}};
    if (r.has_steady_state) {
      // The predicted pattern wavelength only where a pattern is predicted.
      const auto mode = analysis::fastest_allowed_mode(r, dg);
      j["wavelength_allowed"] = r.turing_unstable ? num(mode.wavelength) : nlohmann::json();
      j["growth_allowed"] = num(mode.growth);
    }
    j["steady_states"] = states;
    if (!averaged.empty()) j["parameters_averaged"] = averaged;
    if (mean_diffusion) {
      j["diffusion_averaged"] = true; // analysed with the spatial-mean maps / tensors
      j["direction_fastest_deg"] = num(r.direction_fastest * 180.0 / M_PI);
    }
    return j;
  } catch (const UserError& e) {
    return {{"error", e.what()}};
  }
}

analysis::StabilityResult analyse_states(const ModelEntry& model, const std::vector<double>& params,
                                         const std::vector<double>& D,
                                         const analysis::StabilityOptions& so, int* states) {
  analysis::StabilityResult own = analysis::analyse(model, params, D, so);
  if (own.turing_unstable && !states) return own; // the search would not change the answer
  const auto all = analysis::find_steady_states(model, params);
  if (states) *states = static_cast<int>(all.size());
  std::optional<analysis::StabilityResult> hopf;
  if (own.turing_unstable) return own;
  for (const auto& u : all) {
    analysis::StabilityOptions o = so;
    o.u_star = u;
    analysis::StabilityResult r = analysis::analyse(model, params, D, o);
    if (r.turing_unstable) return r;
    if (r.hopf && !hopf) hopf = std::move(r);
  }
  if (own.hopf || !hopf) return own;
  return *hopf;
}

nlohmann::json samples_json(const analysis::RunSamples& s) {
  auto arr = [](const std::vector<double>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v)
      a.push_back(num(x));
    return a;
  };
  return {{"t", arr(s.t)},
          {"mean", arr(s.mean)},
          {"stddev", arr(s.stddev)},
          {"change", arr(s.change)},
          {"probe", arr(s.probe)}};
}

nlohmann::json run_record(double wall_seconds, double cell_updates, double loop_seconds,
                          int ranks) {
  char petsc[256] = {};
  PetscGetVersion(petsc, sizeof petsc);
  std::string pv = petsc;
  while (!pv.empty() && pv.back() == ' ')
    pv.pop_back();
  unsigned maj = 0, min = 0, rel = 0;
  H5get_libversion(&maj, &min, &rel);
  const std::string hv =
      std::to_string(maj) + "." + std::to_string(min) + "." + std::to_string(rel);
  return {{"wall_time_s", num(wall_seconds)},
          {"loop_time_s", num(loop_seconds)},
          {"cell_updates", num(cell_updates)},
          {"cell_updates_per_s", num(loop_seconds > 0 ? cell_updates / loop_seconds : NAN)},
          {"ranks", ranks},
          {"versions", {{"morphogen", MORPHOGEN_VERSION}, {"petsc", pv}, {"hdf5", hv}}}};
}

} // namespace morphogen
