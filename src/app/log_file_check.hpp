// Checks of the files PETSc writes for its logging options, made before PetscInitialize so that
// a name that cannot be written fails at once (one line) instead of after the whole run (in
// PetscFinalize, with a trace) or inside PetscInitialize:
//   -log_view [ascii][:FILE[:FORMAT]]   FILE written at the end by rank 0 (PetscLogView accepts
//                                       only ASCII viewers: formats default, ascii_info,
//                                       ascii_info_detail, ascii_csv, ascii_xml, ascii_flamegraph)
//   -log_trace [PREFIX]                 PREFIX.<rank> opened by every rank at PetscInitialize
// A missing value (the next argument an option, or none) means standard output: nothing to check.
#pragma once

#include <string>

namespace morphogen {

// "" when `value` of `option` (-log_view or -log_trace) can be honoured, else the one-line
// error "-log_view VALUE: why; allowed: ...". Pure: file-system queries only, no PETSc, no MPI.
std::string log_file_problem(const std::string& option, const std::string& value);

} // namespace morphogen
