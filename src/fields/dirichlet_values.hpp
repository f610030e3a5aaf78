// Dirichlet boundary values of the species on the faces of the Dirichlet axes:
//
//   u_s = g_s(x, t)   on every face normal to an axis with -grid_bc dirichlet
//
// g_s is a ValueSpec evaluated at the face position (the face's coordinate on its axis, the
// cell centres on the others; periodic images share values), written into one FaceValues per
// species in the layout of Halo::face_index. Values constant in time are evaluated once at
// setup; set_time(t) re-evaluates those using t (nothing when t is the last time evaluated), so
// runs without t keep their cost. Collective: an expression error on any rank stops every rank
// with the same one-line message.
#pragma once

#include "fields/value_spec.hpp"
#include "grid/halo.hpp"

#include <memory>
#include <vector>

namespace morphogen {

class DirichletValues {
public:
  // `out`: one FaceValues per species, filled here (kept by reference, as are grid and halo).
  DirichletValues(const Grid& grid, const Halo& halo, std::vector<FaceValues>& out);
  // Species s follows g (evaluated now at t = 0). Collective.
  void add(int s, std::unique_ptr<ValueSpec> g);
  bool time_dependent() const;
  // Re-evaluate the values using t at t; true when any changed. Collective.
  bool set_time(double t);
  const std::vector<FaceValues>& values() const { return out_; }

private:
  void fill(int s, ValueSpec& g, double t);

  const Grid& grid_;
  const Halo& halo_;
  std::vector<FaceValues>& out_;
  std::vector<std::pair<int, std::unique_ptr<ValueSpec>>> timed_;
  double last_t_ = 0;
};

} // namespace morphogen
