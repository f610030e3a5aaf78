// Strong scaling on this node and a weak-scaling model for clusters (see bench_scaling.hpp).
#include "bench/bench_scaling.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace morphogen {
namespace {

// Rank 0 alone runs f on PETSC_COMM_SELF while the other ranks wait; the result is broadcast.
double on_rank0(MPI_Comm comm, const std::function<double()>& f) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  double v = 0;
  if (rank == 0) v = f();
  MPI_Bcast(&v, 1, MPI_DOUBLE, 0, comm);
  return v;
}

std::string grid_text(int edge, int dim, int last_factor) {
  std::string s;
  for (int d = 0; d < dim; ++d)
    s += (d ? "," : "") + std::to_string(d == dim - 1 ? edge * last_factor : edge);
  return s;
}

void strong(MPI_Comm comm, Options& opt, const ScalingProbes& probe, int dim, double bw_all) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const int edge = dim == 2 ? 1024 : 128;
  const std::string n = grid_text(edge, dim, 1);
  const double bw1 = on_rank0(comm, [&] { return probe.stream(PETSC_COMM_SELF); });
  const double c1 = on_rank0(comm, [&] {
    Options self(PETSC_COMM_SELF);
    return probe.explicit_run(PETSC_COMM_SELF, self, n).cell_updates_per_s;
  });
  const double cp = probe.explicit_run(comm, opt, n).cell_updates_per_s;
  const double bw_ratio = bw_all / bw1, speedup = cp / c1;
  const double target = 0.9 * std::min(static_cast<double>(size), bw_ratio);
  PetscPrintf(comm,
              "scaling_strong_%dd grid=%s ranks=%d cell_updates_per_s_1rank=%.4e "
              "cell_updates_per_s_%dranks=%.4e speedup=%.2f stream_ratio=%.2f "
              "target>=0.9*min(ranks,stream_ratio)=%.2f %s\n",
              dim, n.c_str(), size, c1, size, cp, speedup, bw_ratio, target,
              speedup >= target ? "met" : "NOT met");
}

// The most balanced factorisation of P into `dim` factors (smallest largest factor).
std::array<int, 3> process_grid(int P, int dim) {
  std::array<int, 3> best = {P, 1, 1};
  for (int a = 1; a <= P; ++a) {
    if (P % a) continue;
    const int rest = P / a;
    for (int b = 1; b <= rest; ++b) {
      if (rest % b || (dim == 2 && b != rest)) continue;
      const std::array<int, 3> p = {a, b, dim == 2 ? 1 : rest / b};
      if (*std::max_element(p.begin(), p.end()) < *std::max_element(best.begin(), best.end()))
        best = p;
    }
  }
  return best;
}

// Halo of an interior rank per step: messages (one per neighbour and species) and bytes sent.
// Directions along an axis with one rank have no neighbour (periodic wrap is a local copy).
std::array<double, 2> halo_per_step(const std::array<int, 3>& p, int dim, int edge,
                                    const ProbeRun& r) {
  double msgs = 0, cells = 0;
  for (int o = 0; o < 27; ++o) {
    const int off[3] = {o % 3 - 1, (o / 3) % 3 - 1, o / 9 - 1};
    int nonzero = 0;
    bool ok = true;
    double c = 1;
    for (int d = 0; d < 3; ++d) {
      if (off[d] == 0) {
        c *= d < dim ? edge : 1;
        continue;
      }
      ok = ok && d < dim && p[d] > 1;
      ++nonzero;
      c *= r.stencil_width;
    }
    if (!ok || nonzero == 0 || (!r.box_stencil && nonzero > 1)) continue;
    msgs += r.species;
    cells += c;
  }
  return {msgs, cells * 8.0 * r.species};
}

void weak_model(MPI_Comm comm, Options& opt, const ScalingProbes& probe, int dim, double alpha,
                double beta) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const int edge = dim == 2 ? 1024 : 128;
  const double block = std::pow(static_cast<double>(edge), dim);
  const ProbeRun r = probe.explicit_run(comm, opt, grid_text(edge, dim, size));
  const double t_node = block * size / r.cell_updates_per_s;
  PetscPrintf(comm,
              "scaling_model_%dd (a model, not a measurement) block_per_rank=%d^%d "
              "t_node_ms=%.3f (measured: %d ranks of this node, one block each) alpha_us=%.2f "
              "beta_GBps_per_rank=%.3f stencil=%s width=%d species=%d\n",
              dim, edge, dim, 1e3 * t_node, size, 1e6 * alpha, beta / 1e9,
              r.box_stencil ? "box" : "star", r.stencil_width, r.species);
  for (int P : {1, 2, 16, 128, 1024, 8192}) {
    const auto p = process_grid(P, dim);
    const auto [msgs, bytes] = halo_per_step(p, dim, edge, r);
    const double t = t_node + msgs * alpha + bytes / beta;
    PetscPrintf(comm,
                "scaling_model_%dd ranks=%d process_grid=%dx%dx%d global_cells=%.3e "
                "halo_messages_per_step=%.0f halo_kB_per_step=%.1f step_ms=%.3f "
                "cell_updates_per_s=%.3e efficiency=%.3f\n",
                dim, P, p[0], p[1], p[2], block * P, msgs, bytes / 1e3, 1e3 * t, block * P / t,
                t_node / t);
  }
}

} // namespace

ScalingNetwork read_scaling_network(Options& opt) {
  ScalingNetwork net;
  net.alpha = 1e-6 * opt.real("bench_net_latency_us", 2.0, 0.0, 1e6,
                              "weak-scaling model: network latency per message, us");
  net.beta = 1e9 * opt.real("bench_net_GBps", 25.0 / 64.0, 1e-6, 1e6,
                            "weak-scaling model: network bandwidth per rank, GB/s "
                            "(default: a 200 Gb/s link shared by 64 ranks)");
  return net;
}

void bench_scaling(MPI_Comm comm, Options& opt, const ScalingProbes& probe,
                   const ScalingNetwork& net) {
  const double alpha = net.alpha, beta = net.beta;
  const double bw_all = probe.stream(comm);
  for (int dim : {2, 3})
    strong(comm, opt, probe, dim, bw_all);
  for (int dim : {2, 3})
    weak_model(comm, opt, probe, dim, alpha, beta);
}

} // namespace morphogen
