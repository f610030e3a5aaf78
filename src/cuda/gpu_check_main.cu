// morphogen-gpu-check: the GPU checks and bench of the explicit kernels, without PETSc or MPI
// (so it runs on a bare GPU machine; tests/gpu/run_on_gpu.sh).
//   checks: 100 explicit steps of compiled models on periodic 2-D (5pt, 9pt) and 3-D (7pt)
//           grids on the device vs the CPU row kernel; pass when max |gpu - cpu| <= 1e-12 max |cpu|
//           (device code is built with -fmad=false and the host reference without contraction,
//           so the two are expected to agree bitwise; the difference is reported).
//   bench:  Gray-Scott explicit steps at 8192^2 (2-D, 5pt) and 512^3 (3-D, 7pt) in
//           cell-updates/s, as a fraction of the roofline from the measured device-to-device
//           copy bandwidth at 32 bytes per update (2 species, 8 B read + 8 B written each).
// Usage: morphogen-gpu-check [--quick] [--out FILE]; exit 0 all checks pass, 1 a check failed,
// 77 no CUDA device (the ctest skip code), 2 bad arguments.
#include "core/hash_rng.hpp"
#include "cuda/cpu_reference.hpp"
#include "cuda/explicit_cuda.cuh"
#include "models/all_models.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace morphogen::gpu {
namespace {

#define GPU_OK(call)                                                                               \
  do {                                                                                             \
    cudaError_t e_ = (call);                                                                       \
    if (e_ != cudaSuccess) {                                                                       \
      std::fprintf(stderr, "morphogen-gpu-check: %s: %s\n", #call, cudaGetErrorString(e_));        \
      std::exit(1);                                                                                \
    }                                                                                              \
  } while (0)

struct Report {
  std::string json; // accumulated entries
  void add(const std::string& entry) { json += (json.empty() ? "  " : ",\n  ") + entry; }
};

// Coefficients and a perturbed initial state for model M (D_s = 0.1 (s + 1), h = 1).
template <class M> CellCoefficients<M::nspecies, M::nparams> coefficients(double rho) {
  CellCoefficients<M::nspecies, M::nparams> k{};
  for (int q = 0; q < M::nparams; ++q)
    k.p[q] = M::params[q].def;
  double dmax = 0;
  for (int s = 0; s < M::nspecies; ++s) {
    k.D[s] = 0.1 * (s + 1);
    k.floor[s] = M::clamp_default ? 0.0 : -INFINITY;
    dmax = std::max(dmax, k.D[s]);
  }
  k.dt = std::min(0.2 / (dmax * rho), 0.01);
  return k;
}

template <class M>
std::vector<std::vector<double>> initial_state(const GhostedBox& g, const double* p) {
  return perturbed_start<M>(g, p, [&g](int s, int i, int j, int k) {
    const auto cell = static_cast<std::uint64_t>(i + g.n[0] * (j + g.n[1] * k));
    return rng::uniform(7, s, cell) - 0.5;
  });
}

template <int NS> struct DeviceState {
  DeviceFields<NS> a{}, b{};
  explicit DeviceState(long size) {
    for (int s = 0; s < NS; ++s) {
      GPU_OK(cudaMalloc(&a.u[s], size * sizeof(double)));
      GPU_OK(cudaMalloc(&b.u[s], size * sizeof(double)));
      GPU_OK(cudaMemset(b.u[s], 0, size * sizeof(double)));
    }
  }
  ~DeviceState() {
    for (int s = 0; s < NS; ++s) {
      cudaFree(a.u[s]);
      cudaFree(b.u[s]);
    }
  }
  DeviceState(const DeviceState&) = delete;
  DeviceState& operator=(const DeviceState&) = delete;
};

template <class M, int NR, bool Box> struct Case {
  GhostedBox g;
  RowStencil rows;
  CellStencil<NR> st;
  CellCoefficients<M::nspecies, M::nparams> k;
  Case(int n, int dim, const char* stencil) : g(make_ghosted_box(n, n, n, dim)) {
    const double h[3] = {1.0, 1.0, 1.0};
    Stencil s;
    make_stencil(stencil, dim, h, s);
    to_rows(s, rows);
    st = cell_stencil<NR>(rows, g);
    k = coefficients<M>(s.spectral_radius());
  }
  // `steps` device steps from u (host); the result is copied back into u.
  void run_device(std::vector<std::vector<double>>& u, int steps) const {
    constexpr int NS = M::nspecies;
    DeviceState<NS> d(g.size());
    for (int s = 0; s < NS; ++s)
      GPU_OK(cudaMemcpy(d.a.u[s], u[s].data(), g.size() * sizeof(double), cudaMemcpyHostToDevice));
    for (int n = 0; n < steps; ++n)
      explicit_step_device<M, NR, Box>(n % 2 ? d.b : d.a, n % 2 ? d.a : d.b, g, st, k);
    GPU_OK(cudaDeviceSynchronize());
    const DeviceFields<NS>& last = steps % 2 ? d.b : d.a;
    for (int s = 0; s < NS; ++s)
      GPU_OK(cudaMemcpy(u[s].data(), last.u[s], g.size() * sizeof(double), cudaMemcpyDeviceToHost));
  }
};

// GPU vs CPU after `steps` steps; returns true when within 1e-12 of max |cpu|.
template <class M, int NR, bool Box>
bool check(const char* stencil, int dim, int n, int steps, Report& rep) {
  Case<M, NR, Box> c(n, dim, stencil);
  auto cpu = initial_state<M>(c.g, c.k.p);
  auto gpu = cpu;
  auto tmp = cpu;
  explicit_steps_host<M, NR, Box>(c.g, c.rows, c.k, steps, cpu, tmp);
  c.run_device(gpu, steps);
  double diff = 0, scale = 0;
  long differing = 0;
  for (int s = 0; s < M::nspecies; ++s)
    for (int kk = 0; kk < c.g.n[2]; ++kk)
      for (int j = 0; j < c.g.n[1]; ++j)
        for (int i = 0; i < c.g.n[0]; ++i) {
          const long q = c.g.index(i, j, kk);
          const double d = std::fabs(gpu[s][q] - cpu[s][q]);
          diff = std::isnan(d) ? INFINITY : std::max(diff, d);
          scale = std::max(scale, std::fabs(cpu[s][q]));
          differing += gpu[s][q] != cpu[s][q];
        }
  const double rel = scale > 0 ? diff / scale : diff;
  const bool ok = rel <= 1e-12;
  std::printf("check %-16s %dD %-4s %4d^%d %3d steps: max |gpu-cpu| / max |cpu| = %.3e, "
              "%ld values differ: %s\n",
              M::name, dim, stencil, n, dim, steps, rel, differing, ok ? "pass" : "FAIL");
  char e[320];
  std::snprintf(e, sizeof e,
                "{\"kind\": \"check\", \"model\": \"%s\", \"dim\": %d, \"stencil\": \"%s\", "
                "\"n\": %d, \"steps\": %d, \"max_rel_diff\": %.6e, \"values_differing\": %ld, "
                "\"pass\": %s}",
                M::name, dim, stencil, n, steps, rel, differing, ok ? "true" : "false");
  rep.add(e);
  return ok;
}

// Device-to-device copy bandwidth (bytes read + written per second) of a 1 GiB buffer.
double copy_bandwidth(long bytes) {
  void *a, *b;
  GPU_OK(cudaMalloc(&a, bytes));
  GPU_OK(cudaMalloc(&b, bytes));
  GPU_OK(cudaMemset(a, 1, bytes));
  cudaEvent_t t0, t1;
  cudaEventCreate(&t0);
  cudaEventCreate(&t1);
  GPU_OK(cudaMemcpy(b, a, bytes, cudaMemcpyDeviceToDevice)); // warm-up
  const int reps = 20;
  cudaEventRecord(t0);
  for (int r = 0; r < reps; ++r)
    cudaMemcpy(b, a, bytes, cudaMemcpyDeviceToDevice);
  cudaEventRecord(t1);
  GPU_OK(cudaEventSynchronize(t1));
  float ms = 0;
  cudaEventElapsedTime(&ms, t0, t1);
  cudaFree(a);
  cudaFree(b);
  return 2.0 * bytes * reps / (ms * 1e-3);
}

// Gray-Scott explicit steps per second on an n^dim grid, as cell-updates/s.
template <int NR, bool Box>
double bench(const char* stencil, int dim, int n, int steps, double bandwidth, Report& rep) {
  using M = models::GrayScott;
  Case<M, NR, Box> c(n, dim, stencil);
  DeviceState<2> d(c.g.size());
  for (int s = 0; s < 2; ++s) {
    GPU_OK(cudaMemset(d.a.u[s], 0, c.g.size() * sizeof(double)));
  }
  explicit_step_device<M, NR, Box>(d.a, d.b, c.g, c.st, c.k); // warm-up
  cudaEvent_t t0, t1;
  cudaEventCreate(&t0);
  cudaEventCreate(&t1);
  cudaEventRecord(t0);
  for (int k = 0; k < steps; ++k)
    explicit_step_device<M, NR, Box>(k % 2 ? d.b : d.a, k % 2 ? d.a : d.b, c.g, c.st, c.k);
  cudaEventRecord(t1);
  GPU_OK(cudaEventSynchronize(t1));
  GPU_OK(cudaGetLastError());
  float ms = 0;
  cudaEventElapsedTime(&ms, t0, t1);
  const double cells = static_cast<double>(c.g.n[0]) * c.g.n[1] * c.g.n[2];
  const double rate = cells * steps / (ms * 1e-3);
  const double roof = bandwidth / 32.0;
  std::printf("bench gray_scott %dD %-4s %5d^%d: %.3e cell-updates/s, %.3f of the copy roofline "
              "(%.3e at 32 B/update; goal >= 0.7)\n",
              dim, stencil, n, dim, rate, rate / roof, roof);
  char e[320];
  std::snprintf(e, sizeof e,
                "{\"kind\": \"bench\", \"model\": \"gray_scott\", \"dim\": %d, \"stencil\": "
                "\"%s\", \"n\": %d, \"steps\": %d, \"cell_updates_per_s\": %.6e, "
                "\"roofline_fraction\": %.4f}",
                dim, stencil, n, steps, rate, rate / roof);
  rep.add(e);
  return rate;
}

int run(bool quick, const char* out) {
  int count = 0;
  const cudaError_t err = cudaGetDeviceCount(&count);
  if (err != cudaSuccess || count == 0) {
    std::printf("morphogen-gpu-check: no CUDA device (%s): GPU checks skipped\n",
                err != cudaSuccess ? cudaGetErrorString(err) : "0 devices");
    if (out)
      if (FILE* f = std::fopen(out, "w")) {
        std::fprintf(f, "{\"skipped\": \"no CUDA device\"}\n");
        std::fclose(f);
      }
    return 77;
  }
  cudaDeviceProp prop;
  GPU_OK(cudaGetDeviceProperties(&prop, 0));
  std::printf("device: %s (sm_%d%d, %.1f GiB)\n", prop.name, prop.major, prop.minor,
              prop.totalGlobalMem / 1073741824.0);
  Report rep;
  bool ok = true;
  const int n2 = quick ? 128 : 512, n3 = quick ? 32 : 96, steps = 100;
  ok &= check<models::GrayScott, 3, false>("5pt", 2, n2, steps, rep);
  ok &= check<models::GrayScott, 3, true>("9pt", 2, n2, steps, rep);
  ok &= check<models::Brusselator, 3, true>("9pt", 2, n2, steps, rep);
  ok &= check<models::FitzHughNagumo, 3, false>("5pt", 2, n2, steps, rep);
  ok &= check<models::Barkley, 3, false>("5pt", 2, n2, steps, rep);
  ok &= check<models::GrayScott, 5, false>("7pt", 3, n3, steps, rep);
  ok &= check<models::Brusselator, 5, false>("7pt", 3, n3, steps, rep);
  const double bw = copy_bandwidth(quick ? (64L << 20) : (1L << 30));
  std::printf("device-to-device copy: %.3e B/s (read + written)\n", bw);
  char e[160];
  std::snprintf(e, sizeof e, "{\"kind\": \"copy_bandwidth\", \"bytes_per_s\": %.6e}", bw);
  rep.add(e);
  bench<3, false>("5pt", 2, quick ? 1024 : 8192, quick ? 20 : 200, bw, rep);
  bench<5, false>("7pt", 3, quick ? 64 : 512, quick ? 10 : 50, bw, rep);
  if (out) {
    FILE* f = std::fopen(out, "w");
    if (!f) {
      std::fprintf(stderr, "morphogen-gpu-check: --out %s: cannot write\n", out);
      return 1;
    }
    std::fprintf(f, "{\"device\": \"%s\", \"all_checks_pass\": %s, \"results\": [\n%s\n]}\n",
                 prop.name, ok ? "true" : "false", rep.json.c_str());
    std::fclose(f);
  }
  std::printf("%s\n", ok ? "all GPU checks pass" : "GPU checks FAILED");
  return ok ? 0 : 1;
}

} // namespace
} // namespace morphogen::gpu

int main(int argc, char** argv) {
  bool quick = false;
  const char* out = nullptr;
  for (int a = 1; a < argc; ++a) {
    if (!std::strcmp(argv[a], "--probe")) // loads and exits (tests/gpu/run_on_gpu.sh)
      return 0;
    else if (!std::strcmp(argv[a], "--quick"))
      quick = true;
    else if (!std::strcmp(argv[a], "--out") && a + 1 < argc)
      out = argv[++a];
    else {
      std::fprintf(
          stderr,
          "morphogen-gpu-check: unknown argument %s (allowed: --quick, --out FILE, --probe)\n",
          argv[a]);
      return 2;
    }
  }
  return morphogen::gpu::run(quick, out);
}
