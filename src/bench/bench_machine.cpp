// The machine line of morphogen-bench (bench_machine.hpp).
#include "bench/bench_machine.hpp"

#include <petscsys.h>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace morphogen {

namespace {

// "48K", "2048K", "491520K", "32M": bytes (0 when unreadable).
double cache_size_bytes(const std::string& text) {
  std::istringstream in(text);
  double v = 0;
  char unit = 0;
  if (!(in >> v)) return 0;
  in >> unit;
  return unit == 'K'   ? v * 1024
         : unit == 'M' ? v * 1024 * 1024
         : unit == 'G' ? v * 1073741824.0
                       : v;
}

std::string first_line(const std::string& path) {
  std::ifstream f(path);
  std::string s;
  std::getline(f, s);
  return s;
}

// The data/unified caches of cpu0, by level.
void read_caches(MachineInfo& m) {
  for (int i = 0; i < 16; ++i) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(i) + "/";
    const std::string level = first_line(dir + "level"), type = first_line(dir + "type");
    if (level.empty()) break;
    if (type == "Instruction") continue;
    const double bytes = cache_size_bytes(first_line(dir + "size"));
    if (level == "1") m.l1d_bytes = bytes;
    if (level == "2") m.l2_bytes = bytes;
    if (level == "3") m.l3_bytes = bytes;
  }
}

// The first "model name" and whether "flags" lists avx512f.
void read_cpuinfo(MachineInfo& m) {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  bool flags_seen = false;
  while (std::getline(f, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, line.find_last_not_of(" \t", colon - 1) + 1);
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    if (key == "model name" && m.cpu.empty()) m.cpu = value;
    if (key == "flags" && !flags_seen) {
      flags_seen = true;
      m.avx512 = (" " + value + " ").find(" avx512f ") != std::string::npos;
    }
  }
}

} // namespace

MachineInfo read_machine_info(MPI_Comm comm) {
  MachineInfo m;
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) {
    read_cpuinfo(m);
    read_caches(m);
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    m.logical_cpus = n > 0 ? static_cast<int>(n) : 0;
  }
  MPI_Comm node;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int node_rank = 0, node_size = 1, leaders = 0;
  MPI_Comm_rank(node, &node_rank);
  MPI_Comm_size(node, &node_size);
  const int leader = node_rank == 0 ? 1 : 0;
  MPI_Allreduce(&leader, &leaders, 1, MPI_INT, MPI_SUM, comm);
  MPI_Bcast(&node_size, 1, MPI_INT, 0, comm);
  MPI_Comm_free(&node);
  m.nodes = leaders;
  m.ranks_per_node = node_size;
  return m;
}

MachineInfo print_machine(MPI_Comm comm) {
  const MachineInfo m = read_machine_info(comm);
  std::string cpu = m.cpu.empty() ? "unknown" : m.cpu;
  for (char& c : cpu)
    if (c == '"') c = '\'';
  PetscPrintf(comm,
              "machine cpu=\"%s\" logical_cpus=%d l1d_KiB=%.0f l2_KiB=%.0f l3_MiB=%.0f avx512=%s "
              "nodes=%d ranks_per_node=%d\n",
              cpu.c_str(), m.logical_cpus, m.l1d_bytes / 1024, m.l2_bytes / 1024,
              m.l3_bytes / 1048576, m.avx512 ? "yes" : "no", m.nodes, m.ranks_per_node);
  return m;
}

std::string l3_note(double cells, const MachineInfo& m) {
  const double per_node = 16.0 * cells / (m.nodes > 0 ? m.nodes : 1);
  char buf[96];
  std::snprintf(buf, sizeof buf, " state_MiB_per_node=%.4g in_l3=%s", per_node / 1048576,
                m.l3_bytes <= 0          ? "unknown"
                : per_node <= m.l3_bytes ? "yes"
                                         : "no");
  return buf;
}

} // namespace morphogen
