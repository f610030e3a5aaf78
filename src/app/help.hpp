// `morphogen -help`: every option the chosen configuration read (name, current value, help with
// default and range), grouped by topic, then the options this configuration does not read
// (per-species keys such as -png_range_<species>, -split_* without -integrator split, ...) in
// their generic form, then every model with its species and parameters. PETSc's own options are
// listed by `-help petsc` (see app/command_line.hpp).
#pragma once

#include "core/options.hpp"

#include <mpi.h>
#include <vector>

namespace morphogen {

// Rank 0 of comm prints the grouped listing of the options read by `opts` (records of several
// Options objects are merged; the first record of a name wins).
void print_options_help(MPI_Comm comm, const std::vector<const Options*>& opts);

// Rank 0 prints every model of the registry with its species and parameters.
void print_models_help(MPI_Comm comm);

// For an option nothing read: which models have it, e.g. "F is a parameter of gray_scott, not
// of turing (-model gray_scott)"; "" when no model has it.
std::string other_model_hint(const std::string& option, const std::string& model);

} // namespace morphogen
