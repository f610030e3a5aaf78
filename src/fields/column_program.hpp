// One muParser expression's bytecode evaluated column-wise over a row of cells (see below);
// used by the custom kinetics (models/custom_model.cpp) and by field fills (fields/value_spec).
#pragma once

#include <muParser.h>

#include <cstddef>
#include <vector>

namespace morphogen {

// One expression's bytecode (muParser's reverse Polish program, ParserBase::GetByteCode())
// evaluated column-wise over a row: each token is applied to all n cells before the next, on a
// stack of columns. Every cell sees the operations of ParserBase::ParseCmdCodeBulk (muParser
// 2.3.3) in the same order, with the same function pointers, so the rates are bitwise those of
// Eval() cell by cell; this file is compiled with -ffp-contract=off so that x*c + d (cmVARMUL)
// is not fused into an FMA that the library's own loop does not use. Tokens it does not handle
// (if-then-else, assignment, string and bulk functions, functions of more than 3 fixed
// arguments) leave `ok` false: the row is then evaluated cell by cell.
//
// Why not muParser's bulk mode, Eval(results, n)? In 2.3.3 every call re-parses the expression
// (CreateRPN) and, in Debian's OpenMP build, opens a parallel region of omp_get_max_threads()
// threads (ranks x cores threads under MPI). Measured per row of 128 cells: 7-10x slower than
// the per-cell Eval it was meant to replace.
struct ColumnProgram {
  static constexpr int kMaxArgs = 64; // of a function of a variable argument count
  std::vector<mu::SToken> code;       // ends with cmEND
  std::vector<int> var;               // per token: the variable it reads (index into vars), or -1
  int depth = 0;                      // stack columns needed
  bool ok = true;

  // vars: the nvars doubles the parser's variables are bound to (DefineVar), in one array.
  ColumnProgram(const mu::ParserByteCode& bc, const double* vars, int nvars);

  // out[i] = the expression at cell i; col[v]: variable v's column; stack: depth * cap doubles.
  void eval(int n, const double* const* col, double* stack, size_t cap, double* out) const;
};

} // namespace morphogen
