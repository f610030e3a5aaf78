#include "app/device_types.hpp"

#include "core/options.hpp"
#include "core/user_error.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace morphogen {

namespace {

const char* kGpuHowTo =
    "this morphogen and its PETSc compute on the host (Debian's PETSc has no CUDA); device "
    "types need a PETSc configured --with-cuda and the GPU path (README, section GPU)";

void read_type(Options& opt, const std::string& name, const std::string& def,
               const std::vector<std::string>& host, const std::vector<std::string>& device,
               const std::string& help) {
  const std::string v = opt.string(name, def, help);
  if (std::find(host.begin(), host.end(), v) != host.end()) return;
  if (std::find(device.begin(), device.end(), v) != device.end())
    throw UserError("-" + name + " " + shown(v) + ": " + kGpuHowTo);
  std::string allowed;
  for (const auto& h : host)
    allowed += (allowed.empty() ? "" : ", ") + h;
  throw UserError("-" + name + " " + shown(v) + ": unknown type, allowed " + allowed);
}

} // namespace

void read_device_types(Options& opt) {
  read_type(opt, "dm_vec_type", "standard", {"standard", "mpi", "seq"},
            {"cuda", "seqcuda", "mpicuda", "kokkos", "seqkokkos", "mpikokkos", "hip", "seqhip",
             "mpihip", "viennacl", "seqviennacl", "mpiviennacl"},
            "vector type of the grid: standard (host; the device types cuda, kokkos, hip need a "
            "GPU-enabled PETSc)");
  read_type(opt, "dm_mat_type", "aij", {"aij", "mpiaij", "seqaij"},
            {"aijcusparse", "seqaijcusparse", "mpiaijcusparse", "aijkokkos", "seqaijkokkos",
             "mpiaijkokkos", "aijhipsparse", "aijviennacl"},
            "matrix type of the implicit solves: aij (host; aijcusparse, aijkokkos need a "
            "GPU-enabled PETSc)");
}

} // namespace morphogen
