#include "sweep/work_queue.hpp"

#include "core/user_error.hpp"

#include <algorithm>

namespace morphogen::sweep {

namespace {
constexpr int kTagRequest = 7101, kTagAssign = 7102;
}

WorkQueue::WorkQueue(MPI_Comm world, int group_size, std::vector<long long> todo)
    : world_(world), todo_(std::move(todo)) {
  int size = 1;
  MPI_Comm_rank(world, &world_rank_);
  MPI_Comm_size(world, &size);
  if (group_size < 1 || size % group_size != 0)
    throw UserError("-sweep_group_size " + std::to_string(group_size) +
                    ": must divide the number of ranks (" + std::to_string(size) + ")");
  ngroups_ = size / group_size;
  group_index_ = world_rank_ / group_size;
  MPI_Comm_split(world, group_index_, world_rank_, &group_);
  MPI_Comm_rank(group_, &group_rank_);
}

WorkQueue::~WorkQueue() {
  if (group_ != MPI_COMM_NULL) MPI_Comm_free(&group_);
}

long long WorkQueue::take(double seconds) {
  if (seconds < 0) cursor_ = todo_.size(); // a group was stopped by a signal: stop everyone
  longest_ = std::max(longest_, seconds);
  if (cursor_ < todo_.size() && deadline_ > 0 && MPI_Wtime() + 1.5 * longest_ > deadline_) {
    cut_ = true;
    cursor_ = todo_.size();
  }
  return cursor_ < todo_.size() ? todo_[cursor_++] : -1;
}

long long WorkQueue::next(double last_seconds) {
  long long p = -1;
  if (group_rank_ == 0) {
    if (world_rank_ == 0) {
      poll();
      p = take(last_seconds);
    } else {
      MPI_Send(&last_seconds, 1, MPI_DOUBLE, 0, kTagRequest, world_);
      MPI_Recv(&p, 1, MPI_LONG_LONG, 0, kTagAssign, world_, MPI_STATUS_IGNORE);
    }
  }
  MPI_Bcast(&p, 1, MPI_LONG_LONG, 0, group_);
  return p;
}

void WorkQueue::poll() {
  if (world_rank_ != 0) return;
  while (true) {
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, world_, &flag, &st);
    if (!flag) return;
    double seconds = 0;
    MPI_Recv(&seconds, 1, MPI_DOUBLE, st.MPI_SOURCE, kTagRequest, world_, MPI_STATUS_IGNORE);
    const long long p = take(seconds);
    if (p < 0) ++stopped_leaders_;
    MPI_Send(&p, 1, MPI_LONG_LONG, st.MPI_SOURCE, kTagAssign, world_);
  }
}

void WorkQueue::drain() {
  if (world_rank_ == 0) {
    while (stopped_leaders_ < ngroups_ - 1) {
      MPI_Status st;
      double seconds = 0;
      MPI_Recv(&seconds, 1, MPI_DOUBLE, MPI_ANY_SOURCE, kTagRequest, world_, &st);
      const long long p = take(seconds);
      if (p < 0) ++stopped_leaders_;
      MPI_Send(&p, 1, MPI_LONG_LONG, st.MPI_SOURCE, kTagAssign, world_);
    }
  }
  MPI_Barrier(world_);
}

} // namespace morphogen::sweep
