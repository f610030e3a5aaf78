// Dynamic load balancing of sweep points over MPI rank groups.
//
// The world communicator is split into groups of `group_size` consecutive ranks; each group runs
// one point at a time on its own communicator. World rank 0 (also the leader of group 0) hands
// out the next point on request: other group leaders send a request (with their last point's
// run time, for the -max_walltime deadline) and block for the answer;
// rank 0 answers between the time steps of its own points (poll()) and, when it runs out of
// work, until every leader has been told to stop (drain()). No rank idles as a pure master.
#pragma once

#include <mpi.h>

#include <vector>

namespace morphogen::sweep {

class WorkQueue {
public:
  // todo: the point indices to run, in order (identical on every rank).
  WorkQueue(MPI_Comm world, int group_size, std::vector<long long> todo);
  ~WorkQueue();
  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;

  MPI_Comm group() const { return group_; }
  int groups() const { return ngroups_; }
  int group_index() const { return group_index_; }
  bool leader() const { return group_rank_ == 0; }

  // Collective on the group: the next point for this group, or -1 when there is none left.
  // last_seconds: the run time of the group's previous point (0 for none); negative: the group
  // was interrupted, and no further point is handed out to anyone.
  long long next(double last_seconds = 0);
  // No point is handed out once MPI_Wtime() + 1.5 x the longest point time reported so far
  // would pass `deadline` (world rank 0's clock). Returns whether that cut any point.
  void set_deadline(double deadline) { deadline_ = deadline; }
  bool cut_by_deadline() const { return cut_; }
  // World rank 0 only (cheap, non-blocking): answer pending requests. Others: no-op.
  void poll();
  // Collective on the world after next() returned -1: rank 0 answers until all leaders stopped.
  void drain();

private:
  long long take(double seconds);
  MPI_Comm world_, group_ = MPI_COMM_NULL;
  int world_rank_ = 0, group_rank_ = 0, ngroups_ = 1, group_index_ = 0;
  std::vector<long long> todo_;
  size_t cursor_ = 0;
  int stopped_leaders_ = 0;
  double deadline_ = 0, longest_ = 0;
  bool cut_ = false;
};

} // namespace morphogen::sweep
